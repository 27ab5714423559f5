//! Issue 4 tests that the fast path does not pass yet, kept apart so that the lead (who
//! owns `src/accel`, `src/trace/fast.rs` and `src/trace/intersect.rs`) can fix the
//! causes and then move them into the other `robust*.rs` files. Each test names its
//! cause; the report of the `robust` branch has the figures and a patch.
//!
//! Causes, as measured (all three disappear with the patch in the report):
//! 1. `accel` promotes the `f32` direction to `f64` but does not renormalise it, while
//!    `intersect::roots` assumes `d·d = 1`. An `f32`-normalised direction has
//!    `|d·d − 1|` up to ~1e-7, so `l = f + (−f·d)·d` and the discriminant are off by
//!    about `|f|·1e-7`: the error grows with the distance to the sphere's *centre*.
//!    On a ground of radius 1e5 the hit point moves by 5.7e-4 at t = 1.83 (relative
//!    error 3e-4), enough to move contact shadows by a pixel.
//! 2. `Query::origin` is `f32`: a spawn point is rounded to half an `f32` ulp of its
//!    coordinates (3e-5 at 1e3, 5e-4 at 1e4), which is a large part of a small ball
//!    (r = 1e-3) far from the world origin; `Query::t_min` (4·ε₃₂·|o|, 4.8e-3 at 1e4)
//!    then also hides nearby spheres from shadow rays.
//! 3. The primary direction is computed in `f32` as `LL + s·H + t·V − O`: with the
//!    camera at 1e4 this cancels and loses ~1e-3 of the film position.
//! 4. (`src/image_io.rs`) `write_atomically` renames its temporary file over whatever
//!    the target is: a device node (or FIFO) named `out.png` is replaced by a regular
//!    file and the command succeeds, where writing to `/dev/full` must fail with exit 1.

mod robust_support;

use robust_support::cases::{self, Truth};
use robust_support::*;
use whitted::render::Renderer;

/// Causes 1 (ground-1e5, ground-1e6, facing-mirrors), 2 (tiny-far,
/// hw3-translated-1e4) and 3 (hw3-translated-1e4).
#[test]
fn fast_matches_reference_on_the_remaining_stress_scenes() {
    println!("\n{SCENE_TABLE_HEADER}");
    let failures = check_fast_vs_reference(FAILING_FAST_VS_REFERENCE, 320, 180);
    assert!(failures.is_empty(), "{failures:?}");
}

/// Causes 2 and 3: hw3 translated by (1e4, 1e4, 1e4), fast tracer, against hw3.
#[test]
fn translated_hw3_renders_like_hw3_with_the_fast_tracer() {
    println!("\n{TRANSFORM_TABLE_HEADER}");
    let failures = check_transforms(Renderer::Fast, &["translate (1e4,1e4,1e4)"], 320, 180);
    assert!(failures.is_empty(), "{failures:?}");
}

/// Cause 1: the ground of radius 1e5 at grazing angles, relative error of t ≤ 1e-6
/// against `f64` on the very ray of the query.
#[test]
fn huge_ground_at_grazing_angles_keeps_t() {
    let (_, _, max) = cases::ground_grazing(Truth::QueryRay, 1e5);
    assert!(max <= 1e-6, "max relative error {max:e}");
}

/// Cause 2: inward rays against the far exit of the unrounded `f64` spawn point.
#[test]
fn inward_rays_find_the_exit_of_the_unrounded_spawn_point() {
    let s = cases::reintersection(Truth::Unrounded, 1000).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((s.outward_rehits, s.shadowed, s.inward_misses), (0, 0, 0));
}

/// Cause 2: entry/exit symmetry of refraction through balls of radius 10^U(−3,5) with
/// |centre| up to 1e4: the exit point found from the `f32` spawn point is off by half
/// an `f32` ulp of the coordinates, which tilts the exit normal (a ball of radius 1 at
/// 638 from the origin: sin θ 4.2e-6 in, 5.0e-5 out).
#[test]
fn refraction_through_any_ball_is_symmetric() {
    let (err, _) = cases::refraction_symmetry(f64::INFINITY).unwrap_or_else(|e| panic!("{e}"));
    assert!(err <= 1e-5);
}

/// Cause 4: a render written to a device node that behaves like `/dev/full` (char 1,7,
/// made with mknod under the name `out.png` in a temporary folder, so that the real
/// /dev/full is never at risk): exit 1 with one line, the node left as it was, no other
/// file. Today the node is replaced by a PNG file and the exit status is 0.
#[test]
fn writing_to_a_full_device_fails_and_leaves_it_alone() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let node = dir.path().join("out.png");
    let made = std::process::Command::new("mknod")
        .arg(&node)
        .args(["c", "1", "7"])
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        eprintln!("SKIPPED: cannot make a device node here (mknod needs CAP_MKNOD)");
        return;
    }
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(["render", "--width", "32", "--height", "18", "--quiet", "-o"])
        .arg(&node)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("full device: {:?} {stderr:?}", out.status.code());
    let still_device =
        std::fs::symlink_metadata(&node).is_ok_and(|m| m.file_type().is_char_device());
    let others = std::fs::read_dir(dir.path()).unwrap().count() - 1;
    assert!(still_device, "the device node was replaced");
    assert_eq!(others, 0, "files left beside it");
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
}
