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
/// one error line, and the folder is left empty; for an EXR, which is encoded into
/// its temporary file, and for a PPM and a PNG.
#[test]
fn a_full_disk_or_a_read_only_folder_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let mnt = dir.path().display().to_string();
    let bin = env!("CARGO_BIN_EXE_whitted");
    for (what, options) in [
        ("full disk", "size=64k"),
        ("read-only folder", "ro,size=64k"),
    ] {
        // A plain PPM of 320x180 is about 500 KB and an EXR 700 KB: neither fits in
        // 64 KiB. The EXR is encoded into the temporary file as it goes.
        let script = format!(
            "mount -t tmpfs -o {options} tmpfs '{mnt}' || exit 99; \
             '{bin}' render --width 320 --height 180 --quiet -o '{mnt}/out.exr'; \
             echo \"rc=$?\"; \
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
        assert_eq!(lines.next(), Some("rc=1"), "{what}: exit status (EXR)");
        assert_eq!(lines.next(), Some("rc=1"), "{what}: exit status");
        assert_eq!(lines.next(), None, "{what}: files left behind: {stdout}");
        let errors: Vec<&str> = stderr.lines().collect();
        assert_eq!(errors.len(), 2, "{what}: one error line each: {stderr}");
        for error in errors {
            assert!(error.starts_with("whitted: error: "), "{stderr}");
        }
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
/// /dev/full is never at risk): exit 1 with one line that gives the system's reason,
/// the node left as it was, no other file. A small image fails when its buffer is
/// written out; a large one (2,000 × 2,000) fails inside the encoder, which writes
/// into the file as it goes: the reason is the same, not the encoder's.
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
    for (width, height) in [("32", "18"), ("2000", "2000")] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_whitted"))
            .args([
                "render", "--width", width, "--height", height, "--quiet", "-o",
            ])
            .arg(&node)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        println!(
            "full device, {width}x{height}: {:?} {stderr:?}",
            out.status.code()
        );
        let still_device =
            std::fs::symlink_metadata(&node).is_ok_and(|m| m.file_type().is_char_device());
        let others = std::fs::read_dir(dir.path()).unwrap().count() - 1;
        assert!(still_device, "the device node was replaced");
        assert_eq!(others, 0, "files left beside it");
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains("No space left on device"), "{stderr}");
    }
}

/// Sends `signal` (a name for kill(1): TERM, INT) to process `pid`.
fn send(signal: &str, pid: u32) {
    let sent = Command::new("kill")
        .args([&format!("-{signal}"), &pid.to_string()])
        .status()
        .unwrap();
    assert!(sent.success(), "kill -{signal} {pid}");
}

/// Waits until process `pid` catches SIGTERM (its handler is installed: a signal from
/// then on is the program's to handle, not a kill).
fn wait_for_handler(pid: u32) {
    wait_until("the signal handler", || {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
        let caught = status
            .lines()
            .find_map(|l| l.strip_prefix("SigCgt:"))
            .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
            .unwrap_or(0);
        caught & (1 << (libc::SIGTERM - 1)) != 0
    });
}

