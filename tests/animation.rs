//! Animation (SPEC §4 "Encoding and animation", §5 "Animation"): the `[animation]`
//! table's defaults and errors, keyframe cameras against hand-computed ones, the
//! turntable against still scenes turned by hand, and the files of `whitted render`:
//! numbered frames, GIF and APNG decoded frame by frame, slices of a sequence equal
//! to the same frames of the whole run.

use glam::DVec3;
use whitted::camera::CameraSpec;
use whitted::image_io;
use whitted::render::{self, RenderControl, Sequence};
use whitted::scene::{hw3_scene, to_toml, Animation, CameraKey, Motion, HW3_DEFAULT_SEED};
use whitted::settings::Encoding;
use whitted::{Overrides, Scene};

fn parse(text: &str) -> Scene {
    Scene::from_toml_str(text, "anim.toml").unwrap_or_else(|e| panic!("{e}"))
}

/// The error of `text` as `anim.toml:LINE:COLUMN: message`.
fn error(text: &str) -> String {
    Scene::from_toml_str(text, "anim.toml")
        .expect_err("an error")
        .to_string()
}

const BALL: &str = "[[sphere]]\ncenter = [0, 0, -2]\nradius = 0.5\n";

// ---- Scene files -----------------------------------------------------------------

#[test]
fn each_animation_key_has_its_default() {
    assert_eq!(parse(BALL).animation, None, "no table: a still scene");
    assert_eq!(parse(BALL).frames(), 1);
    let empty = parse(&format!("[animation]\n{BALL}"));
    assert_eq!(empty.animation, Some(Animation::default()));
    assert_eq!(
        Animation::default(),
        Animation {
            frames: 1,
            fps: 24.0,
            motion: Motion::Still
        }
    );
    let counted = parse(&format!("[animation]\nframes = 48\n{BALL}"));
    assert_eq!(counted.frames(), 48);
    let a = counted.animation.unwrap();
    assert_eq!((a.fps, a.motion), (24.0, Motion::Still));
    // Integers where numbers are expected.
    let spun = parse(&format!("[animation]\nfps = 30\norbit = 360\n{BALL}"));
    let a = spun.animation.unwrap();
    assert_eq!(
        (a.frames, a.fps, a.motion),
        (1, 30.0, Motion::Orbit { degrees: 360.0 })
    );
}

#[test]
fn bad_animation_tables_name_the_line_and_column() {
    for (text, expected) in [
        (
            "[animation]\nframes = 4\nspeed = 2\n",
            "anim.toml:3:1: unknown field `speed`",
        ),
        (
            "[animation]\nframes = 0\n",
            "anim.toml:2:10: animation.frames = 0 is out of range: expected 1 to 1048576",
        ),
        (
            "[animation]\nframes = 2.5\n",
            "anim.toml:2:10: animation.frames: expected a whole number, got 2.5",
        ),
        (
            "[animation]\nfps = 0\n",
            "anim.toml:2:7: animation.fps = 0 is out of range: expected more than 0, at most 1000",
        ),
        (
            "[animation]\norbit = \"half\"\n",
            "anim.toml:2:9: animation.orbit: expected a number, got the string \"half\"",
        ),
        (
            "[animation]\norbit = nan\n",
            "anim.toml:2:9: animation.orbit must be a finite number, got NaN",
        ),
        (
            "[animation]\nframes = 9\n\n[[animation.key]]\nframe = 4\nvfov = 30\n\n\
             [[animation.key]]\nframe = 2\nvfov = 60\n",
            "anim.toml:9:9: animation key 2: frame = 2 is not after the previous key's frame 4: \
             keys go in increasing frame order",
        ),
        (
            "[animation]\n[[animation.key]]\nframe = 3\n[[animation.key]]\nframe = 3\n",
            "anim.toml:5:9: animation key 2: frame = 3 is not after the previous key's frame 3: \
             keys go in increasing frame order",
        ),
        (
            "[animation]\norbit = 90\n\n[[animation.key]]\nframe = 0\nvfov = 30\n",
            "anim.toml:2:9: animation: give either orbit or [[animation.key]] tables, not both",
        ),
        (
            "[[animation.key]]\nframe = 1\nzoom = 2\n",
            "anim.toml:3:1: unknown field `zoom`",
        ),
        (
            "[[animation.key]]\nframe = -1\n",
            "anim.toml:2:9: animation key 1: frame = -1 is out of range: expected 0 to 1048575",
        ),
        (
            "[[animation.key]]\nframe = 0\nlook_from = [0, 0, inf]\n",
            "anim.toml:3:13: animation key 1: look_from must be finite numbers, got [0.0, 0.0, inf]",
        ),
    ] {
        let text = format!("{text}{BALL}");
        let message = error(&text);
        // serde lists the known keys after an unknown one.
        assert!(message.starts_with(expected), "{text}\n{message}");
    }
    // Two good keys whose eye passes through the look-at point half way.
    let text = format!(
        "[camera]\nlook_at = [0, 0, -1]\n\n[animation]\nframes = 3\n\n\
         [[animation.key]]\nframe = 0\nlook_from = [0, 0, 0]\n\n\
         [[animation.key]]\nframe = 2\nlook_from = [0, 0, -2]\n{BALL}"
    );
    assert_eq!(
        error(&text),
        "anim.toml:4:1: animation: frame 1: camera: look_from and look_at must be different points"
    );
}

