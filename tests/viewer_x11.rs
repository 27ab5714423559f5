//! The viewer driven for real: the release binary in an Xvfb server, for both blit
//! paths. Screenshots (`import -window`) are compared pixel by pixel with what
//! `whitted render` writes; keys are real key presses (XTEST via `xdotool key` to the
//! focused window), since winit ignores synthetic events.
//!
//! The tests need `Xvfb`, `xdotool` and ImageMagick's `import`. Without them a test is
//! skipped with a line the test harness shows (written past its output capture); with
//! `CI=true` (CI always has them: see `.ci/run`) a missing tool fails the test.
#![cfg(all(feature = "cli", feature = "viewer"))]

mod common;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use image::RgbImage;

use common::x11::*;

/// The built-in scene at 320×180 written as `small.toml` in `dir`.
fn small_scene(dir: &Path, spp: u32) -> PathBuf {
    let mut scene = whitted::scene::hw3_scene(whitted::scene::HW3_DEFAULT_SEED);
    scene.image.width = Some(320);
    scene.image.height = Some(180);
    scene.image.spp = Some(spp);
    let path = dir.join("small.toml");
    fs::write(&path, whitted::scene::to_toml(&scene)).unwrap();
    path
}

fn start_viewer(x: &XServer, dir: &Path, scene: &Path, blit: &str) -> (Viewer, String) {
    start_viewer_with(x, dir, scene, &[("WHITTED_BLIT", blit)])
}

/// The whole session of SPEC §6 with one blitter.
fn session(blit: &str) {
    let test = format!("viewer session with WHITTED_BLIT={blit}");
    if !x_tools_or_skip(&test) {
        return;
    }
    let x = XServer::start();
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let scene = small_scene(dir, 1);
    let expected = headless(dir, &scene, &[], "render.png");

    let (mut viewer, window) = start_viewer(&x, dir, &scene, blit);
    let title = x.wait_title(&mut viewer, &window, |t| t.ends_with("- done"));
    assert!(
        title.starts_with("whitted - small - 320x180 - 1/1 spp - "),
        "title: {title}"
    );
    // One line names the blitter, whichever it is.
    let line = format!("whitted: drawing with {blit}");
    assert!(
        viewer
            .stderr()
            .lines()
            .any(|l| l.starts_with(&line) && l.ends_with(&format!("(WHITTED_BLIT={blit})"))),
        "no `{line}` line: {}",
        viewer.stderr()
    );
    // WHITTED_STATS names the blitter that drew the first frame.
    assert!(
        viewer
            .stderr()
            .contains(&format!("stats: blitter {blit}\n")),
        "WHITTED_BLIT={blit} was not used: {}",
        viewer.stderr()
    );

    // What the window shows equals the headless render, pixel for pixel.
    let diff = screenshot_matching(&x, &window, dir, &expected);
    assert_eq!(
        diff, 0,
        "{blit}: {diff} pixels differ from `whitted render`"
    );
    let shot = x.screenshot(&window, dir, "shown.png");

    // S saves what is on screen, under new names each time.
    x.key(&window, "s");
    viewer.wait_stdout("saved small-001.png and small-001.ppm");
    for name in ["small-001.png", "small-001.ppm"] {
        let saved = image::open(dir.join(name)).unwrap().to_rgb8();
        assert_eq!(
            differing(&saved, &shot),
            0,
            "{name} differs from the screen"
        );
    }
    x.key(&window, "s");
    viewer.wait_stdout("saved small-002.png and small-002.ppm");
    let second = image::open(dir.join("small-002.ppm")).unwrap().to_rgb8();
    assert_eq!(differing(&second, &shot), 0);

    // A click prints the pixel, counted from the bottom, and its ray tree.
    x.xdotool(&["mousemove", "--sync", "10", "170", "click", "1"]);
    viewer.wait_stdout("pixel i=10 j=9 (j from the bottom) of 320x180");
    // Spheres counted from 1, as in scene errors: the ground is sphere 1.
    viewer.wait_stdout("primary  depth 0 sphere 1 ");

    // A drag orbits (the picture changes); R brings back the scene's camera.
    x.xdotool(&["mousemove", "--sync", "160", "90", "mousedown", "1"]);
    for step in 1..=4 {
        let to = (160 + 15 * step).to_string();
        x.xdotool(&["mousemove", "--sync", &to, "100"]);
    }
    x.xdotool(&["mouseup", "1"]);
    wait_for("the orbited view", || {
        viewer.assert_running();
        let done = x.title(&window).ends_with("- done");
        let orbited = x.screenshot(&window, dir, "orbited.png");
        (done && differing(&orbited, &expected) > 1000).then_some(())
    });
    x.key(&window, "r");
    let diff = screenshot_matching(&x, &window, dir, &expected);
    assert_eq!(diff, 0, "{blit}: after R, {diff} pixels differ");

    // The arrows and PageUp move the camera; R again brings it back; H lists keys.
    for key in ["Up", "Left", "Prior"] {
        x.key(&window, key);
    }
    wait_for("the moved view", || {
        viewer.assert_running();
        let done = x.title(&window).ends_with("- done");
        let moved = x.screenshot(&window, dir, "moved.png");
        (done && differing(&moved, &expected) > 1000).then_some(())
    });
    x.key(&window, "r");
    let diff = screenshot_matching(&x, &window, dir, &expected);
    assert_eq!(diff, 0, "{blit}: after moving and R, {diff} pixels differ");
    x.key(&window, "h");
    viewer.wait_stdout("PageUp, PageDown");

    // Resizing re-renders at the new size, with the same vertical field of view as a
    // headless render at that size.
    x.xdotool(&["windowsize", &window, "240", "200"]);
    x.wait_title(&mut viewer, &window, |t| {
        t.contains(" 240x200 ") && t.ends_with("- done")
    });
    let resized = headless(
        dir,
        &scene,
        &["--width", "240", "--height", "200"],
        "resized.png",
    );
    let diff = screenshot_matching(&x, &window, dir, &resized);
    assert_eq!(diff, 0, "{blit}: after resizing, {diff} pixels differ");

    // Esc quits with status 0.
    x.key(&window, "Escape");
    let status = wait_for("the viewer to exit", || viewer.child.try_wait().unwrap());
    assert!(
        status.success(),
        "exit status {status}; stderr:\n{}",
        viewer.stderr()
    );
}

