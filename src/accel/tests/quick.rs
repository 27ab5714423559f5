//! The quick tests and boxes in front of the exact tests, against the `f64` geometry
//! of the sphere they stand for: never `false` for a ray that meets it, nor a box that
//! cuts it (the exact test would have found a hit there), and `false` for a ray that
//! clearly misses it, a box that clearly fits (the work they exist to skip).

use std::cell::Cell;

use glam::{DVec3, Vec3};
use proptest::prelude::*;

use super::*;
use crate::accel::point::{EyeQuick, ShadowQuick};
use crate::accel::{may_cross, quick_radius, sphere_box, Ray, QUICK_SLACK};

/// A ray from a point against a sphere, the geometry in `f64`.
#[derive(Debug)]
struct Case {
    point: DVec3,
    centre: DVec3,
    radius: f32,
    /// The ray's direction, a unit vector in `f32`.
    d: Vec3,
    t_max: f32,
    /// How far the quick test's line may pass from the point (`may_cross_near`).
    offset: f32,
}

impl Case {
    /// The half chord of the sphere widened by `widen` along the ray's line (0 when
    /// the line misses it).
    fn half_chord(&self, widen: f64) -> f64 {
        let r = f64::from(self.radius) + widen;
        let line = (self.point - self.centre).cross(self.d.as_dvec3().normalize());
        (r * r - line.length_squared()).max(0.0).sqrt()
    }
}

/// A sphere of radius 10^U(−2, 2) 10 radii from the origin, a line at U(0, 1.6)
/// radii from its centre, the point on that line U(−60, 60) radii from the foot of
/// the perpendicular (inside the sphere, just outside and far away), `t_max` anything
/// from 0 to beyond the sphere, and an offset of 0 or up to a radius.
fn cases() -> impl Strategy<Value = Case> {
    (
        log_uniform(-2.0, 2.0),
        unit_vector(),
        unit_vector(),
        unit_vector(),
        0.0f64..1.6,
        -60.0f64..60.0,
        0.0f64..130.0,
        (0.0f64..1.0, 0.0f64..1.0),
    )
        .prop_map(|(r, c_dir, d, e, line, along, reach, (pick, o))| {
            let radius = r as f32;
            let r = f64::from(radius);
            let centre = c_dir * (10.0 * r);
            let d = d.as_vec3().normalize();
            let d64 = d.as_dvec3();
            let across = (e - d64 * e.dot(d64)).normalize_or(d64.any_orthonormal_vector());
            let point = centre + across * (line * r) - d64 * (along * r);
            let t_max = if reach > 125.0 {
                f32::INFINITY
            } else {
                (reach * r) as f32
            };
            let offset = if pick < 0.3 { 0.0 } else { (o * r) as f32 };
            Case {
                point,
                centre,
                radius,
                d,
                t_max,
                offset,
            }
        })
}

/// How far a quick test stretches the crossings of its (widened) sphere along the ray:
/// it must pass a ray whose crossings lie `must` beyond `(0, t_max)`, and may pass one
/// whose crossings lie up to `may` beyond it.
#[derive(Clone, Copy)]
struct Stretch {
    must: f64,
    may: f64,
}

/// What a quick test must answer for the ray of `c` against its sphere widened by
/// `widen`: `Some(true)` when the ray meets it at a distance in `(0, t_max)`
/// stretched by `stretch.must` (by a margin), `Some(false)` when its line passes
/// outside it, or its crossings, stretched by `stretch.may` each way, lie all before 0
/// or all beyond `t_max` (by a margin), `None` when it is too close to call.
fn expected(c: &Case, widen: f64, stretch: Stretch) -> Option<bool> {
    let d = c.d.as_dvec3().normalize();
    let f = c.point - c.centre;
    let r = f64::from(c.radius) + widen;
    let t_max = f64::from(c.t_max);
    // 25 times the quick tests' slack of 2⁻¹⁸ relative.
    let margin = 1e-4 * (r + f.length());
    let along = -f.dot(d);
    let line2 = f.cross(d).length_squared();
    if line2 > r * r + margin * (r + f.length()) {
        return Some(false);
    }
    if line2 > r * r {
        return None;
    }
    let half = c.half_chord(widen);
    let (near, far) = (along - half, along + half);
    let meets = |t: f64| t > margin - stretch.must && t < t_max + stretch.must - margin;
    if meets(near) || meets(far) {
        return Some(true);
    }
    if far + stretch.may < -margin || near - stretch.may > t_max + margin {
        return Some(false);
    }
    None
}

