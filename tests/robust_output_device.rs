//! Output to a device: a render written to a full device fails with exit 1 and leaves
//! the device alone (`image_io::write_atomically` writes into a target that exists and
//! is not a regular file instead of renaming a temporary file over it).
#![cfg(all(feature = "cli", feature = "viewer"))]

/// A render written to a device node that behaves like `/dev/full` (char 1,7,
/// made with mknod under the name `out.png` in a temporary folder, so that the real
/// /dev/full is never at risk): exit 1 with one line, the node left as it was, no other
/// file.
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