#[test]
fn session_with_pixels() {
    session("pixels");
}

#[test]
fn session_with_softbuffer() {
    session("softbuffer");
}

#[test]
fn samples_accumulate_to_the_render_at_the_target_spp() {
    if !x_tools_or_skip("progressive refinement test") {
        return;
    }
    let x = XServer::start();
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let scene = small_scene(dir, 6);
    let expected = headless(dir, &scene, &[], "render.png");
    let (mut viewer, window) = start_viewer(&x, dir, &scene, "softbuffer");
    let title = x.wait_title(&mut viewer, &window, |t| t.ends_with("- done"));
    assert!(title.contains(" 6/6 spp "), "title: {title}");
    let diff = screenshot_matching(&x, &window, dir, &expected);
    assert_eq!(diff, 0, "{diff} pixels differ from the 6-spp render");
    x.key(&window, "q");
    let status = wait_for("the viewer to exit", || viewer.child.try_wait().unwrap());
    assert!(status.success());
}

/// The frame number in a title `... - frame K/N - ...`, when the title ends in done.
fn done_frame(title: &str) -> Option<u32> {
    let rest = title.split(" - frame ").nth(1)?;
    let k = rest.split('/').next()?.parse().ok()?;
    title.ends_with("- done").then_some(k)
}

