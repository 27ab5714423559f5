//! Cases of the shading model (SPEC §2) whose answers are worked out by hand, here in
//! the comments and in plain trigonometry: first the shared formulas of
//! `whitted::model` in both precisions, then whole renders of tiny scenes through
//! `Scene::from_toml_str` + `render::render`, with the fast tracer and the reference.

use glam::{DVec3, Vec3};
use whitted::camera::{self, Camera, CameraError, CameraSpec};
use whitted::intersect;
use whitted::model;
use whitted::render::{self, Frame, RenderControl};
use whitted::settings::Precision;
use whitted::trace::RayCounts;
use whitted::Scene;

// ---------------------------------------------------------------------------------
// The formulas
// ---------------------------------------------------------------------------------

fn close(a: DVec3, b: DVec3, tol: f64) -> bool {
    (a - b).abs().max_element() <= tol
}

/// `sin` of the angle between a unit direction and the normal: `|d × n|`.
fn sin_to_normal(d: DVec3, n: DVec3) -> f64 {
    d.cross(n).length()
}

#[test]
fn sky_at_straight_down_horizontal_and_straight_up() {
    let (down, up) = (DVec3::ONE, DVec3::new(0.5, 0.7, 1.0));
    // t = (d.y + 1)/2: 0 looking down (all `down`), 1/2 level, 1 looking up.
    assert_eq!(model::sky(DVec3::NEG_Y, down, up), down);
    assert_eq!(model::sky(DVec3::Y, down, up), up);
    assert!(close(
        model::sky(DVec3::NEG_Z, down, up),
        DVec3::new(0.75, 0.85, 1.0),
        1e-15
    ));
    let (down32, up32) = (Vec3::ONE, Vec3::new(0.5, 0.7, 1.0));
    assert_eq!(model::sky(Vec3::NEG_Y, down32, up32), down32);
    assert_eq!(model::sky(Vec3::Y, down32, up32), up32);
    assert!(
        (model::sky(Vec3::X, down32, up32) - Vec3::new(0.75, 0.85, 1.0))
            .abs()
            .max_element()
            < 1e-7
    );
}

#[test]
fn reflect_mirrors_about_the_normal() {
    let s = 0.5f64.sqrt();
    // 45° down onto a floor comes back 45° up.
    let r = model::reflect(DVec3::new(s, -s, 0.0), DVec3::Y);
    assert!(close(r, DVec3::new(s, s, 0.0), 1e-15), "{r}");
    // Head-on comes straight back.
    assert_eq!(model::reflect(DVec3::NEG_Z, DVec3::Z), DVec3::Z);
    // Any direction: same length, normal component flipped, tangent kept.
    let n = DVec3::new(1.0, 2.0, -2.0) / 3.0;
    let d = DVec3::new(0.3, -0.8, 0.52).normalize();
    let r = model::reflect(d, n);
    assert!((r.length() - 1.0).abs() < 1e-12);
    assert!((r.dot(n) + d.dot(n)).abs() < 1e-12);
    assert!(close(r - n * r.dot(n), d - n * d.dot(n), 1e-12));
    let r32 = model::reflect(d.as_vec3(), n.as_vec3());
    assert!(close(r32.as_dvec3(), r, 1e-6));
}

/// A ray from outside at `theta` from the normal `+y` of a surface, in the x-y plane.
fn incoming(theta: f64) -> DVec3 {
    DVec3::new(theta.sin(), -theta.cos(), 0.0)
}

#[test]
fn entering_refraction_obeys_snells_law() {
    let n = DVec3::Y;
    for ior in [1.0, 1.33, 1.5, 2.0, 2.42] {
        for deg in (0..90).step_by(3).map(f64::from).chain([89.9]) {
            let d = incoming(deg.to_radians());
            let (t, crosses) = model::transmit(d, n, true, ior);
            assert!(
                crosses,
                "entering never reflects totally (ior {ior}, {deg}°)"
            );
            // sin θi = ior · sin θt, the ray goes on below the surface, in the plane of
            // incidence, bent towards the normal.
            let (si, st) = (sin_to_normal(d, n), sin_to_normal(t, n));
            assert!(
                (si - ior * st).abs() < 1e-6,
                "ior {ior}, {deg}°: {si} vs {}",
                ior * st
            );
            assert!((t.length() - 1.0).abs() < 1e-12);
            assert!(t.dot(n) < 0.0 && t.z.abs() < 1e-12 && t.x >= 0.0);
            // The same in f32.
            let (t32, _) = model::transmit(d.as_vec3(), n.as_vec3(), true, ior as f32);
            let st32 = sin_to_normal(t32.as_dvec3(), n);
            assert!((si - ior * st32).abs() < 1e-6, "f32: ior {ior}, {deg}°");
        }
    }
    // By hand: 60° into glass of index 1.5 gives sin θt = (√3/2)/1.5 = 0.5773503.
    let (t, _) = model::transmit(incoming(60f64.to_radians()), n, true, 1.5);
    assert!((t.x - 0.577_350_269_189_625_8).abs() < 1e-12, "{t}");
    // Head-on goes straight through.
    assert!(close(
        model::transmit(DVec3::NEG_Y, n, true, 2.0).0,
        DVec3::NEG_Y,
        1e-15
    ));
}

#[test]
fn leaving_refraction_undoes_entering() {
    let n = DVec3::Y;
    for ior in [1.2, 1.5, 2.0] {
        for deg in (0..90).step_by(5).map(f64::from) {
            let d = incoming(deg.to_radians());
            let (t, _) = model::transmit(d, n, true, ior);
            // Run the refracted ray backwards: from inside, up through the same surface
            // (d·n > 0, so not `front`). Light paths are reversible: out comes −d.
            let (back, crosses) = model::transmit(-t, n, false, ior);
            assert!(crosses);
            assert!(close(back, -d, 1e-6), "ior {ior}, {deg}°: {back} vs {}", -d);
            let (back32, _) = model::transmit((-t).as_vec3(), n.as_vec3(), false, ior as f32);
            assert!(close(back32.as_dvec3(), -d, 1e-6), "f32: ior {ior}, {deg}°");
            // Snell's law on the way out: sin θout = ior · sin θin.
            assert!((sin_to_normal(back, n) - ior * sin_to_normal(t, n)).abs() < 1e-6);
        }
    }
}

#[test]
fn total_internal_reflection_beyond_the_critical_angle() {
    let n = DVec3::Y; // outward normal; the ray comes from inside (below), going up
    let ior = 1.5; // critical angle asin(1/1.5) = 41.81°
    for deg in [42.0, 50.0, 60.0, 75.0, 89.0] {
        let theta = f64::to_radians(deg);
        let d = DVec3::new(theta.sin(), theta.cos(), 0.0);
        let (r, crosses) = model::transmit(d, n, false, ior);
        assert!(!crosses, "{deg}° is beyond the critical angle");
        // The mirror image, back down into the ball.
        assert!(
            close(r, DVec3::new(theta.sin(), -theta.cos(), 0.0), 1e-12),
            "{deg}°: {r}"
        );
        let (r32, crosses32) = model::transmit(d.as_vec3(), n.as_vec3(), false, ior as f32);
        assert!(!crosses32 && r32.is_finite());
        assert!(close(r32.as_dvec3(), r, 1e-6));
    }
    // Just below the critical angle the ray still leaves, almost along the surface.
    let theta = f64::to_radians(41.5);
    let (t, crosses) = model::transmit(DVec3::new(theta.sin(), theta.cos(), 0.0), n, false, ior);
    assert!(crosses && t.y > 0.0 && (t.x - 1.5 * theta.sin()).abs() < 1e-12);
}

/// Exactly at the critical angle `k = 0`, and SPEC §2 calls only `k < 0` total internal
/// reflection: the ray leaves along the surface. With `cos i = 1/2` (an exact dot
/// product) and `ior = √(4/3)` (whose square times 3/4 rounds to exactly 1 in `f64`),
/// `k = 1 − ior²·(1 − 1/4)` is exactly 0 and the direction is `ior·d + (ior/2)·N`,
/// which is `(ior·√¾, 0, 0)`: along +x.
#[test]
fn at_exactly_the_critical_angle_the_ray_leaves_along_the_surface() {
    let ior = (4.0f64 / 3.0).sqrt();
    assert_eq!(1.0 - ior * ior * (1.0 - 0.5 * 0.5), 0.0, "k is exactly 0");
    let d = DVec3::new(0.75f64.sqrt(), 0.5, 0.0);
    let (t, crosses) = model::transmit(d, DVec3::Y, false, ior);
    assert!(crosses, "k = 0 is not total internal reflection");
    assert!(close(t, DVec3::X, 1e-15), "{t}");
}

