//! Timing renders the way the peer programs of `../shared/peers` report them, so that
//! one run compares all: median render time (acceleration build excluded, reported
//! apart, as the Embree peer does), rays and Mrays/s.

use crate::render::{render, RenderControl, RenderError};
use crate::scene::Scene;
use crate::settings::Settings;

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
    pub fn result_line(&self, scene: &str, opts: &Settings, spheres: usize) -> String {
        format!(
            "RESULT peer=whitted scene={scene} threads={} size={}x{} spheres={spheres} depth={} \
             render_s={:.4} best_s={:.4} build_s={:.4} runs={} rays={} primary={} shadow={} secondary={} mrays_s={:.3}",
            opts.threads.unwrap_or_else(rayon::current_num_threads),
            opts.width,
            opts.height,
            opts.quality.max_depth,
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
pub fn time_render(scene: &Scene, opts: &Settings, runs: usize) -> Result<Timing, RenderError> {
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

/// The viewer's frames while the camera orbits: see [`time_orbit`].
#[derive(Clone, Debug)]
pub struct OrbitTiming {
    /// Seconds of each view's first full-resolution pass (what the window then shows),
    /// conversion to screen bytes included; after a preview it traces the pixels the
    /// preview did not.
    pub frame_seconds: Vec<f64>,
    /// Seconds from each view's submission to its full-resolution frame: its eye grid,
    /// its preview (whose pixels the full pass takes) and its full pass.
    pub view_seconds: Vec<f64>,
    /// Views that showed a preview before their full pass.
    pub previews: usize,
    /// Wall time of all the views, from the first submission to the last frame.
    pub wall_seconds: f64,
}

impl OrbitTiming {
    /// Median seconds of a full-resolution frame.
    pub fn median_frame_seconds(&self) -> f64 {
        median(&mut self.frame_seconds.clone())
    }

    /// Median seconds from a view's submission to its full-resolution frame.
    pub fn median_view_seconds(&self) -> f64 {
        median(&mut self.view_seconds.clone())
    }

    /// Full-resolution frames per second of wall time (everything the worker does
    /// between frames included: a new view's eye grid, previews).
    pub fn frames_per_second(&self) -> f64 {
        self.frame_seconds.len() as f64 / self.wall_seconds.max(1e-9)
    }

    /// One line in the form of [`Timing::result_line`].
    pub fn result_line(&self, scene: &str, threads: usize, (w, h): (u32, u32)) -> String {
        format!(
            "RESULT peer=whitted-viewer scene={scene} threads={threads} size={w}x{h} views={} \
             frame_ms={:.2} best_ms={:.2} view_ms={:.2} fps={:.1} previews={}",
            self.frame_seconds.len(),
            self.median_frame_seconds() * 1e3,
            self.frame_seconds
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min)
                * 1e3,
            self.median_view_seconds() * 1e3,
            self.frames_per_second(),
            self.previews,
        )
    }
}

/// Orbits the camera of `scene` (one sample a pixel) by a short mouse drag per view,
/// `views` times after one warm-up view, and renders each view at `size` exactly as
/// the viewer's window does — its worker's passes, tracer cache and buffers, its
/// choice of preview from the speed measured so far — without a window: the render
/// time per frame of the viewer, apart from the blit. Without `preview`, every view is
/// one full pass (the window's choice when a frame fits 1/30 s). With `views_to`, each
/// timed view is also written there as a scene of the peers' format ([`peer_scene`]),
/// `view_01.txt` on.
pub fn time_orbit(
    scene: &Scene,
    size: (u32, u32),
    views: usize,
    preview: bool,
    views_to: Option<&std::path::Path>,
) -> anyhow::Result<OrbitTiming> {
    use crate::viewer::controls::{Action, CameraControl};
    use crate::viewer::schedule::{measured_speed, preview_factor};
    use crate::viewer::worker::{self, Buffers, Job, Report, TracerCache};
    use anyhow::Context as _;
    use std::sync::Arc;
    use std::time::Instant;

    let mut scene = scene.clone();
    scene.image.spp = Some(1);
    let (mut cache, mut buffers) = (TracerCache::default(), Buffers::default());
    let mut camera = CameraControl::new(&scene);
    let mut speed = f64::NAN;
    let mut timing = OrbitTiming {
        frame_seconds: Vec::new(),
        view_seconds: Vec::new(),
        previews: 0,
        wall_seconds: 0.0,
    };
    let mut start = Instant::now();
    for view in 0..=views {
        let drag = Action::Drag {
            dx: 10.0,
            dy: 0.0,
            height: size.1,
        };
        camera.apply(&scene, size.0, size.1, drag);
        let mut seen = scene.clone();
        seen.camera = Some(camera.spec(&scene, size.0, size.1));
        let job = Job::new(
            view as u64,
            Arc::new(seen),
            size,
            if preview {
                preview_factor(size.0, size.1, speed)
            } else {
                1
            },
        );
        let reports = std::cell::RefCell::new(Vec::new());
        worker::run(&job, &mut cache, &mut buffers, &|r| {
            reports.borrow_mut().push(r)
        })?;
        let mut shown = Vec::new();
        for report in reports.into_inner() {
            match report {
                Report::Frame(s) => shown.push(s),
                Report::Failed { message, .. } => anyhow::bail!(message),
            }
        }
        for s in &shown {
            speed = measured_speed(s.samples, s.pass_pixels, s.pass_seconds).unwrap_or(speed);
        }
        if view == 0 {
            start = Instant::now(); // the warm-up view: thread pool, caches
            continue;
        }
        if let Some(dir) = views_to {
            // Left out of the wall time: the views' files are not the viewer's work.
            let writing = Instant::now();
            let path = dir.join(format!("view_{view:02}.txt"));
            let text = peer_scene(&job.scene, size)?;
            crate::image_io::write_atomically(&path, text.as_bytes())
                .context("cannot write a view")?;
            start += writing.elapsed();
        }
        timing.previews += usize::from(shown.iter().any(|s| s.preview));
        if let Some(full) = shown.iter().find(|s| !s.preview) {
            timing.frame_seconds.push(full.pass_seconds);
            timing.view_seconds.push(full.since_submit);
        }
    }
    timing.wall_seconds = start.elapsed().as_secs_f64();
    Ok(timing)
}

/// `scene` at `size` in the peer programs' scene format (`../shared/peers/make_hw3.py`):
/// its camera's frame, one light, the image's size and depth, and a line a sphere. The
/// peers know no other sky and one light only; a scene they cannot render is an error.
pub fn peer_scene(scene: &Scene, size: (u32, u32)) -> anyhow::Result<String> {
    use std::fmt::Write;
    let [light] = scene.lights.as_slice() else {
        anyhow::bail!("the peers render one light, not {}", scene.lights.len());
    };
    anyhow::ensure!(
        scene.sky == crate::scene::Sky::default(),
        "the peers render the default sky only"
    );
    let c = scene.camera(size.0, size.1)?;
    let v = |v: glam::DVec3| format!("{} {} {}", v.x, v.y, v.z);
    let mut text = format!(
        "camera {}  {}  {}  {}\nlight {}  {}\nsize {} {}\ndepth {}\n",
        v(c.origin),
        v(c.lower_left),
        v(c.horizontal),
        v(c.vertical),
        v(light.position),
        v(light.intensity),
        size.0,
        size.1,
        scene.settings().quality.max_depth,
    );
    for s in &scene.spheres {
        writeln!(
            text,
            "sphere {}  {}  {}  {} {}  {}",
            v(s.center),
            s.radius,
            v(s.color),
            s.reflect,
            s.transmit,
            s.ior
        )?;
    }
    Ok(text)
}

/// The walk of incoherent rays through the hierarchy alone, for `cargo bench`: the
/// mirror reflections of the primary hits of a scene's view (every `stride`-th pixel
/// each way), spawned as the tracer spawns them and queried for their closest hits
/// with no shading around them. In a large scene this walk is most of a render.
pub struct SecondaryWalk {
    spheres: crate::accel::Spheres,
    rays: Vec<crate::accel::Query>,
}

impl SecondaryWalk {
    /// The rays of `scene`'s camera at `width`×`height`, every `stride`-th pixel.
    pub fn new(scene: &Scene, width: u32, height: u32, stride: u32) -> Result<Self, RenderError> {
        use crate::accel::{Query, Spheres};
        use crate::model::Side;
        let camera = scene.camera(width, height)?;
        let spheres = Spheres::new(&scene.spheres);
        let mut rays = Vec::new();
        for y in (0..height).step_by(stride.max(1) as usize) {
            for x in (0..width).step_by(stride.max(1) as usize) {
                let (s, t) = (
                    (f64::from(x) + 0.5) / f64::from(width),
                    (f64::from(y) + 0.5) / f64::from(height),
                );
                let corner = camera.lower_left - camera.origin;
                let dir = crate::model::primary_direction(
                    corner,
                    camera.horizontal,
                    camera.vertical,
                    s,
                    t,
                )
                .as_vec3();
                let primary = Query {
                    origin: camera.origin,
                    dir,
                    from: None,
                };
                if let Some(hit) = spheres.closest(&primary) {
                    let n = hit.normal.as_vec3();
                    rays.push(Query {
                        origin: hit.point,
                        dir: crate::model::reflect(dir, n).normalize(),
                        from: Some((hit.sphere, Side::inside(!hit.entering))),
                    });
                }
            }
        }
        Ok(SecondaryWalk { spheres, rays })
    }

    /// The rays walked by [`SecondaryWalk::closest_hits`].
    pub fn len(&self) -> usize {
        self.rays.len()
    }

    /// Whether there are no rays (a view of sky only).
    pub fn is_empty(&self) -> bool {
        self.rays.is_empty()
    }

    /// Walks every ray to its closest hit, on this thread; returns how many hit.
    pub fn closest_hits(&self) -> usize {
        self.rays
            .iter()
            .filter(|q| self.spheres.closest(q).is_some())
            .count()
    }
}
