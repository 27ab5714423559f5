//! The run-time/error study behind the quality presets (`whitted bench`): a grid of
//! quality settings rendered on several scenes, each timed (median of several runs) and
//! compared with a converged reference (the `f64` tracer, 256 stratified samples per
//! pixel, depth 16). Writes `bench.csv`, `bench.md` and `bench.svg` (time against
//! error with the Pareto front of each scene marked).

use std::collections::hash_map::DefaultHasher;
use std::fmt::Write as _;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use glam::{DVec3, Vec3};

use crate::image_io::{to_byte, to_rgb8};
use crate::render::{render_bounded, Frame, RenderControl};
use crate::scene::{hw3_scene, many_scene, Scene, HW3_DEFAULT_SEED};
use crate::settings::{Adaptive, Preset, Quality};
use crate::settings::{Precision, Settings};

/// A scene of the study.
#[derive(Clone, Debug)]
pub struct BenchScene {
    pub name: String,
    pub scene: Scene,
}

/// The scenes of the study: the built-in hw3; "stress", hw3 on a ground sphere of
/// radius 1e5 (grazing precision); "many_N", N small random balls on a large ground
/// (many tiny features: aliasing everywhere); "glass", hw3 with every ball glassy
/// (long transmission chains, where depth and the cutoff matter).
pub fn study_scenes(tiny: bool) -> Vec<BenchScene> {
    let hw3 = hw3_scene(HW3_DEFAULT_SEED);

    let mut stress = hw3.clone();
    stress.name = "stress".into();
    stress.spheres[0].center = DVec3::new(0.0, -1e5 - 0.5, -2.0);
    stress.spheres[0].radius = 1e5;

    let mut glass = hw3.clone();
    glass.name = "glass".into();
    for s in glass.spheres.iter_mut().skip(1) {
        // Transmission only: with a reflected branch too, every glass hit doubles the
        // rays and the depth-16 reference becomes exponentially slow.
        s.transmit = 0.9;
        s.reflect = 0.0;
        s.ior = 1.5;
    }

    let n = if tiny { 50 } else { 1000 };
    vec![
        BenchScene {
            name: "hw3".into(),
            scene: hw3,
        },
        BenchScene {
            name: "stress".into(),
            scene: stress,
        },
        BenchScene {
            name: format!("many_{n}"),
            scene: many_scene(n),
        },
        BenchScene {
            name: "glass".into(),
            scene: glass,
        },
    ]
}

/// One setting of the grid; `preset` names it when it is a preset's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    pub quality: Quality,
    pub preset: Option<Preset>,
}

fn fast(spp: u32, threshold: Option<f32>, cutoff: f32, max_depth: u32) -> Quality {
    Quality {
        spp,
        adaptive: threshold.map(Adaptive::with_threshold),
        cutoff,
        max_depth,
        precision: Precision::Fast,
    }
}

/// The settings measured on every scene. Each knob is swept alone from the plain
/// setting (1 spp, depth 5, exact), then a few combinations, then the presets (the
/// reference preset is the converged reference itself, rendered once per scene).
pub fn grid(tiny: bool) -> Vec<Setting> {
    let mut qs: Vec<Quality> = Vec::new();
    if tiny {
        qs.push(fast(1, None, 0.0, 5));
        qs.push(fast(4, Some(0.05), 0.0, 5));
        qs.push(fast(1, None, 0.05, 3));
    } else {
        // Square counts (and 2) only: the stratification fills an n×n grid of cells,
        // and other counts leave part of its last row empty (a bias the study showed).
        for spp in [1, 2, 4, 9, 16, 36, 64] {
            qs.push(fast(spp, None, 0.0, 5));
        }
        for spp in [16, 64] {
            for t in [0.01, 0.03, 0.1] {
                qs.push(fast(spp, Some(t), 0.0, 5));
            }
        }
        for eps in [0.01, 0.05, 0.2] {
            qs.push(fast(1, None, eps, 5));
        }
        for d in [1, 2, 3, 4, 8, 16] {
            qs.push(fast(1, None, 0.0, d));
        }
        // Fixed spp at depth 16, the comparison for the presets (same depth, no
        // adaptive sampling); 1 spp at depth 16 is in the depth sweep.
        for spp in [4, 9, 16, 36, 64] {
            qs.push(fast(spp, None, 0.0, 16));
        }
        qs.push(fast(9, Some(0.03), 0.0, 16));
        qs.push(fast(16, Some(0.1), 0.0, 16));
        qs.push(fast(16, Some(0.03), 0.0, 16));
        qs.push(fast(16, Some(0.03), 0.01, 16));
        qs.push(fast(64, Some(0.03), 0.0, 16));
        qs.push(fast(64, Some(0.01), 0.0, 16));
        qs.push(Quality {
            precision: Precision::Reference,
            ..fast(1, None, 0.0, 5)
        });
    }
    let mut settings: Vec<Setting> = qs
        .into_iter()
        .map(|quality| Setting {
            quality,
            preset: None,
        })
        .collect();
    for p in [Preset::Draft, Preset::Default, Preset::High] {
        let q = p.quality();
        match settings.iter_mut().find(|s| s.quality == q) {
            Some(s) => s.preset = Some(p),
            None => settings.push(Setting {
                quality: q,
                preset: Some(p),
            }),
        }
    }
    settings
}

