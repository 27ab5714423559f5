//! What the robust intersection and spawn cost, measured in one run on the
//! hw3 scene's rays: nanoseconds per ray–sphere test for the assignment's textbook `f32`
//! form against the stable form in `f32` and in `f64` (what `accel` uses), and
//! nanoseconds per query for primary, spawned (reflected, with the own-sphere rule and
//! the rounding `t_min`) and shadow rays through `accel::Spheres`, against the
//! assignment's loop (textbook `f32`, fixed `t_min` 0.01, every sphere).
//!
//! `cargo run --release --example robust_cost` (single thread; median of 7 runs).

use std::hint::black_box;
use std::time::Instant;

use glam::{DVec3, Vec3};
use whitted::accel::{Query, Spheres};
use whitted::model::{self, Side};
use whitted::scene::hw3_scene;
use whitted::trace::intersect::roots;

/// Median nanoseconds per item of `f` over `items` items.
fn time(items: usize, mut f: impl FnMut() -> f64) -> f64 {
    let mut runs: Vec<f64> = (0..7)
        .map(|_| {
            let start = Instant::now();
            black_box(f());
            start.elapsed().as_secs_f64() * 1e9 / items as f64
        })
        .collect();
    runs.sort_by(f64::total_cmp);
    runs[3]
}

/// The assignment's test: `b² − c` with `f = o − c`, near root `−b − √disc`, `t > 0.01`.
#[inline]
fn textbook(o: Vec3, d: Vec3, c: Vec3, r: f32) -> Option<f32> {
    let f = o - c;
    let b = f.dot(d);
    let disc = b * b - (f.dot(f) - r * r);
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let t = -b - s;
    if t > 0.01 {
        return Some(t);
    }
    let t = -b + s;
    (t > 0.01).then_some(t)
}

fn main() {
    let scene = hw3_scene(whitted::scene::HW3_DEFAULT_SEED);
    let (w, h) = (640u32, 360u32);
    let camera = scene.camera(w, h).unwrap();
    let dirs: Vec<Vec3> = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| {
            model::primary_direction(
                (camera.lower_left - camera.origin).as_vec3(),
                camera.horizontal.as_vec3(),
                camera.vertical.as_vec3(),
                (i as f32 + 0.5) / w as f32,
                (j as f32 + 0.5) / h as f32,
            )
        })
        .collect();
    let o32 = camera.origin.as_vec3();
    let o64 = camera.origin;
    let c32: Vec<(Vec3, f32)> = scene
        .spheres
        .iter()
        .map(|s| (s.center.as_vec3(), s.radius as f32))
        .collect();
    let tests = dirs.len() * c32.len();

    // Per ray–sphere test.
    let t_textbook = time(tests, || {
        let mut acc = 0.0;
        for &d in &dirs {
            for &(c, r) in &c32 {
                acc += textbook(o32, d, c, r).unwrap_or(0.0) as f64;
            }
        }
        acc
    });
    let t_stable32 = time(tests, || {
        let mut acc = 0.0;
        for &d in &dirs {
            for &(c, r) in &c32 {
                acc += roots(o32, d, c, r).map_or(0.0, |x| x.near) as f64;
            }
        }
        acc
    });
    let t_stable64 = time(tests, || {
        let mut acc = 0.0;
        for &d in &dirs {
            let d = d.as_dvec3().normalize();
            for s in &scene.spheres {
                acc += roots(o64, d, s.center, s.radius).map_or(0.0, |x| x.near);
            }
        }
        acc
    });

    // Per query, through accel (BVH; the eye grid for primaries).
    let eye_only = Spheres::new(&scene.spheres);
    let lights: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
    let gridded = Spheres::new(&scene.spheres).with_light_grids(&lights);
    let eye = gridded.eye_grid(o64);
    let primary = |d: Vec3| Query {
        origin: o64,
        dir: d,
        from: None,
    };
    let hits: Vec<_> = dirs
        .iter()
        .filter_map(|&d| eye_only.closest(&primary(d)).map(|h| (d, h)))
        .collect();
    let t_closest = time(dirs.len(), || {
        dirs.iter()
            .filter_map(|&d| eye_only.closest(&primary(d)))
            .count() as f64
    });
    let t_primary_grid = time(dirs.len(), || {
        dirs.iter()
            .filter_map(|&d| gridded.closest_primary(&eye, &primary(d)))
            .count() as f64
    });
    // Spawned reflected rays: the own-sphere rule, t_min and the re-projected origin.
    let spawned: Vec<Query> = hits
        .iter()
        .map(|(d, hit)| Query {
            origin: hit.point,
            dir: model::reflect(*d, hit.normal.as_vec3()).normalize(),
            from: Some((hit.sphere, Side::inside(!hit.entering))),
        })
        .collect();
    let t_spawned = time(spawned.len(), || {
        spawned.iter().filter_map(|q| eye_only.closest(q)).count() as f64
    });
    let light = lights[0];
    let shadows: Vec<(Query, f64)> = hits
        .iter()
        .map(|(_, hit)| {
            let to = light - hit.point;
            let dist = to.length();
            (
                Query {
                    origin: hit.point,
                    dir: (to / dist).as_vec3(),
                    from: Some((hit.sphere, Side::Outward)),
                },
                dist,
            )
        })
        .collect();
    let t_shadow = time(shadows.len(), || {
        shadows
            .iter()
            .map(|(q, dist)| f64::from(eye_only.shadow(q, *dist)))
            .sum()
    });
    let t_shadow_grid = time(shadows.len(), || {
        shadows
            .iter()
            .map(|(q, dist)| f64::from(gridded.shadow_to_light(q, *dist, 0)))
            .sum()
    });
    // The assignment's closest hit: every sphere, textbook f32, fixed t_min 0.01, and
    // the hit point and normal in f32 with no re-projection.
    let t_assignment = time(spawned.len(), || {
        let mut acc = 0.0;
        for q in &spawned {
            let o = q.origin.as_vec3();
            let mut best = (f32::INFINITY, 0usize);
            for (k, &(c, r)) in c32.iter().enumerate() {
                if let Some(t) = textbook(o, q.dir, c, r) {
                    if t < best.0 {
                        best = (t, k);
                    }
                }
            }
            if best.0.is_finite() {
                let p = o + q.dir * best.0;
                acc += ((p - c32[best.1].0) / c32[best.1].1).x as f64;
            }
        }
        acc
    });

    println!(
        "hw3, {} rays ({}x{}), {} spheres, {} hits; single thread, median of 7",
        dirs.len(),
        w,
        h,
        c32.len(),
        hits.len()
    );
    println!("per ray-sphere test:");
    println!("  textbook f32 (assignment)          {t_textbook:7.2} ns");
    println!("  stable roots f32                   {t_stable32:7.2} ns");
    println!("  stable roots f64 (accel's exact)   {t_stable64:7.2} ns");
    println!("per query (accel::Spheres):");
    println!("  primary, closest (BVH)             {t_closest:7.1} ns");
    println!("  primary, closest_primary (grid)    {t_primary_grid:7.1} ns");
    println!("  spawned reflected, closest (BVH)   {t_spawned:7.1} ns");
    println!("  shadow (BVH)                       {t_shadow:7.1} ns");
    println!("  shadow_to_light (grid)             {t_shadow_grid:7.1} ns");
    println!("  assignment loop, spawned rays      {t_assignment:7.1} ns  (textbook f32, every sphere, t_min 0.01)");
}
