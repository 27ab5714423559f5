//! Intersection and spawned rays through the fast path's queries ([`Spheres::closest`]
//! and [`Spheres::shadow`] with a [`Query`]), against an independent `f64` computation
//! ([`roots64`]).
//!
//! Two truths: the query's own ray (its direction rounded to `f32`, promoted), which
//! measures the intersection maths and the spawn logic alone, and the unrounded `f64`
//! ray, which adds the rounding of the direction (what a user sees).

use std::cell::RefCell;

use std::ops::Sub;

use glam::DVec3;
use proptest::prelude::*;

use super::*;
use crate::accel::Spheres;
use crate::model;
use crate::scene::Sphere;

/// What the fast path's answer is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Truth {
    /// The ray the query holds (its `f32` direction promoted), computed in `f64`: the
    /// error of the intersection maths alone.
    QueryRay,
    /// The `f64` ray before it was rounded into the query: the error a user sees.
    Unrounded,
}

#[derive(Default, Debug)]
struct ReHits {
    spheres: u64,
    primary_misses: u64,
    outward: u64,
    outward_rehits: u64,
    shadow: u64,
    shadowed: u64,
    inward: u64,
    inward_misses: u64,
    max_rel_t: f64,
}

/// pbrt's TestReintersectConvex for spheres, through the fast path: `spheres` random
/// spheres; from the hit of a ray coming from a random distance, 32 outward rays (one of
/// them the mirror reflection, the others random down to 1e-6 from the tangent plane)
/// must never meet their own sphere, 32 shadow rays toward random points outside must
/// not be shadowed by it, and 32 inward rays must find the far exit with t within 1e-5
/// (relative) of the `f64` value; 0 misses. Returns the figures, or the first failure
/// (shrunk by proptest) with the figures so far.
fn reintersection(truth: Truth, spheres: u32) -> Result<ReHits, String> {
    let stats = RefCell::new(ReHits::default());
    let spawn = prop::collection::vec((unit_vector(), log_uniform(-3.0, 3.0)), 32);
    let result = runner(spheres).run(&(sphere_and_eye(), spawn), |((c, r, eye, aim), dirs)| {
        let set = Spheres::new(&[Sphere::new(c, r)]);
        let mut s = stats.borrow_mut();
        s.spheres += 1;
        let primary = query(eye, aim - eye, None);
        let Some(hit) = set.closest(&primary) else {
            // The f32 direction can miss a ball that is tiny next to its distance;
            // counted, and nothing to spawn from.
            s.primary_misses += 1;
            return Ok(());
        };
        prop_assert!(hit.entering, "an eye outside the ball enters it");
        let n = hit.normal;
        let d = query_ray(&primary).1;
        for (k, &(u, far)) in dirs.iter().enumerate() {
            // Outward: the reflection first, then random, some nearly tangent.
            let out = if k == 0 {
                model::reflect(d, n).normalize()
            } else {
                in_hemisphere(n, u, 1e-6)
            };
            s.outward += 1;
            if set
                .closest(&query(hit.point, out, Some((0, Side::Outward))))
                .is_some()
            {
                s.outward_rehits += 1;
            }
            // A shadow ray toward a point outside, r·10^U(−3,3) away.
            let to = in_hemisphere(n, u, 1e-3) * (r * far);
            s.shadow += 1;
            if set.shadow(
                &query(hit.point, to, Some((0, Side::Outward))),
                to.length(),
                hit.point + to,
            ) < 1.0
            {
                s.shadowed += 1;
            }
            // Inward: the far side, at least 1e-2 from the tangent plane.
            let inward = in_hemisphere(-n, u, 1e-2);
            let q = query(hit.point, inward, Some((0, Side::Inward)));
            let (o, dq) = match truth {
                Truth::QueryRay => query_ray(&q),
                Truth::Unrounded => (hit.point, inward),
            };
            s.inward += 1;
            let expected = roots64(o, dq, c, r)
                .map(|(_, far)| far)
                .filter(|t| *t > 0.0);
            match (set.closest(&q), expected) {
                (Some(exit), Some(t_ref)) => {
                    prop_assert_eq!(exit.sphere, 0);
                    prop_assert!(!exit.entering, "an inward ray leaves the ball");
                    let t = (exit.point - o).dot(dq);
                    let rel = (t - t_ref).abs() / t_ref;
                    s.max_rel_t = s.max_rel_t.max(rel);
                    prop_assert!(
                        rel <= 1e-5,
                        "r {r:e}, |c| {:e}: exit t {t} vs f64 {t_ref}: relative error {rel:e}",
                        c.length()
                    );
                    // A light inside the ball, halfway to the far side: the segment
                    // to it ends before it leaves the ball, which does not shadow it.
                    s.shadow += 1;
                    if set.shadow(&q, 0.5 * t_ref, o + dq * (0.5 * t_ref)) < 1.0 {
                        s.shadowed += 1;
                    }
                }
                // A grazing line that misses at f64 precision: so does the fast path.
                (None, None) if truth == Truth::QueryRay => {}
                (got, want) => {
                    s.inward_misses += 1;
                    prop_assert!(
                        false,
                        "r {r:e}, |c| {:e}: exit {got:?} but f64 says {want:?}",
                        c.length()
                    );
                }
            }
        }
        prop_assert_eq!(s.outward_rehits, 0, "an outward ray met its own sphere");
        prop_assert_eq!(s.shadowed, 0, "a shadow ray was shadowed by its own sphere");
        Ok(())
    });
    let s = stats.into_inner();
    println!(
        "re-intersection ({truth:?}): {} spheres tried ({} primary misses at f32 resolution); \
         outward rays {} re-hits {}; shadow rays {} shadowed {}; inward rays {} misses {} \
         max rel. error of t {:.2e}",
        s.spheres,
        s.primary_misses,
        s.outward,
        s.outward_rehits,
        s.shadow,
        s.shadowed,
        s.inward,
        s.inward_misses,
        s.max_rel_t
    );
    result.map(|()| s).map_err(|e| e.to_string())
}

