//! The command line's contract (SPEC §5): exit status 0 on success, 2 for a usage
//! error, 1 for anything else, with one clear line on stderr that says where (the
//! file's line and column, or the field); and a failed write leaves no file behind.
#![cfg(all(feature = "cli", feature = "viewer"))]

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::run as whitted;

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Exit status 1 with exactly one line on stderr that contains every `needle`.
#[track_caller]
fn assert_fails_with(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "stderr: {err}");
    assert_eq!(err.lines().count(), 1, "one line on stderr, got: {err}");
    assert!(err.starts_with("whitted: error: "), "{err}");
    for needle in needles {
        assert!(err.contains(needle), "stderr lacks {needle:?}: {err}");
    }
}

/// Writes `text` as `name` in a fresh folder and renders it into that folder.
fn render_scene(name: &str, text: &str) -> (tempfile::TempDir, Output) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join(name);
    std::fs::write(&scene, text).unwrap();
    let png = dir.path().join("out.png");
    let out = whitted(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "9",
    ]);
    (dir, out)
}

#[test]
fn bad_scene_files_exit_1_naming_the_place() {
    // An unknown key: the key's line and column.
    let (dir, out) = render_scene(
        "unknown.toml",
        "[[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\nshine = 3\n",
    );
    assert_fails_with(&out, &["unknown.toml:4:1", "shine"]);
    assert_eq!(
        common::entries(dir.path()),
        ["unknown.toml"],
        "no image written"
    );

    // A wrong type: the value's line and column, the field, in the file's words.
    let (_, out) = render_scene(
        "type.toml",
        "[[sphere]]\ncenter = [0, 0, -1]\nradius = \"big\"\n",
    );
    assert_fails_with(
        &out,
        &["type.toml:3:10: sphere 1: radius: expected a number, got the string \"big\""],
    );
    let (_, out) = render_scene(
        "int.toml",
        "[image]\nspp = 2.5\n\n[[light]]\nposition = [1, 2]\n",
    );
    assert_fails_with(
        &out,
        &["int.toml:2:7: image.spp: expected a whole number, got 2.5"],
    );
    let (_, out) = render_scene(
        "length.toml",
        "[[light]]\nposition = [1, 2]\n\n[[light]]\nposition = [1, 2, 3, 4]\n",
    );
    assert_fails_with(
        &out,
        &["length.toml:2:12: light 1: position: expected an array of 3 numbers, got 2 values"],
    );

    // A NaN radius (TOML `nan`): the place and the field.
    let (_, out) = render_scene(
        "nan.toml",
        "[image]\nwidth = 8\n\n[[sphere]]\ncenter = [0, 0, -1]\nradius = nan\n",
    );
    assert_fails_with(&out, &["nan.toml:6:10", "sphere 1", "radius"]);

    // A bad value in the second sphere names that sphere.
    let (_, out) = render_scene(
        "weight.toml",
        "[[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\n\n\
         [[sphere]]\ncenter = [1, 0, -1]\nradius = 0.5\nreflect = 1.5\n",
    );
    assert_fails_with(&out, &["weight.toml:8:11", "sphere 2", "reflect"]);

    // A missing key names the sphere, counted from 1 like the others.
    let (_, out) = render_scene(
        "missing.toml",
        "[[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\n\n[[sphere]]\ncenter = [1, 0, -1]\n",
    );
    assert_fails_with(
        &out,
        &["missing.toml:5:1: sphere 2: missing field `radius`"],
    );

    // Not TOML at all.
    let (_, out) = render_scene("broken.toml", "[[sphere]\ncenter = [0, 0, -1]\n");
    assert_fails_with(&out, &["broken.toml:1:"]);
}