#[test]
fn shadow_factor_of_an_occluder() {
    let l = DVec3::Z;
    // Dead ahead: the shadow ray meets the occluder head-on, n_k = −L: (1 − 1)/2 = 0.
    assert_eq!(model::occluder_factor(l, DVec3::NEG_Z), 0.0);
    // Grazing: n_k ⟂ L: (1 + 0)/2 = 1/2.
    assert_eq!(model::occluder_factor(l, DVec3::X), 0.5);
    assert_eq!(model::occluder_factor(Vec3::Z, Vec3::Y), 0.5);
    // 60° from head-on: (1 − cos 60°)/2 = 1/4.
    let n = DVec3::new(0.75f64.sqrt(), 0.0, -0.5);
    assert!((model::occluder_factor(l, n) - 0.25).abs() < 1e-15);
}

#[test]
fn combine_mixes_local_reflected_and_transmitted() {
    let (local, refl, trans) = (DVec3::X, DVec3::Y, DVec3::Z);
    // (1 − w_t)((1 − w_r)·local + w_r·reflected) + w_t·transmitted
    let c = model::combine(0.25, 0.5, local, refl, trans);
    assert!(close(c, DVec3::new(0.375, 0.125, 0.5), 1e-15), "{c}");
    assert_eq!(model::combine(0.0, 0.0, local, refl, trans), local);
    assert_eq!(model::combine(1.0, 0.0, local, refl, trans), refl);
    assert_eq!(model::combine(0.3, 1.0, local, refl, trans), trans);
    // w_r + w_t > 1 is allowed and stays a convex mix (SPEC §3).
    let c = model::combine(0.9, 0.9, DVec3::ONE, DVec3::ONE, DVec3::ONE);
    assert!(close(c, DVec3::ONE, 1e-15));
}

// ---------------------------------------------------------------------------------
// Ray and sphere (SPEC §3: the stable roots of Ray Tracing Gems ch. 7)
// ---------------------------------------------------------------------------------

/// The roots and both normals of `o + t·d` with the sphere `(c, r)` in `f64` and in
/// `f32`, against the hand values `(near, far, normal_near, normal_far)`.
#[track_caller]
fn assert_roots(o: [f64; 3], d: [f64; 3], c: [f64; 3], r: f64, want: (f64, f64, DVec3, DVec3)) {
    let (o, d, c) = (DVec3::from(o), DVec3::from(d), DVec3::from(c));
    let hit = intersect::roots(o, d, c, r).expect("a hit");
    assert!(
        (hit.near - want.0).abs() < 1e-12,
        "near {} vs {}",
        hit.near,
        want.0
    );
    assert!(
        (hit.far - want.1).abs() < 1e-12,
        "far {} vs {}",
        hit.far,
        want.1
    );
    assert!(
        close(hit.normal_near(d, r), want.2, 1e-12),
        "{}",
        hit.normal_near(d, r)
    );
    assert!(
        close(hit.normal_far(d, r), want.3, 1e-12),
        "{}",
        hit.normal_far(d, r)
    );
    let hit = intersect::roots(o.as_vec3(), d.as_vec3(), c.as_vec3(), r as f32).expect("a hit");
    assert!(
        (f64::from(hit.near) - want.0).abs() < 1e-5,
        "f32 near {}",
        hit.near
    );
    assert!(
        (f64::from(hit.far) - want.1).abs() < 1e-5,
        "f32 far {}",
        hit.far
    );
    let (n, f) = (
        hit.normal_near(d.as_vec3(), r as f32),
        hit.normal_far(d.as_vec3(), r as f32),
    );
    assert!(close(n.as_dvec3(), want.2, 1e-6), "f32 {n}");
    assert!(close(f.as_dvec3(), want.3, 1e-6), "f32 {f}");
}

#[test]
fn ray_sphere_roots_and_normals_by_hand() {
    // From (1, 0, 0) down −z to the ball of radius 3 at (0, 0, −5): the line passes 1
    // from the centre, half the chord is √(9 − 1) = 2√2, so t = 5 ∓ 2√2; the hits are
    // (1, 0, −5 ± 2√2), normals (1, 0, ±2√2)/3.
    let s = 2.0 * 2f64.sqrt();
    let (n_front, n_back) = (
        DVec3::new(1.0, 0.0, s) / 3.0,
        DVec3::new(1.0, 0.0, -s) / 3.0,
    );
    let ball = ([0.0, 0.0, -5.0], 3.0);
    assert_roots(
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        ball.0,
        ball.1,
        (5.0 - s, 5.0 + s, n_front, n_back),
    );
    // From inside, at the depth of the centre: t = ∓2√2, the same points.
    assert_roots(
        [1.0, 0.0, -5.0],
        [0.0, 0.0, -1.0],
        ball.0,
        ball.1,
        (-s, s, n_front, n_back),
    );
    // Looking away (+z): both roots behind, t = −5 ∓ 2√2, near is the far side.
    assert_roots(
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        ball.0,
        ball.1,
        (-5.0 - s, -5.0 + s, n_back, n_front),
    );
    // A tangent line (1 from the centre of a unit ball): the double root t = 5, whose
    // normal is (1, 0, 0) either way.
    let x = DVec3::X;
    assert_roots(
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [0.0, 0.0, -5.0],
        1.0,
        (5.0, 5.0, x, x),
    );
    // Starting on the surface at (0.6, 0.8, 0) of the unit ball at the origin, aimed
    // through its centre: t = 0 and t = 2, normals ±(0.6, 0.8, 0). The near root comes
    // from c/q with q = 2 (no cancellation of b' − √disc).
    let p = DVec3::new(0.6, 0.8, 0.0);
    assert_roots(
        [0.6, 0.8, 0.0],
        [-0.6, -0.8, 0.0],
        [0.0; 3],
        1.0,
        (0.0, 2.0, p, -p),
    );
    // From the same point straight out: t = −2 and 0 (the centre behind, b' < 0: the
    // near root is q = b' − √disc = −2, the far one c/q, again no cancellation).
    let out = [0.6, 0.8, 0.0];
    assert_roots(out, out, [0.0; 3], 1.0, (-2.0, 0.0, -p, p));
    // Passing 1.5 from the centre of a unit ball: a miss.
    let miss = intersect::roots(
        DVec3::new(1.5, 0.0, 0.0),
        DVec3::NEG_Z,
        DVec3::new(0.0, 0.0, -5.0),
        1.0,
    );
    assert!(miss.is_none());
}

// ---------------------------------------------------------------------------------
// The camera (SPEC §2 "Camera and pixels", §3 degenerate cameras)
// ---------------------------------------------------------------------------------

fn look_at(from: [f64; 3], at: [f64; 3], up: [f64; 3], vfov: f64) -> CameraSpec {
    CameraSpec::LookAt {
        look_from: DVec3::from(from),
        look_at: DVec3::from(at),
        up: DVec3::from(up),
        vfov,
    }
}

fn frame_spec(origin: [f64; 3], ll: [f64; 3], h: [f64; 3], v: [f64; 3]) -> CameraSpec {
    CameraSpec::Frame {
        origin: DVec3::from(origin),
        lower_left: DVec3::from(ll),
        horizontal: DVec3::from(h),
        vertical: DVec3::from(v),
    }
}

#[track_caller]
fn assert_camera(c: Camera, o: [f64; 3], ll: [f64; 3], h: [f64; 3], v: [f64; 3]) {
    let want = [o, ll, h, v].map(DVec3::from);
    let got = [c.origin, c.lower_left, c.horizontal, c.vertical];
    for (name, (g, w)) in ["O", "LL", "H", "V"].iter().zip(got.iter().zip(want)) {
        assert!(close(*g, w, 1e-12), "{name}: {g} vs {w}");
    }
}

