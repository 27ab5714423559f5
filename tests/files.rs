//! Image files written by `whitted render`: every format decodes (with the `image`
//! crate) back to what the library rendered, PPM comes as plain P3 or binary P6, and
//! every file is upright (top row sky, bottom row ground). Saving never leaves a
//! partial or temporary file behind.
#![cfg(all(feature = "cli", feature = "viewer"))]

mod common;
use common::whitted;

use std::path::Path;
use std::process::Command;

use image::{Rgb32FImage, RgbImage};
use whitted::image_io::{self, Encoding, Format, UnknownFormat};
use whitted::render::{self, Frame, RenderControl};
use whitted::scene::{hw3_scene, HW3_DEFAULT_SEED};

const W: u32 = 96;
const H: u32 = 54;

/// The built-in scene at W×H, rendered by the library.
fn library_frame() -> Frame {
    let scene = hw3_scene(HW3_DEFAULT_SEED);
    let mut opts = scene.settings();
    opts.width = W;
    opts.height = H;
    render::render(&scene, &opts, &RenderControl::default())
        .expect("render")
        .0
}

/// Every pixel of the top row is sky (clearly bluer than red: the sky blends white into
/// (0.5, 0.7, 1)), every pixel of the bottom row is the white ground under a white
/// light (grey); `tol` allows for lossy formats.
#[track_caller]
fn assert_upright(img: &RgbImage, tol: u8, what: &str) {
    let (w, h) = img.dimensions();
    for x in 0..w {
        let [r, _, b] = img.get_pixel(x, 0).0;
        assert!(
            b >= 255 - tol && i32::from(b) - i32::from(r) > 60,
            "{what}: top row pixel {x} is not sky: {:?}",
            img.get_pixel(x, 0).0
        );
        let [r, g, b] = img.get_pixel(x, h - 1).0;
        let spread = r.max(g).max(b) - r.min(g).min(b);
        assert!(
            spread <= tol && r > 20,
            "{what}: bottom row pixel {x} is not lit grey ground: {:?}",
            img.get_pixel(x, h - 1).0
        );
    }
}

#[test]
fn every_format_decodes_to_the_rendered_image() {
    let frame = library_frame();
    let expected = image_io::to_rgb8(&frame, Encoding::Linear);
    let expected_f32: Rgb32FImage = image_io::to_rgb32f(&frame);
    assert_upright(&expected, 0, "the library's bytes");

    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let size = [
        "--width".to_owned(),
        W.to_string(),
        "--height".into(),
        H.to_string(),
    ];
    let mut args: Vec<String> = vec!["render".into(), "--quiet".into()];
    args.extend(size.iter().cloned());
    for name in ["plain.ppm", "a.png", "a.bmp", "a.jpg", "a.exr"] {
        args.extend(["-o".into(), p(name)]);
    }
    whitted(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let mut args: Vec<String> = vec!["render".into(), "--quiet".into(), "--ppm-binary".into()];
    args.extend(size.iter().cloned());
    args.extend(["-o".into(), p("binary.ppm")]);
    whitted(&args.iter().map(String::as_str).collect::<Vec<_>>());

    // PPM: the header says which kind; both decode to the same bytes.
    let plain = std::fs::read(p("plain.ppm")).unwrap();
    let binary = std::fs::read(p("binary.ppm")).unwrap();
    assert!(plain.starts_with(b"P3"), "plain PPM is P3");
    assert!(binary.starts_with(b"P6"), "--ppm-binary writes P6");
    // P6: a short header, then exactly the bytes, top row first.
    assert!(binary.ends_with(expected.as_raw()));
    assert_eq!(
        binary.len() - expected.as_raw().len(),
        format!("P6\n{W} {H}\n255\n").len()
    );

    for name in ["plain.ppm", "binary.ppm", "a.png", "a.bmp"] {
        let decoded = image::open(p(name))
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .into_rgb8();
        assert_eq!(decoded.dimensions(), (W, H), "{name}");
        assert!(
            decoded == expected,
            "{name} differs from the rendered bytes"
        );
        assert_upright(&decoded, 0, name);
    }

    // JPEG is lossy: close on average and everywhere within a sharp edge's ringing.
    let jpg = image::open(p("a.jpg")).unwrap().into_rgb8();
    assert_eq!(jpg.dimensions(), (W, H));
    let diffs: Vec<u8> = jpg
        .as_raw()
        .iter()
        .zip(expected.as_raw())
        .map(|(a, b)| a.abs_diff(*b))
        .collect();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    let max = *diffs.iter().max().unwrap();
    println!("jpg vs rendered bytes: mean |difference| {mean:.2} levels, max {max}");
    assert!(mean < 2.0, "jpg mean difference {mean}");
    assert!(max < 32, "jpg max difference {max}");
    assert_upright(&jpg, 12, "a.jpg");

    // EXR holds the linear values themselves, bit for bit.
    let exr = image::open(p("a.exr")).unwrap().into_rgb32f();
    assert_eq!(exr.dimensions(), (W, H));
    assert!(
        exr.as_raw()
            .iter()
            .zip(expected_f32.as_raw())
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "exr values differ from the rendered linear values"
    );
    // And they are the linear values of the frame, top row first.
    assert_eq!(exr.get_pixel(0, 0).0, frame.get(0, H - 1).to_array());
    assert_eq!(
        exr.get_pixel(W - 1, H - 1).0,
        frame.get(W - 1, 0).to_array()
    );

    // Written files are ordinary files: the mode any program's new file gets under
    // this umask (not the private 0600 of a temporary file).
    {
        use std::os::unix::fs::PermissionsExt;
        let reference = dir.path().join("plain-file");
        std::fs::write(&reference, b"").unwrap();
        let mode = |f: &str| std::fs::metadata(f).unwrap().permissions().mode() & 0o777;
        let expected_mode = mode(reference.to_str().unwrap());
        for name in [
            "plain.ppm",
            "binary.ppm",
            "a.png",
            "a.bmp",
            "a.jpg",
            "a.exr",
        ] {
            assert_eq!(
                mode(&p(name)),
                expected_mode,
                "{name}: mode {:o}",
                mode(&p(name))
            );
        }
        std::fs::remove_file(reference).unwrap();
    }

    // Nothing else was left in the folder (no temporary files).
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "a.bmp",
            "a.exr",
            "a.jpg",
            "a.png",
            "binary.ppm",
            "plain.ppm"
        ]
    );
}

