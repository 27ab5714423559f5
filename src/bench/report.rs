//! The study's outputs: `bench.csv` (one line per row), `bench.md` (the presets, each
//! scene's knee and every row by scene), `bench.svg` (drawn by `plot`) and the
//! summary for the terminal.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;

use super::analysis::{fixed_spp_time_for, knee, plain_row, scene_names};
use super::plot::plot;
use super::{BenchOptions, Errors, Row, Setting};
use crate::settings::{Adaptive, Precision, Quality};

/// The CSV header; [`Row::csv`] fills every column.
pub const CSV_HEADER: &str = "scene,setting,preset,precision,spp,adaptive_threshold,cutoff,\
max_depth,runs,median_s,min_s,rays,refined_share,rmse_levels,psnr_db,\
share_off_by_more_than_1,max_error_levels,flip_mean,cutoff_bound_levels,\
cutoff_error_levels,pareto";

impl Row {
    /// The row as a line of `bench.csv`, in the columns of [`CSV_HEADER`].
    pub fn csv(&self) -> String {
        let q = &self.setting.quality;
        format!(
            "{},{},{},{},{},{},{},{},{},{:.6},{:.6},{},{:.4},{:.4},{:.2},{:.6},{},{:.5},{:.3},{},{}",
            self.scene,
            q.label(),
            self.setting.preset.map_or("none", |p| p.name()),
            precision_name(q.precision),
            q.spp,
            q.adaptive
                .map_or("off".to_string(), |a| a.threshold.to_string()),
            q.cutoff,
            q.max_depth,
            self.runs,
            self.median_s,
            self.min_s,
            self.rays,
            self.refined,
            self.errors.rmse,
            self.errors.psnr,
            self.errors.off_by_more_than_1,
            self.errors.max,
            self.errors.flip,
            self.cutoff_bound,
            self.cutoff_error,
            self.pareto
        )
    }
}

impl Row {
    /// A line of `bench.csv` read back (the values as rounded there); `None` if it is
    /// not one.
    pub fn from_csv(line: &str) -> Option<Row> {
        let f: Vec<&str> = line.trim_end().split(',').collect();
        let [scene, _label, preset, precision, spp, adaptive, cutoff, max_depth, runs, median_s, min_s, rays, refined, rmse, psnr, off, max, flip, cutoff_bound, cutoff_error, pareto] =
            f.as_slice()
        else {
            return None;
        };
        let quality = Quality {
            spp: spp.parse().ok()?,
            adaptive: match *adaptive {
                "off" => None,
                t => Some(Adaptive::with_threshold(t.parse().ok()?)),
            },
            cutoff: cutoff.parse().ok()?,
            max_depth: max_depth.parse().ok()?,
            precision: match *precision {
                "f32" => Precision::Fast,
                "f64" => Precision::Reference,
                _ => return None,
            },
        };
        Some(Row {
            scene: scene.to_string(),
            setting: Setting {
                quality,
                preset: match *preset {
                    "none" => None,
                    name => Some(name.parse().ok()?),
                },
            },
            runs: runs.parse().ok()?,
            median_s: median_s.parse().ok()?,
            min_s: min_s.parse().ok()?,
            rays: rays.parse().ok()?,
            refined: refined.parse().ok()?,
            errors: Errors {
                rmse: rmse.parse().ok()?,
                psnr: psnr.parse().ok()?,
                off_by_more_than_1: off.parse().ok()?,
                max: max.parse().ok()?,
                flip: flip.parse().ok()?,
            },
            cutoff_bound: cutoff_bound.parse().ok()?,
            cutoff_error: cutoff_error.parse().ok()?,
            pareto: pareto.parse().ok()?,
        })
    }
}

/// Draws `bench.svg` in `out` again from the `bench.csv` there, without measuring.
pub fn replot(out: &Path) -> anyhow::Result<()> {
    let path = out.join("bench.csv");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let rows = text
        .lines()
        .enumerate()
        .skip(1)
        .map(|(n, line)| {
            Row::from_csv(line)
                .with_context(|| format!("{}:{}: not a row of the study", path.display(), n + 1))
        })
        .collect::<anyhow::Result<Vec<Row>>>()?;
    plot(&rows, &out.join("bench.svg"))
}

fn precision_name(r: Precision) -> &'static str {
    match r {
        Precision::Fast => "f32",
        Precision::Reference => "f64",
    }
}

/// `bench.csv`: the header, then one line per row.
fn csv(rows: &[Row]) -> String {
    let mut csv = String::from(CSV_HEADER);
    csv.push('\n');
    for r in rows {
        csv += &r.csv();
        csv.push('\n');
    }
    csv
}