#[test]
fn look_at_camera_by_the_spec_s_formulas() {
    // From (1, 2, 3) towards (5, 2, 3), up (0, 2, 0) (not unit), vfov = 2·atan(1/2), a
    // 4×2 image: w = (−1, 0, 0), u = up × w normalised = (0, 0, 1), v = w × u =
    // (0, 1, 0), h = 1/2, a = 2. O = (1, 2, 3), LL = O − a·h·u − h·v − w = (2, 1.5, 2),
    // H = 2·a·h·u = (0, 0, 2), V = 2·h·v = (0, 1, 0).
    let vfov = 2.0 * 0.5f64.atan().to_degrees();
    let spec = look_at([1.0, 2.0, 3.0], [5.0, 2.0, 3.0], [0.0, 2.0, 0.0], vfov);
    assert_eq!(spec.check(), Ok(()));
    let c = Camera::new(&spec, 4, 2).unwrap();
    assert_camera(
        c,
        [1.0, 2.0, 3.0],
        [2.0, 1.5, 2.0],
        [0.0, 0.0, 2.0],
        [0.0, 1.0, 0.0],
    );

    // The assignment's look-at form at 16:9 is its exact frame (SPEC §2), and its vfov
    // is 2·atan(2.25) = 132.0750°.
    assert!((camera::assignment_vfov_degrees() - 132.075_022_05).abs() < 1e-8);
    let assignment = [
        [0.0, 0.0, 0.0],
        [-4.0, -2.25, -1.0],
        [8.0, 0.0, 0.0],
        [0.0, 4.5, 0.0],
    ];
    for spec in [
        CameraSpec::assignment_look_at(),
        CameraSpec::assignment_frame(),
    ] {
        let c = Camera::new(&spec, 1280, 720).unwrap();
        assert_camera(
            c,
            assignment[0],
            assignment[1],
            assignment[2],
            assignment[3],
        );
    }
}

#[test]
fn a_frame_camera_is_taken_as_given_and_turns_into_its_look_at_form() {
    let (o, ll, h, v) = (
        [1.0, 2.0, 3.0],
        [-3.0, -0.25, 2.0],
        [8.0, 0.0, 0.0],
        [0.0, 4.5, 0.0],
    );
    let c = Camera::new(&frame_spec(o, ll, h, v), 7, 3).unwrap();
    assert_camera(c, o, ll, h, v);
    // The film centre LL + H/2 + V/2 = (1, 2, 2) is one unit ahead of O: look_at is
    // that centre, up is V's direction, vfov = 2·atan((|V|/2)/1) = 2·atan(2.25).
    let CameraSpec::LookAt {
        look_from,
        look_at,
        up,
        vfov,
    } = c.to_look_at()
    else {
        panic!("to_look_at gives the look-at form")
    };
    assert_eq!(look_from, DVec3::new(1.0, 2.0, 3.0));
    assert!(
        close(look_at, DVec3::new(1.0, 2.0, 2.0), 1e-15),
        "{look_at}"
    );
    assert!(close(up, DVec3::Y, 1e-15), "{up}");
    assert!(
        (vfov - 2.0 * 2.25f64.atan().to_degrees()).abs() < 1e-12,
        "{vfov}"
    );
}

#[test]
fn degenerate_cameras_are_refused_with_their_reason() {
    use CameraError::*;
    let y = [0.0, 1.0, 0.0];
    let cases = [
        (
            look_at([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], y, 60.0),
            SamePoints,
        ),
        // So far apart that |look_at − look_from|² overflows.
        (
            look_at([-1e200, 0.0, 0.0], [1e200, 0.0, 0.0], y, 60.0),
            SamePoints,
        ),
        (look_at([0.0; 3], [0.0, 0.0, -1.0], [0.0; 3], 60.0), ZeroUp),
        (
            look_at([0.0; 3], [0.0, 0.0, -1.0], [0.0, 0.0, 3.0], 60.0),
            UpParallel,
        ),
        // |up × w| = 1e-10 of |up|: parallel within rounding.
        (
            look_at([0.0; 3], [0.0, 0.0, -1.0], [1e-10, 0.0, 1.0], 60.0),
            UpParallel,
        ),
        (look_at([0.0; 3], [0.0, 0.0, -1.0], y, 0.0), Vfov(0.0)),
        (look_at([0.0; 3], [0.0, 0.0, -1.0], y, -5.0), Vfov(-5.0)),
        (look_at([0.0; 3], [0.0, 0.0, -1.0], y, 180.0), Vfov(180.0)),
        (look_at([0.0; 3], [0.0, 0.0, -1.0], y, 200.0), Vfov(200.0)),
        (frame_spec([0.0; 3], [0.0; 3], [0.0; 3], y), ZeroSpan),
        (frame_spec([0.0; 3], [0.0; 3], y, [0.0; 3]), ZeroSpan),
        (
            frame_spec([0.0; 3], [0.0; 3], [1.0, 0.0, 0.0], [-2.0, 0.0, 0.0]),
            ParallelSpans,
        ),
        // |H × V| = 2e-9 ≤ 1e-12·|H|·|V| = 2e-8: the sine of their angle is 1e-13.
        (
            frame_spec([0.0; 3], [0.0; 3], [100.0, 0.0, 0.0], [200.0, 2e-11, 0.0]),
            ParallelSpans,
        ),
        (
            frame_spec([f64::INFINITY, 0.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0], y),
            NotFinite,
        ),
        (
            frame_spec([0.0; 3], [f64::NAN; 3], [1.0, 0.0, 0.0], y),
            NotFinite,
        ),
    ];
    for (spec, want) in cases {
        let got = Camera::new(&spec, 16, 9).unwrap_err();
        assert_eq!(got, want, "{spec:?}");
        // The spans are checked before the image size is known, finiteness after.
        let checked = if want == NotFinite { Ok(()) } else { Err(want) };
        assert_eq!(spec.check(), checked, "{spec:?}");
    }
    // Just inside each limit, or on it where the limit is strict: accepted.
    let z = [0.0, 0.0, -1.0];
    for spec in [
        look_at([0.0; 3], z, [1e-8, 0.0, 1.0], 60.0),
        // |up × w| = 1e-9 exactly (√(x²) is x in binary floating point), not below it.
        look_at([0.0; 3], z, [1e-9, 0.0, 1.0], 60.0),
        look_at([0.0; 3], z, y, 0.001),
        look_at([0.0; 3], z, y, 179.9),
        // |H × V| = 2e-7 > 2e-8: a sine of 1e-11.
        frame_spec([0.0; 3], [0.0; 3], [100.0, 0.0, 0.0], [200.0, 2e-9, 0.0]),
    ] {
        assert_eq!(spec.check(), Ok(()), "{spec:?}");
        assert!(Camera::new(&spec, 16, 9).is_ok(), "{spec:?}");
    }
}

// ---------------------------------------------------------------------------------
// Whole renders of tiny scenes
// ---------------------------------------------------------------------------------

/// A camera at the origin looking down −z whose 1×1 (or centre) pixel sees exactly
/// −z: `LL + H/2 + V/2 − O = (0, 0, −1)`.
const CAMERA: &str = "[camera]
origin = [0, 0, 0]
lower_left = [-1, -1, -1]
horizontal = [2, 0, 0]
vertical = [0, 2, 0]
";

/// A scene seen through [`CAMERA`] in one pixel, whose ray is exactly −z; `rest` is
/// its lights and spheres.
fn one_pixel(rest: &str) -> String {
    format!("{CAMERA}\n[image]\nwidth = 1\nheight = 1\n\n{rest}")
}

/// The scene a test's TOML text describes.
fn scene_of(toml: &str) -> Scene {
    Scene::from_toml_str(toml, "test.toml").expect("a valid test scene")
}

/// The `f64` reference tracer of `scene` for a one-pixel image, at the default depth.
fn reference_tracer(scene: &Scene) -> whitted::trace::reference::ReferenceTracer<'_> {
    let camera = scene.camera(1, 1).unwrap();
    whitted::trace::reference::ReferenceTracer::new(scene, camera, 5)
}

/// Renders the scene with both renderers; returns (fast, reference).
fn render_both(toml: &str) -> (Frame, Frame) {
    let scene = scene_of(toml);
    let mut opts = scene.settings();
    let control = RenderControl::default();
    let (fast, _) = render::render(&scene, &opts, &control).expect("fast render");
    opts.quality.precision = Precision::Reference;
    let (reference, _) = render::render(&scene, &opts, &control).expect("reference render");
    (fast, reference)
}

/// Asserts pixel `(i, j)` (j from the bottom) is `expected` in both renders.
#[track_caller]
fn assert_pixel(frames: &(Frame, Frame), i: u32, j: u32, expected: DVec3) {
    let (fast, reference) = (frames.0.get(i, j).as_dvec3(), frames.1.get(i, j).as_dvec3());
    // The frame stores f32: the reference's f64 result rounded, within 6e-8.
    assert!(
        close(reference, expected, 1e-7),
        "reference {reference} vs {expected}"
    );
    // f32 arithmetic: a few rounding errors of values near 1, far below one 8-bit
    // level (1/255 = 3.9e-3).
    assert!(close(fast, expected, 1e-5), "fast {fast} vs {expected}");
}

