//! Output that cannot be written: a full disk, a read-only folder, a file-size limit,
//! `/dev/full`, a full device node, or a render interrupted by SIGINT. Each ends with
//! exit 1 (exit 2 for a usage error) and one error line, and leaves no partial or
//! temporary file: images are written to a temporary file and renamed into place, and
//! a target that exists and is not a regular file (a device) is written in place and
//! left alone (`image_io::write_atomically`).
#![cfg(all(feature = "cli", feature = "viewer"))]

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn whitted() -> Command {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
}

/// Runs `script` in `sh` inside new user and mount namespaces (so it may mount a tmpfs
/// without privileges and the mount vanishes with it); `None` if that is not possible.
fn in_mount_namespace(script: &str) -> Option<std::process::Output> {
    let probe = Command::new("unshare")
        .args(["-rm", "true"])
        .stderr(Stdio::null())
        .status();
    if !probe.is_ok_and(|s| s.success()) {
        return None;
    }
    Some(
        Command::new("unshare")
            .args(["-rm", "sh", "-c", script])
            .output()
            .unwrap(),
    )
}

/// A full disk (a 64 KiB tmpfs) and a read-only folder (a read-only tmpfs): exit 1,
/// one error line, and the folder is left empty.
#[test]
fn a_full_disk_or_a_read_only_folder_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let mnt = dir.path().display().to_string();
    let bin = env!("CARGO_BIN_EXE_whitted");
    for (what, options) in [
        ("full disk", "size=64k"),
        ("read-only folder", "ro,size=64k"),
    ] {
        // A plain PPM of 320x180 is about 500 KB: it cannot fit in 64 KiB.
        let script = format!(
            "mount -t tmpfs -o {options} tmpfs '{mnt}' || exit 99; \
             '{bin}' render --width 320 --height 180 --quiet -o '{mnt}/out.ppm' -o '{mnt}/out.png'; \
             echo \"rc=$?\"; ls -A '{mnt}'"
        );
        let Some(out) = in_mount_namespace(&script) else {
            common::skip(
                what,
                "cannot create user/mount namespaces (unshare -rm) here",
                "a full or read-only file system",
            );
            continue;
        };
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        println!("{what}: stdout {stdout:?} stderr {stderr:?}");
        if out.status.code() == Some(99) {
            common::skip(
                what,
                &format!("cannot mount a tmpfs in a namespace: {stderr}"),
                "a full or read-only file system",
            );
            continue;
        }
        let mut lines = stdout.lines();
        assert_eq!(lines.next(), Some("rc=1"), "{what}: exit status");
        assert_eq!(lines.next(), None, "{what}: files left behind: {stdout}");
        let errors: Vec<&str> = stderr.lines().collect();
        assert_eq!(errors.len(), 1, "{what}: one error line: {stderr}");
        assert!(errors[0].starts_with("whitted: error: "), "{stderr}");
    }
    // A file-size limit (RLIMIT_FSIZE, SIGXFSZ ignored) fails writes like a full disk,
    // without privileges.
    let out = Command::new("sh")
        .args([
            "-c",
            &format!(
                "trap '' XFSZ; ulimit -f 16; exec '{bin}' render --width 320 --height 180 \
                 --quiet -o '{}/out.ppm'",
                dir.path().display()
            ),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("file-size limit: {:?} {stderr:?}", out.status.code());
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        common::entries(dir.path()).is_empty(),
        "{:?}",
        common::entries(dir.path())
    );
}

/// `-o /dev/full`: a path with no image extension is a usage error (exit 2) found
/// before any work; a path under it (`/dev/full/out.png`, not a folder) fails to create
/// the temporary file: exit 1. One line each, nothing left in /dev. Writing through a
/// device node with an image name is in `writing_to_a_full_device_fails_and_leaves_it_alone`.
#[test]
fn writing_to_dev_full_fails_cleanly() {
    let before = common::entries(Path::new("/dev"));
    for (target, code) in [("/dev/full", 2), ("/dev/full/out.png", 1)] {
        let out = whitted()
            .args([
                "render", "--width", "32", "--height", "18", "--quiet", "-o", target,
            ])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        println!("{target}: {:?} {stderr:?}", out.status.code());
        assert_eq!(out.status.code(), Some(code), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains("/dev/full"), "{stderr}");
    }
    assert_eq!(
        common::entries(Path::new("/dev")),
        before,
        "nothing left in /dev"
    );
}

/// SIGINT during a long render (the f64 reference, 64 spp at 1280x720): exit 1 with one
/// line, and neither the image nor a temporary file is left.
#[test]
fn an_interrupted_render_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = whitted()
        .args([
            "render",
            "--reference",
            "--spp",
            "64",
            "--width",
            "1280",
            "--height",
            "720",
        ])
        .arg("-o")
        .arg(dir.path().join("out.png"))
        .arg("-o")
        .arg(dir.path().join("out.ppm"))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Long enough for the interrupt handler to be in place and the render under way.
    std::thread::sleep(Duration::from_millis(1500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the render ended too early to interrupt"
    );
    let sent = Instant::now();
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    let stopped = sent.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!(
        "SIGINT: stopped {stopped:.2} s after the signal: {:?} {stderr:?}",
        out.status.code()
    );
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    assert!(
        common::entries(dir.path()).is_empty(),
        "{:?}",
        common::entries(dir.path())
    );
}

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
        common::skip(
            "a full device node",
            "cannot make a device node here (mknod needs CAP_MKNOD)",
            "writing into a device",
        );
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
