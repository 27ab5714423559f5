//! Refraction through the fast queries: a ray refracted into a ball leaves it at the
//! angle it came in at; from inside a ball (a camera in glass, a ray just entered at a
//! grazing angle) the far side is found, and where Snell's law has no solution the ray
//! reflects and stays inside. Nothing is NaN or infinite.

use std::cell::RefCell;

use glam::DVec3;
use proptest::prelude::*;

use super::*;
use crate::accel::Spheres;
use crate::model;
use crate::scene::Sphere;

/// Entry/exit symmetry through the fast queries: a ray refracted into a ball leaves it
/// at the angle it came in at (the chord makes equal angles with both normals):
/// |sin θ_out − sin θ_in| ≤ 1e-5. Balls of radius 10^U(−3,5) with |centre| up to 1e4,
/// those with |centre| > `max_centre_over_radius`·r left out. Returns (max error, balls).
fn refraction_symmetry(max_centre_over_radius: f64) -> Result<(f64, u64), String> {
    let worst = RefCell::new((0.0f64, 0u64));
    let result = runner(5_000)
        .run(&(sphere_and_eye(), ior()), |((c, r, eye, aim), ior)| {
            if c.length() > max_centre_over_radius * r {
                return Ok(());
            }
            let set = Spheres::new(&[Sphere::new(c, r)]);
            let primary = query(eye, aim - eye, None);
            let Some(hit) = set.closest(&primary) else {
                return Ok(());
            };
            let d = primary.dir;
            let (inside, crosses) = model::transmit(d, hit.normal.as_vec3(), true, ior as f32);
            if !crosses {
                // Rounding can make k < 0 at grazing entry; then it reflects (tested below).
                return Ok(());
            }
            let q = query(hit.point, inside.as_dvec3(), Some((0, Side::Inward)));
            let exit = set.closest(&q);
            prop_assert!(exit.is_some(), "the refracted ray must find the exit");
            let exit = exit.unwrap();
            prop_assert!(!exit.entering);
            let (out, crosses) = model::transmit(q.dir, exit.normal.as_vec3(), false, ior as f32);
            prop_assert!(out.is_finite());
            prop_assert!(
                crosses,
                "a chord's exit angle equals its entry angle: no TIR"
            );
            let sin_in = sin_between(d.as_dvec3(), hit.normal);
            let sin_out = sin_between(out.as_dvec3(), exit.normal);
            let err = (sin_out - sin_in).abs();
            let mut w = worst.borrow_mut();
            w.0 = w.0.max(err);
            w.1 += 1;
            prop_assert!(
                err <= 1e-5,
                "r {r:e} |c| {:e}: sin in {sin_in} out {sin_out}",
                c.length()
            );
            Ok(())
        })
        .map_err(|e| e.to_string());
    let (err, n) = worst.into_inner();
    println!(
        "entry/exit symmetry (|c| ≤ {max_centre_over_radius:e} r): {n} balls, max |sin θout − sin θin| {err:.2e}"
    );
    result.map(|()| (err, n))
}

/// Entry/exit symmetry through the fast queries (see `refraction_symmetry`):
/// balls of radius 10^U(−3,5) with |centre| up to 1e4, |sin θout − sin θin| ≤ 1e-5.
#[test]
fn refraction_through_a_ball_is_symmetric() {
    let (err, n) = refraction_symmetry(f64::INFINITY).unwrap_or_else(|e| panic!("{e}"));
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