/// Hit or miss, fast path against `f64`: rays from an eye near the origin aimed within
/// 2r of a ball `dist` away. Returns (rays, wrong, and the largest distance from the
/// ball's silhouette of a wrong ray in units of `|c − eye|·ε_f32`, the lateral shift
/// of rounding a direction to `f32`).
fn hit_miss(truth: Truth, r: f64, dist: f64, rays: u32) -> (u64, u64, f64) {
    let counts = RefCell::new((0u64, 0u64, 0f64));
    let case = (
        log_uniform(-2.0, 1.0),
        unit_vector(),
        unit_vector(),
        unit_vector(),
        0.0f64..1.0,
    );
    runner(rays)
        .run(&case, |(eye_dist, eye_dir, view, off, k)| {
            let eye = eye_dir * eye_dist;
            let c = eye + view * dist;
            // A point within 2r of the centre, across the view, uniform over the disc.
            let across = (off - view * off.dot(view)).normalize_or(view.any_orthonormal_vector());
            let aim = c + across * (2.0 * r * k.sqrt());
            let q = query(eye, aim - eye, None);
            let (o, d) = match truth {
                Truth::QueryRay => query_ray(&q),
                Truth::Unrounded => (eye, (aim - eye).normalize()),
            };
            let want = roots64(o, d, c, r).is_some_and(|(near, far)| near > 0.0 || far > 0.0);
            let got = Spheres::new(&[Sphere::new(c, r)]).closest(&q).is_some();
            let mut n = counts.borrow_mut();
            n.0 += 1;
            if got != want {
                n.1 += 1;
                let edge = ((c - o).cross(d).length() - r).abs();
                n.2 = n.2.max(edge / ((c - o).length() * f64::from(f32::EPSILON)));
            }
            Ok(())
        })
        .unwrap();
    let (n, wrong, edge) = counts.into_inner();
    println!(
        "hit/miss ({truth:?}) r={r:e} at {dist:e}: {wrong} wrong of {n} ({:.3}%), within \
         {edge:.2} |c-eye|·eps_f32 of the silhouette",
        100.0 * wrong as f64 / n as f64
    );
    (n, wrong, edge)
}