/// Runs `quick` on 4,000 cases against [`expected`] with the widening and stretch
/// `bounds` gives, and checks that both answers were asked for often.
fn check(name: &str, quick: impl Fn(&Case) -> bool, bounds: impl Fn(&Case) -> (f64, Stretch)) {
    let (passed, rejected) = (Cell::new(0), Cell::new(0));
    runner(4000)
        .run(&cases(), |c| {
            let (widen, stretch) = bounds(&c);
            if let Some(want) = expected(&c, widen, stretch) {
                assert_eq!(quick(&c), want, "{c:?}");
                let count = if want { &passed } else { &rejected };
                count.set(count.get() + 1);
            }
            Ok(())
        })
        .unwrap();
    let (passed, rejected) = (passed.get(), rejected.get());
    println!("{name}: {passed} passed, {rejected} rejected, the rest too close to call");
    assert!(
        passed > 800 && rejected > 2000,
        "{passed} passed, {rejected} rejected"
    );
}

/// The quick test of a ray of any origin ([`may_cross`]): the sphere itself.
#[test]
fn the_quick_test_passes_every_ray_that_meets_the_sphere_and_rejects_clear_misses() {
    check(
        "may_cross",
        |c| {
            let q = Query {
                origin: c.point,
                dir: c.d,
                from: None,
            };
            may_cross(c.centre, c.radius, &Ray::new(&q), c.t_max)
        },
        |_| {
            (
                0.0,
                Stretch {
                    must: 0.0,
                    may: 0.0,
                },
            )
        },
    );
}

fn eye_quick(c: &Case) -> EyeQuick {
    EyeQuick::new(c.point, c.centre, c.radius)
}

fn shadow_quick(c: &Case) -> ShadowQuick {
    ShadowQuick::new(c.point, c.centre, c.radius)
}

/// The quick test of a ray through a grid's point bounds the crossings by the radius,
/// not the half chord: a ray is rejected as passing before 0 or beyond `t_max` only if
/// the whole radius is.
#[test]
fn the_point_s_quick_test_passes_every_ray_that_meets_the_sphere_and_rejects_clear_misses() {
    check(
        "EyeQuick::may_cross",
        |c| eye_quick(c).may_cross(c.d, c.t_max),
        |c| {
            let may = f64::from(c.radius) - c.half_chord(0.0);
            (0.0, Stretch { must: 0.0, may })
        },
    );
}

/// `may_cross_near` stands for every ray whose origin lies within `offset` of the
/// point: the sphere widened by `offset`, its crossings stretched by `offset` (from an
/// origin that far away, a crossing at `t` is one at `t ± offset`).
#[test]
fn the_near_quick_test_passes_every_ray_within_its_offset_and_rejects_clear_misses() {
    check(
        "ShadowQuick::may_cross_near",
        |c| shadow_quick(c).may_cross_near(c.d, c.t_max, c.offset),
        |c| {
            let o = f64::from(c.offset);
            (o, Stretch { must: o, may: o })
        },
    );
}

