//! Tests of the queries of [`Spheres`] against independent `f64` computations: the
//! rounding of spawn points and distances ([`intersection`]), refraction through a ball
//! ([`refraction`]), the culling of the hierarchy and the grids ([`culling`]), bundles
//! of primary rays ([`bundle`]) and the work it skips ([`work`]).
//! Random cases come from proptest with log-uniform radii and distances and a fixed
//! seed, so the printed figures reproduce.

mod bundle;
mod culling;
mod intersection;
mod quick;
mod refraction;
mod work;

use glam::DVec3;
use proptest::strategy::Strategy;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

use super::{list_radius, round_down, round_up, InsideLists, Query, WALK_INSIDE_FROM};
use crate::model::Side;

/// A proptest runner of `cases` cases with a fixed seed and no persisted failures.
pub(super) fn runner(cases: u32) -> TestRunner {
    TestRunner::new_with_rng(
        Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    )
}

/// `count` unit vectors spread evenly over the sphere of directions (a Fibonacci
/// lattice: equal steps in z, the golden angle about it).
pub(super) fn even_directions(count: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / count as f64;
            let s = (1.0 - z * z).sqrt();
            let phi = golden * k as f64;
            DVec3::new(s * phi.cos(), s * phi.sin(), z)
        })
        .collect()
}

/// A fast-path query from an `f64` spawn point and an `f64` direction rounded to `f32`
/// and renormalised in `f32`, as the fast tracer makes them: the one place to change
/// if the query's types change.
fn query(origin: DVec3, dir: DVec3, from: Option<(u32, Side)>) -> Query {
    Query {
        origin,
        dir: dir.as_vec3().normalize(),
        from,
    }
}

/// The ray the fast path actually traces for a query: its origin and direction in
/// `f64`, the direction normalised in `f64`.
fn query_ray(q: &Query) -> (DVec3, DVec3) {
    (q.origin, q.dir.as_dvec3().normalize())
}

/// Independent `f64` ray/sphere roots (unit `d`): `(near, far)`, written here rather
/// than taken from `crate::intersect` so that the tests do not check it against itself.
/// Distance from the centre to the line via the cross product; roots from the chord.
fn roots64(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<(f64, f64)> {
    let f = c - o;
    let along = f.dot(d);
    let off = f.cross(d).length();
    if off > r {
        return None;
    }
    let half = ((r - off) * (r + off)).sqrt();
    // Near root without cancellation: (|f|² − r²)/(along + half) when along > 0.
    let far_abs = along.abs() + half;
    let c_term = (f.length() - r) * (f.length() + r);
    if along >= 0.0 {
        Some((c_term / far_abs, far_abs))
    } else {
        Some((-far_abs, -c_term / far_abs))
    }
}

/// Uniform numbers in [0, 1) from a Mersenne twister seeded with `seed`: the unit
/// tests' reproducible random cases.
pub(super) fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut rng = rand_mt::Mt64::new(seed);
    move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// Log-uniform `10^U(lo, hi)`.
pub(super) fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo..hi).prop_map(|e: f64| 10f64.powf(e))
}

/// A uniformly distributed unit vector.
pub(super) fn unit_vector() -> impl Strategy<Value = DVec3> {
    (-1.0f64..1.0, 0.0f64..std::f64::consts::TAU).prop_map(|(z, phi)| {
        let s = (1.0 - z * z).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    })
}

/// A unit vector in the hemisphere around `n`, at least `min_cos` from the tangent plane.
fn in_hemisphere(n: DVec3, u: DVec3, min_cos: f64) -> DVec3 {
    let mut v = if u.dot(n) < 0.0 { -u } else { u };
    let cos = v.dot(n);
    if cos < min_cos {
        v = (v - n * cos).normalize_or(n.any_orthonormal_vector())
            * (1.0 - min_cos * min_cos).sqrt()
            + n * min_cos;
    }
    v.normalize()
}