/// How the study runs.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Where bench.csv, bench.md, bench.svg and the reference cache go.
    pub out: PathBuf,
    pub width: u32,
    pub height: u32,
    /// Timed runs per setting, at least (5 for the published study); fast settings
    /// get more, up to ten times as many.
    pub runs: usize,
    /// The small grid and scenes (for tests).
    pub tiny: bool,
    pub threads: Option<usize>,
    /// Show a progress bar on stderr.
    pub progress: bool,
}

/// Errors of an image against the reference, both clamped to [0,1] as displayed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Errors {
    /// Root mean square error over pixels and channels, in 8-bit levels.
    pub rmse: f64,
    /// 20·log10(255 / rmse) in dB (infinite for identical images).
    pub psnr: f64,
    /// Share of pixels with a channel more than one 8-bit level off.
    pub off_by_more_than_1: f64,
    /// The largest difference of any channel, in 8-bit levels.
    pub max: u32,
    /// Mean FLIP error (NVIDIA's perceptual metric, 0 = identical, 1 = most different),
    /// on the 8-bit images as displayed.
    pub flip: f64,
}

/// Measures `test` against `reference` (same size).
pub fn compare(test: &Frame, reference: &Frame) -> Errors {
    assert_eq!(
        (test.width, test.height),
        (reference.width, reference.height),
        "images of different sizes"
    );
    let shown = |c: f32| f64::from(c.clamp(0.0, 1.0)) * 255.0;
    let mut sq = 0.0;
    let mut off = 0usize;
    let mut max = 0u32;
    for (a, b) in test.pixels.iter().zip(&reference.pixels) {
        let mut pixel_off = false;
        for c in 0..3 {
            let d = shown(a[c]) - shown(b[c]);
            sq += d * d;
            let levels = u32::from(to_byte(a[c]).abs_diff(to_byte(b[c])));
            max = max.max(levels);
            pixel_off |= levels > 1;
        }
        off += usize::from(pixel_off);
    }
    let n = test.pixels.len().max(1);
    let rmse = (sq / (3 * n) as f64).sqrt();
    let flip = {
        let rgb = |f: &Frame| nv_flip::FlipImageRgb8::with_data(f.width, f.height, &to_rgb8(f));
        let map = nv_flip::flip(
            rgb(reference),
            rgb(test),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        );
        f64::from(nv_flip::FlipPool::from_image(&map).mean())
    };
    Errors {
        rmse,
        psnr: 20.0 * (255.0 / rmse).log10(),
        off_by_more_than_1: off as f64 / n as f64,
        max,
        flip,
    }
}

/// One measured setting on one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub scene: String,
    pub setting: Setting,
    pub runs: usize,
    /// Median and fastest wall time of a render, seconds.
    pub median_s: f64,
    pub min_s: f64,
    pub rays: u64,
    /// Share of pixels that adaptive anti-aliasing gave all samples.
    pub refined: f64,
    pub errors: Errors,
    /// The largest per-pixel error bound reported by the contribution cutoff, levels.
    pub cutoff_bound: f64,
    /// The largest difference, in 8-bit levels, that the cutoff made against the same
    /// setting without it (0 without a cutoff).
    pub cutoff_error: u32,
    /// On the scene's Pareto front of (median time, RMSE).
    pub pareto: bool,
}