/// The default sky for a unit direction with vertical component `y`.
fn default_sky(y: f64) -> DVec3 {
    let t = 0.5 * (y + 1.0);
    DVec3::ONE * (1.0 - t) + DVec3::new(0.5, 0.7, 1.0) * t
}

#[test]
fn single_sphere_and_light_by_hand() {
    let toml = format!(
        "{CAMERA}
[image]
width = 3
height = 3

[[light]]
position = [2, 0, 0]
intensity = [1.0, 0.8, 0.5]

[[sphere]]
center = [0, 0, -3]
radius = 1
color = [1.0, 0.5, 0.25]
"
    );
    let frames = render_both(&toml);
    // Centre pixel (1, 1): s = t = 1.5/3 = 1/2, so d = (0, 0, −1). It meets the sphere
    // at p = (0, 0, −2), normal n = (0, 0, 1). To the light: P − p = (2, 0, 2), so
    // L = (1, 0, 1)/√2 and n·L = 1/√2. The segment p→P leaves the sphere outwards and
    // meets nothing: s = 1. Colour = kd ⊙ I · (1/√2)
    //   = (1·1, 0.5·0.8, 0.25·0.5)/√2 = (0.7071068, 0.2828427, 0.0883883),
    // 8-bit: round(·255) = (180, 72, 23).
    let r = 0.5f64.sqrt();
    let centre = DVec3::new(r, 0.4 * r, 0.125 * r);
    assert_pixel(&frames, 1, 1, centre);
    let bytes = whitted::image_io::to_rgb8(&frames.0, whitted::image_io::Encoding::Linear);
    assert_eq!(bytes.get_pixel(1, 1).0, [180, 72, 23]);
    // Bottom-left pixel (0, 0): s = t = 1/6, d ∝ (−2/3, −2/3, −1), 43° off the axis,
    // outside the sphere's 19.5° (asin 1/3): sky with d.y = −(2/3)/√(17/9) = −0.48507.
    assert_pixel(
        &frames,
        0,
        0,
        default_sky(-(2.0 / 3.0) / (17.0f64 / 9.0).sqrt()),
    );
    // Top-left pixel (0, 2) looks as far up: d.y = +0.48507.
    assert_pixel(
        &frames,
        0,
        2,
        default_sky((2.0 / 3.0) / (17.0f64 / 9.0).sqrt()),
    );
    // Image bytes put the top row first: byte row 0 is frame row 2, and the two
    // differ (d.y = ±0.485 give different skies).
    let to_bytes = |c: Vec3| c.to_array().map(whitted::image_io::to_byte);
    assert_eq!(bytes.get_pixel(0, 0).0, to_bytes(frames.0.get(0, 2)));
    assert_eq!(bytes.get_pixel(0, 2).0, to_bytes(frames.0.get(0, 0)));
    assert_ne!(bytes.get_pixel(0, 0), bytes.get_pixel(0, 2));
}

#[test]
fn half_mirror_sphere_by_hand() {
    let toml = one_pixel(
        "[[light]]
position = [2, 0, 0]
intensity = [1.0, 0.8, 0.5]

[[sphere]]
center = [0, 0, -3]
radius = 1
color = [1.0, 0.5, 0.25]
reflect = 0.5
",
    );
    // As above, local = (1, 0.4, 0.125)/√2. Head-on, d − 2(d·n)n = (0, 0, 1): back past
    // the camera to the sky at d.y = 0, (0.75, 0.85, 1). Half of each.
    let local = DVec3::new(1.0, 0.4, 0.125) * 0.5f64.sqrt();
    let expected = local * 0.5 + DVec3::new(0.75, 0.85, 1.0) * 0.5;
    assert_pixel(&render_both(&toml), 0, 0, expected);
}

#[test]
fn glass_ball_refracts_in_and_out_by_hand() {
    // The ray leaves the camera at α = asin 0.2 above −z: d = (0, tan α, −1)/|·|. The
    // ball (centre (0,0,−3), radius 1, index 1.5) lies 3 away, so the ray passes
    // 3·sin α = 0.6 from its centre and meets it at θi = asin 0.6 from the normal. Inside,
    // sin θt = 0.6/1.5 = 0.4; the chord is symmetric, so it leaves at θi again. Each
    // crossing turns the ray towards the axis by θi − θt: it leaves at α − 2(θi − θt)
    // = 11.537° − 26.576° = −15.039° from −z, d.y = sin(−15.039°) = −0.2596, and sees the
    // sky there (transmit = 1: no local or reflected light).
    let alpha = 0.2f64.asin();
    let camera = format!(
        "[camera]
origin = [0, 0, 0]
lower_left = [-1, {}, -1]
horizontal = [2, 0, 0]
vertical = [0, 2, 0]
",
        alpha.tan() - 1.0
    );
    let toml = format!(
        "{camera}
[image]
width = 1
height = 1

[[sphere]]
center = [0, 0, -3]
radius = 1
transmit = 1
ior = 1.5
"
    );
    let (ti, tt) = (0.6f64.asin(), 0.4f64.asin());
    let out = alpha - 2.0 * (ti - tt);
    assert!((out.sin() + 0.2596).abs() < 1e-4);
    assert_pixel(&render_both(&toml), 0, 0, default_sky(out.sin()));
}

#[test]
fn total_internal_reflection_inside_a_glass_ball_by_hand() {
    // The camera sits inside a glass ball (centre 0, radius 1, index 2) at y = 0.9 and
    // looks down −z. The ray passes 0.9 from the centre, so it meets the surface at
    // θ = asin 0.9 = 64.16° from the normal, beyond the critical angle asin(1/2) = 30°:
    // total internal reflection. A mirrored chord keeps its distance to the centre, so
    // every later hit reflects too, and each turns the ray by the chord's central angle
    // π − 2θ (in the y-z plane, from the direction angle π of −z). With max_depth m
    // the ray is reflected m times and then returns the sky of its direction.
    let theta = 0.9f64.asin();
    for max_depth in 0..=4u32 {
        let toml = format!(
            "[camera]
origin = [0, 0.9, 0]
lower_left = [-1, -0.1, -1]
horizontal = [2, 0, 0]
vertical = [0, 2, 0]

[image]
width = 1
height = 1
max_depth = {max_depth}

[[sphere]]
center = [0, 0, 0]
radius = 1
transmit = 1
ior = 2
"
        );
        let angle =
            std::f64::consts::PI + f64::from(max_depth) * (std::f64::consts::PI - 2.0 * theta);
        let frames = render_both(&toml);
        let (fast, reference) = (frames.0.get(0, 0).as_dvec3(), frames.1.get(0, 0).as_dvec3());
        let expected = default_sky(angle.sin());
        assert!(
            close(reference, expected, 1e-7),
            "depth {max_depth}: {reference} vs {expected}"
        );
        // Each bounce in f32 loses a little; a few bounces stay well within 1e-5.
        assert!(
            close(fast, expected, 1e-5),
            "depth {max_depth}: {fast} vs {expected}"
        );
    }
}

/// A white-ish ball at (0, 0, −5) seen head-on at p = (0, 0, −4), normal (0, 0, 1); the
/// light at (0, 0, 6) straight behind the camera: L = (0, 0, 1), n·L = 1, so the pixel
/// is 0.6 · s where s is the shadow factor of what lies on the segment p → light.
fn shadow_scene(occluder: &str) -> String {
    format!(
        "{CAMERA}
[image]
width = 1
height = 1

[[light]]
position = [0, 0, 6]

[[sphere]]
center = [0, 0, -5]
radius = 1
color = [0.6, 0.6, 0.6]
{occluder}"
    )
}

