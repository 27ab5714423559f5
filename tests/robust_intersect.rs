//! Issue 4, intersection and spawned rays through the fast path's public queries
//! (`accel::Spheres::closest` / `shadow` with an `accel::Query`), against an independent
//! `f64` computation (`robust_support::roots64`). Random cases come from proptest with
//! log-uniform radii and distances and a fixed seed, so the printed figures reproduce.
//!
//! Two truths: the query's own ray (its direction rounded to `f32`, promoted), which
//! measures the intersection maths and the spawn logic alone, and the unrounded `f64`
//! ray, which adds the rounding of the direction (what a user sees).

mod robust_support;

use robust_support::cases::{self, Truth};

#[test]
fn spawned_rays_never_rehit_their_sphere_and_always_find_the_exit() {
    for truth in [Truth::QueryRay, Truth::Unrounded] {
        let s = cases::reintersection(truth, 1000).unwrap_or_else(|e| panic!("{e}"));
        assert!(s.spheres >= 1000);
        assert!(
            s.spheres - s.primary_misses >= 990,
            "too few hits to spawn from: {s:?}"
        );
        assert_eq!((s.outward_rehits, s.shadowed, s.inward_misses), (0, 0, 0));
    }
}

#[test]
fn hit_or_miss_matches_f64_for_small_far_balls() {
    let (_, wrong) = cases::hit_miss(Truth::QueryRay, 0.01, 100.0, 20_000);
    assert_eq!(wrong, 0, "r = 0.01 at distance 100");
    let (n, wrong) = cases::hit_miss(Truth::QueryRay, 1e-3, 1e3, 20_000);
    assert!(wrong as f64 <= 0.02 * n as f64, "r = 1e-3 at distance 1e3");
    // Against the unrounded ray the f32 direction's resolution shows (printed figures).
    let (n, wrong) = cases::hit_miss(Truth::Unrounded, 1e-3, 1e3, 20_000);
    assert!(
        wrong as f64 <= 0.02 * n as f64,
        "unrounded, r = 1e-3 at distance 1e3"
    );
    cases::hit_miss(Truth::Unrounded, 0.01, 100.0, 20_000);
}

/// The ground of radius 1e5 (and 1e6) at grazing angles: relative error of t ≤ 1e-6
/// against `f64` on the query's ray; the unrounded ray's figures are printed.
#[test]
fn huge_ground_at_grazing_angles_keeps_t() {
    for radius in [1e5, 1e6] {
        let (_, _, max) = cases::ground_grazing(Truth::QueryRay, radius);
        assert!(max <= 1e-6, "r {radius:e}: max relative error {max:e}");
        cases::ground_grazing(Truth::Unrounded, radius);
    }
}
