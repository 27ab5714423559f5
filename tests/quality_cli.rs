//! `whitted render --quality` and `whitted bench` from the command line.
#![cfg(all(feature = "cli", feature = "viewer"))]

use std::process::Command;

fn whitted() -> Command {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
}

fn read_ppm(path: &std::path::Path) -> image::RgbImage {
    image::open(path).unwrap().into_rgb8()
}

#[test]
fn render_quality_presets_and_overrides() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name);
    let run = |args: &[&str], file: &str| {
        let o = whitted()
            .args(["render", "--width", "32", "--height", "18", "-q", "-o"])
            .arg(out(file))
            .args(args)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        read_ppm(&out(file))
    };
    let plain = run(&[], "plain.ppm");
    let draft = run(&["--quality", "draft"], "draft.ppm");
    assert_eq!(plain, draft, "draft is the plain setting");
    let default = run(&["--quality", "default"], "default.ppm");
    assert_ne!(plain, default);
    // Explicit options override the preset's: default with 1 spp and depth 5 and no
    // refinement possible is the plain image again.
    let overridden = run(
        &["--quality", "default", "--spp", "1", "--depth", "5"],
        "o.ppm",
    );
    assert_eq!(plain, overridden);
    for preset in ["high", "reference"] {
        run(&["--quality", preset], &format!("{preset}.ppm"));
    }

    let o = whitted()
        .args(["render", "--quality", "ultra", "-o"])
        .arg(out("x.png"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("ultra"), "{err}");
    assert!(!out("x.png").exists());
}

#[test]
fn bench_tiny_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let o = whitted()
        .args(["bench", "--tiny", "--size", "24x16", "--runs", "5", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["bench.csv", "bench.md", "bench.svg"] {
        assert!(dir.path().join(f).is_file(), "{f}");
    }
    let o = whitted()
        .args(["bench", "--size", "0x16", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = whitted()
        .args(["bench", "--runs", "0", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}