/// The CSV header; [`Row::csv`] fills every column.
pub const CSV_HEADER: &str = "scene,setting,preset,precision,spp,adaptive_threshold,cutoff,\
max_depth,runs,median_s,min_s,rays,refined_share,rmse_levels,psnr_db,\
share_off_by_more_than_1,max_error_levels,flip_mean,cutoff_bound_levels,\
cutoff_error_levels,pareto";

impl Row {
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

fn precision_name(r: Precision) -> &'static str {
    match r {
        Precision::Fast => "f32",
        Precision::Reference => "f64",
    }
}

/// Timed runs per setting aim to add up to this (within `runs` to 10 × `runs`).
const TIMING_BUDGET_S: f64 = 0.3;

/// Renders `scene` with `quality`; returns the frame, its cutoff bound (levels), the
/// share of refined pixels, rays and seconds.
fn render_once(
    scene: &Scene,
    quality: &Quality,
    opts: &BenchOptions,
) -> anyhow::Result<(Frame, f64, f64, u64, f64)> {
    let ro = Settings {
        width: opts.width,
        height: opts.height,
        quality: *quality,
        threads: opts.threads,
        ..scene.settings()
    };
    let r = render_bounded(scene, &ro, &RenderControl::default())
        .with_context(|| format!("{}: {}", scene.name, quality.label()))?;
    let bound = r.cutoff_bound.iter().fold(0.0f32, |m, &b| m.max(b));
    let pixels = r.frame.pixels.len().max(1) as f64;
    Ok((
        r.frame,
        f64::from(bound) * 255.0,
        r.refined as f64 / pixels,
        r.stats.rays.total(),
        r.stats.seconds,
    ))
}

/// The converged reference of a scene, from the cache in `dir` when a previous run
/// made it for the same scene, size and settings; with the time and rays of the render
/// that made it.
fn reference(
    scene: &Scene,
    opts: &BenchOptions,
    dir: &Path,
) -> anyhow::Result<(Frame, (f64, u64))> {
    let q = Preset::Reference.quality();
    let mut h = DefaultHasher::new();
    (
        crate::scene::to_toml(scene),
        q.label(),
        opts.width,
        opts.height,
    )
        .hash(&mut h);
    // A tiny render of the same scene stands for the reference code: if that code
    // changes what it computes, the probe (almost surely) changes and the cache misses.
    let probe = BenchOptions {
        width: 8,
        height: 8,
        ..opts.clone()
    };
    let probe_q = Quality { spp: 4, ..q };
    for p in render_once(scene, &probe_q, &probe)?.0.pixels {
        p.to_array().map(f32::to_bits).hash(&mut h);
    }
    let path = dir.join(format!(
        "{}-{}x{}-{:016x}.f32",
        scene.name,
        opts.width,
        opts.height,
        h.finish()
    ));
    let n = opts.width as usize * opts.height as usize;
    let timing = path.with_extension("time");
    if let (Ok(bytes), Ok(t)) = (std::fs::read(&path), std::fs::read_to_string(&timing)) {
        let cost = t
            .split_once(' ')
            .and_then(|(s, r)| Some((s.parse::<f64>().ok()?, r.trim().parse::<u64>().ok()?)));
        if let (true, Some(cost)) = (bytes.len() == n * 12, cost) {
            let floats: Vec<f32> = bytes
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            let pixels = floats
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect();
            let frame = Frame {
                width: opts.width,
                height: opts.height,
                pixels,
            };
            return Ok((frame, cost));
        }
    }
    let (frame, _, _, rays, seconds) = render_once(scene, &q, opts)?;
    let bytes: Vec<u8> = frame
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    std::fs::write(&path, bytes).with_context(|| format!("cannot write {}", path.display()))?;
    std::fs::write(&timing, format!("{seconds} {rays}\n"))
        .with_context(|| format!("cannot write {}", timing.display()))?;
    Ok((frame, (seconds, rays)))
}