#[test]
fn animations_survive_the_round_trip_through_toml() {
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    scene.animation = Some(Animation {
        frames: 36,
        fps: 12.5,
        motion: Motion::Orbit { degrees: -90.0 },
    });
    let back = |scene: &Scene| Scene {
        name: scene.name.clone(),
        ..Scene::from_toml_str(&to_toml(scene), "x").unwrap()
    };
    assert_eq!(back(&scene), scene);
    scene.animation = Some(Animation {
        frames: 10,
        fps: 24.0,
        motion: Motion::Keys(vec![
            CameraKey {
                frame: 0,
                look_from: Some(DVec3::new(0.0, 1.0, 1.0)),
                ..CameraKey::default()
            },
            CameraKey {
                frame: 9,
                vfov: Some(40.0),
                up: Some(DVec3::new(0.1, 1.0, 0.0)),
                look_at: Some(DVec3::new(0.0, 0.0, -2.0)),
                ..CameraKey::default()
            },
        ]),
    });
    assert_eq!(back(&scene), scene);
}

/// A look-at camera from its four values.
fn look(from: [f64; 3], at: [f64; 3], up: [f64; 3], vfov: f64) -> CameraSpec {
    CameraSpec::LookAt {
        look_from: DVec3::from_array(from),
        look_at: DVec3::from_array(at),
        up: DVec3::from_array(up),
        vfov,
    }
}

#[test]
fn keyframes_interpolate_each_value_between_the_keys_that_give_it() {
    // The eye and the field of view are keyed at frames 2 and 6, the look-at point
    // at frame 4 only; `up` comes from the scene's camera.
    let scene = parse(&format!(
        "[camera]\nlook_from = [9, 9, 9]\nlook_at = [0, 0, -4]\nup = [0, 1, 0]\nvfov = 90\n\n\
         [animation]\nframes = 10\n\n\
         [[animation.key]]\nframe = 2\nlook_from = [0, 0, 0]\nvfov = 40\n\n\
         [[animation.key]]\nframe = 4\nlook_at = [0, 0, -8]\n\n\
         [[animation.key]]\nframe = 6\nlook_from = [4, 2, 0]\nvfov = 60\n{BALL}"
    ));
    let at = |k| scene.frame_camera_spec(k, 64, 36);
    let up = [0.0, 1.0, 0.0];
    // Before the first key: held at the first.
    assert_eq!(at(0), look([0.0, 0.0, 0.0], [0.0, 0.0, -8.0], up, 40.0));
    assert_eq!(at(2), look([0.0, 0.0, 0.0], [0.0, 0.0, -8.0], up, 40.0));
    // A quarter of the way from frame 2 to frame 6: (0,0,0) + ¼·(4,2,0), 40 + ¼·20.
    assert_eq!(at(3), look([1.0, 0.5, 0.0], [0.0, 0.0, -8.0], up, 45.0));
    assert_eq!(at(5), look([3.0, 1.5, 0.0], [0.0, 0.0, -8.0], up, 55.0));
    // After the last key: held at the last.
    for k in [6, 7, 9, 1000] {
        assert_eq!(at(k), look([4.0, 2.0, 0.0], [0.0, 0.0, -8.0], up, 60.0));
    }
    // The still scene of frame 3 is that camera, with no animation.
    let still = scene.frame(3, 64, 36);
    assert_eq!(still.camera, Some(at(3)));
    assert_eq!(still.animation, None);
}

