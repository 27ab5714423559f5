//! Speed benchmarks (`cargo bench`): the intersection kernel, the fast tracer's rays
//! of one and two bounces, the fast tracer's build (hierarchy and grids), the walk of
//! incoherent rays through the hierarchy alone, whole frames of the peers' scenes, and
//! the viewer's views, refinements and screen conversions. Compare runs of one
//! sitting, as ratios.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{DVec3, Vec3};
use whitted::intersect::roots;
use whitted::render::{accumulate, render, RenderControl};
use whitted::scene::{hw3_scene, many_scene, HW3_DEFAULT_SEED};
use whitted::speed::SecondaryWalk;
use whitted::trace::fast::FastTracer;
use whitted::trace::{RayCounts, SampleTracer};

/// Rays from the hw3 camera through a grid of film positions.
fn hw3_rays(n: u32) -> Vec<Vec3> {
    let scene = hw3_scene(HW3_DEFAULT_SEED);
    let cam = scene.camera(1280, 720).expect("camera");
    (0..n * n)
        .map(|k| {
            let (s, t) = ((k % n) as f64 / n as f64, (k / n) as f64 / n as f64);
            (cam.lower_left + cam.horizontal * s + cam.vertical * t - cam.origin)
                .normalize()
                .as_vec3()
        })
        .collect()
}

fn kernel(c: &mut Criterion) {
    let dirs = hw3_rays(64);
    let centre = DVec3::new(0.0, 0.0, -2.0);
    c.bench_function("intersect/roots_f64_4096_rays", |b| {
        b.iter(|| {
            let mut hits = 0;
            for d in &dirs {
                hits += roots(DVec3::ZERO, d.as_dvec3(), centre, 0.5).is_some() as u32;
            }
            black_box(hits)
        })
    });
    // The fast tracer's samples of 64×64 film positions, with no light: at depth 1 a
    // sample is its primary ray (the eye grid's query) and its shading; at depth 2 the
    // reflected and transmitted rays (the hierarchy's query) are added.
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    scene.lights.clear();
    let cam = scene.camera(1280, 720).expect("camera");
    let n = 64;
    let film: Vec<(f32, f32)> = (0..n * n)
        .map(|k| ((k % n) as f32 / n as f32, (k / n) as f32 / n as f32))
        .collect();
    for (name, depth) in [
        ("trace/primary_hw3_4096_rays", 1),
        ("trace/one_bounce_hw3_4096_rays", 2),
    ] {
        let tracer = FastTracer::new(&scene, &cam, depth);
        c.bench_function(name, |b| {
            b.iter(|| {
                let mut counts = RayCounts::default();
                let mut sum = 0.0;
                for &(s, t) in &film {
                    sum += tracer.sample(s, t, &mut counts).x;
                }
                black_box((sum, counts))
            })
        });
    }
}

fn build(c: &mut Criterion) {
    let mut group = c.benchmark_group("build");
    group.sample_size(10);
    for n in [10_000, 100_000] {
        let scene = many_scene(n);
        let cam = scene.camera(1280, 720).expect("camera");
        let depth = scene.settings().quality.max_depth;
        // The hierarchy, the lights' grids and the eye grid, with the materials.
        group.bench_function(format!("tracer_many_{n}"), |b| {
            b.iter(|| black_box(FastTracer::new(&scene, &cam, depth)))
        });
    }
    group.finish();
}

/// The walk of incoherent rays through the hierarchy alone (see
/// [`whitted::speed::SecondaryWalk`]): many_100000's reflected rays of every fourth
/// pixel each way of its 1280x720 view, on one thread.
fn secondary(c: &mut Criterion) {
    let mut group = c.benchmark_group("secondary");
    group.sample_size(10);
    for n in [10_000, 100_000] {
        let walk = SecondaryWalk::new(&many_scene(n), 1280, 720, 4).expect("camera");
        group.bench_function(format!("closest_many_{n}_{}_rays", walk.len()), |b| {
            b.iter(|| black_box(walk.closest_hits()))
        });
    }
    group.finish();
}

fn frames(c: &mut Criterion) {
    let mut group = c.benchmark_group("frame");
    group.sample_size(10);
    for scene in [hw3_scene(HW3_DEFAULT_SEED), many_scene(10_000)] {
        let opts = scene.settings();
        let control = RenderControl::default();
        group.bench_function(format!("{}_1280x720", scene.name), |b| {
            b.iter(|| black_box(render(&scene, &opts, &control).expect("renders")))
        });
    }
    group.finish();
}