/// Polls until `ready` holds (at most two minutes).
fn wait_until(what: &str, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `whitted render` of the turntable (hw3 with an animation) at 320x180, `frames`
/// frames, into `outputs`, started in the background.
fn animation(frames: u32, outputs: &[&Path]) -> std::process::Child {
    let mut c = whitted();
    c.args(["render", "assets/scenes/turntable.toml", "--quiet"])
        .args(["--width", "320", "--height", "180"])
        .args(["--frames", &frames.to_string()]);
    for out in outputs {
        c.arg("-o").arg(out);
    }
    c.stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// The files in `dir` that are not hidden (temporary files start with a dot).
fn finished(dir: &Path) -> usize {
    common::entries(dir)
        .iter()
        .filter(|n| !n.starts_with('.'))
        .count()
}

/// The numbered PNG frames `f-NN.png` in `dir` (asserting that nothing else is there),
/// each decoded whole at 320x180; frame 0 equals a render of frame 0 alone.
fn whole_frames(dir: &Path) -> usize {
    let names = common::entries(dir);
    for (k, name) in names.iter().enumerate() {
        assert_eq!(name, &format!("f-{k:02}.png"), "{names:?}");
        let frame = image::open(dir.join(name))
            .unwrap_or_else(|e| panic!("{name} is not whole: {e}"))
            .to_rgb8();
        assert_eq!(frame.dimensions(), (320, 180), "{name}");
    }
    let alone = tempfile::tempdir().unwrap();
    let first = alone.path().join("f0.png");
    let out = whitted()
        .args(["render", "assets/scenes/turntable.toml", "--quiet"])
        .args(["--width", "320", "--height", "180", "--frame", "0", "-o"])
        .arg(&first)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let kept = std::fs::read(dir.join("f-00.png")).unwrap();
    assert_eq!(kept, std::fs::read(&first).unwrap(), "f-00.png");
    names.len()
}

/// SIGTERM while an animation is written as numbered frames and a GIF: exit 1 with one
/// line, the frames finished before the signal kept whole, no GIF and no temporary
/// file left.
#[test]
fn sigterm_during_an_animation_keeps_finished_frames_and_no_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, gif) = (dir.path().join("frames"), dir.path().join("gif"));
    std::fs::create_dir(&frames).unwrap();
    std::fs::create_dir(&gif).unwrap();
    let child = animation(200, &[&frames.join("f-%02d.png"), &gif.join("out.gif")]);
    wait_until("three frames", || finished(&frames) >= 3);
    send("TERM", child.id());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("SIGTERM during an animation: {:?} {stderr:?}", out.status);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    assert_eq!(common::entries(&gif), Vec::<String>::new(), "left in gif/");
    let kept = whole_frames(&frames);
    println!("kept {kept} whole frames");
    assert!((3..200).contains(&kept), "{kept} frames");
}

/// Parts of a 1280x720 image (four EXR tiles) in `dir`, and the image stitched from
/// them into `whole.ppm` (plain PPM: large, so that stitching takes a while).
fn parts_and_whole(dir: &Path) -> (Vec<String>, Vec<u8>, Duration) {
    let parts: Vec<String> = (0..4)
        .map(|i| {
            let part = dir.join(format!("part-{i}.exr"));
            let out = whitted()
                .args(["render", "--width", "1280", "--height", "720", "--quiet"])
                .args(["--tile", &format!("{i}/4"), "-o"])
                .arg(&part)
                .output()
                .unwrap();
            assert!(out.status.success(), "{out:?}");
            part.display().to_string()
        })
        .collect();
    let whole = dir.join("whole.ppm");
    let start = Instant::now();
    let out = whitted()
        .args(["stitch", "-o", whole.to_str().unwrap()])
        .args(&parts)
        .output()
        .unwrap();
    let took = start.elapsed();
    assert!(out.status.success(), "{out:?}");
    let bytes = std::fs::read(&whole).unwrap();
    std::fs::remove_file(&whole).unwrap();
    (parts, bytes, took)
}

