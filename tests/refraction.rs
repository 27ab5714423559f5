//! Refraction and deep recursion in the tracers: Snell's law in the fast path's `f32`
//! formula (`model::transmit::<Vec3>`) and two facing mirrors at the depth limit.
//! Refraction through the fast path's sphere queries is tested with those queries, in
//! `src/accel/tests/refraction.rs`.

mod support;

use std::cell::RefCell;

use glam::DVec3;
use proptest::prelude::*;
use support::*;
use whitted::camera::Camera;
use whitted::camera::CameraSpec;
use whitted::model;
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
        animation: None,
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