#[test]
fn shadow_factor_in_whole_renders() {
    // Nothing in the way: s = 1.
    assert_pixel(&render_both(&shadow_scene("")), 0, 0, DVec3::splat(0.6));

    // A ball dead ahead on the segment, centred on it at z = 3 (behind the camera, so
    // the camera still sees the lit ball): the segment first crosses it at z = 2, where
    // its normal is (0, 0, −1) = −L: s = (1 − 1)/2 = 0, black.
    let dead_ahead = "[[sphere]]\ncenter = [0, 0, 3]\nradius = 1\n";
    assert_pixel(&render_both(&shadow_scene(dead_ahead)), 0, 0, DVec3::ZERO);

    // A ball that the segment only grazes: centre 0.999 to the side, so the segment
    // runs h = √(1 − 0.999²) = 0.0447 inside it either side of z = 3. It first crosses
    // at (0, 0, 3 − h), normal (−0.999, 0, −h): L·n = −h, s = (1 − h)/2 = 0.4776, about
    // one half.
    let grazing = "[[sphere]]\ncenter = [0.999, 0, 3]\nradius = 1\n";
    let h = (1.0f64 - 0.999 * 0.999).sqrt();
    let s = (1.0 - h) / 2.0;
    assert!((s - 0.5).abs() < 0.025);
    let frames = render_both(&shadow_scene(grazing));
    let (fast, reference) = (frames.0.get(0, 0).as_dvec3(), frames.1.get(0, 0).as_dvec3());
    assert!(close(reference, DVec3::splat(0.6 * s), 1e-7), "{reference}");
    // Near a grazing hit f32 positions lose digits of h; 1e-4 is a tenth of a level.
    assert!(close(fast, DVec3::splat(0.6 * s), 1e-4), "{fast}");

    // The same ball beyond the light (z = 10 > 6) casts nothing: the segment stops at
    // the light (the assignment counted casters beyond it).
    let beyond = "[[sphere]]\ncenter = [0, 0, 10]\nradius = 1\n";
    assert_pixel(&render_both(&shadow_scene(beyond)), 0, 0, DVec3::splat(0.6));

    // No light at all: `light = []` leaves only black on the ball.
    let dark = format!(
        "light = []\n{}",
        shadow_scene("").replace("[[light]]\nposition = [0, 0, 6]\n", "")
    );
    assert_pixel(&render_both(&dark), 0, 0, DVec3::ZERO);
}

#[test]
fn sky_in_whole_renders() {
    // An empty scene, looking straight down, level and straight up: the centre ray is
    // look_at − look_from, so the pixel is sky(d) at d.y = −1, 0, 1.
    for (look_at, up, y) in [
        ("[0, -1, 0]", "[0, 0, -1]", -1.0),
        ("[0, 0, -1]", "[0, 1, 0]", 0.0),
        ("[0, 1, 0]", "[0, 0, -1]", 1.0),
    ] {
        let toml = format!(
            "sphere = []
[camera]
look_from = [0, 0, 0]
look_at = {look_at}
up = {up}
vfov = 90

[image]
width = 1
height = 1
"
        );
        assert_pixel(&render_both(&toml), 0, 0, default_sky(y));
        // A scene's own sky colours: t = (y + 1)/2 between down and up.
        let custom = format!("{toml}\n[sky]\ndown = [0.2, 0.4, 0.6]\nup = [1, 0, 0.5]\n");
        let t = 0.5 * (y + 1.0);
        let expected = DVec3::new(0.2, 0.4, 0.6) * (1.0 - t) + DVec3::new(1.0, 0.0, 0.5) * t;
        assert_pixel(&render_both(&custom), 0, 0, expected);
    }
}

/// The rays a whole render of the scene `toml` casts, by kind, with `precision`'s tracer.
fn rays_cast(toml: &str, precision: Precision) -> RayCounts {
    let scene = scene_of(toml);
    let mut opts = scene.settings();
    opts.quality.precision = precision;
    let (_, stats) = render::render(&scene, &opts, &RenderControl::default()).unwrap();
    stats.rays
}

/// Rays counted by hand, kind by kind and in all, summed over the bands of rows. A
/// half-mirror ball fills the 90° view (its angular radius, asin(2.5/3) = 56.4°, beyond
/// the film corners' 54.7°), lit from behind the camera: each of the 4×24 pixels (three
/// bands of 8 rows) casts one primary ray, whose hit faces the light (the visible cap's
/// normals have n_z ≥ 0.83) and casts one shadow ray and one reflected ray, which leaves
/// the convex ball for the sky.
#[test]
fn rays_are_counted_by_kind_and_in_all() {
    let toml = format!(
        "{CAMERA}
[image]
width = 4
height = 24

[[light]]
position = [0, 0, 10]

[[sphere]]
center = [0, 0, -3]
radius = 2.5
reflect = 0.5
"
    );
    for precision in [Precision::Fast, Precision::Reference] {
        let rays = rays_cast(&toml, precision);
        let expected = RayCounts {
            primary: 96,
            secondary: 96,
            shadow: 96,
        };
        assert_eq!(rays, expected, "{precision:?}");
        assert_eq!(rays.total(), 288, "{precision:?}");
    }
}

/// Rays counted by hand where most of the view is sky, in runs of pixels that fall in
/// one empty cell of the eye grid (12 cells a face for one sphere: 16 of the 192 pixel
/// columns a cell, two aligned runs of 8). A ball of radius 1 at distance 3 is hit by
/// the ray through film point (x, y) iff 9(x² + y²)/(x² + y² + 1) < 1, i.e.
/// x² + y² < ⅛. The 192×8 pixel centres have y ∈ ±⅛, ±⅜, ±⅝, ±⅞ and x = k/192 for odd
/// |k| ≤ 191: only the rows y = ±⅛ reach the ball, where x² < 7/64 holds for |k| ≤ 63
/// (x² = 0.1077 against 0.1094; |k| = 65 gives 0.1146): 2 × 64 = 128 hits, each
/// facing every light. So 1,536 primary rays, 1,408 of them sky, and each hit casts
/// one shadow ray per light and, when the ball reflects, one reflected ray.
#[test]
fn rays_are_counted_by_hand_in_a_view_mostly_of_sky() {
    let one_light = "[[light]]\nposition = [0, 0, 10]\n";
    let two_lights = "[[light]]\nposition = [0, 0, 10]\n[[light]]\nposition = [0, 10, 10]\n";
    for (lights, count, reflect) in [
        (one_light, 1, 0.0),
        (one_light, 1, 0.5),
        (two_lights, 2, 0.0),
        (two_lights, 2, 0.5),
    ] {
        let toml = format!(
            "{CAMERA}
[image]
width = 192
height = 8

{lights}
[[sphere]]
center = [0, 0, -3]
radius = 1
reflect = {reflect}
"
        );
        for precision in [Precision::Fast, Precision::Reference] {
            let rays = rays_cast(&toml, precision);
            let expected = RayCounts {
                primary: 1536,
                secondary: if reflect > 0.0 { 128 } else { 0 },
                shadow: 128 * count,
            };
            let case = format!("{count} light(s), w_r {reflect}, {precision:?}");
            assert_eq!(rays, expected, "{case}");
        }
    }
}

/// SPEC §2: a term of zero weight is not computed. One ball (radius 2.5, index 2)
/// fills a 3×3 view, lit from behind the camera, at `max_depth = 2`: the rays of depth
/// 2 return the sky uncounted. Each of the 9 primary hits faces the light (n·L ≥ 0.96)
/// and casts a shadow ray unless `(1 − w_t)(1 − w_r) = 0`; a reflected ray when
/// `(1 − w_t)·w_r > 0`, which leaves the convex ball for the sky; a transmitted ray
/// when `w_t > 0`, which crosses to the back of the ball (q.z ≤ −5.0). There, at depth
/// 1 and from inside, the inward normal faces the light too (n·L ≥ 0.85), so a
/// shadow ray follows on the same rule; the branches of depth 2 are not counted.
#[test]
fn terms_of_zero_weight_cast_no_rays() {
    // (w_r, w_t, secondary rays, shadow rays), for the 9 pixels.
    for (reflect, transmit, secondary, shadow) in [
        // A perfect mirror: reflected rays only.
        (1.0, 0.0, 9, 0),
        // Clear glass: a transmitted ray, and at the back nothing counted.
        (0.0, 1.0, 9, 0),
        // No local term, but both branches at the front.
        (1.0, 0.5, 18, 0),
        // w_t = 1 leaves the reflected branch a weight of 0 too.
        (0.5, 1.0, 9, 0),
        // Every term at the front, and local shading at the back.
        (0.5, 0.5, 18, 18),
        // Diffuse: a shadow ray each, no secondary rays.
        (0.0, 0.0, 0, 9),
    ] {
        let toml = format!(
            "{CAMERA}
[image]
width = 3
height = 3
max_depth = 2

[[light]]
position = [0, 0, 10]

[[sphere]]
center = [0, 0, -3]
radius = 2.5
reflect = {reflect}
transmit = {transmit}
"
        );
        let expected = RayCounts {
            primary: 9,
            secondary,
            shadow,
        };
        for precision in [Precision::Fast, Precision::Reference] {
            let rays = rays_cast(&toml, precision);
            assert_eq!(
                rays, expected,
                "w_r {reflect}, w_t {transmit}, {precision:?}"
            );
        }
    }
}