/// `scene` rendered at 96×54 through the ordinary path, as 8-bit bytes.
fn still_bytes(scene: &Scene) -> Vec<u8> {
    let settings = scene.settings().with(&Overrides {
        width: Some(96),
        height: Some(54),
        ..Overrides::default()
    });
    let (frame, _) = render::render(scene, &settings, &RenderControl::default()).unwrap();
    image_io::to_rgb8(&frame, Encoding::Linear).into_raw()
}

/// hw3 seen from above and in front of its balls, turning about (0, 0, -2).
fn turntable(frames: u32, degrees: f64) -> Scene {
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    scene.camera = Some(look(
        [0.0, 1.0, 1.0],
        [0.0, 0.0, -2.0],
        [0.0, 1.0, 0.0],
        50.0,
    ));
    scene.animation = Some(Animation {
        frames,
        fps: 24.0,
        motion: Motion::Orbit { degrees },
    });
    scene
}

#[test]
fn turntable_frames_are_the_still_scene_turned_by_hand() {
    let scene = turntable(8, 360.0);
    let mut still = scene.clone();
    still.animation = None;
    // Frame 0 is the still image, bit for bit.
    assert_eq!(scene.frame_camera_spec(0, 96, 54), still.camera.unwrap());
    assert_eq!(still_bytes(&scene.frame(0, 96, 54)), still_bytes(&still));

    // Frame k: the eye turned by 360·k/8 degrees about the vertical through the
    // look-at point: from (0, 1, 3) relative to it, (3 sin θ, 1, 3 cos θ).
    for k in [1u32, 2, 3, 6] {
        let theta = (45.0 * f64::from(k)).to_radians();
        let turned = look(
            [3.0 * theta.sin(), 1.0, -2.0 + 3.0 * theta.cos()],
            [0.0, 0.0, -2.0],
            [0.0, 1.0, 0.0],
            50.0,
        );
        let CameraSpec::LookAt { look_from, .. } = scene.frame_camera_spec(k, 96, 54) else {
            panic!("a look-at camera turns into a look-at camera");
        };
        let CameraSpec::LookAt {
            look_from: by_hand, ..
        } = turned
        else {
            unreachable!()
        };
        assert!(
            (look_from - by_hand).length() < 1e-14,
            "frame {k}: {look_from}"
        );
        let mut by_hand_scene = still.clone();
        by_hand_scene.camera = Some(turned);
        let (frame, hand) = (
            still_bytes(&scene.frame(k, 96, 54)),
            still_bytes(&by_hand_scene),
        );
        // The two eyes differ by a rounding of the rotation (below 1e-14): the same
        // pixels, or a level or so at a few silhouette pixels.
        let off: Vec<u8> = frame
            .iter()
            .zip(&hand)
            .map(|(a, b)| a.abs_diff(*b))
            .filter(|&d| d > 0)
            .collect();
        assert!(
            off.len() <= 6 && off.iter().all(|&d| d <= 2),
            "frame {k}: {} values differ, by up to {:?}",
            off.len(),
            off.iter().max()
        );
    }
}

