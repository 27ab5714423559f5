//! The run-time/error study behind the quality presets (`whitted bench`): a grid of
//! quality settings rendered on several scenes, each timed (median of several runs) and
//! compared with a converged reference (the `f64` tracer, 256 stratified samples per
//! pixel, depth 16). Writes `bench.csv`, `bench.md` and `bench.svg` (time against
//! error with the Pareto front of each scene marked).
//!
//! `grid` holds the scenes and settings, `measure` renders them, `metrics` compares an
//! image with the reference (and serves `whitted compare`), `analysis` reads the rows (medians, Pareto front, knee),
//! `report` and `plot` write the outputs; [`run`] drives them.

mod analysis;
mod grid;
mod measure;
mod metrics;
mod plot;
mod report;

use std::path::PathBuf;

use anyhow::{bail, Context};
use indicatif::ProgressBar;

pub use analysis::{fixed_spp_time_for, knee};
pub use grid::{grid, study_scenes, BenchScene, Setting};
pub use metrics::{compare, measure, Comparison, Errors, Levels};
pub use report::{replot, summary, CSV_HEADER};

use crate::settings::{Preset, Quality};
use analysis::{mark_pareto, median};
use measure::{reference, render_once, Measured, Reference};

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

/// Timed runs per setting aim to add up to this (within `runs` to 10 × `runs`).
const TIMING_BUDGET_S: f64 = 0.3;

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
        ProgressBar::new((scenes.len() * (settings.len() + 1)) as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}",
        )
        .expect("a valid template"),
    );

    let mut rows = Vec::new();
    for bs in &scenes {
        rows.extend(measure_scene(bs, &settings, opts, &bar)?);
    }
    bar.finish_and_clear();
    mark_pareto(&mut rows);
    report::write_all(&rows, opts)?;
    Ok(rows)
}

/// The rows of one scene: every setting, then the reference preset (not yet marked
/// for the Pareto front).
fn measure_scene(
    bs: &BenchScene,
    settings: &[Setting],
    opts: &BenchOptions,
    bar: &ProgressBar,
) -> anyhow::Result<Vec<Row>> {
    bar.set_message(format!("{}: reference (f64, 256 spp, depth 16)", bs.name));
    let refr: Reference = reference(&bs.scene, opts, &opts.out.join("cache"))?;
    // The reference's levels, made once for every setting's comparison.
    let reference_levels = Levels::from_frame(&refr.frame);
    let against_reference = |frame: &crate::render::Frame| {
        measure(&Levels::from_frame(frame), &reference_levels)
            .expect("renders of one size")
            .errors
    };
    bar.inc(1);
    // A first, untimed render of every setting gives the image (and warms up).
    // The timed runs then cycle through the settings, so that a burst of load from
    // other programs spreads over all of them instead of spoiling one; settings
    // that render in a few milliseconds get more runs (up to 10×), as their times
    // are the noisiest.
    let mut rows = Vec::with_capacity(settings.len() + 1);
    let mut wanted: Vec<usize> = Vec::with_capacity(settings.len());
    for setting in settings {
        bar.set_message(format!("{}: {}", bs.name, setting.quality.label()));
        let m: Measured = render_once(&bs.scene, &setting.quality, opts)?;
        // The cutoff's own error: against the same setting without it.
        let cutoff_error = if setting.quality.cutoff > 0.0 {
            let exact = Quality {
                cutoff: 0.0,
                ..setting.quality
            };
            compare(&m.frame, &render_once(&bs.scene, &exact, opts)?.frame).max
        } else {
            0
        };
        let runs = ((TIMING_BUDGET_S / m.seconds.max(1e-6)).ceil() as usize)
            .clamp(opts.runs, opts.runs * 10);
        wanted.push(runs);
        rows.push(Row {
            scene: bs.name.clone(),
            setting: *setting,
            runs,
            median_s: 0.0,
            min_s: 0.0,
            rays: m.rays,
            refined: m.refined,
            errors: against_reference(&m.frame),
            cutoff_bound: m.cutoff_bound,
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
                t.push(render_once(&bs.scene, &setting.quality, opts)?.seconds);
            }
        }
    }
    for (row, t) in rows.iter_mut().zip(times.iter_mut()) {
        row.min_s = t.iter().copied().fold(f64::INFINITY, f64::min);
        row.median_s = median(t);
    }
    // The reference preset is the reference: error 0 by definition, one run (when it
    // came from the cache, the run that made it).
    rows.push(Row {
        scene: bs.name.clone(),
        setting: Setting {
            quality: Preset::Reference.quality(),
            preset: Some(Preset::Reference),
        },
        runs: 1,
        median_s: refr.seconds,
        min_s: refr.seconds,
        rays: refr.rays,
        refined: 1.0,
        errors: against_reference(&refr.frame),
        cutoff_bound: 0.0,
        cutoff_error: 0,
        pareto: false,
    });
    Ok(rows)
}
