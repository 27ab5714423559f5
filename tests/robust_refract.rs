//! Issue 4, refraction and deep recursion: Snell's law in the fast path's `f32`
//! formula (`model::transmit::<Vec3>`), entry/exit symmetry through the fast queries,
//! a camera inside glass and ultra-grazing entries (no NaN or infinity, total internal
//! reflection reflects), and two facing mirrors at the depth limit.

mod robust_support;

use std::cell::RefCell;

use glam::DVec3;
use proptest::prelude::*;
use robust_support::cases::{self, ior, runner, sin_between};
use robust_support::*;
use whitted::accel::Spheres;
use whitted::camera::Camera;
use whitted::camera::CameraSpec;
use whitted::model::{self, Side};
use whitted::scene::{Light, Scene, Sphere};
use whitted::settings::Precision;
use whitted::trace::fast::FastTracer;
use whitted::trace::reference::ReferenceTracer;
use whitted::trace::{RayCounts, SampleTracer};

/// Snell's law for the `f32` formula, leaving (η = ior) and entering (η = 1/ior):
/// |sin θt − η·sin θi| ≤ 1e-6, the ray continues on the far side, unit length.
#[test]
fn snell_holds_in_f32_on_exit_and_entry() {
    let worst = RefCell::new((0.0f64, 0.0f64));
    runner(20_000)
        .run(
            &(unit_vector(), unit_vector(), ior(), 0.0f64..1.0),
            |(n, u, ior, k)| {
                let n32 = n.as_vec3();
                for front in [false, true] {
                    let eta = if front { 1.0 / ior } else { ior };
                    // Incidence below the critical angle when leaving: sin θi < 1/ior.
                    let sin_i = if front { k } else { k / ior };
                    let t = (u - n * u.dot(n)).normalize_or(n.any_orthonormal_vector());
                    // Travelling against the normal the ray meets the surface on: −n
                    // from outside (front), +n from inside.
                    let along = if front { -n } else { n };
                    let d = (along * (1.0 - sin_i * sin_i).sqrt() + t * sin_i).as_vec3();
                    let (out, crosses) = model::transmit(d, n32, front, ior as f32);
                    let out64 = out.as_dvec3();
                    let sin_i = sin_between(d.as_dvec3(), n32.as_dvec3());
                    let sin_t = sin_between(out64, n32.as_dvec3());
                    let expected = eta * sin_i;
                    prop_assert!(out.is_finite());
                    if expected < 1.0 - 1e-6 {
                        prop_assert!(crosses, "below the critical angle the ray crosses");
                        let err = (sin_t - expected).abs();
                        let mut w = worst.borrow_mut();
                        if front {
                            w.1 = w.1.max(err);
                        } else {
                            w.0 = w.0.max(err);
                        }
                        prop_assert!(err <= 1e-6, "front {front}: sin θt {sin_t} vs {expected}");
                        prop_assert!(out64.dot(along.as_vec3().as_dvec3()) > 0.0);
                        prop_assert!((out64.length() - 1.0).abs() < 1e-6);
                    }
                }
                Ok(())
            },
        )
        .unwrap();
    let (exit, entry) = worst.into_inner();
    println!("Snell in f32: max |sin θt − η sin θi| on exit {exit:.2e}, on entry {entry:.2e}");
}

/// Entry/exit symmetry through the fast queries (see `cases::refraction_symmetry`):
/// balls of radius 10^U(−3,5) with |centre| up to 1e4, |sin θout − sin θin| ≤ 1e-5.
#[test]
fn refraction_through_a_ball_is_symmetric() {
    let (err, n) = cases::refraction_symmetry(f64::INFINITY).unwrap_or_else(|e| panic!("{e}"));
    assert!(n > 4_000 && err <= 1e-5);
}

/// A camera inside a glass ball (ior 1.5): every direction finds the far root; where
/// Snell's law has no solution the ray reflects (mirror of d about the normal, staying
/// inside); nothing is NaN or infinite. Prints the share of total internal reflection.
#[test]
fn camera_inside_glass_reflects_totally_and_stays_finite() {
    let counts = RefCell::new((0u64, 0u64));
    runner(20_000)
        .run(
            &(
                log_uniform(-3.0, 4.0),
                unit_vector(),
                unit_vector(),
                0.0f64..0.99,
            ),
            |(r, u, dir, k)| {
                let c = DVec3::new(0.3, -0.2, 1.0) * r;
                let eye = c + u * (r * k);
                let set = Spheres::new(&[Sphere::new(c, r)]);
                let q = query(eye, dir, None);
                let hit = set.closest(&q);
                prop_assert!(hit.is_some(), "from inside, the far root");
                let hit = hit.unwrap();
                prop_assert!(!hit.entering);
                let n = hit.normal.as_vec3();
                let (out, crosses) = model::transmit(q.dir, n, false, 1.5);
                prop_assert!(out.is_finite());
                let mut cnt = counts.borrow_mut();
                cnt.0 += 1;
                if !crosses {
                    cnt.1 += 1;
                    let mirror = model::reflect(q.dir, -n).normalize();
                    prop_assert!((out - mirror).length() < 1e-6, "TIR reflects");
                    prop_assert!(out.dot(n) <= 0.0, "a reflected ray stays inside");
                    // And it finds the far side again.
                    let again =
                        set.closest(&query(hit.point, out.as_dvec3(), Some((0, Side::Inward))));
                    prop_assert!(again.is_some_and(|h| !h.entering));
                } else {
                    prop_assert!(out.dot(n) >= 0.0, "a transmitted ray leaves");
                }
                Ok(())
            },
        )
        .unwrap();
    let (n, tir) = counts.into_inner();
    println!(
        "camera inside glass (ior 1.5): {n} rays, {tir} totally reflected ({:.1}%)",
        100.0 * tir as f64 / n as f64
    );
    assert!(tir > 0, "some rays must meet total internal reflection");
}