#[test]
fn a_film_camera_turns_rigidly_about_its_film_centre() {
    // No [camera]: at 16:9 the assignment's film; it turns about its centre (0,0,-1).
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    scene.animation = Some(Animation {
        frames: 4,
        fps: 24.0,
        motion: Motion::Orbit { degrees: 360.0 },
    });
    assert_eq!(
        scene.frame_camera_spec(0, 64, 36),
        CameraSpec::assignment_frame()
    );
    let CameraSpec::Frame {
        origin,
        lower_left,
        horizontal,
        vertical,
    } = scene.frame_camera_spec(1, 64, 36)
    else {
        panic!("a film turns into a film");
    };
    // A quarter turn about +y through (0,0,-1): the eye (0,0,0) goes to (1,0,-1), the
    // corner (-4,-2.25,-1) to (0,-2.25,3), H = (8,0,0) to (0,0,-8); V stays.
    let near = |a: DVec3, b: [f64; 3]| (a - DVec3::from_array(b)).length() < 1e-12;
    assert!(near(origin, [1.0, 0.0, -1.0]), "{origin}");
    assert!(near(lower_left, [0.0, -2.25, 3.0]), "{lower_left}");
    assert!(near(horizontal, [0.0, 0.0, -8.0]), "{horizontal}");
    assert!(near(vertical, [0.0, 4.5, 0.0]), "{vertical}");
}

#[test]
fn a_sequence_renders_each_frame_as_its_still_scene_does() {
    let scene = turntable(5, 200.0);
    let settings = scene.settings().with(&Overrides {
        width: Some(96),
        height: Some(54),
        ..Overrides::default()
    });
    let mut sequence = Sequence::new(&scene);
    for k in 0..5 {
        let camera = scene.frame_camera_spec(k, 96, 54);
        let (frame, _) = sequence
            .render(&camera, &settings, &RenderControl::default())
            .unwrap();
        let alone = still_bytes(&scene.frame(k, 96, 54));
        assert!(
            image_io::to_rgb8(&frame, Encoding::Linear).into_raw() == alone,
            "frame {k}"
        );
    }
}

// ---- Files -----------------------------------------------------------------------

/// What goes through the `whitted` binary, which needs the `cli` and `viewer` features.
#[cfg(all(feature = "cli", feature = "viewer"))]
mod command_line {
    use std::io::BufReader;
    use std::path::Path;
    use std::process::{Command, Output};

    use image::{AnimationDecoder, RgbImage};

    use super::*;

    const BIN: &str = env!("CARGO_BIN_EXE_whitted");