/// `bench.md`: the presets against the plain setting and fixed spp, each scene's knee,
/// then every row of each scene by time.
fn markdown(rows: &[Row], opts: &BenchOptions) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Run time against error\n\n{}x{} pixels, median of at least {} timed runs after an \
         untimed one (more, up to 10×, for settings that take milliseconds), threads: {}. Error \
         against the converged reference (f64, 256 stratified spp, depth 16), both clamped \
         to [0,1]; RMSE and max in 8-bit levels; FLIP mean in [0,1]. ★ = on the scene's \
         Pareto front of (time, RMSE).\n",
        opts.width,
        opts.height,
        opts.runs,
        opts.threads.map_or("all".to_string(), |t| t.to_string())
    );
    let _ = writeln!(md, "## Presets\n");
    let _ = writeln!(
        md,
        "| scene | preset | setting | time ms | RMSE | PSNR dB | >1 level | max | FLIP | \
         vs 1 spp | vs fixed spp, same depth and RMSE |\n|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for name in scene_names(rows) {
        let plain = plain_row(rows, &name);
        for r in rows
            .iter()
            .filter(|r| r.scene == name && r.setting.preset.is_some())
        {
            let vs_plain = plain.map_or("-".to_string(), |p| {
                format!("{:.2}× the time", r.median_s / p.median_s)
            });
            let vs_fixed =
                fixed_spp_time_for(rows, &name, r.setting.quality.max_depth, r.errors.rmse)
                    .map_or("outside the sweep".to_string(), |t| {
                        format!("{:.2}× the time ({:.1} ms)", r.median_s / t, t * 1e3)
                    });
            let _ = writeln!(
                md,
                "| {} | {} | `{}` | {:.1} | {:.3} | {:.1} | {:.3}% | {} | {:.4} | {} | {} |",
                name,
                r.setting.preset.map_or("", |p| p.name()),
                r.setting.quality.label(),
                r.median_s * 1e3,
                r.errors.rmse,
                r.errors.psnr,
                r.errors.off_by_more_than_1 * 100.0,
                r.errors.max,
                r.errors.flip,
                vs_plain,
                vs_fixed
            );
        }
    }
    let _ = writeln!(
        md,
        "\nKnee of each front (time and RMSE scaled to [0,1] between the plain setting, \
         1 spp at depth 5, and the cheapest front point within 10% of the best RMSE; the \
         knee is the front point farthest below the line joining them):\n"
    );
    for name in scene_names(rows) {
        if let Some(k) = knee(rows, &name) {
            let _ = writeln!(
                md,
                "- {name}: `{}` ({:.1} ms, RMSE {:.3})",
                k.setting.quality.label(),
                k.median_s * 1e3,
                k.errors.rmse
            );
        }
    }
    for name in scene_names(rows) {
        let _ = writeln!(md, "\n## {name}\n");
        let _ = writeln!(
            md,
            "| setting | preset | time ms | rays | refined | RMSE | PSNR dB | >1 level | max | \
             FLIP | cutoff bound | cutoff error | front |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        );
        let mut these: Vec<&Row> = rows.iter().filter(|r| r.scene == name).collect();
        these.sort_by(|a, b| a.median_s.total_cmp(&b.median_s));
        for r in these {
            let _ = writeln!(
                md,
                "| `{}` | {} | {:.1} | {} | {:.0}% | {:.3} | {:.1} | {:.3}% | {} | {:.4} | {:.2} | {} | {} |",
                r.setting.quality.label(),
                r.setting.preset.map_or("", |p| p.name()),
                r.median_s * 1e3,
                r.rays,
                r.refined * 100.0,
                r.errors.rmse,
                r.errors.psnr,
                r.errors.off_by_more_than_1 * 100.0,
                r.errors.max,
                r.errors.flip,
                r.cutoff_bound,
                r.cutoff_error,
                if r.pareto { "★" } else { "" }
            );
        }
    }
    md
}

/// A few lines for the terminal: where the outputs went and each preset's figures.
pub fn summary(rows: &[Row], out: &Path) -> String {
    let mut s = String::new();
    for f in ["bench.csv", "bench.md", "bench.svg"] {
        let _ = writeln!(s, "wrote {}", out.join(f).display());
    }
    for r in rows.iter().filter(|r| r.setting.preset.is_some()) {
        let _ = writeln!(
            s,
            "{:<10} {:<9} {:>9.1} ms  RMSE {:>6.3} levels  >1 level {:>6.3}%  max {:>3}",
            r.scene,
            r.setting.preset.map_or("", |p| p.name()),
            r.median_s * 1e3,
            r.errors.rmse,
            r.errors.off_by_more_than_1 * 100.0,
            r.errors.max
        );
    }
    s
}

/// Writes `bench.csv`, `bench.md` and `bench.svg` into `opts.out`.
pub(crate) fn write_all(rows: &[Row], opts: &BenchOptions) -> anyhow::Result<()> {
    write(&opts.out.join("bench.csv"), &csv(rows))?;
    write(&opts.out.join("bench.md"), &markdown(rows, opts))?;
    plot(rows, &opts.out.join("bench.svg"))
}

fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_csv_reads_back_line_for_line() {
        let text = include_str!("../../assets/bench/bench.csv");
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some(CSV_HEADER));
        for line in lines {
            let row = Row::from_csv(line).unwrap_or_else(|| panic!("{line}"));
            assert_eq!(row.csv(), line);
        }
        assert_eq!(Row::from_csv("hw3,fast-spp1-d5,draft"), None);
    }
}
