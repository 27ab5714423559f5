//! Issue 4 tests that the program does not pass yet, kept apart so that the owner of the
//! code at fault can fix it and then move the test next to the others. Each test names
//! its cause; the report of the `robust` branch has the figures.
//!
//! (Causes 1-3 of the first version of this file, in the fast path's precision, were
//! fixed on main by 54e7bc6; their tests now live in robust_intersect.rs,
//! robust_refract.rs and robust_scenes.rs.)
//!
//! 4. (`src/image_io.rs`) `write_atomically` renames its temporary file over whatever
//!    the target is: a device node (or FIFO) named `out.png` is replaced by a regular
//!    file and the command succeeds, where writing to a full device must fail with
//!    exit 1 and leave the node alone.

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