/// The contribution cutoff ε by hand. A ball that is half mirror, half clear glass of
/// index 1 (so rays cross it unbent) is seen head-on at p = (0, 0, −2), normal
/// (0, 0, 1), lit from straight behind the camera: n·L = 1, nothing on the segment, so
/// local = kd ⊙ I = (1, 0.5, 0.25). Its branches' path weights, all exact in binary:
/// - at p (weight 1): local (1 − w_t)(1 − w_r) = ¼; reflected (1 − w_t)·w_r = ¼, back
///   past the camera to the sky at d.y = 0, (0.75, 0.85, 1); transmitted w_t = ½, to
///   the far side q = (0, 0, −4);
/// - at q (weight ½): local ⅛; reflected ⅛, back inside the ball; transmitted ¼, out to
///   the sky at d.y = 0.
///
/// A branch of weight below ε is not traced: its colour counts as 0 and its weight
/// goes into the pixel's bound, times the largest value a trace returns (1 here: the
/// sky's `down` and the light's intensity).
/// - ε = ¼ keeps the branches of weight ¼ (below is strict) and skips q's local and
///   reflected: colour ¼·local + ¼·sky + ½·(½·sky) = (0.625, 0.55, 0.5625), bound ¼;
///   one primary ray, three secondary (p's reflected and transmitted, q's
///   transmitted), one shadow ray (p's).
/// - ε = 0.3 keeps only p's transmitted branch, whose three branches at q are all
///   skipped: colour 0, bound ¼ + ¼ + ⅛ + ⅛ + ¼ = 1; one primary and one secondary ray.
/// - The same under a light of intensity 2: the largest value a trace returns is 2, so
///   the bound is 2 (the colour still 0).
#[test]
fn the_cutoff_skips_branches_below_it_by_hand() {
    let toml = one_pixel(
        "[[light]]
position = [0, 0, 10]

[[sphere]]
center = [0, 0, -3]
radius = 1
color = [1.0, 0.5, 0.25]
reflect = 0.5
transmit = 0.5
ior = 1
",
    );
    let scene = scene_of(&toml);
    let sky = DVec3::new(0.75, 0.85, 1.0);
    let local = DVec3::new(1.0, 0.5, 0.25);
    for (cutoff, colour, bound, rays) in [
        (
            0.25,
            local * 0.25 + sky * 0.5,
            0.25,
            RayCounts {
                primary: 1,
                secondary: 3,
                shadow: 1,
            },
        ),
        (
            0.3,
            DVec3::ZERO,
            1.0,
            RayCounts {
                primary: 1,
                secondary: 1,
                shadow: 0,
            },
        ),
    ] {
        let mut opts = scene.settings();
        opts.quality.cutoff = cutoff;
        let cut = render::render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
        let got = cut.frame.get(0, 0).as_dvec3();
        assert!(close(got, colour, 1e-6), "ε {cutoff}: {got} vs {colour}");
        assert_eq!(cut.cutoff_bound, [bound], "ε {cutoff}");
        assert_eq!(cut.stats.rays, rays, "ε {cutoff}");
    }
    let bright = scene_of(&toml.replace(
        "position = [0, 0, 10]",
        "position = [0, 0, 10]\nintensity = [2, 2, 2]",
    ));
    let mut opts = bright.settings();
    opts.quality.cutoff = 0.3;
    let cut = render::render_bounded(&bright, &opts, &RenderControl::default()).unwrap();
    assert_eq!(
        (cut.frame.get(0, 0), cut.cutoff_bound),
        (Vec3::ZERO, vec![2.0])
    );
}

/// A light in the plane tangent to the hit point (n·L = 0 exactly) adds nothing and
/// casts no shadow ray (SPEC §2 step 4 takes `max(0, n·L)`; a factor of 0 is a term of
/// zero weight). The diffuse ball at (0, 0, −3) is seen head-on at p = (0, 0, −2),
/// n = (0, 0, 1); the light at (5, 0, −2) gives L = (1, 0, 0). Both tracers, one pixel
/// at a time; and the fast tracer's row of two samples, which shades pairs of diffuse
/// hits side by side.
#[test]
fn a_light_in_the_tangent_plane_casts_no_shadow_ray() {
    let toml = one_pixel(
        "[[light]]
position = [5, 0, -2]

[[sphere]]
center = [0, 0, -3]
radius = 1
",
    );
    let one_ray = RayCounts {
        primary: 1,
        secondary: 0,
        shadow: 0,
    };
    for precision in [Precision::Fast, Precision::Reference] {
        assert_eq!(rays_cast(&toml, precision), one_ray, "{precision:?}");
    }
    assert_pixel(&render_both(&toml), 0, 0, DVec3::ZERO);

    let scene = scene_of(&toml);
    let tracer = render::make_tracer(&scene, &scene.settings()).unwrap();
    let (mut out, mut rays) = ([Vec3::ONE; 2], RayCounts::default());
    tracer.sample_row(&[0.5, 0.5], 0.5, &mut out, &mut rays);
    assert_eq!(out, [Vec3::ZERO; 2]);
    let two_rays = RayCounts {
        primary: 2,
        ..one_ray
    };
    assert_eq!(rays, two_rays);
}

/// SPEC §2 step 2 takes intersections in front of the origin: `t > 0`. A camera on a
/// ball's surface (the ball at (0, 0, −1), radius 1, through the origin) has a root at
/// `t = 0` exactly (`|o − c|² = r²`), which does not count: the ray looks down −z into
/// the ball and meets its far side q = (0, 0, −2) from inside, where the normal that
/// faces the ray is (0, 0, 1). The light at the ball's centre is then straight ahead
/// (n·L = 1) and nothing lies between (the segment stops at the light, before the ball
/// is left again): colour kd ⊙ I = (1, 0.5, 0.25). Counting the root at 0, the camera
/// would see the ball's outside, facing away from the light: black.
#[test]
fn a_camera_on_a_ball_s_surface_sees_its_inside() {
    let toml = one_pixel(
        "[[light]]
position = [0, 0, -1]

[[sphere]]
center = [0, 0, -1]
radius = 1
color = [1.0, 0.5, 0.25]
",
    );
    assert_pixel(&render_both(&toml), 0, 0, DVec3::new(1.0, 0.5, 0.25));
}

/// The shadow segment is open at the light's end: a ball that the light sits on does
/// not shadow it. The diffuse ball at (0, 0, −3) is seen head-on at p = (0, 0, −2);
/// the light at (0, 0, 2) lies on the surface of a ball at (0, 0, 3) behind the
/// camera, which the segment p → P (length 4) meets exactly at its end, t = 4. So
/// n·L = 1 and s = 1: colour kd ⊙ I. (Counted as an occluder it would give s = 0:
/// its normal there, (0, 0, −1), faces the segment head-on.)
#[test]
fn a_ball_the_light_sits_on_casts_no_shadow_through_the_segment_s_end() {
    let toml = one_pixel(
        "[[light]]
position = [0, 0, 2]

[[sphere]]
center = [0, 0, -3]
radius = 1
color = [1.0, 0.5, 0.25]

[[sphere]]
center = [0, 0, 3]
radius = 1
",
    );
    assert_pixel(&render_both(&toml), 0, 0, DVec3::new(1.0, 0.5, 0.25));
}