/// Writes `small.toml` into `dir`: hw3 at 320×180 turning a quarter round in 4 frames
/// at 2 frames a second (time enough for screenshots); returns its path.
fn quarter_turn_scene(dir: &Path) -> PathBuf {
    let mut scene = whitted::scene::hw3_scene(whitted::scene::HW3_DEFAULT_SEED);
    scene.image.width = Some(320);
    scene.image.height = Some(180);
    scene.camera = Some(whitted::CameraSpec::LookAt {
        look_from: glam::DVec3::new(0.0, 1.0, 1.0),
        look_at: glam::DVec3::new(0.0, 0.0, -2.0),
        up: glam::DVec3::Y,
        vfov: 50.0,
    });
    scene.animation = Some(whitted::scene::Animation {
        frames: 4,
        fps: 2.0,
        motion: whitted::scene::Motion::Orbit { degrees: 90.0 },
    });
    let path = dir.join("small.toml");
    fs::write(&path, whitted::scene::to_toml(&scene)).unwrap();
    path
}

/// A key held down as the window gains focus is not a press: winit reports it as a
/// synthetic one, which the viewer leaves alone. (The animation test's first `.` came
/// right after its `windowfocus`, and on a loaded machine the viewer read the focus
/// while the key was down: it stepped twice.) After `.` held through the focus, `,`
/// steps back from frame 0 to frame 3, where a `.` taken for a press would have led
/// to frame 1 and back to 0.
#[test]
fn a_key_held_as_the_window_gains_focus_is_no_press() {
    if !x_tools_or_skip("held key at focus test") {
        return;
    }
    let x = XServer::start();
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let path = quarter_turn_scene(dir);
    let (mut viewer, window) = start_viewer(&x, dir, &path, "softbuffer");
    x.wait_title(&mut viewer, &window, |t| done_frame(t) == Some(0));
    let root = x.xdotool(&["search", "--maxdepth", "0", "--name", ".*"]);
    x.xdotool(&["windowfocus", "--sync", &root]);
    x.xdotool(&["keydown", "period"]);
    x.xdotool(&["windowfocus", "--sync", &window]);
    x.xdotool(&["keyup", "period"]);
    x.key(&window, "comma");
    let title = x.wait_title(&mut viewer, &window, |t| {
        done_frame(t).is_some_and(|k| k != 0)
    });
    assert_eq!(done_frame(&title), Some(3), "title: {title}");
}