#[test]
fn a_missing_scene_file_exits_1_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere.toml");
    let png = dir.path().join("out.png");
    let out = whitted(&[
        "render",
        missing.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_fails_with(&out, &["nowhere.toml"]);
    assert!(common::entries(dir.path()).is_empty());
}

#[test]
fn usage_errors_exit_2() {
    for args in [
        &["render", "--bogus"][..],
        &["--bogus"],
        &["render", "--width", "0"],
        &["render", "--width", "wide"],
        &["render", "--spp", "-1"],
        &["render", "--region", "1,2,3"],
        &["render", "--region", "0,0,0,5"],
        &["render", "-o", "picture.tiff"],
        &["render", "-o", "no-extension"],
        &["scene", "hw4"],
        &["scene", "hw3", "--seed", "x"],
        &["frobnicate"],
    ] {
        let out = whitted(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        // One line, like every other error.
        let err = stderr(&out);
        assert!(err.starts_with("whitted: error: "), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    }
    // The hints stay on that line: a similar option, the possible values.
    let err = stderr(&whitted(&["render", "--widht", "5"]));
    assert!(
        err.contains("'--widht'") && err.contains("'--width'"),
        "{err}"
    );
    let err = stderr(&whitted(&["scene", "hw4"]));
    assert!(err.contains("hw3"), "{err}");
    // Help and version are not errors.
    for args in [&["--help"][..], &["render", "--help"], &["--version"]] {
        let out = whitted(args);
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        assert!(!out.stdout.is_empty());
    }
}

/// The exact line of a usage error (exit status 2).
#[track_caller]
fn assert_usage_error(args: &[&str], line: &str) {
    let out = whitted(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
    assert_eq!(
        stderr(&out),
        format!("whitted: error: {line}\n"),
        "{args:?}"
    );
}

#[test]
fn misplaced_options_and_negative_numbers_say_what_is_wrong() {
    // An option of `render` given to the viewer: no "use '-- --width'" tip.
    assert_usage_error(
        &["view", "--width", "640"],
        "`whitted view` takes no --width: the window is resizable, or set width in the \
         scene's [image] table (see --help)",
    );
    assert_usage_error(
        &["--spp", "4"],
        "`whitted` takes no --spp: set spp in the scene's [image] table, or use --quality \
         (see --help)",
    );
    assert_usage_error(
        &["view", "-o", "x.png"],
        "`whitted view` takes no -o: it is an option of `whitted render` (see --help)",
    );
    // A negative number is a bad value, not an unknown option.
    assert_usage_error(
        &["render", "--spp", "-1"],
        "invalid value '-1' for '--spp <SPP>': expected a whole number from 1 to 65536 \
         (see --help)",
    );
    assert_usage_error(
        &["render", "--depth", "-3"],
        "invalid value '-3' for '--depth <DEPTH>': expected a whole number from 0 to 64 \
         (see --help)",
    );
    let out = whitted(&["render", "--seed", "-1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!stderr(&out).contains("tip: to pass"), "{}", stderr(&out));
}

/// README's rule: a bad option value is a usage error (exit status 2) whether clap or
/// the settings find it, and the line says what would fit.
#[test]
fn option_values_that_do_not_fit_exit_2_saying_what_would() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("out.png");
    let png = png.to_str().unwrap();
    assert_usage_error(
        &["render", "--region", "1200,700,200,200", "-o", png],
        "region 1200,700,200,200 does not fit in the 1280x720 image: the largest region at \
         1200,700 is 80x20",
    );
    assert_usage_error(
        &[
            "render",
            "--width",
            "50",
            "--height",
            "50",
            "--region",
            "50,0,10,10",
            "-o",
            png,
        ],
        "region 50,0,10,10 does not fit in the 50x50 image: its corner must be inside, at X \
         below 50 and Y below 50",
    );
    assert_usage_error(
        &["render", "--width", "65536", "--height", "65536", "-o", png],
        "image size 65536x65536 is too large: at most 268435456 pixels in one render \
         (65536x4096 at this width); render it in parts, a region or a tile at a time",
    );
    assert_usage_error(
        &["render", "--width", "100000", "-o", png],
        "invalid value '100000' for '--width <WIDTH>': expected a whole number from 1 to \
         65536 (see --help)",
    );
    assert_usage_error(
        &[
            "render", "--tile", "8/9", "--width", "2", "--height", "2", "-o", png,
        ],
        "tile 8/9 does not exist in a 2x2 image: expected an index from 0 to 8 and at most \
         as many tiles as pixels",
    );
    assert!(common::entries(dir.path()).is_empty());
}

/// Only the region is allocated: a 64x64 corner of a 65536x65536 image renders (within
/// 1 GB of address space; the whole image's pixels would take 51 GB).
#[test]
fn a_small_region_of_a_giant_image_renders() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("corner.png");
    let out = Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 1048576 && exec "$@""#)
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_whitted"))
        .args(["render", "--width", "65536", "--height", "65536"])
        .args(["--region", "0,0,64,64", "--threads", "2", "-o"])
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let image = image::open(&png).unwrap();
    assert_eq!((image.width(), image.height()), (64, 64));
}

/// The closing line of `render` (the last line on stderr).
fn closing_line(args: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("out.png");
    let out = whitted(&[args, &["-o", png.to_str().unwrap()]].concat());
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    stderr(&out).lines().last().unwrap_or_default().to_string()
}

#[test]
fn the_closing_line_says_how_many_samples_adaptive_anti_aliasing_took() {
    let size = ["render", "--width", "64", "--height", "36"];
    let line = closing_line(&[&size[..], &["--quality", "high"]].concat());
    // e.g. "rendered hw3 64x36 (adaptive, up to 64 spp, mean 9.3, depth 16) in ..."
    let rest = line
        .strip_prefix("rendered hw3 64x36 (adaptive, up to 64 spp, mean ")
        .unwrap_or_else(|| panic!("closing line: {line}"));
    let (mean, rest) = rest.split_once(", ").unwrap();
    let mean: f64 = mean.parse().unwrap();
    assert!(mean > 4.0 && mean < 64.0, "{line}");
    assert!(rest.starts_with("depth 16) in "), "{line}");
    // A fixed number of samples is said as it is.
    let line = closing_line(&[&size[..], &["--spp", "16"]].concat());
    assert!(
        line.starts_with("rendered hw3 64x36 (16 spp, depth 5) in "),
        "{line}"
    );
}

/// Depth 0 traces no ray (SPEC §2: `trace` returns the sky at `max_depth`): allowed,
/// written, and said in the closing line.
#[test]
fn depth_0_renders_the_sky_and_says_so() {
    let line = closing_line(&["render", "--width", "64", "--height", "36", "--depth", "0"]);
    assert!(
        line.starts_with(
            "rendered hw3 64x36 (1 spp, depth 0: no ray traced, every pixel is the sky) in "
        ) && line.contains(": 0 rays, "),
        "{line}"
    );
    let help = String::from_utf8_lossy(&whitted(&["render", "--help"]).stdout).into_owned();
    assert!(help.contains("0 traces no ray at all"), "{help}");
}

#[test]
fn a_region_outside_the_image_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("out.png");
    let out = whitted(&[
        "render",
        "--width",
        "50",
        "--height",
        "50",
        "--region",
        "45,0,10,10",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("50x50 image"), "{}", stderr(&out));
    assert!(common::entries(dir.path()).is_empty());
}

#[test]
fn output_into_a_missing_folder_exits_1_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("missing/out.png");
    let ppm = dir.path().join("good.ppm");
    let out = whitted(&[
        "render",
        "--width",
        "16",
        "--height",
        "9",
        "-o",
        ppm.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_fails_with(&out, &["missing"]);
    // Checked before rendering: not even the writable target was written.
    assert!(
        common::entries(dir.path()).is_empty(),
        "{:?}",
        common::entries(dir.path())
    );
}

#[test]
fn output_into_a_read_only_folder_exits_1_and_leaves_nothing() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let target = ro.join("out.png");
    let args = [
        "render",
        "--width",
        "16",
        "--height",
        "9",
        "-o",
        target.to_str().unwrap(),
    ];

    // root ignores folder permissions; without CAP_DAC_OVERRIDE (dropped by util-linux
    // `setpriv`) it cannot write into a 0555 folder either.
    let probe = ro.join("probe");
    let out = if std::fs::write(&probe, b"").is_err() {
        whitted(&args)
    } else {
        std::fs::remove_file(&probe).unwrap();
        let drop_caps = ["--bounding-set=-dac_override,-dac_read_search", "--"];
        let denied = Command::new("setpriv")
            .args(drop_caps)
            .args(["touch", probe.to_str().unwrap()])
            .output()
            .map(|o| !o.status.success())
            .unwrap_or(false);
        if !denied {
            common::skip(
                "output_into_a_read_only_folder",
                "running as root and `setpriv` cannot drop CAP_DAC_OVERRIDE here, so no \
                 folder is read-only",
                "a read-only folder",
            );
            return;
        }
        Command::new("setpriv")
            .args(drop_caps)
            .arg(env!("CARGO_BIN_EXE_whitted"))
            .args(args)
            .output()
            .unwrap()
    };
    let listing = common::entries(&ro);
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_fails_with(&out, &["ro", "ermission denied"]);
    assert!(listing.is_empty(), "left behind: {listing:?}");
}

#[test]
fn a_good_render_exits_0_with_a_closing_line() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("out.png");
    let out = whitted(&[
        "render",
        "--width",
        "32",
        "--height",
        "18",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let err = stderr(&out);
    let last = err.lines().last().unwrap_or_default();
    // e.g. "rendered hw3 32x18 (1 spp, depth 5) in 0.0011 s (build 0.0002 s): 3541 rays,
    // 1.3 Mrays/s"
    assert!(
        last.starts_with("rendered hw3 32x18")
            && last.contains(" rays, ")
            && last.ends_with("Mrays/s"),
        "closing line: {last}"
    );
    // The build is part of the time the line gives, and both are figures (a build of
    // hw3 may round to 0.0000 s on a fast machine).
    let seconds = |before: &str, after: &str| -> f64 {
        let from = last.find(before).expect(before) + before.len();
        let to = from + last[from..].find(after).expect(after);
        last[from..to].parse().expect("seconds")
    };
    let (total, build) = (seconds(" in ", " s (build"), seconds("(build ", " s)"));
    assert!(0.0 <= build && build <= total, "closing line: {last}");
    assert!(err.contains("wrote "), "{err}");
    assert_eq!(common::entries(dir.path()), ["out.png"]);

    // --quiet: nothing on stderr (and no progress bar when stderr is not a terminal).
    let out = whitted(&[
        "render",
        "--quiet",
        "--width",
        "32",
        "--height",
        "18",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stderr.is_empty(), "{}", stderr(&out));
}

#[test]
fn scene_printing_fails_cleanly_when_stdout_cannot_be_written() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        common::skip(
            "scene_printing_fails_cleanly",
            "no /dev/full on this system",
            "a full standard output",
        );
        return;
    };
    let out = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(["scene", "hw3"])
        .stdout(full)
        .output()
        .unwrap();
    // A clear error and status 1, not a panic (status 101).
    assert_fails_with(&out, &["standard output"]);
}

/// The value of `key=` in a RESULT line.
fn field<'a>(line: &'a str, key: &str) -> &'a str {
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
        .unwrap_or_else(|| panic!("no {key} in {line}"))
}

/// The built-in hw3 scene as a file in `dir`, at `width`×`height`.
fn hw3_file(dir: &Path, width: u32, height: u32) -> std::path::PathBuf {
    let scene = dir.join(format!("hw3_{width}x{height}.toml"));
    let text = whitted::scene::hw3_toml(whitted::scene::HW3_DEFAULT_SEED)
        .replace("width = 1280", &format!("width = {width}"))
        .replace("height = 720", &format!("height = {height}"));
    std::fs::write(&scene, text).unwrap();
    scene
}

/// An orbit whose frames no machine renders within 1/30 s (hw3 at 4096×4096, two
/// threads: 16.8 million pixels) shows a preview before every timed view, and counts
/// each (`previews`).
#[test]
fn an_orbit_too_slow_for_thirty_frames_a_second_shows_previews() {
    let dir = tempfile::tempdir().unwrap();
    let scene = hw3_file(dir.path(), 4096, 4096);
    let scene = scene.to_str().unwrap();
    let out = whitted(&["time", scene, "--orbit", "2", "--threads", "2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = String::from_utf8(out.stdout).unwrap();
    assert_eq!(field(&line, "size"), "4096x4096", "{line}");
    assert_eq!(field(&line, "views"), "2", "{line}");
    assert_eq!(field(&line, "previews"), "2", "{line}");
}

#[test]
fn time_prints_one_result_line_for_renders_and_for_orbits() {
    let dir = tempfile::tempdir().unwrap();
    let scene = hw3_file(dir.path(), 64, 36);
    let scene = scene.to_str().unwrap();

    let out = whitted(&["time", scene, "--runs", "2", "--threads", "1"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = String::from_utf8(out.stdout).unwrap();
    assert_eq!(line.lines().count(), 1, "{line}");
    assert!(line.starts_with("RESULT peer=whitted "), "{line}");
    assert_eq!(field(&line, "size"), "64x36");
    assert_eq!(field(&line, "runs"), "2");
    assert_eq!(field(&line, "primary"), (64 * 36).to_string());
    let count = |k| field(&line, k).parse::<u64>().unwrap();
    assert_eq!(
        count("rays"),
        count("primary") + count("shadow") + count("secondary")
    );

    let out = whitted(&["time", scene, "--orbit", "3", "--threads", "2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = String::from_utf8(out.stdout).unwrap();
    assert!(line.starts_with("RESULT peer=whitted-viewer "), "{line}");
    assert_eq!(field(&line, "threads"), "2");
    assert_eq!(field(&line, "views"), "3");
    // 64×36 is below the preview's smallest size: every view is one full pass.
    assert_eq!(field(&line, "previews"), "0");
    let ms: f64 = field(&line, "frame_ms").parse().unwrap();
    let view_ms: f64 = field(&line, "view_ms").parse().unwrap();
    let fps: f64 = field(&line, "fps").parse().unwrap();
    // A view's time runs from its submission to its frame, so it holds the pass.
    assert!(ms > 0.0 && view_ms >= ms && fps > 0.0, "{line}");

    // Whole frames only: no view starts with a preview, whatever the speed.
    let out = whitted(&["time", "--orbit", "2", "--no-preview", "--threads", "2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = String::from_utf8(out.stdout).unwrap();
    assert_eq!(field(&line, "size"), "1280x720");
    assert_eq!(field(&line, "views"), "2");
    assert_eq!(field(&line, "previews"), "0");
    // The flag belongs to orbits.
    let out = whitted(&["time", scene, "--no-preview"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--orbit"), "{}", stderr(&out));
}

/// README explains the stretched balls near the edges (the assignment's 132° vertical
/// field of view) and gives one line that renders with a narrower one; that line works.
#[test]
fn the_readme_line_for_a_narrower_view_renders_with_vfov_60() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    assert!(
        readme.contains("132° vertically"),
        "README explains the stretching"
    );
    let line = readme
        .lines()
        .find(|l| l.contains("vfov = 60") && l.contains("whitted render"))
        .expect("README gives the line");
    let dir = tempfile::tempdir().unwrap();
    let bin = Path::new(env!("CARGO_BIN_EXE_whitted")).parent().unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
    let out = Command::new("sh")
        .args(["-c", line])
        .current_dir(dir.path())
        .env("PATH", path)
        .output()
        .unwrap();
    assert!(out.status.success(), "{line}: {}", stderr(&out));
    let scene = whitted::Scene::load(&dir.path().join("narrow.toml")).unwrap();
    match scene.camera {
        Some(whitted::CameraSpec::LookAt { vfov, .. }) => assert_eq!(vfov, 60.0),
        other => panic!("camera: {other:?}"),
    }
    assert_eq!(scene.spheres.len(), 52);
    let image = image::open(dir.path().join("narrow.png")).unwrap();
    assert_eq!((image.width(), image.height()), (1280, 720));
}
