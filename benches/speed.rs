//! Speed benchmarks (`cargo bench`): the intersection kernel, the acceleration build,
//! and whole frames of the peers' scenes. Compare runs of one sitting, as ratios.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{DVec3, Vec3};
use whitted::accel::{Query, Spheres};
use whitted::render::{render, RenderControl, RenderOptions};
use whitted::scene::{hw3_scene, many_scene, HW3_DEFAULT_SEED};
use whitted::trace::intersect::roots;

/// Rays from the hw3 camera through a grid of film positions.
fn hw3_rays(n: u32) -> Vec<Vec3> {
    let scene = hw3_scene(HW3_DEFAULT_SEED);
    let cam = whitted::Camera::for_scene(&scene, 1280, 720).expect("camera");
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
    let scene = hw3_scene(HW3_DEFAULT_SEED);
    let spheres = Spheres::new(&scene.spheres);
    c.bench_function("accel/closest_bvh_hw3_4096_rays", |b| {
        b.iter(|| {
            let mut hits = 0;
            for &dir in &dirs {
                let q = Query {
                    origin: DVec3::ZERO,
                    dir,
                    from: None,
                };
                hits += spheres.closest(&q).is_some() as u32;
            }
            black_box(hits)
        })
    });
    let lights = [scene.lights[0].position];
    let gridded = Spheres::new(&scene.spheres).with_light_grids(&lights);
    let eye = gridded.eye_grid(DVec3::ZERO);
    c.bench_function("accel/closest_primary_grid_hw3_4096_rays", |b| {
        b.iter(|| {
            let mut hits = 0;
            for &dir in &dirs {
                let q = Query {
                    origin: DVec3::ZERO,
                    dir,
                    from: None,
                };
                hits += gridded.closest_primary(&eye, &q).is_some() as u32;
            }
            black_box(hits)
        })
    });
}

fn build(c: &mut Criterion) {
    let mut group = c.benchmark_group("build");
    group.sample_size(10);
    for n in [10_000, 100_000] {
        let scene = many_scene(n);
        let cam = whitted::Camera::for_scene(&scene, 1280, 720).expect("camera");
        let lights: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
        group.bench_function(format!("bvh_and_grids_many_{n}"), |b| {
            b.iter(|| {
                let spheres = Spheres::new(&scene.spheres).with_light_grids(&lights);
                black_box(spheres.eye_grid(cam.origin))
            })
        });
    }
    group.finish();
}

fn frames(c: &mut Criterion) {
    let mut group = c.benchmark_group("frame");
    group.sample_size(10);
    for scene in [hw3_scene(HW3_DEFAULT_SEED), many_scene(10_000)] {
        let opts = RenderOptions::for_scene(&scene);
        let control = RenderControl::default();
        group.bench_function(format!("{}_1280x720", scene.name), |b| {
            b.iter(|| black_box(render(&scene, &opts, &control).expect("renders")))
        });
    }
    group.finish();
}

criterion_group!(benches, kernel, build, frames);
criterion_main!(benches);
