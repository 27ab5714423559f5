//! Bundles of primary rays ([`Spheres::closest_bundle`]) get each ray's own hit, to
//! the bit, from [`Spheres::closest`] (which `culling` checks against brute force):
//! rows of directions across a ball as the camera forms them, directions of every
//! sign, and directions along the axes (zero components), from eyes outside and
//! inside the spheres.

use std::cell::RefCell;

use glam::{DVec3, Vec3};
use proptest::prelude::*;

use super::culling::world;
use super::*;
use crate::accel::{Hit, Spheres, BUNDLE};

#[test]
fn a_bundle_gets_each_ray_s_own_hit() {
    // (bundles, rays, hits, bundles from inside a sphere)
    let counts = RefCell::new((0u64, 0u64, 0u64, 0u64));
    let bundle = (0.0f64..1.0, unit_vector(), 0.0f64..0.05, 0u8..3, 1..=BUNDLE);
    runner(120)
        .run(
            &(
                world(),
                log_uniform(-1.0, 4.0),
                unit_vector(),
                prop::collection::vec(bundle, 16),
            ),
            |(spheres, eye_dist, eye_dir, bundles)| {
                let eye = eye_dir * eye_dist;
                let set = Spheres::new(&spheres);
                let inside = spheres.iter().any(|s| (s.center - eye).length() < s.radius);
                let mut c = counts.borrow_mut();
                for &(pick, across, span, kind, len) in &bundles {
                    let s =
                        &spheres[((pick * spheres.len() as f64) as usize).min(spheres.len() - 1)];
                    let base = (s.center - eye).normalize_or(across);
                    let side = across.cross(base).normalize_or(across);
                    let dirs: Vec<Vec3> = (0..len)
                        .map(|i| {
                            let x = i as f64 / BUNDLE as f64 - 0.5;
                            let d = match kind {
                                // A row across the ball.
                                0 => base + side * (span * x),
                                // Any directions: every sign on every axis.
                                1 => {
                                    let a = 40.0 * pick + 3.0 * i as f64;
                                    DVec3::new(a.sin(), (1.3 * a).cos(), (0.7 * a).sin() - 0.2)
                                }
                                // Along the ball's direction with one axis zeroed.
                                _ => {
                                    let mut d = base + side * (span * x);
                                    d[i % 3] = 0.0;
                                    d
                                }
                            };
                            d.normalize_or(across).as_vec3().normalize()
                        })
                        .collect();
                    let mut hits = [None; BUNDLE];
                    set.closest_bundle(eye, &dirs, &mut hits[..len]);
                    c.0 += 1;
                    c.3 += u64::from(inside);
                    for (&dir, &got) in dirs.iter().zip(&hits[..len]) {
                        let alone = set.closest(&Query {
                            origin: eye,
                            dir,
                            from: None,
                        });
                        let key =
                            |h: Option<Hit>| h.map(|h| (h.sphere, h.point, h.normal, h.entering));
                        prop_assert_eq!(key(got), key(alone), "direction {:?}", dir);
                        c.1 += 1;
                        c.2 += u64::from(got.is_some());
                    }
                }
                Ok(())
            },
        )
        .unwrap_or_else(|e| panic!("{e}\n{:?}", counts.borrow()));
    let (bundles, rays, hits, inside) = counts.into_inner();
    println!("{bundles} bundles ({inside} from inside a sphere), {rays} rays, {hits} hits");
    assert!(
        rays > 5000 && hits > 2000 && inside > 100 && bundles - inside > 100,
        "too few to say anything: {rays} rays, {hits} hits, {inside} of {bundles} inside"
    );
}