/// Marks the rows of each scene that no other row of that scene beats in both median
/// time and RMSE.
fn mark_pareto(rows: &mut [Row]) {
    for i in 0..rows.len() {
        let (t, e) = (rows[i].median_s, rows[i].errors.rmse);
        rows[i].pareto = !rows.iter().any(|o| {
            o.scene == rows[i].scene
                && o.median_s <= t
                && o.errors.rmse <= e
                && (o.median_s < t || o.errors.rmse < e)
        });
    }
}

fn median(xs: &mut [f64]) -> f64 {
    xs.sort_by(f64::total_cmp);
    let m = xs.len() / 2;
    if xs.len() % 2 == 1 {
        xs[m]
    } else {
        (xs[m - 1] + xs[m]) / 2.0
    }
}

/// Runs the study and writes its outputs into `opts.out`.
pub fn run(opts: &BenchOptions) -> anyhow::Result<Vec<Row>> {
    if opts.runs == 0 {
        bail!("runs must be at least 1");
    }
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("cannot create {}", opts.out.display()))?;
    let scenes = study_scenes(opts.tiny);
    let settings = grid(opts.tiny);
    let bar = if opts.progress {
        indicatif::ProgressBar::new((scenes.len() * (settings.len() + 1)) as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}",
        )
        .expect("a valid template"),
    );

    let mut rows = Vec::new();
    for bs in &scenes {
        bar.set_message(format!("{}: reference (f64, 256 spp, depth 16)", bs.name));
        let (refr, ref_time) = reference(&bs.scene, opts, &opts.out.join("cache"))?;
        bar.inc(1);
        // A first, untimed render of every setting gives the image (and warms up).
        // The timed runs then cycle through the settings, so that a burst of load from
        // other programs spreads over all of them instead of spoiling one; settings
        // that render in a few milliseconds get more runs (up to 10×), as their times
        // are the noisiest.
        let first = rows.len();
        let mut wanted: Vec<usize> = Vec::with_capacity(settings.len());
        for setting in &settings {
            bar.set_message(format!("{}: {}", bs.name, setting.quality.label()));
            let (frame, bound, refined, rays, seconds) =
                render_once(&bs.scene, &setting.quality, opts)?;
            // The cutoff's own error: against the same setting without it.
            let cutoff_error = if setting.quality.cutoff > 0.0 {
                let exact = Quality {
                    cutoff: 0.0,
                    ..setting.quality
                };
                compare(&frame, &render_once(&bs.scene, &exact, opts)?.0).max
            } else {
                0
            };
            let runs = ((TIMING_BUDGET_S / seconds.max(1e-6)).ceil() as usize)
                .clamp(opts.runs, opts.runs * 10);
            wanted.push(runs);
            rows.push(Row {
                scene: bs.name.clone(),
                setting: *setting,
                runs,
                median_s: 0.0,
                min_s: 0.0,
                rays,
                refined,
                errors: compare(&frame, &refr),
                cutoff_bound: bound,
                cutoff_error,
                pareto: false,
            });
            bar.inc(1);
        }
        let mut times: Vec<Vec<f64>> = vec![Vec::new(); settings.len()];
        let cycles = wanted.iter().copied().max().unwrap_or(0);
        for run in 0..cycles {
            bar.set_message(format!(
                "{}: timed runs, cycle {}/{cycles}",
                bs.name,
                run + 1
            ));
            for ((setting, t), &n) in settings.iter().zip(times.iter_mut()).zip(&wanted) {
                if run < n {
                    t.push(render_once(&bs.scene, &setting.quality, opts)?.4);
                }
            }
        }
        for (row, t) in rows[first..].iter_mut().zip(times.iter_mut()) {
            row.min_s = t.iter().copied().fold(f64::INFINITY, f64::min);
            row.median_s = median(t);
        }
        {
            // The reference preset is the reference: error 0 by definition, one run
            // (when it came from the cache, the run that made it).
            let (seconds, rays) = ref_time;
            rows.push(Row {
                scene: bs.name.clone(),
                setting: Setting {
                    quality: Preset::Reference.quality(),
                    preset: Some(Preset::Reference),
                },
                runs: 1,
                median_s: seconds,
                min_s: seconds,
                rays,
                refined: 1.0,
                errors: compare(&refr, &refr),
                cutoff_bound: 0.0,
                cutoff_error: 0,
                pareto: false,
            });
        }
    }
    bar.finish_and_clear();
    mark_pareto(&mut rows);

    let mut csv = String::from(CSV_HEADER);
    csv.push('\n');
    for r in &rows {
        csv += &r.csv();
        csv.push('\n');
    }
    write(&opts.out.join("bench.csv"), &csv)?;
    write(&opts.out.join("bench.md"), &markdown(&rows, opts))?;
    plot(&rows, &opts.out.join("bench.svg"))?;
    Ok(rows)
}

fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}

fn scene_names(rows: &[Row]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        if !names.contains(&r.scene) {
            names.push(r.scene.clone());
        }
    }
    names
}

/// The time a fixed-spp render at depth `max_depth` (no other knob) would need for
/// `rmse`, interpolated log-log between the measured spp sweep; `None` outside it.
pub fn fixed_spp_time_for(rows: &[Row], scene: &str, max_depth: u32, rmse: f64) -> Option<f64> {
    let mut sweep: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| {
            let q = &r.setting.quality;
            r.scene == scene
                && q.adaptive.is_none()
                && q.cutoff == 0.0
                && q.max_depth == max_depth
                && q.precision == Precision::Fast
        })
        .map(|r| (r.errors.rmse, r.median_s))
        .collect();
    sweep.sort_by(|a, b| b.0.total_cmp(&a.0));
    sweep.windows(2).find_map(|w| {
        let ((e0, t0), (e1, t1)) = (w[0], w[1]);
        (rmse <= e0 && rmse >= e1 && e0 > e1).then(|| {
            let f = (e0.ln() - rmse.ln()) / (e0.ln() - e1.ln());
            (t0.ln() + f * (t1.ln() - t0.ln())).exp()
        })
    })
}

/// The knee of a scene's front, "Kneedle" style: time and RMSE scaled to [0,1] between
/// the plain setting (1 spp, depth 5, exact: the program's default) and the cheapest
/// front point within 10% of the best RMSE of the fast tracer; the knee is the front
/// point in between farthest below the straight line joining those two, where extra
/// time stops buying much error.
pub fn knee<'a>(rows: &'a [Row], scene: &str) -> Option<&'a Row> {
    let plain = rows
        .iter()
        .find(|r| r.scene == scene && r.setting.quality == fast(1, None, 0.0, 5))?;
    let mut front: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            r.scene == scene
                && r.pareto
                && r.setting.quality.precision == Precision::Fast
                && r.median_s >= plain.median_s
                && r.errors.rmse <= plain.errors.rmse
        })
        .collect();
    front.sort_by(|a, b| a.median_s.total_cmp(&b.median_s));
    let best = front
        .iter()
        .map(|r| r.errors.rmse)
        .fold(f64::INFINITY, f64::min);
    let end = front.iter().position(|r| r.errors.rmse <= best * 1.1)?;
    let last = front[end];
    let (t0, t1) = (plain.median_s, last.median_s);
    let (e0, e1) = (plain.errors.rmse, last.errors.rmse);
    if t1 <= t0 || e0 <= e1 {
        return None;
    }
    // Scaled so that the chord runs from (0, 1) to (1, 0): distance below it is 1 − x − y.
    let below = |r: &Row| 1.0 - (r.median_s - t0) / (t1 - t0) - (r.errors.rmse - e1) / (e0 - e1);
    front[..=end]
        .iter()
        .copied()
        .max_by(|a, b| below(a).total_cmp(&below(b)))
}

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
        let plain = rows
            .iter()
            .find(|r| r.scene == name && r.setting.quality == fast(1, None, 0.0, 5));
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