/// The shadow rays' line test keeps its error bound relative to the distance, not to
/// its square: from a light 100 away, a line 5% of a radius outside a ball of radius
/// 0.2 is rejected, one 5% inside passes (a slack of 2⁻¹⁷·|f|² on the squared
/// distance passed lines up to 1.7 radii out: an exact test each).
#[test]
fn the_near_quick_test_rejects_lines_just_outside_a_small_ball_far_away() {
    let (light, r) = (DVec3::new(-30.0, 60.0, 40.0), 0.2);
    for k in 0..16 {
        let angle = f64::from(k) * 0.4;
        let towards = DVec3::new(angle.cos(), -1.5, angle.sin()).normalize();
        let across = towards.cross(DVec3::Y).normalize();
        let centre = light + towards * 100.0;
        let quick = ShadowQuick::new(light, centre, quick_radius(centre, r));
        for (out, passes) in [(1.05, false), (0.95, true)] {
            let d = (towards * 100.0 + across * (out * r)).normalize().as_vec3();
            assert_eq!(
                quick.may_cross_near(d, 200.0, 0.0),
                passes,
                "line {out} radii from the centre, direction {towards}"
            );
        }
    }
}

/// The shadow entries' tail, derived from `|f|∞`, is at least the slack `may_cross`
/// gives `−f·d` (`QUICK_SLACK·(|f| + r)`, in `f64`) and at most twice it: along the
/// diagonals `|f|` is √3·`|f|∞`, the most it can be.
#[test]
fn the_shadow_entries_tail_covers_the_slack_of_the_distance_along_the_line() {
    let diagonal = Just(DVec3::ONE.normalize()).boxed();
    let directions = prop_oneof![unit_vector().boxed(), diagonal];
    runner(4000)
        .run(
            &(sphere(), directions, log_uniform(-2.0, 5.0)),
            |((c, r), u, d)| {
                let light = c + u * d;
                let w = quick_radius(c, r);
                let tail = f64::from(ShadowQuick::new(light, c, w).tail());
                let slack = f64::from(QUICK_SLACK) * ((light - c).length() + f64::from(w));
                assert!(
                    tail >= slack && tail <= 2.0 * slack,
                    "{c} {r} {light}: {tail} against {slack}"
                );
                Ok(())
            },
        )
        .unwrap();
}

/// A sphere of radius 10^U(−3, 5) with its centre 10^U(−2, 5) from the origin.
fn sphere() -> impl Strategy<Value = (DVec3, f64)> {
    (
        log_uniform(-2.0, 5.0),
        unit_vector(),
        log_uniform(-3.0, 5.0),
    )
        .prop_map(|(d, u, r)| (u * d, r))
}

/// The quick tests' `f32` radius around the centre rounded to `f32` holds the `f64`
/// sphere, and is larger by no more than a few units of `f32` rounding of the
/// centre's and radius's size.
#[test]
fn the_quick_radius_holds_the_sphere_and_little_more() {
    runner(4000)
        .run(&sphere(), |(c, r)| {
            let w = f64::from(quick_radius(c, r));
            let c32 = c.as_vec3().as_dvec3();
            let scale = c.abs().max_element() + r;
            assert!((c32 - c).length() + r <= w, "{c} {r}: {w}");
            assert!(w - r <= 1e-6 * scale, "{c} {r}: {w}");
            Ok(())
        })
        .unwrap();
}

/// The hierarchy's `f32` box of a sphere holds it, and is larger by no more than a
/// few millionths of the sphere's size and distance from the origin.
#[test]
fn the_box_of_a_sphere_holds_it_and_little_more() {
    runner(4000)
        .run(&sphere(), |(c, r)| {
            let b = sphere_box(c, r);
            let (lo, hi) = (b.min.as_dvec3(), b.max.as_dvec3());
            let scale = c.abs().max_element() + r;
            assert!(
                lo.cmple(c - r).all() && hi.cmpge(c + r).all(),
                "{c} {r}: {lo} {hi}"
            );
            let slack = (c - r - lo).max(hi - c - r).max_element();
            assert!(slack <= 3e-6 * scale, "{c} {r}: {slack:e}");
            Ok(())
        })
        .unwrap();
}