/// A light on the surface of the ball the shading point is inside of: the shadow
/// segment runs inside the ball (it is convex) to its end at the light and crosses
/// nothing, s = 1. The camera at the origin sits on a ball of radius r centred at
/// (0, 0, −r) and sees its far wall at p = (0, 0, −2r), seen normal (0, 0, 1), so
/// the colour is kd ⊙ I · L.z. The lights lie exactly on their spheres in binary:
/// Pythagorean triples scaled by powers of 2, 576 of them. There the segment's far
/// root and the light's distance agree up to a few ulps; decided by the root, the
/// ball shadowed the light, s = (1 + L·n)/2, in 96 of them in each tracer.
#[test]
fn a_light_on_the_ball_the_point_is_inside_of_is_not_shadowed_by_it() {
    let kd = DVec3::new(1.0, 0.5, 0.25);
    let mut lights = 0;
    for (a, b, c) in [(1.0, 0.0, 1.0)].into_iter().chain(PYTHAGOREAN) {
        for scale in (-4..8).map(|k| 2f64.powi(k)) {
            let (r, centre) = (c * scale, DVec3::new(0.0, 0.0, -c * scale));
            for (across, along) in [(a, b), (b, a), (-a, b), (-b, a)] {
                for axis in [DVec3::X, DVec3::Y] {
                    let light = centre + (axis * across + DVec3::Z * along) * scale;
                    assert_eq!((light - centre).length_squared(), r * r, "on the sphere");
                    let toml = one_pixel(&format!(
                        "[[light]]\nposition = [{}, {}, {}]\n\n[[sphere]]\ncenter = [0, 0, {}]\nradius = {r}\ncolor = [1.0, 0.5, 0.25]\n",
                        light.x, light.y, light.z, centre.z
                    ));
                    let to_light = (light - centre * 2.0).normalize();
                    assert_pixel(&render_both(&toml), 0, 0, kd * to_light.z);
                    lights += 1;
                }
            }
        }
    }
    assert_eq!(lights, 576);
}

/// A light on the surface of a ball that the shadow segment arrives at from outside:
/// the segment meets the ball first at its open end, the light, and crosses nothing:
/// s = 1. The diffuse ball at (0, 0, −3) is seen head-on at p = (0, 0, −2), normal
/// (0, 0, 1), so the colour is kd ⊙ I · L.z. Each light P has balls beyond it, centred
/// at P + u·2ᵏ for Pythagorean vectors u (|u| = c, radius c·2ᵏ), so that P lies
/// exactly on each in binary, and the segment arrives from outside ((c − P)·L > 0);
/// balls that come near the camera's ray or hold p are left out: 1,735 lights. There
/// the near root and the light's distance agree up to rounding; decided by the root,
/// the ball shadowed the light in 375 of them in the fast tracer and 224 in the
/// reference.
#[test]
fn a_light_on_a_ball_the_segment_arrives_at_is_not_shadowed_by_it() {
    let kd = DVec3::new(1.0, 0.5, 0.25);
    let p = DVec3::new(0.0, 0.0, -2.0);
    let towards = [
        (1.0, 0.0, 2.0),
        (2.0, 0.0, 1.0),
        (0.0, 0.0, 3.0),
        (-1.0, 0.0, 1.0),
    ];
    let towards = towards
        .into_iter()
        .chain([(0.0, -2.0, 1.0), (4.0, 4.0, 2.0)]);
    let mut lights = 0;
    for light in towards.map(|(x, y, z)| p + DVec3::new(x, y, z)) {
        let l = (light - p).normalize();
        for (a, b, c) in PYTHAGOREAN {
            for scale in (-4..8).map(|k| 2f64.powi(k)) {
                for u in across_two_axes(a, b) {
                    let (centre, r) = (light + u * scale, c * scale);
                    // Clear of the camera's ray, the −z axis, and of p.
                    let clear = centre.truncate().length() > r + 1e-3;
                    if (centre - light).dot(l) <= 0.0 || !clear || (centre - p).length() <= r {
                        continue;
                    }
                    assert_eq!((light - centre).length_squared(), r * r, "on the sphere");
                    let toml = one_pixel(&format!(
                        "[[light]]\nposition = [{}, {}, {}]\n\n[[sphere]]\ncenter = [0, 0, -3]\nradius = 1\ncolor = [1.0, 0.5, 0.25]\n\n[[sphere]]\ncenter = [{}, {}, {}]\nradius = {r}\n",
                        light.x, light.y, light.z, centre.x, centre.y, centre.z
                    ));
                    assert_pixel(&render_both(&toml), 0, 0, kd * l.z);
                    lights += 1;
                }
            }
        }
    }
    assert_eq!(lights, 1735);
}

/// A light a hair across a ball's surface from the segment, 2⁻²⁰ away, where the root
/// and the light's distance still agree to 2⁻¹⁸, is shadowed by the ball: the light's
/// side decides, as for a light on the surface, and here the segment does cross.
/// - Arriving: the diffuse ball at (0, 0, −3) is seen head-on at p = (0, 0, −2); the
///   light at (0, 0, 2 + 2⁻²⁰) is just inside the ball at (0, 0, 3), which the segment
///   enters head-on at its pole: L·n = −1, s = 0. Black.
/// - Leaving: the camera at the origin on the unit ball at (0, 0, −1) sees its far
///   wall at p = (0, 0, −2); the light at (1 + 2⁻²⁰, 0, −1) is just outside. The
///   segment leaves the ball at t = 2·L.z (p is on the sphere), X = p + t·L, with the
///   normal n = X − c: s = (1 + L·n)/2 ≈ 0.854, and the colour kd ⊙ I · L.z · s.
#[test]
fn a_light_a_hair_beyond_a_ball_s_surface_is_shadowed_by_it() {
    let hair = 2f64.powi(-20);
    let arriving = one_pixel(&format!(
        "[[light]]\nposition = [0, 0, {}]\n\n[[sphere]]\ncenter = [0, 0, -3]\nradius = 1\n\n[[sphere]]\ncenter = [0, 0, 3]\nradius = 1\n",
        2.0 + hair
    ));
    assert_pixel(&render_both(&arriving), 0, 0, DVec3::ZERO);

    let light = DVec3::new(1.0 + hair, 0.0, -1.0);
    let leaving = one_pixel(&format!(
        "[[light]]\nposition = [{}, 0, -1]\n\n[[sphere]]\ncenter = [0, 0, -1]\nradius = 1\ncolor = [1.0, 0.5, 0.25]\n",
        light.x
    ));
    let p = DVec3::new(0.0, 0.0, -2.0);
    let l = (light - p).normalize();
    let n = p + l * (2.0 * l.z) - DVec3::new(0.0, 0.0, -1.0);
    let s = (1.0 + l.dot(n)) / 2.0;
    assert!((s - 0.854).abs() < 1e-3, "s = {s}");
    assert_pixel(
        &render_both(&leaving),
        0,
        0,
        DVec3::new(1.0, 0.5, 0.25) * (l.z * s),
    );
}

/// Triples a² + b² = c², exact in binary at every power-of-2 scale the tests use.
const PYTHAGOREAN: [(f64, f64, f64); 5] = [
    (3.0, 4.0, 5.0),
    (5.0, 12.0, 13.0),
    (8.0, 15.0, 17.0),
    (7.0, 24.0, 25.0),
    (20.0, 21.0, 29.0),
];

/// The 24 vectors with coordinates ±a and ±b on two axes and 0 on the third.
fn across_two_axes(a: f64, b: f64) -> Vec<DVec3> {
    let mut out = Vec::new();
    for (i, j) in [(0, 1), (1, 0), (0, 2), (2, 0), (1, 2), (2, 1)] {
        for (sa, sb) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let mut u = [0.0; 3];
            (u[i], u[j]) = (sa * a, sb * b);
            out.push(DVec3::from_array(u));
        }
    }
    out
}

/// A hit at the world's origin is shadowed like any other. The camera at (0, 0, 1)
/// sees the ball at (0, 0, −1) head-on at p = (0, 0, 0), normal (0, 0, 1); the light
/// at (10, 0, 10) gives n·L = 1/√2, and the ball at (5, 0, 5) sits on the segment's
/// line: the segment enters it head-on, L·n_k = −1, s = 0. Black. (A spawn tolerance
/// that scales with 1/|p| would be infinite here and see no occluder.)
#[test]
fn a_hit_at_the_world_s_origin_is_shadowed() {
    let toml = "[camera]
origin = [0, 0, 1]
lower_left = [-1, -1, 0]
horizontal = [2, 0, 0]
vertical = [0, 2, 0]

[image]
width = 1
height = 1

[[light]]
position = [10, 0, 10]

[[sphere]]
center = [0, 0, -1]
radius = 1

[[sphere]]
center = [5, 0, 5]
radius = 1
";
    assert_pixel(&render_both(toml), 0, 0, DVec3::ZERO);
}