#[test]
fn default_outputs_are_output_ppm_and_output_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(["render", "--quiet", "--width", "32", "--height", "18"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success());
    let ppm = image::open(dir.path().join("output.ppm"))
        .unwrap()
        .into_rgb8();
    let png = image::open(dir.path().join("output.png"))
        .unwrap()
        .into_rgb8();
    assert!(std::fs::read(dir.path().join("output.ppm"))
        .unwrap()
        .starts_with(b"P3"));
    assert_eq!(ppm.dimensions(), (32, 18));
    assert!(ppm == png);
    assert_upright(&png, 0, "output.png");
}

#[test]
fn a_failed_save_leaves_nothing_behind() {
    let frame = library_frame();
    let dir = tempfile::tempdir().unwrap();
    // The target is an existing folder: refused, and nothing is created beside it.
    let target = dir.path().join("taken.png");
    std::fs::create_dir(&target).unwrap();
    let err = image_io::save(&frame, &target, Format::Png, Encoding::Linear).unwrap_err();
    assert!(err.to_string().contains("taken.png"), "{err}");
    assert_eq!(common::entries(dir.path()), ["taken.png"]);
    assert!(common::entries(&target).is_empty());

    // A missing folder: an error naming the path, nothing created.
    let missing = dir.path().join("no/such/folder/a.png");
    let err = image_io::save(&frame, &missing, Format::Png, Encoding::Linear).unwrap_err();
    assert!(err.to_string().contains("no/such/folder"), "{err}");
    assert_eq!(common::entries(dir.path()), ["taken.png"]);

    // A successful save replaces an existing file whole.
    let file = dir.path().join("a.ppm");
    std::fs::write(&file, b"old contents").unwrap();
    image_io::save(
        &frame,
        &file,
        Format::Ppm { binary: true },
        Encoding::Linear,
    )
    .unwrap();
    assert!(image::open(&file).unwrap().into_rgb8() == image_io::to_rgb8(&frame, Encoding::Linear));
    let mut names = common::entries(dir.path());
    names.sort();
    assert_eq!(names, ["a.ppm", "taken.png"]);
}

#[test]
fn format_follows_the_extension() {
    let f = |name: &str| Format::from_path(Path::new(name), false);
    assert_eq!(f("a.ppm"), Ok(Format::Ppm { binary: false }));
    assert_eq!(
        Format::from_path(Path::new("a.ppm"), true),
        Ok(Format::Ppm { binary: true })
    );
    assert_eq!(f("dir.x/A.PNG"), Ok(Format::Png));
    assert_eq!(f("a.bmp"), Ok(Format::Bmp));
    assert_eq!(f("a.jpg"), Ok(Format::Jpeg));
    assert_eq!(f("a.jpeg"), Ok(Format::Jpeg));
    assert_eq!(f("a.exr"), Ok(Format::Exr));
    assert!(f("a.gif").unwrap_err().to_string().contains("a.gif"));
    assert_eq!(
        f("noextension"),
        Err(UnknownFormat(Path::new("noextension").to_path_buf()))
    );
}