#[test]
fn an_animated_scene_plays_and_steps_through_its_frames() {
    if !x_tools_or_skip("animation playback test") {
        return;
    }
    let x = XServer::start();
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let path = quarter_turn_scene(dir);
    let out = Command::new(BIN)
        .args(["render", "small.toml", "-q", "-o", "f-%d.png"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let numbered: Vec<RgbImage> = (0..4)
        .map(|k| {
            image::open(dir.join(format!("f-{k}.png")))
                .unwrap()
                .to_rgb8()
        })
        .collect();

    let (mut viewer, window) = start_viewer(&x, dir, &path, "softbuffer");
    let shows = |x: &XServer, viewer: &mut Viewer, k: u32| {
        let title = x.wait_title(viewer, &window, |t| done_frame(t) == Some(k));
        assert!(title.contains(" - 320x180 - frame "), "title: {title}");
        let diff = screenshot_matching(x, &window, dir, &numbered[k as usize]);
        assert_eq!(diff, 0, "frame {k}: {diff} pixels differ from f-{k}.png");
    };
    shows(&x, &mut viewer, 0);
    // `.` steps forward, `,` back (wrapping round).
    x.key(&window, "period");
    shows(&x, &mut viewer, 1);
    x.key(&window, "period");
    shows(&x, &mut viewer, 2);
    x.key(&window, "comma");
    shows(&x, &mut viewer, 1);
    x.key(&window, "comma");
    x.key(&window, "comma");
    shows(&x, &mut viewer, 3);

    // P plays: the frames advance by themselves, each one the numbered file, until P
    // again pauses.
    x.key(&window, "p");
    let mut seen = Vec::new();
    wait_for("three frames played", || {
        viewer.assert_running();
        let before = done_frame(&x.title(&window));
        let shot = x.screenshot(&window, dir, "playing.png");
        let after = done_frame(&x.title(&window));
        if let (Some(k), true) = (before, before == after) {
            if seen.last() != Some(&k) {
                assert_eq!(
                    differing(&shot, &numbered[k as usize]),
                    0,
                    "frame {k} on screen differs from f-{k}.png"
                );
                seen.push(k);
            }
        }
        (seen.len() >= 3).then_some(())
    });
    assert!(
        seen.windows(2).all(|w| w[1] == (w[0] + 1) % 4),
        "order: {seen:?}"
    );
    x.key(&window, "p");
    std::thread::sleep(Duration::from_millis(700));
    let paused = x.title(&window);
    std::thread::sleep(Duration::from_millis(1500));
    assert_eq!(x.title(&window), paused, "paused, the frame stays");

    x.key(&window, "h");
    viewer.wait_stdout("play or pause");
    x.key(&window, "Escape");
    let status = wait_for("the viewer to exit", || viewer.child.try_wait().unwrap());
    assert!(status.success(), "stderr:\n{}", viewer.stderr());
}

/// Opens the 320×180 one-sample scene in the viewer with `env`, waits for the
/// finished image, checks that the window shows `whitted render`'s pixels, and quits;
/// the viewer's stderr. `None` (said loudly) without the X tools.
fn shows_the_render_with(test: &str, env: &[(&str, &str)]) -> Option<String> {
    if !x_tools_or_skip(test) {
        return None;
    }
    let x = XServer::start();
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let scene = small_scene(dir, 1);
    let expected = headless(dir, &scene, &[], "render.png");
    let (mut viewer, window) = start_viewer_with(&x, dir, &scene, env);
    x.wait_title(&mut viewer, &window, |t| t.ends_with("- done"));
    let stderr = viewer.stderr();
    let diff = screenshot_matching(&x, &window, dir, &expected);
    assert_eq!(diff, 0, "{diff} pixels differ from `whitted render`");
    x.key(&window, "q");
    let status = wait_for("the viewer to exit", || viewer.child.try_wait().unwrap());
    assert!(status.success());
    Some(stderr)
}

#[test]
fn without_a_gpu_adapter_it_falls_back_to_softbuffer() {
    // Vulkan only, and no Vulkan driver: wgpu finds no adapter.
    let no_gpu = [
        ("WHITTED_BLIT", ""),
        ("WGPU_BACKEND", "vulkan"),
        ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
        ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
    ];
    let Some(stderr) = shows_the_render_with("softbuffer fallback test", &no_gpu) else {
        return;
    };
    assert!(
        stderr.contains("drawing with softbuffer instead")
            && stderr.contains("stats: blitter softbuffer\n"),
        "{stderr}"
    );
}

/// Left to choose, the viewer draws with `pixels` on a GPU only: where wgpu's only
/// adapter is a CPU rasterizer (lavapipe, as on CI), with `softbuffer`, and says why.
#[test]
fn the_automatic_blitter_uses_pixels_on_a_gpu_only() {
    let automatic = [("WHITTED_BLIT", "")];
    let Some(stderr) = shows_the_render_with("automatic blitter test", &automatic) else {
        return;
    };
    if stderr.contains("stats: blitter pixels\n") {
        let adapter = stderr
            .lines()
            .find_map(|l| l.strip_prefix("stats: adapter "))
            .unwrap_or_else(|| panic!("no adapter named: {stderr}"));
        assert!(!adapter.ends_with("(Cpu)"), "pixels on a CPU: {stderr}");
    } else {
        assert!(
            stderr.contains("stats: blitter softbuffer\n")
                && stderr.contains("drawing with softbuffer instead"),
            "{stderr}"
        );
        // With lavapipe installed (as on CI), wgpu finds that CPU adapter: the viewer
        // must have turned it down, not failed to find one.
        if Path::new("/usr/share/vulkan/icd.d/lvp_icd.x86_64.json").exists() {
            assert!(
                stderr.contains("is a CPU; drawing with softbuffer"),
                "{stderr}"
            );
        }
        let reason = stderr.lines().find(|l| l.contains("instead")).unwrap();
        println!("automatic blitter: {reason}");
    }
}

/// With `encoding = "srgb"` the window shows the sRGB file's bytes, and `S` saves them.
#[test]
fn with_srgb_the_window_shows_the_bytes_of_the_srgb_file() {
    if !x_tools_or_skip("sRGB viewer test") {
        return;
    }
    let x = XServer::start();
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let mut scene = whitted::scene::hw3_scene(whitted::scene::HW3_DEFAULT_SEED);
    (scene.image.width, scene.image.height) = (Some(320), Some(180));
    scene.image.encoding = Some(whitted::settings::Encoding::Srgb);
    let path = dir.join("small.toml");
    fs::write(&path, whitted::scene::to_toml(&scene)).unwrap();
    let expected = headless(dir, &path, &[], "srgb.png");
    let linear = headless(dir, &path, &["--encoding", "linear"], "linear.png");
    assert!(
        differing(&expected, &linear) > 1000,
        "sRGB changes the bytes"
    );

    let (mut viewer, window) = start_viewer(&x, dir, &path, "softbuffer");
    x.wait_title(&mut viewer, &window, |t| t.ends_with("- done"));
    let diff = screenshot_matching(&x, &window, dir, &expected);
    assert_eq!(diff, 0, "{diff} pixels differ from the sRGB file");
    x.key(&window, "s");
    viewer.wait_stdout("saved small-001.png and small-001.ppm");
    for name in ["small-001.png", "small-001.ppm"] {
        let saved = image::open(dir.join(name)).unwrap().to_rgb8();
        assert_eq!(differing(&saved, &expected), 0, "{name}");
    }
    x.key(&window, "q");
    let status = wait_for("the viewer to exit", || viewer.child.try_wait().unwrap());
    assert!(status.success());
}

#[test]
fn without_a_display_it_says_so_and_exits_1() {
    let out = Command::new(BIN)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    assert!(
        stderr.contains("no display") && stderr.contains("whitted render"),
        "{stderr}"
    );
    // An unreachable display is the same kind of error.
    let out = Command::new(BIN)
        .args(["view"])
        .env("DISPLAY", ":9999")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    assert!(
        stderr.contains("cannot open the display") && stderr.contains("whitted render"),
        "{stderr}"
    );
    assert!(!stderr.contains(".rs:"), "no source locations: {stderr}");
}

/// Without the X tools the tests are skipped where the harness shows it, and under
/// `CI=true` they fail. Runs this test binary again on one test, with no X tool on
/// PATH.
#[test]
fn a_missing_x_tool_is_a_visible_skip_or_a_ci_failure() {
    let empty = tempfile::tempdir().unwrap();
    let run = |ci: &str| {
        Command::new(std::env::current_exe().unwrap())
            .args(["--exact", "session_with_softbuffer", "--test-threads", "1"])
            .env("PATH", empty.path())
            .env("CI", ci)
            .output()
            .unwrap()
    };
    let skipped = run("");
    let stderr = String::from_utf8_lossy(&skipped.stderr);
    assert!(skipped.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "SKIPPED viewer session with WHITTED_BLIT=softbuffer: Xvfb, xdotool, import not \
             installed"
        ),
        "no visible skip: {stderr}"
    );
    let failed = run("true");
    let stdout = String::from_utf8_lossy(&failed.stdout);
    assert!(!failed.status.success(), "{stdout}");
    assert!(
        stdout.contains("CI=true, so the viewer must be tested"),
        "{stdout}"
    );
}

/// A server stopped by its guard removes its lock file and socket, also when the test
/// that started it fails.
#[test]
fn x_servers_leave_no_lock_file_or_socket() {
    if !x_tools_or_skip("X server clean-up test") {
        return;
    }
    let x = XServer::start();
    let files = x.files();
    assert!(files.iter().all(|f| f.exists()), "{files:?}");
    drop(x);
    for f in &files {
        assert!(!f.exists(), "{} is left behind", f.display());
    }
    let files = std::panic::catch_unwind(|| {
        let x = XServer::start();
        let files = x.files();
        std::panic::panic_any(files);
    })
    .unwrap_err()
    .downcast::<[PathBuf; 2]>()
    .unwrap();
    for f in files.iter() {
        assert!(!f.exists(), "after a panic, {} is left behind", f.display());
    }
}

/// Without `XDG_RUNTIME_DIR`, the window opens with `pixels` (Vulkan) and stderr holds
/// only whitted's own lines: no "XDG_RUNTIME_DIR is invalid" from libwayland.
#[test]
fn without_xdg_runtime_dir_the_window_says_nothing_of_it() {
    let env = [("WHITTED_BLIT", "pixels"), ("XDG_RUNTIME_DIR", "")];
    let Some(stderr) = shows_the_render_with("XDG_RUNTIME_DIR test", &env) else {
        return;
    };
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
    for line in stderr.lines() {
        assert!(
            line.starts_with("whitted: ") || line.starts_with("stats: "),
            "a line not in whitted's voice: {line}"
        );
    }
}

/// SIGTERM or SIGHUP while `S` writes a large image: the viewer exits with status 1
/// and one line, leaves no temporary file, and every image in its folder decodes whole
/// (the save finished before the signal is kept; the one it interrupts is either
/// whole or absent).
#[test]
fn a_signal_during_a_save_leaves_only_whole_files() {
    for signal in ["TERM", "HUP"] {
        signal_during_a_save(signal);
    }
}

fn signal_during_a_save(signal: &str) {
    let test = format!("SIG{signal} during a save");
    if !x_tools_or_skip(&test) {
        return;
    }
    let x = XServer::start_with_screen(2560, 1440);
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let scene = small_scene(dir, 1);
    let (mut viewer, window) = start_viewer(&x, dir, &scene, "softbuffer");
    x.wait_title(&mut viewer, &window, |t| t.ends_with("- done"));
    x.key(&window, "s");
    viewer.wait_stdout("saved small-001.png and small-001.ppm");

    // At 2560×1440 the plain PPM alone is 30 MB: writing takes a while.
    x.xdotool(&["windowsize", &window, "2560", "1440"]);
    x.wait_title(&mut viewer, &window, |t| {
        t.contains(" 2560x1440 ") && t.ends_with("- done")
    });
    x.key(&window, "s");
    // The signal as soon as a temporary file shows (or once the save is over).
    let start = Instant::now();
    let mut seen = Vec::new();
    while start.elapsed() < Duration::from_secs(20) && !viewer.stdout().contains("small-002") {
        seen = common::entries(dir);
        if seen.iter().any(|n| n.ends_with(".part")) {
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    let sent = Command::new("kill")
        .args([&format!("-{signal}"), &viewer.child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success(), "kill -{signal}");
    let status = wait_for("the viewer to exit", || viewer.child.try_wait().unwrap());
    let stderr = viewer.stderr();
    println!("SIG{signal}: {status}; folder before: {seen:?}; stderr: {stderr:?}");
    assert_eq!(
        status.code(),
        Some(1),
        "SIG{signal}: {status}; stderr:\n{stderr}"
    );
    assert!(
        stderr.lines().any(|l| l == "whitted: error: interrupted"),
        "SIG{signal}: {stderr}"
    );

    let left = common::entries(dir);
    assert!(
        !left
            .iter()
            .any(|n| n.ends_with(".part") || n.starts_with(".whitted-")),
        "SIG{signal}: temporary files left: {left:?}"
    );
    let first = image::open(dir.join("small-001.png")).unwrap().to_rgb8();
    assert_eq!(first.dimensions(), (320, 180));
    for name in left.iter().filter(|n| n.starts_with("small-00")) {
        let decoded = image::open(dir.join(name))
            .unwrap_or_else(|e| panic!("SIG{signal}: {name}: {e}"))
            .to_rgb8();
        let expected = if name.starts_with("small-001") {
            (320, 180)
        } else {
            (2560, 1440)
        };
        assert_eq!(decoded.dimensions(), expected, "SIG{signal}: {name}");
    }
}