/// The viewer: a view of the orbit as the window renders it (a 2×2 preview, then the
/// full pass that takes its pixels), and the conversions for the screen.
fn viewer(c: &mut Criterion) {
    use std::sync::Arc;
    use whitted::settings::Encoding;
    use whitted::viewer::buffer::{blit_xrgb, fill_for_screen, fill_upscaled_for_screen};
    use whitted::viewer::controls::{Action, CameraControl};
    use whitted::viewer::worker::{self, Buffers, Job, TracerCache};
    use whitted::Frame;

    let (w, h) = (1280, 720);
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    scene.image.spp = Some(1);
    // Views 25 and 26 of `whitted time --orbit`, in turn: each iteration is a new
    // camera, so its eye grid is built as in a drag.
    let mut camera = CameraControl::new(&scene);
    let drag = Action::Drag {
        dx: 10.0,
        dy: 0.0,
        height: h,
    };
    let mut views = Vec::new();
    for view in 1..=26 {
        camera.apply(&scene, w, h, drag);
        if view >= 25 {
            let mut seen = scene.clone();
            seen.camera = Some(camera.spec(&scene, w, h));
            views.push(Arc::new(seen));
        }
    }
    let (mut cache, mut buffers) = (TracerCache::default(), Buffers::default());
    let mut group = c.benchmark_group("viewer");
    group.sample_size(20);
    let mut turn = 0;
    group.bench_function("orbit_view_hw3_1280x720_preview_2", |b| {
        b.iter(|| {
            turn += 1;
            let job = Job::new(turn, Arc::clone(&views[turn as usize % 2]), (w, h), 2);
            worker::run(&job, &mut cache, &mut buffers, &|r| drop(black_box(r))).expect("renders")
        })
    });

    // The window's refinements of a still view after its first pass: sample 1 of
    // every pixel, then samples 2 and 3 (the passes of one and two samples a pixel).
    let mut still = scene.clone();
    still.image.spp = Some(16);
    let settings = still.settings();
    let camera = still.camera(w, h).expect("camera");
    let tracer = FastTracer::new(&still, &camera, settings.quality.max_depth);
    let mut sums = vec![Vec3::ZERO; (w * h) as usize];
    for samples in [1..2, 2..4] {
        let name = format!(
            "refine_hw3_1280x720_samples_{}_{}",
            samples.start, samples.end
        );
        group.bench_function(name, |b| {
            b.iter(|| {
                let control = RenderControl::default();
                accumulate(&tracer, &settings, samples.clone(), &mut sums, &control)
                    .expect("renders")
            })
        });
    }

    let image = render(&scene, &scene.settings(), &RenderControl::default())
        .expect("renders")
        .0;
    let (mut frame, mut rgba) = (Frame::new(w, h), Vec::new());
    let mut small = scene.settings();
    (small.width, small.height) = (w / 2, h / 2);
    let preview = render(&scene, &small, &RenderControl::default())
        .expect("renders")
        .0;
    for encoding in Encoding::ALL {
        // The linear names are those of the benchmarks before the sRGB option.
        let suffix = match encoding {
            Encoding::Linear => String::new(),
            other => format!("_{other}"),
        };
        group.bench_function(format!("screen_fill_1280x720{suffix}"), |b| {
            b.iter(|| {
                fill_for_screen(&mut frame, &mut rgba, encoding, |j, row| {
                    let from = &image.pixels[j * row.len()..(j + 1) * row.len()];
                    whitted::render::pixel_values(from, 1, row)
                })
            })
        });
        group.bench_function(format!("preview_fill_1280x720_factor_2{suffix}"), |b| {
            b.iter(|| {
                let values = (preview.pixels.as_slice(), preview.width);
                fill_upscaled_for_screen(&mut frame, &mut rgba, values, 2, encoding)
            })
        });
    }
    let mut surface = vec![0u32; (w * h) as usize];
    group.bench_function("blit_xrgb_1280x720", |b| {
        b.iter(|| blit_xrgb(&rgba, w, h, &mut surface, w, h))
    });
    group.finish();
}

criterion_group!(benches, kernel, build, secondary, frames, viewer);
criterion_main!(benches);