#[test]
fn bytes_are_rounded_and_clamped_linear_values() {
    // round(clamp(c, 0, 1)·255), no gamma; NaN cannot reach a file.
    assert_eq!(image_io::to_byte(0.0), 0);
    assert_eq!(image_io::to_byte(1.0), 255);
    assert_eq!(image_io::to_byte(0.5), 128); // 127.5 rounds half away from zero
    assert_eq!(image_io::to_byte(0.25), 64); // 63.75
    assert_eq!(image_io::to_byte(100.0 / 255.0 - 0.001), 100);
    assert_eq!(image_io::to_byte(-3.0), 0);
    assert_eq!(image_io::to_byte(7.0), 255);
    assert_eq!(image_io::to_byte(f32::INFINITY), 255);
    assert_eq!(image_io::to_byte(f32::NAN), 0);
}

#[test]
fn bytes_round_every_value_as_round_does() {
    // Every f32 in [0, 1] (about a billion values: to_byte rounds with the 2²³ trick,
    // so every one is checked), every 4099th f32 of the whole range (negatives, above
    // 1, infinities, NaNs with any payload), and the halfway points k + 0.5 and their
    // neighbours: the same byte as `(c·255).round()` (half away from zero), 0 for NaN.
    let check = |c: f32| {
        let want = if c.is_nan() {
            0
        } else {
            (c.clamp(0.0, 1.0) * 255.0).round() as u8
        };
        assert_eq!(image_io::to_byte(c), want, "c = {c:e} ({:#x})", c.to_bits());
    };
    for bits in 0..=1.0f32.to_bits() {
        check(f32::from_bits(bits));
    }
    for bits in (0..=u32::MAX).step_by(4099) {
        check(f32::from_bits(bits));
    }
    for k in 0..255 {
        let half = (k as f32 + 0.5) / 255.0;
        for c in [half.next_down(), half, half.next_up()] {
            check(c);
        }
    }
}

#[test]
fn the_committed_readme_image_is_the_hw3_render() {
    // assets/hw3.png (shown in README.md) is `whitted render -o assets/hw3.png`. Speed
    // work may move a pixel by a level on an edge; anything more means it is stale.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/hw3.png");
    let committed = image::open(path).expect("assets/hw3.png").into_rgb8();
    let scene = hw3_scene(HW3_DEFAULT_SEED);
    let opts = scene.settings();
    let (frame, _) = render::render(&scene, &opts, &RenderControl::default()).unwrap();
    let fresh = image_io::to_rgb8(&frame, Encoding::Linear);
    assert_eq!(committed.dimensions(), (1280, 720));
    let off: Vec<u8> = committed
        .pixels()
        .zip(fresh.pixels())
        .map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap())
        .filter(|&d| d > 0)
        .collect();
    assert!(
        off.len() <= 100 && off.iter().all(|&d| d <= 1),
        "assets/hw3.png is stale ({} pixels differ, by up to {:?} levels): regenerate it \
         with `whitted render -o assets/hw3.png`",
        off.len(),
        off.iter().max()
    );
}

#[test]
fn a_symbolic_link_keeps_pointing_at_the_new_image() {
    let frame = library_frame();
    let dir = tempfile::tempdir().unwrap();
    let images = dir.path().join("images");
    std::fs::create_dir(&images).unwrap();
    let real = images.join("real.png");
    std::fs::write(&real, b"old").unwrap();
    let link = dir.path().join("link.png");
    std::os::unix::fs::symlink(&real, &link).unwrap();

    image_io::save(&frame, &link, Format::Png, Encoding::Linear).unwrap();
    // The link is still a link to the same file, which now holds the image; the
    // temporary file went into the real file's folder and is gone.
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read_link(&link).unwrap(), real);
    assert!(image::open(&real).unwrap().into_rgb8() == image_io::to_rgb8(&frame, Encoding::Linear));
    assert_eq!(common::entries(&images), ["real.png"]);
}

#[test]
fn a_fifo_receives_the_image_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.ppm");
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        common::skip(
            "a_fifo_receives_the_image_in_place",
            "mkfifo failed here",
            "writing into a FIFO",
        );
        return;
    }
    // A reader on the other end, as in `whitted render -o pipe.ppm & viewer pipe.ppm`.
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    whitted(&[
        "render",
        "--quiet",
        "--ppm-binary",
        "--width",
        &W.to_string(),
        "--height",
        &H.to_string(),
        "-o",
        fifo.to_str().unwrap(),
    ]);
    // Still a FIFO, and nothing else in the folder. (Checked first: had the FIFO been
    // replaced, the reader would wait forever, and joining it would hang the test.)
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo(),
        "the FIFO was replaced by a file"
    );
    assert_eq!(common::entries(dir.path()), ["pipe.ppm"]);
    let bytes = reader.join().unwrap();
    let decoded = image::load_from_memory(&bytes).unwrap().into_rgb8();
    assert!(decoded == image_io::to_rgb8(&library_frame(), Encoding::Linear));
}