/// A ground of `radius` seen from 0.5 above its top, at depressions from just past the
/// horizon to 0.1 rad beyond it, eyes within 10 of the top: the relative error of the
/// hit's t. Returns (rays, median, max, and the largest excess of the error over what
/// rounding the direction to `f32` explains: the relative change of the `f64` t
/// between the unrounded ray and the query's).
fn ground_grazing(truth: Truth, radius: f64) -> (u64, f64, f64, f64) {
    let h = 0.5;
    let c = DVec3::new(0.0, -h - radius, 0.0);
    let horizon = (2.0 * h / radius).sqrt();
    let errors = RefCell::new(Vec::new());
    let excess = RefCell::new(0f64);
    let case = (
        log_uniform(-6.0, -1.0),
        0.0f64..std::f64::consts::TAU,
        (-10.0f64..10.0, -10.0f64..10.0),
    );
    runner(5000)
        .run(&case, |(past, azimuth, (x, z))| {
            let depression = horizon * (1.0 + past) + past;
            let eye = DVec3::new(x, 0.0, z);
            let dir = DVec3::new(
                depression.cos() * azimuth.cos(),
                -depression.sin(),
                depression.cos() * azimuth.sin(),
            );
            let q = query(eye, dir, None);
            let (o, d) = match truth {
                Truth::QueryRay => query_ray(&q),
                Truth::Unrounded => (eye, dir),
            };
            let Some((t_ref, _)) = roots64(o, d, c, radius) else {
                return Ok(());
            };
            let hit = Spheres::new(&[Sphere::new(c, radius)]).closest(&q);
            // What rounding the direction alone moves t by (0 on the query's ray).
            let (qo, qd) = query_ray(&q);
            let rounding = roots64(qo, qd, c, radius)
                .map_or(f64::INFINITY, |(t_q, _)| (t_q - t_ref).abs() / t_ref);
            // t along the measured ray to the fast path's hit point.
            if let Some(hit) = hit {
                let e = (hit.point - o).dot(d).sub(t_ref).abs() / t_ref;
                errors.borrow_mut().push(e);
                let mut x = excess.borrow_mut();
                *x = x.max(e - rounding);
            } else {
                errors.borrow_mut().push(f64::INFINITY);
            }
            Ok(())
        })
        .unwrap();
    let mut e = errors.into_inner();
    e.sort_by(f64::total_cmp);
    let (n, median, max) = (e.len() as u64, e[e.len() / 2], *e.last().unwrap());
    let excess = excess.into_inner();
    println!(
        "ground r={radius:e} grazing ({truth:?}): {n} rays, rel. error of t median {median:.2e} \
         max {max:.2e}, beyond the direction's rounding {excess:.2e}"
    );
    (n, median, max, excess)
}

#[test]
fn spawned_rays_never_rehit_their_sphere_and_always_find_the_exit() {
    for truth in [Truth::QueryRay, Truth::Unrounded] {
        let s = reintersection(truth, 1000).unwrap_or_else(|e| panic!("{e}"));
        assert!(s.spheres >= 1000);
        assert!(
            s.spheres - s.primary_misses >= 990,
            "too few hits to spawn from: {s:?}"
        );
        assert_eq!((s.outward_rehits, s.shadowed, s.inward_misses), (0, 0, 0));
    }
}

/// On the query's own ray hit or miss is always right. Against the unrounded ray the
/// `f32` direction's resolution shows: a wrong answer only for a ray that passes the
/// silhouette within the lateral shift of rounding its direction (`|c − eye|·ε_f32`:
/// each component moves by at most half an ulp, and the renormalisation by a few).
#[test]
fn hit_or_miss_matches_f64_for_small_far_balls() {
    for (r, dist) in [(0.01, 100.0), (1e-3, 1e3)] {
        let (_, wrong, _) = hit_miss(Truth::QueryRay, r, dist, 20_000);
        assert_eq!(wrong, 0, "r = {r} at distance {dist}");
        let (_, _, edge) = hit_miss(Truth::Unrounded, r, dist, 20_000);
        assert!(
            edge <= 1.0,
            "unrounded, r = {r} at distance {dist}: a wrong ray {edge} |c-eye|·eps_f32 \
             from the silhouette"
        );
    }
}

/// The ground of radius 1e5 (and 1e6) at grazing angles: relative error of t ≤ 1e-6
/// against `f64` on the query's ray, and against the unrounded ray ≤ 1e-6 beyond what
/// rounding the direction moves the exact t by.
#[test]
fn huge_ground_at_grazing_angles_keeps_t() {
    for radius in [1e5, 1e6] {
        let (_, _, max, _) = ground_grazing(Truth::QueryRay, radius);
        assert!(max <= 1e-6, "r {radius:e}: max relative error {max:e}");
        let (_, _, _, excess) = ground_grazing(Truth::Unrounded, radius);
        assert!(
            excess <= 1e-6,
            "r {radius:e}, unrounded: {excess:e} beyond the direction's rounding"
        );
    }
}