/// SPEC §3: a spawned ray never meets the surface it leaves at its spawn point. A ray
/// that leaves a ball outwards cannot meet it again at all (the ball is convex), but
/// at a grazing angle the root at the spawn point is computed with an error of about
/// `ε·r²/(n·d)`, far above any tolerance scaled to the point's coordinates. The
/// reference tracer looks at a half-mirror ball of radius 1 at distance 3, through film
/// points ever closer to its silhouette (the tangent ray's film radius is 1/√8 of the
/// half-width), all around it: its reflected and shadow rays leave at angles down to
/// about 10⁻⁶ and meet nothing.
#[test]
fn rays_leaving_a_ball_at_grazing_angles_never_meet_it_again() {
    let toml = one_pixel(
        "[[light]]
position = [0, 0, 10]

[[sphere]]
center = [0, 0, -3]
radius = 1
reflect = 0.5
",
    );
    let scene = scene_of(&toml);
    let tracer = reference_tracer(&scene);
    let tangent = 0.125f64.sqrt();
    let (mut hits, mut shadow_rays) = (0, 0);
    for k in 0..4000 {
        // Around the silhouette by the golden angle; 10⁻² to 10⁻¹² inside it.
        let phi = k as f64 * 2.399_963_229_728_653;
        let inside = 10f64.powf(-2.0 - 10.0 * (k as f64 / 4000.0));
        let x = tangent * (1.0 - inside);
        let (s, t) = (0.5 + 0.5 * x * phi.cos(), 0.5 + 0.5 * x * phi.sin());
        let (_, tree) = tracer.inspect(s, t);
        if tree.hit.is_none() {
            continue;
        }
        hits += 1;
        for child in &tree.children {
            assert!(child.hit.is_none(), "film ({s}, {t}): {:?}", child.hit);
        }
        for shadow in &tree.shadows {
            shadow_rays += 1;
            assert_eq!(shadow.occluder, None, "film ({s}, {t})");
        }
    }
    // Every ray 10⁻¹² inside the silhouette still meets the ball; the light behind the
    // camera, a little off the view's axis, faces a bit more than half of the rim.
    assert_eq!(hits, 4000);
    assert!(shadow_rays > 1000, "{shadow_rays} shadow rays");
}

/// The same inside a glass ball: the camera sits 10⁻⁸ below the top of a ball of index
/// 2, and the rays of the middle row, nearly level, pass within 1.3·10⁻⁷ of the
/// ball's radius from its centre. They meet the surface from inside at about 10⁻⁴
/// from the tangent, far beyond the critical angle (30°), and reflect totally, again
/// and again at the same angle (a mirrored chord keeps its distance to the centre):
/// every spawned ray stays inside and meets the ball at the far end of its chord
/// (about 10⁻⁴ long), never at its spawn point.
#[test]
fn rays_inside_a_ball_at_grazing_angles_never_meet_it_at_their_start() {
    let toml = one_pixel(
        "[[sphere]]
center = [0, -0.99999999, 0]
radius = 1
transmit = 1
",
    );
    let scene = scene_of(&toml);
    let tracer = reference_tracer(&scene);
    let mut spawned = 0;
    for k in 0..1000 {
        let (s, t) = (k as f64 / 1000.0, 0.5 + 5e-4 * (k % 7) as f64 / 7.0);
        let (_, tree) = tracer.inspect(s, t);
        let mut node = &tree;
        while let Some(child) = node.children.first() {
            if child.depth_limited {
                break;
            }
            spawned += 1;
            let hit = child.hit.as_ref().expect("a ray inside a ball meets it");
            let chord = (hit.point - child.origin).length();
            assert!(
                !hit.entering && chord > 1e-6,
                "film ({s}, {t}), depth {}: chord {chord}, entering {}",
                child.depth,
                hit.entering
            );
            node = child;
        }
    }
    // Below the primary hit, the reflected rays of depths 1 to 4 (the depth limit, 5,
    // returns the sky).
    assert_eq!(spawned, 1000 * 4);
}

/// The reference tracer's ray tree names the occluder that set the shadow factor: the
/// one of least `(1 + L·n_k)/2`. The diffuse ball at (0, 0, −3) is seen head-on at
/// p = (0, 0, −2) and lit from (0, 0, 10); the segment runs up the z axis behind the
/// camera through two balls: the first listed, at (0.9, 0, 3), it crosses 0.9 off its
/// centre, entering at (0, 0, 3 − √0.19) where n_k = (−0.9, 0, −√0.19), so its factor
/// is (1 − √0.19)/2 = 0.282; the second, at (0, 0, 6), head-on: factor 0, s = 0.
#[test]
fn the_ray_tree_names_the_occluder_of_least_factor() {
    let toml = one_pixel(
        "[[light]]
position = [0, 0, 10]

[[sphere]]
center = [0, 0, -3]
radius = 1

[[sphere]]
center = [0.9, 0, 3]
radius = 1

[[sphere]]
center = [0, 0, 6]
radius = 1
",
    );
    let scene = scene_of(&toml);
    let tracer = reference_tracer(&scene);
    let (colour, tree) = tracer.inspect(0.5, 0.5);
    assert_eq!(colour, DVec3::ZERO);
    let [shadow] = tree.shadows.as_slice() else {
        panic!("one shadow ray: {:?}", tree.shadows);
    };
    assert_eq!((shadow.light, shadow.occluder), (0, Some(2)));
    assert_eq!(shadow.factor, 0.0);
    // Alone, the first ball sets the factor, and is named.
    let mut scene = scene;
    scene.spheres.pop();
    let tracer = reference_tracer(&scene);
    let (_, tree) = tracer.inspect(0.5, 0.5);
    assert_eq!(tree.shadows[0].occluder, Some(1));
    let expected = (1.0 - 0.19f64.sqrt()) / 2.0;
    assert!((tree.shadows[0].factor - expected).abs() < 1e-12);
}

/// The reference tracer's ray tree gives each term its weight in the pixel, the
/// product of step 7's mixing weights along the path. A ball with `w_r = ¼`,
/// `w_t = ½` and index 1, seen head-on and lit from behind the camera: at the front,
/// local (1 − ½)(1 − ¼) = 3/8, reflected (1 − ½)·¼ = 1/8, transmitted ½; the
/// transmitted ray meets the back from inside, faces the light again, and its terms
/// weigh half as much: 3/16, 1/16, ¼.
#[test]
fn the_ray_tree_weighs_each_term_by_its_path() {
    let toml = one_pixel(
        "[[light]]
position = [0, 0, 10]

[[sphere]]
center = [0, 0, -3]
radius = 1
reflect = 0.25
transmit = 0.5
ior = 1
",
    );
    let scene = scene_of(&toml);
    let tracer = reference_tracer(&scene);
    let (_, front) = tracer.inspect(0.5, 0.5);
    let weights = |node: &whitted::trace::reference::RayNode| {
        let shadows: Vec<f64> = node.shadows.iter().map(|s| s.weight).collect();
        let children: Vec<f64> = node.children.iter().map(|c| c.weight).collect();
        (node.weight, shadows, children)
    };
    assert_eq!(weights(&front), (1.0, vec![0.375], vec![0.125, 0.5]));
    let back = &front.children[1];
    assert!(back.hit.as_ref().is_some_and(|h| !h.entering));
    assert_eq!(weights(back), (0.5, vec![0.1875], vec![0.0625, 0.25]));
}

/// The fast tracer's primary rays look for spheres only among those that reach into
/// the view (the camera's pyramid, widened by 10⁻³ of the film), and a sphere that
/// reaches in by less than a millionth of its radius still counts. A ball of radius
/// 10⁴ pokes 5·10⁻⁴ through the view's left side 4 away from the eye (the centre lies
/// r − 5·10⁻⁴ outside the plane x = z, level with the eye; the cap inside the view has
/// radius √(2·r·5·10⁻⁴) ≈ 3.2, so the eye is outside the ball), about 0.0095 into the
/// widened pyramid, less than r·10⁻⁶ = 0.01. The three leftmost pixels of a
/// 20,000-wide row see it, 0.9 to 1.5 from the eye (the fourth misses it); both
/// tracers agree, pixel by pixel.
#[test]
fn a_ball_reaching_into_the_view_by_a_hair_is_seen() {
    let toml = format!(
        "{CAMERA}
[image]
width = 20000
height = 1

[[light]]
position = [5, 0, -5]

[[sphere]]
center = [-7073.895885436829, 0, 7068.239031187338]
radius = 10000
"
    );
    let (fast, reference) = render_both(&toml);
    let sky = default_sky(0.0);
    for i in 0..8 {
        let (f, r) = (fast.get(i, 0).as_dvec3(), reference.get(i, 0).as_dvec3());
        assert!(close(f, r, 1e-5), "pixel {i}: fast {f}, reference {r}");
        assert_eq!(close(r, sky, 1e-6), i >= 3, "pixel {i}: {r}");
    }
}