/// A sphere of radius 10^U(−3,5) with its centre 10^U(−2,4) from the origin, an eye
/// r·10^U(0.01,3) from the centre, and a point of the ball to aim at.
fn sphere_and_eye() -> impl Strategy<Value = (DVec3, f64, DVec3, DVec3)> {
    (
        log_uniform(-3.0, 5.0),
        log_uniform(-2.0, 4.0),
        unit_vector(),
        log_uniform(0.01, 3.0),
        unit_vector(),
        unit_vector(),
        0.0f64..0.9,
    )
        .prop_map(|(r, dist_c, dir_c, eye_k, dir_eye, dir_aim, aim_k)| {
            let c = dir_c * dist_c;
            (c, r, c + dir_eye * (r * eye_k), c + dir_aim * (r * aim_k))
        })
}

/// An index of refraction 1 + 10^U(−3, 0.2) (1.001 to 2.58).
fn ior() -> impl Strategy<Value = f64> {
    log_uniform(-3.0, 0.2).prop_map(|x| 1.0 + x)
}

/// sin of the angle between two vectors, in `f64`.
fn sin_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length() / (a.length() * b.length())
}

/// Values on, beside and between `f32`s of every magnitude and sign, the zeros, the
/// limits and beyond, the infinities and NaN.
fn roundings_to_check() -> Vec<f64> {
    let mut values = vec![
        0.0,
        -0.0,
        1e-300,
        -1e-300,
        f64::from(f32::MAX),
        f64::from(f32::MAX) * (1.0 + 1e-12),
        -f64::from(f32::MAX) * (1.0 + 1e-12),
        1e300,
        -1e300,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        -1.5,
    ];
    for e in -155..=129 {
        let f = 2f64.powi(e) * 1.2345;
        for x in [f, -f] {
            let f32_near = f64::from(x as f32);
            values.extend([x, f32_near, f32_near.next_up(), f32_near.next_down()]);
        }
    }
    values
}

#[test]
fn round_up_is_the_least_f32_not_below() {
    for t in roundings_to_check() {
        let up = round_up(t);
        let f = t as f32;
        let want = if f64::from(f) < t { f.next_up() } else { f };
        assert_eq!(up.to_bits(), want.to_bits(), "t = {t:e}");
        assert!(t.is_nan() || f64::from(up) >= t, "t = {t:e}");
    }
}

#[test]
fn round_down_is_the_greatest_f32_not_above() {
    for t in roundings_to_check() {
        let down = round_down(t);
        let f = t as f32;
        let want = if f64::from(f) > t { f.next_down() } else { f };
        assert_eq!(down.to_bits(), want.to_bits(), "t = {t:e}");
        assert!(t.is_nan() || f64::from(down) <= t, "t = {t:e}");
    }
}

/// Every sphere of a scene up to `WALK_INSIDE_FROM` spheres keeps its list of
/// overlapping spheres; in a larger one, those of more than twice the median radius.
#[test]
fn only_large_spheres_of_large_scenes_keep_lists() {
    let balls =
        |radii: &[f64]| -> Vec<(DVec3, f64)> { radii.iter().map(|&r| (DVec3::ZERO, r)).collect() };
    let mut radii = vec![0.25; WALK_INSIDE_FROM];
    radii[7] = 1000.0;
    assert_eq!(list_radius(&balls(&radii)), 0.0);
    let all = InsideLists::new(&balls(&radii));
    assert!((0..WALK_INSIDE_FROM as u32).all(|s| all.of(s).is_some()));
    // One more sphere: 2^18 + 1 radii, the median (the 2^17-th from 0) is 0.25.
    radii.push(3.0);
    assert_eq!(list_radius(&balls(&radii)), 0.5);
    let few = InsideLists::new(&balls(&radii));
    let keepers: Vec<u32> = (0..radii.len() as u32)
        .filter(|&s| few.of(s).is_some())
        .collect();
    assert_eq!(keepers, [7, WALK_INSIDE_FROM as u32]);
    assert_eq!(few.lists.len(), 2, "no list kept for the small balls");
    // Each keeper its own list.
    few.of(7).unwrap().set(Some(Box::new([1]))).unwrap();
    assert!(few.of(WALK_INSIDE_FROM as u32).unwrap().get().is_none());
    // Half the spheres larger: the median moves to the larger radius.
    let n = radii.len();
    radii[..n / 2 + 1].fill(2.0);
    assert_eq!(list_radius(&balls(&radii)), 4.0);
}
