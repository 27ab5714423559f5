//! Timing renders the way the peer programs of `../shared/peers` report them, so that
//! one run compares all: median render time (acceleration build excluded, reported
//! apart, as the Embree peer does), rays and Mrays/s.

use crate::render::{render, RenderControl, RenderError, RenderOptions};
use crate::scene::Scene;

/// Medians over several runs of one render.
#[derive(Clone, Debug)]
pub struct Timing {
    pub runs: usize,
    /// Median seconds of tracing (build excluded); Mrays/s are of this median.
    pub render_seconds: f64,
    /// Median seconds of the acceleration build.
    pub build_seconds: f64,
    /// Every run's tracing seconds, in run order.
    pub all_render_seconds: Vec<f64>,
    pub rays: crate::trace::RayCounts,
}

impl Timing {
    /// The fastest run (what `run.sh` keeps for the peers: "best of N").
    pub fn best_render_seconds(&self) -> f64 {
        self.all_render_seconds
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }

    pub fn mrays_per_second(&self) -> f64 {
        self.rays.total() as f64 / self.render_seconds.max(1e-9) / 1e6
    }

    /// One line in the form of the peers' `RESULT` lines.
    pub fn result_line(&self, scene: &str, opts: &RenderOptions, spheres: usize) -> String {
        format!(
            "RESULT peer=whitted scene={scene} threads={} size={}x{} spheres={spheres} depth={} \
             render_s={:.4} best_s={:.4} build_s={:.4} runs={} rays={} primary={} shadow={} secondary={} mrays_s={:.3}",
            opts.threads.unwrap_or_else(rayon::current_num_threads),
            opts.image.width,
            opts.image.height,
            opts.image.max_depth,
            self.render_seconds,
            self.best_render_seconds(),
            self.build_seconds,
            self.runs,
            self.rays.total(),
            self.rays.primary,
            self.rays.shadow,
            self.rays.secondary,
            self.mrays_per_second(),
        )
    }
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    }
}

/// Renders `runs` times (after one warm-up) and takes medians.
pub fn time_render(
    scene: &Scene,
    opts: &RenderOptions,
    runs: usize,
) -> Result<Timing, RenderError> {
    let control = RenderControl::default();
    render(scene, opts, &control)?; // warm-up: caches, thread pool, page faults
    let mut trace = Vec::with_capacity(runs);
    let mut build = Vec::with_capacity(runs);
    let mut rays = Default::default();
    for _ in 0..runs.max(1) {
        let (_, stats) = render(scene, opts, &control)?;
        trace.push(stats.seconds - stats.build_seconds);
        build.push(stats.build_seconds);
        rays = stats.rays;
    }
    let all = trace.clone();
    Ok(Timing {
        runs: trace.len(),
        render_seconds: median(&mut trace),
        build_seconds: median(&mut build),
        all_render_seconds: all,
        rays,
    })
}