/// Time against RMSE, log-log, one panel per scene; the Pareto front joined by a line.
fn plot(rows: &[Row], path: &Path) -> anyhow::Result<()> {
    use plotters::prelude::*;
    let names = scene_names(rows);
    let cols = 2usize;
    let panels_y = names.len().div_ceil(cols).max(1);
    let legend_h = 36;
    let root = SVGBackend::new(path, (1200, 480 * panels_y as u32 + legend_h)).into_drawing_area();
    let e = |err: &dyn std::fmt::Display| anyhow::anyhow!("plot: {err}");
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let (top, bottom) = root.split_vertically(480 * panels_y as u32);
    let panels = top.split_evenly((panels_y, cols));
    // Explicit light greys: some SVG renderers ignore opacity.
    let grid_bold = RGBColor(200, 200, 200);
    let grid_light = RGBColor(235, 235, 235);
    for (name, panel) in names.iter().zip(panels.iter()) {
        // The reference itself (error 0) has no place on a log axis; the tables give
        // its time.
        let these: Vec<&Row> = rows
            .iter()
            .filter(|r| &r.scene == name && r.errors.rmse > 0.0)
            .collect();
        let pts: Vec<(f64, f64)> = these
            .iter()
            .map(|r| (r.median_s * 1e3, r.errors.rmse))
            .collect();
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(x, y) in &pts {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("{name}: time against error, Pareto front in red"),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(
                (x0 * 0.8..x1 * 1.25).log_scale(),
                (y0 * 0.8..y1 * 1.25).log_scale(),
            )
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .bold_line_style(grid_bold)
            .light_line_style(grid_light)
            .x_desc("median render time (ms, log)")
            .y_desc("RMSE vs reference (8-bit levels, log)")
            .draw()
            .map_err(|x| e(&x))?;
        let kind_color = |r: &Row| {
            let q = &r.setting.quality;
            if r.setting.preset.is_some() {
                RED
            } else if q.precision == Precision::Reference {
                BLACK
            } else if q.adaptive.is_some() {
                GREEN
            } else if q.cutoff > 0.0 {
                MAGENTA
            } else if q.max_depth != 5 {
                CYAN
            } else {
                BLUE
            }
        };
        chart
            .draw_series(
                these
                    .iter()
                    .zip(&pts)
                    .map(|(r, &p)| Circle::new(p, 4, kind_color(r).filled())),
            )
            .map_err(|x| e(&x))?;
        let mut front: Vec<(f64, f64)> = these
            .iter()
            .zip(&pts)
            .filter(|(r, _)| r.pareto)
            .map(|(_, &p)| p)
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Segment by segment: some renderers fill a polyline's area despite fill="none".
        chart
            .draw_series(
                front
                    .windows(2)
                    .map(|w| PathElement::new(vec![w[0], w[1]], RED.stroke_width(2))),
            )
            .map_err(|x| e(&x))?;
        chart
            .draw_series(
                front
                    .iter()
                    .map(|&p| Circle::new(p, 7, RED.stroke_width(2))),
            )
            .map_err(|x| e(&x))?;
        for (r, &p) in these.iter().zip(&pts) {
            if let Some(preset) = r.setting.preset {
                chart
                    .draw_series(std::iter::once(Text::new(
                        preset.name().to_string(),
                        p,
                        ("sans-serif", 13),
                    )))
                    .map_err(|x| e(&x))?;
            }
        }
    }
    // A legend of the colours, drawn once at the bottom of the image.
    let legend = [
        ("plain spp", BLUE),
        ("adaptive AA", GREEN),
        ("cutoff", MAGENTA),
        ("max depth", CYAN),
        ("f64", BLACK),
        ("preset", RED),
    ];
    for (n, (label, color)) in legend.iter().enumerate() {
        let x = 60 + 115 * n as i32;
        let y = 18;
        bottom
            .draw(&Circle::new((x, y), 5, color.filled()))
            .map_err(|x| e(&x))?;
        bottom
            .draw(&Text::new(
                label.to_string(),
                (x + 10, y - 7),
                ("sans-serif", 14),
            ))
            .map_err(|x| e(&x))?;
    }
    bottom
        .draw(&Text::new(
            "red rings and line: the Pareto front of each scene".to_string(),
            (60 + 115 * legend.len() as i32, 11),
            ("sans-serif", 14),
        ))
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))?;
    Ok(())
}

/// Parses `WxH` (each side 1 to 4096) for `--size`.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let parsed = text
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if (1..=4096).contains(&w) && (1..=4096).contains(&h) => Ok((w, h)),
        _ => Err(format!(
            "expected WxH with each side from 1 to 4096, such as 320x180; got \"{text}\""
        )),
    }
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