    fn run(args: &[&str], dir: &Path) -> Output {
        let out = Command::new(BIN)
            .args(args)
            .current_dir(dir)
            .output()
            .expect("run whitted");
        assert!(
            out.status.success(),
            "whitted {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    }

    /// A 6-frame turntable of hw3 at 96×54 and 10 fps, written as `spin.toml` in `dir`.
    fn spin_file(dir: &Path) -> String {
        let mut scene = turntable(6, 300.0);
        scene.animation.as_mut().unwrap().fps = 10.0;
        scene.image.width = Some(96);
        scene.image.height = Some(54);
        let path = dir.join("spin.toml");
        std::fs::write(&path, to_toml(&scene)).unwrap();
        path.to_str().unwrap().to_string()
    }

    fn png(path: &Path) -> RgbImage {
        image::open(path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .to_rgb8()
    }

    fn rgb(frame: image::Frame) -> RgbImage {
        image::DynamicImage::ImageRgba8(frame.into_buffer()).to_rgb8()
    }

    #[test]
    fn gif_and_apng_hold_the_numbered_frames() {
        let dir = tempfile::tempdir().unwrap();
        let dir = dir.path();
        let scene = spin_file(dir);
        run(
            &[
                "render",
                &scene,
                "-q",
                "-o",
                "f-%03d.png",
                "-o",
                "spin.gif",
                "-o",
                "spin.apng",
            ],
            dir,
        );
        let numbered: Vec<RgbImage> = (0..6)
            .map(|k| png(&dir.join(format!("f-{k:03}.png"))))
            .collect();
        assert!(
            numbered.windows(2).all(|w| w[0] != w[1]),
            "the frames differ"
        );

        // APNG: lossless, 6 frames of 1/10 s.
        let file = BufReader::new(std::fs::File::open(dir.join("spin.apng")).unwrap());
        let decoder = image::codecs::png::PngDecoder::new(file).unwrap();
        assert!(decoder.is_apng().unwrap());
        let frames = decoder
            .apng()
            .unwrap()
            .into_frames()
            .collect_frames()
            .unwrap();
        assert_eq!(frames.len(), 6);
        for (k, frame) in frames.into_iter().enumerate() {
            assert_eq!(frame.delay().numer_denom_ms(), (100, 1), "frame {k}");
            assert!(
                rgb(frame) == numbered[k],
                "APNG frame {k} differs from f-{k:03}.png"
            );
        }

        // GIF: 6 frames of 10/100 s, each within its palette's error of the PNG.
        let file = BufReader::new(std::fs::File::open(dir.join("spin.gif")).unwrap());
        let frames = image::codecs::gif::GifDecoder::new(file)
            .unwrap()
            .into_frames()
            .collect_frames()
            .unwrap();
        assert_eq!(frames.len(), 6);
        let mut errors: Vec<u8> = Vec::new();
        for (k, frame) in frames.into_iter().enumerate() {
            assert_eq!(frame.delay().numer_denom_ms(), (100, 1), "frame {k}");
            let decoded = rgb(frame);
            assert_eq!(decoded.dimensions(), (96, 54));
            let pixels = decoded.pixels().zip(numbered[k].pixels());
            errors.extend(pixels.map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap()));
        }
        errors.sort_unstable();
        let mean = errors.iter().map(|&d| f64::from(d)).sum::<f64>() / errors.len() as f64;
        let p99 = errors[errors.len() * 99 / 100];
        let worst = errors[errors.len() - 1];
        println!("GIF palette error per pixel: mean {mean:.2}, 99th percentile {p99}, max {worst}");
        // NeuQuant's 256 colours a frame (sampling factor 10) on these frames: measured
        // mean 2.45 levels, 99th percentile 36, max 91 (the few pixels of a rare colour:
        // small balls). Factor 1 gives 1.51, 22, 83 at about ten times the time.
        assert!(
            mean <= 4.0 && p99 <= 48 && worst <= 128,
            "mean {mean}, p99 {p99}, max {worst}"
        );
    }

    #[test]
    fn a_slice_of_frames_equals_the_same_frames_of_the_whole_run() {
        let dir = tempfile::tempdir().unwrap();
        let dir = dir.path();
        let scene = spin_file(dir);
        run(&["render", &scene, "-q", "-o", "all-%02d.ppm"], dir);
        run(
            &[
                "render",
                &scene,
                "-q",
                "--frame",
                "2..5",
                "-o",
                "part-%02d.ppm",
            ],
            dir,
        );
        run(
            &["render", &scene, "-q", "--frame", "4", "-o", "one.ppm"],
            dir,
        );
        let read = |name: String| std::fs::read(dir.join(name)).unwrap();
        for k in 2..5 {
            assert!(
                read(format!("part-{k:02}.ppm")) == read(format!("all-{k:02}.ppm")),
                "frame {k}"
            );
        }
        for k in [0, 1, 5] {
            assert!(
                !dir.join(format!("part-{k:02}.ppm")).exists(),
                "frame {k} is outside 2..5"
            );
        }
        assert!(read("one.ppm".into()) == read("all-04.ppm".into()));
        // Frame 0 of the turntable is the still scene's image.
        let still = parse(&std::fs::read_to_string(dir.join("spin.toml")).unwrap());
        let mut still = still;
        still.animation = None;
        std::fs::write(dir.join("still.toml"), to_toml(&still)).unwrap();
        run(&["render", "still.toml", "-q", "-o", "still.ppm"], dir);
        assert!(read("still.ppm".into()) == read("all-00.ppm".into()));
    }

    #[test]
    fn animation_options_override_the_scene_and_bad_ones_say_why() {
        let dir = tempfile::tempdir().unwrap();
        let dir = dir.path();
        // --frames and --orbit on the still built-in scene: 3 numbered files.
        run(
            &[
                "render", "-q", "--width", "32", "--height", "18", "--frames", "3", "--orbit",
                "30", "-o", "o-%d.png",
            ],
            dir,
        );
        for k in 0..3 {
            assert!(dir.join(format!("o-{k}.png")).exists());
        }
        let fails = |args: &[&str], code: i32, needle: &str| {
            let out = Command::new(BIN)
                .args(args)
                .current_dir(dir)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
            assert_eq!(err.lines().count(), 1, "{err}");
            assert!(err.contains(needle), "{args:?}: {err}");
        };
        let small = ["render", "--width", "8", "--height", "8"];
        let with = |extra: &[&'static str]| [&small[..], extra].concat();
        fails(
            &with(&["--frames", "4", "-o", "x.png"]),
            2,
            "one image cannot hold 4 frames",
        );
        fails(&with(&["--frames", "4"]), 2, "name the files with -o");
        fails(
            &with(&["--frames", "4", "--frame", "4", "-o", "x.png"]),
            2,
            "has 4 frames (0 to 3)",
        );
        fails(&with(&["--frame", "3..1", "-o", "x.png"]), 2, "A < B");
        fails(&with(&["--orbit", "inf", "-o", "x.gif"]), 2, "finite");
        fails(&with(&["-o", "x-%02d.gif"]), 2, "no %d pattern");
        assert!(!dir.join("x.png").exists() && !dir.join("x.gif").exists());
    }

    #[test]
    fn delays_follow_the_frame_rate() {
        assert_eq!(image_io::gif_delay_centiseconds(24.0), 4);
        assert_eq!(image_io::gif_delay_centiseconds(10.0), 10);
        assert_eq!(
            image_io::gif_delay_centiseconds(100.0),
            2,
            "browsers' minimum"
        );
        assert_eq!(image_io::apng_delay(24.0), (1, 24));
        assert_eq!(image_io::apng_delay(29.97), (334, 10_000));
    }

    #[test]
    fn the_committed_turntable_gif_is_the_turntable_scene() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let scene = Scene::load(&root.join("assets/scenes/turntable.toml")).unwrap();
        let animation = scene.animation.clone().unwrap();
        assert_eq!(animation.motion, Motion::Orbit { degrees: 360.0 });
        let file = BufReader::new(std::fs::File::open(root.join("assets/turntable.gif")).unwrap());
        let frames = image::codecs::gif::GifDecoder::new(file)
            .unwrap()
            .into_frames()
            .collect_frames()
            .unwrap();
        assert_eq!(frames.len() as u32, animation.frames);
        let settings = scene.settings();
        assert_eq!(
            frames[0].buffer().dimensions(),
            (settings.width, settings.height)
        );
        // Frame 0 of the file is the still scene's image, within the palette's error.
        let mut still = scene.clone();
        still.animation = None;
        let (frame, _) = render::render(&still, &settings, &RenderControl::default()).unwrap();
        let expected = image_io::to_rgb8(&frame, Encoding::Linear);
        let far_off = |decoded: &RgbImage, expected: &RgbImage| {
            decoded
                .pixels()
                .zip(expected.pixels())
                .filter(|(a, b)| (0..3).any(|c| a[c].abs_diff(b[c]) > 48))
                .count()
        };
        let mut frames: Vec<RgbImage> = frames.into_iter().map(rgb).collect();
        let off = far_off(&frames[0], &expected);
        assert!(off * 100 < expected.len() / 3, "{off} pixels far off");
        // A frame half way round is that frame of the scene (a stale file with another
        // orbit would still match at frame 0).
        let k = animation.frames / 2;
        let turned = scene.frame(k, settings.width, settings.height);
        let (frame, _) = render::render(&turned, &settings, &RenderControl::default()).unwrap();
        let expected = image_io::to_rgb8(&frame, Encoding::Linear);
        let off = far_off(&frames.swap_remove(k as usize), &expected);
        assert!(
            off * 100 < expected.len() / 3,
            "frame {k}: {off} pixels far off"
        );
    }
}