/// Ultra-grazing entries: rays passing the centre at r·(1 − 10^U(−12,−2)), so they meet
/// the ball at up to 1e-6 from the tangent: the hit is an entry (near root) whatever the
/// sign of d·n says, the refracted direction is finite, and a crossing ray finds the
/// exit. Prints how often sign(d·n) disagrees and how often rounding reflects.
#[test]
fn ultra_grazing_entries_stay_finite_and_find_the_exit() {
    let counts = RefCell::new([0u64; 4]);
    runner(20_000)
        .run(
            &(
                log_uniform(-3.0, 3.0),
                unit_vector(),
                unit_vector(),
                log_uniform(-12.0, -2.0),
                log_uniform(0.5, 3.0),
                ior(),
            ),
            |(r, view, side, gap, dist, ior)| {
                let c = DVec3::new(1.0, 2.0, -3.0) * r;
                let across =
                    (side - view * side.dot(view)).normalize_or(view.any_orthonormal_vector());
                let eye = c - view * (r * dist) + across * (r * (1.0 - gap));
                let set = Spheres::new(&[Sphere::new(c, r)]);
                let q = query(eye, view, None);
                let Some(hit) = set.closest(&q) else {
                    return Ok(()); // the rounded ray passes outside
                };
                let mut cnt = counts.borrow_mut();
                cnt[0] += 1;
                prop_assert!(hit.entering, "a ray from outside enters at the near root");
                if q.dir.as_dvec3().dot(hit.normal) >= 0.0 {
                    cnt[1] += 1; // sign(d·n) would call this an exit
                }
                let n = hit.normal.as_vec3();
                let (dir, crosses) = model::transmit(q.dir, n, true, ior as f32);
                prop_assert!(dir.is_finite());
                if crosses {
                    let exit =
                        set.closest(&query(hit.point, dir.as_dvec3(), Some((0, Side::Inward))));
                    if exit.is_none() {
                        cnt[3] += 1;
                    }
                    prop_assert!(exit.is_some_and(|h| !h.entering), "the exit is found");
                } else {
                    cnt[2] += 1;
                    prop_assert!(dir.dot(n) >= -1e-6, "a reflected ray stays outside");
                }
                Ok(())
            },
        )
        .unwrap();
    let [n, sign, tir, miss] = counts.into_inner();
    println!(
        "ultra-grazing entries: {n} hits, sign(d·n) wrong {sign}, rounding TIR {tir}, exit misses {miss}"
    );
    assert!(n > 10_000);
}

/// A scene of two facing pure mirrors (reflect 1) and a camera between them looking
/// along the axis: the ray bounces to the depth limit and returns the sky seen
/// horizontally, `(down + up)/2`.
fn mirrors() -> (Scene, Camera) {
    let r = 1e4;
    let mirror = |x: f64| Sphere {
        reflect: 1.0,
        ..Sphere::new(DVec3::new(x, 0.0, 0.0), r)
    };
    let scene = Scene {
        name: "mirrors".into(),
        camera: Some(CameraSpec::LookAt {
            look_from: DVec3::ZERO,
            look_at: DVec3::X,
            up: DVec3::Y,
            vfov: 10.0,
        }),
        image: Default::default(),
        sky: Default::default(),
        lights: vec![Light::default()],
        spheres: vec![mirror(-r - 1.0), mirror(r + 1.0)],
    };
    let camera = scene.camera(16, 9).unwrap();
    (scene, camera)
}

#[test]
fn facing_mirrors_at_depth_64_bounce_to_the_limit() {
    let (scene, camera) = mirrors();
    let expected = (scene.sky.down + scene.sky.up) * 0.5;
    // A thread with a quarter of rayon's default stack: recursion must fit with room.
    let result = std::thread::Builder::new()
        .stack_size(512 * 1024)
        .spawn(move || {
            let mut fast_counts = RayCounts::default();
            let fast = FastTracer::new(&scene, &camera, 64).sample(0.5, 0.5, &mut fast_counts);
            let mut ref_counts = RayCounts::default();
            let reference =
                ReferenceTracer::new(&scene, camera, 64).sample(0.5, 0.5, &mut ref_counts);
            (fast, fast_counts, reference, ref_counts)
        })
        .unwrap()
        .join()
        .expect("no stack overflow");
    let (fast, fast_counts, reference, ref_counts) = result;
    println!("facing mirrors depth 64: fast {fast} ({fast_counts:?}), reference {reference} ({ref_counts:?})");
    for (c, counts) in [(fast, fast_counts), (reference, ref_counts)] {
        assert!(c.is_finite());
        assert_eq!(counts.primary, 1);
        assert_eq!(
            counts.secondary, 63,
            "every level up to the limit is traced"
        );
        assert!(
            (c - expected.as_vec3()).abs().max_element() < 1e-5,
            "{c} vs {expected}"
        );
    }
    // And the whole stress scene at depth 64 through the renderer's threads.
    let scene = Scene::load(&stress_dir().join("facing-mirrors.toml")).unwrap();
    assert_eq!(scene.image.max_depth, Some(64));
    for renderer in [Precision::Fast, Precision::Reference] {
        let img = render_with(&scene, 160, 90, renderer);
        assert_eq!(img.non_finite, 0);
    }
}
