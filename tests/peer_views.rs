//! `whitted time --orbit N --views-to DIR`: the viewer's timed views written as scenes
//! of the peer programs' format, so that the peers time the same frames.
#![cfg(all(feature = "cli", feature = "viewer"))]

mod common;

use std::path::Path;
use std::process::Command;

use common::{entries, run, skip, whitted};

/// The peers' own generator's hw3 scene (`../shared/peers/make_hw3.py`), its lines
/// but the comment; `None` where the generator or Python is missing.
fn peers_hw3(dir: &Path) -> Option<Vec<String>> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/peers/make_hw3.py");
    let made = Command::new("python3")
        .arg(script)
        .arg("--outdir")
        .arg(dir)
        .output()
        .ok()?;
    assert!(made.status.success(), "make_hw3.py failed: {made:?}");
    let text = std::fs::read_to_string(dir.join("hw3.txt")).expect("hw3.txt");
    Some(
        text.lines()
            .filter(|l| !l.starts_with('#'))
            .map(str::to_string)
            .collect(),
    )
}

/// The numbers of a scene line after its keyword.
fn numbers(line: &str) -> Vec<f64> {
    line.split_whitespace()
        .skip(1)
        .map(|x| x.parse().expect("a number"))
        .collect()
}

/// Each timed view of the built-in scene's orbit is a file: the peers' own hw3 scene
/// (spheres, light, size, depth, line for line as their generator writes them) with
/// the camera of that view: the eye turned about the look-at point (0, 0, −1) by 2.5°
/// a view (a drag of 10 pixels of 720, after one warm-up view), the film frame turned
/// with it.
#[test]
fn the_orbit_s_views_are_the_peers_scene_seen_from_the_orbit() {
    let dir = tempfile::tempdir().unwrap();
    let Some(peers) = peers_hw3(dir.path()) else {
        skip(
            "the_orbit_s_views_are_the_peers_scene_seen_from_the_orbit",
            "python3 is missing",
            "the views' scene files",
        );
        return;
    };
    let views = dir.path().join("views");
    std::fs::create_dir(&views).unwrap();
    let out = whitted(&[
        "time",
        "--orbit",
        "2",
        "--no-preview",
        "--threads",
        "1",
        "--views-to",
        views.to_str().unwrap(),
    ]);
    assert!(String::from_utf8_lossy(&out).starts_with("RESULT peer=whitted-viewer"));
    assert_eq!(entries(&views), ["view_01.txt", "view_02.txt"]);
    for (view, turns) in [(1, 2.0f64), (2, 3.0)] {
        let text = std::fs::read_to_string(views.join(format!("view_{view:02}.txt"))).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), peers.len(), "view {view}");
        for (line, peer) in lines.iter().zip(&peers) {
            if peer.starts_with("camera") {
                continue;
            }
            assert_eq!(line, peer, "view {view}");
        }
        let camera = numbers(lines[0]);
        assert!(lines[0].starts_with("camera "), "{}", lines[0]);
        let a = (2.5 * turns).to_radians();
        let (sin, cos) = a.sin_cos();
        // The default frame (eye at the origin, film 8 × 4.5 at z = −1) turned by `a`
        // about the y axis through (0, 0, −1).
        let turn = |x: f64, z: f64| (x * cos - (z + 1.0) * sin, x * sin + (z + 1.0) * cos - 1.0);
        let (ex, ez) = turn(0.0, 0.0);
        let (lx, lz) = turn(-4.0, -1.0);
        let expected = [
            ex,
            0.0,
            ez,
            lx,
            -2.25,
            lz,
            8.0 * cos,
            0.0,
            8.0 * sin,
            0.0,
            4.5,
            0.0,
        ];
        for (k, (got, want)) in camera.iter().zip(expected).enumerate() {
            assert!(
                (got - want).abs() < 1e-9,
                "view {view}, camera number {k}: {got} against {want}"
            );
        }
    }
}

/// A scene the peers cannot render (two lights, or a sky of its own) is a one-line
/// error and a failure, and writes no view; so is a folder that cannot be written;
/// `--views-to` needs `--orbit`. The same scene with one light and the default sky
/// gives its view, line for line.
#[test]
fn views_the_peers_cannot_take_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let views = dir.path().to_str().unwrap();
    let light = |x: u32| format!("[[light]]\nposition = [{x}, 5, 0]\nintensity = [1, 1, 1]\n\n");
    let ball = "[[sphere]]\ncenter = [0, 0, -3]\nradius = 1\ncolor = [1, 1, 1]\n\n\
                [image]\nwidth = 16\nheight = 9\n";
    let sky = "[sky]\ndown = [0.2, 0.4, 0.6]\nup = [1, 0, 0.5]\n\n";
    for (name, text, error) in [
        (
            "two.toml",
            format!("{}{}{ball}", light(0), light(5)),
            Some("the peers render one light, not 2"),
        ),
        (
            "sky.toml",
            format!("{}{sky}{ball}", light(0)),
            Some("the peers render the default sky only"),
        ),
        ("fine.toml", format!("{}{ball}", light(0)), None),
    ] {
        let scene = dir.path().join(name);
        std::fs::write(&scene, text).unwrap();
        let scene = scene.to_str().unwrap();
        let out = run(&[
            "time",
            scene,
            "--orbit",
            "1",
            "--no-preview",
            "--views-to",
            views,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        let view = dir.path().join("view_01.txt");
        let Some(error) = error else {
            assert!(out.status.success(), "{name}: {err}");
            let text = std::fs::read_to_string(view).unwrap();
            let lines: Vec<&str> = text.lines().skip(1).collect();
            let expected = [
                "light 0 5 0  1 1 1",
                "size 16 9",
                "depth 5",
                "sphere 0 0 -3  1  1 1 1  0 0  2",
            ];
            assert_eq!(lines, expected, "{name}");
            continue;
        };
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(error), "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(!view.exists(), "{name}");
    }

    let missing = dir.path().join("no").join("such");
    let out = run(&[
        "time",
        "--orbit",
        "1",
        "--no-preview",
        "--views-to",
        missing.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot write") && err.contains("view_01.txt"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");

    let out = run(&["time", "--views-to", views]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--orbit"));
}