/// SIGTERM at several moments of a `whitted stitch`: each time, either exit 1 with
/// one line and nothing written, or exit 0 with the whole image; never a partial or
/// temporary file. The first signal comes as soon as the handler is in place, before
/// the end.
#[test]
fn sigterm_during_a_stitch_leaves_the_whole_image_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (parts, whole, took) = parts_and_whole(dir.path());
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let target = out_dir.join("whole.ppm");
    let mut interrupted = 0;
    for share in [0.0, 0.3, 0.6, 1.2] {
        let delay = took.mul_f64(share);
        let child = whitted()
            .args(["stitch", "-o", target.to_str().unwrap()])
            .args(&parts)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        wait_for_handler(child.id());
        std::thread::sleep(delay);
        let _ = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status();
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let left = common::entries(&out_dir);
        println!(
            "SIGTERM {:.0} ms after the handler, in a {:.0} ms stitch: {:?} {stderr:?} left {left:?}",
            delay.as_secs_f64() * 1e3,
            took.as_secs_f64() * 1e3,
            out.status.code()
        );
        match out.status.code() {
            Some(1) => {
                interrupted += 1;
                assert_eq!(stderr.lines().count(), 1, "{stderr}");
                assert!(stderr.contains("interrupted"), "{stderr}");
                assert!(left.is_empty(), "left behind: {left:?}");
            }
            Some(0) => {
                assert_eq!(left, ["whole.ppm"]);
                assert!(std::fs::read(&target).unwrap() == whole, "not whole");
                std::fs::remove_file(&target).unwrap();
            }
            other => panic!("stitch ended with {other:?} (killed?): {stderr}"),
        }
    }
    assert!(interrupted > 0, "no signal came before the end of a stitch");
}

/// A FIFO with no reader: the write waits for one, and Ctrl-C or SIGTERM ends the
/// wait with exit 1 and one line, the FIFO left as it was and nothing beside it. For a
/// still render, an animation (the file is opened before the first frame) and a
/// stitch.
#[test]
fn a_signal_ends_the_wait_for_a_fifo_reader() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let part = dir.path().join("part.png");
    let out = whitted()
        .args(["render", "--width", "32", "--height", "18", "--quiet"])
        .args(["--tile", "0/1", "-o"])
        .arg(&part)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let pipes = dir.path().join("pipes");
    std::fs::create_dir(&pipes).unwrap();
    let part = part.display().to_string();
    let cases: [(&str, &str, Vec<&str>); 3] = [
        (
            "INT",
            "still.png",
            vec!["render", "--width", "32", "--height", "18", "--quiet"],
        ),
        (
            "TERM",
            "moving.gif",
            vec!["render", "--width", "32", "--height", "18", "--frames", "3"],
        ),
        ("TERM", "stitched.png", vec!["stitch", &part]),
    ];
    for (signal, name, args) in cases {
        let fifo = pipes.join(name);
        let made = Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            common::skip("FIFO test", "mkfifo failed here", "writing into a FIFO");
            return;
        }
        let child = whitted()
            .args(&args)
            .arg("-o")
            .arg(&fifo)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Time to render (the still) and come to the wait.
        std::thread::sleep(Duration::from_millis(1500));
        send(signal, child.id());
        let sent = Instant::now();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || tx.send(child.wait_with_output()));
        let Ok(out) = rx.recv_timeout(Duration::from_secs(30)) else {
            // Open the FIFO for reading, so that the writer (and this test) can end.
            let _ = std::fs::read(&fifo);
            panic!("{name}: SIG{signal} did not end the wait for a reader");
        };
        let out = out.unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        println!(
            "{name}: SIG{signal}, stopped after {:.2} s: {:?} {stderr:?}",
            sent.elapsed().as_secs_f64(),
            out.status.code()
        );
        assert_eq!(out.status.code(), Some(1), "{name}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{name}: {stderr}");
        assert!(stderr.contains("interrupted"), "{name}: {stderr}");
        let still_fifo = std::fs::symlink_metadata(&fifo).is_ok_and(|m| m.file_type().is_fifo());
        assert!(still_fifo, "{name}: the FIFO was replaced");
        std::fs::remove_file(&fifo).unwrap();
        assert!(
            common::entries(&pipes).is_empty(),
            "{:?}",
            common::entries(&pipes)
        );
    }
}

/// The folder of the GIF removed while the animation renders: exit 1 at the next
/// frame with one line, the numbered frames in another folder kept whole. Then the
/// folder of the numbered frames removed: exit 1, and no GIF (nor temporary file) in
/// its folder.
#[test]
fn a_folder_removed_mid_run_stops_the_animation_and_keeps_finished_files() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, gif) = (dir.path().join("frames"), dir.path().join("gif"));
    for (removed, kept) in [(&gif, &frames), (&frames, &gif)] {
        std::fs::create_dir(&frames).unwrap();
        std::fs::create_dir(&gif).unwrap();
        let child = animation(200, &[&frames.join("f-%02d.png"), &gif.join("out.gif")]);
        wait_until("two frames", || finished(&frames) >= 2);
        remove_while_written(removed);
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let what = removed.file_name().unwrap().to_string_lossy();
        println!("{what}/ removed: {:?} {stderr:?}", out.status.code());
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(&*what), "{stderr}");
        if kept == &frames {
            let n = whole_frames(&frames);
            assert!((2..200).contains(&n), "{n} frames: the render went on");
        } else {
            assert!(
                common::entries(&gif).is_empty(),
                "{:?}",
                common::entries(&gif)
            );
        }
        std::fs::remove_dir_all(kept).unwrap();
    }
}

/// Removes `dir` as `rm -rf` would while a render still writes into it: a file the
/// render creates between the listing and the last `rmdir` leaves the folder not
/// empty, so the removal goes again until the folder is gone.
fn remove_while_written(dir: &Path) {
    for attempt in 1.. {
        match std::fs::remove_dir_all(dir) {
            Ok(()) => return,
            Err(e) if e.kind() == std::io::ErrorKind::DirectoryNotEmpty && attempt < 100 => {}
            Err(e) => panic!("removing {}: {e} (attempt {attempt})", dir.display()),
        }
    }
}

/// A full disk (a 2 MiB tmpfs) while an animation is written as numbered plain PPM
/// frames and an APNG into it: exit 1 with one line; the frames that fitted are
/// whole, the one that did not is not there, and no APNG or temporary file is left.
#[test]
fn a_disk_filling_up_mid_animation_keeps_the_frames_that_fitted() {
    let dir = tempfile::tempdir().unwrap();
    let (mnt, kept) = (dir.path().join("mnt"), dir.path().join("kept"));
    std::fs::create_dir(&mnt).unwrap();
    std::fs::create_dir(&kept).unwrap();
    let (mnt_s, kept_s) = (mnt.display(), kept.display());
    let bin = env!("CARGO_BIN_EXE_whitted");
    // A plain PPM frame of 320x180 is about 500 KB: three or four fit.
    let script = format!(
        "mount -t tmpfs -o size=2m tmpfs '{mnt_s}' || exit 99; \
         '{bin}' render assets/scenes/turntable.toml --quiet --width 320 --height 180 \
         --frames 24 -o '{mnt_s}/f-%02d.ppm' -o '{mnt_s}/out.apng'; \
         echo \"rc=$?\"; cp -a '{mnt_s}/.' '{kept_s}/'"
    );
    let what = "a full disk during an animation";
    let Some(out) = in_mount_namespace(&script) else {
        common::skip(
            what,
            "cannot create user/mount namespaces (unshare -rm) here",
            "a full file system",
        );
        return;
    };
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.code() == Some(99) {
        common::skip(
            what,
            &format!("cannot mount a tmpfs in a namespace: {stderr}"),
            "a full file system",
        );
        return;
    }
    let names = common::entries(&kept);
    println!("{what}: {stdout:?} {stderr:?} left {names:?}");
    assert_eq!(stdout.trim(), "rc=1", "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(names.len() >= 2, "{names:?}");
    for (k, name) in names.iter().enumerate() {
        assert_eq!(name, &format!("f-{k:02}.ppm"), "{names:?}");
        let frame = image::open(kept.join(name))
            .unwrap_or_else(|e| panic!("{name} is not whole: {e}"))
            .to_rgb8();
        assert_eq!(frame.dimensions(), (320, 180), "{name}");
    }
}
