//! `encoding = "srgb"` (SPEC §4): the sRGB curve applied once, when 8-bit bytes are
//! made; EXR stays linear; without the key, the assignment's linear bytes.

use glam::Vec3;
use whitted::image_io::{self, to_byte, to_byte_srgb, to_byte_srgb_exact, Encoding, Format};
use whitted::render::Frame;
use whitted::scene::{hw3_scene, Scene, HW3_DEFAULT_SEED};

/// The sRGB formula of IEC 61966-2-1, then `round(·255)`, written out again here.
fn srgb_formula(c: f64) -> u8 {
    let s = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[test]
fn srgb_bytes_follow_the_formula_at_hand_picked_values() {
    // 0 → 0; 0.0031308 is the end of the linear segment: 12.92·0.0031308·255 = 10.31;
    // 0.5 → (1.055·0.5^(1/2.4) − 0.055)·255 = 187.52; 1 → 255.
    for (c, want) in [(0.0f32, 0u8), (0.0031308, 10), (0.5, 188), (1.0, 255)] {
        assert_eq!(srgb_formula(f64::from(c)), want, "formula at {c}");
        assert_eq!(to_byte_srgb(c), want, "table at {c}");
        assert_eq!(to_byte_srgb_exact(c), want, "f64 formula at {c}");
    }
    // Clamped like linear bytes; NaN cannot reach a file.
    for (c, want) in [
        (-1.0f32, 0u8),
        (7.0, 255),
        (f32::INFINITY, 255),
        (f32::NAN, 0),
    ] {
        assert_eq!(to_byte_srgb(c), want, "{c}");
    }
    // Dark values are brighter than in the linear bytes, the ends stay put.
    assert_eq!(to_byte(0.5), 128);
    assert!(to_byte_srgb(0.2) > to_byte(0.2));
}

#[test]
fn linear_bytes_round_the_f32_products_halves_up() {
    // c = 0x3b008081 (0.0019607844…): c·255 = 0.50000003 exactly, 0.5 in f32, byte 1;
    // c = 0x3c20a0a1 (0.0098039219…): c·255 = 2.50000009, 2.5 in f32, byte 3.
    // Rounding halves to even would give 0 and 2.
    assert_eq!(to_byte(f32::from_bits(0x3b00_8081)), 1);
    assert_eq!(to_byte(f32::from_bits(0x3c20_a0a1)), 3);
    // Every half k + ½ (k = 0..254) and 16 f32 either side of it: the byte is std's
    // `round` (halves away from zero) of the f32 product, and below ½, where each f32
    // product that is a half comes from an exact product just above it, the rounding
    // of the exact product (c·255 is exact in f64).
    for k in 0..255u32 {
        let near = ((k as f32 + 0.5) / 255.0).to_bits();
        for bits in near - 16..=near + 16 {
            let c = f32::from_bits(bits);
            let want = (c * 255.0).round() as u8;
            assert_eq!(to_byte(c), want, "c = {c:e} ({bits:#x})");
            if c < 0.5 {
                assert_eq!(want, (f64::from(c) * 255.0).round() as u8, "{c:e}");
            }
        }
    }
}

#[test]
fn the_srgb_table_gives_the_formula_s_byte_for_every_f32() {
    // The table is a step function like the formula: equal at every step, where the
    // formula's byte goes up (found by bisection on the f32 bit patterns), and never
    // going down over all f32 in [0, 1] (a billion values), the two are equal
    // everywhere.
    let exact = |bits: u32| srgb_formula(f64::from(f32::from_bits(bits)));
    for k in 1..=255u8 {
        let (mut below, mut at) = (0u32, 1.0f32.to_bits());
        while at - below > 1 {
            let mid = below + (at - below) / 2;
            if exact(mid) >= k {
                at = mid;
            } else {
                below = mid;
            }
        }
        assert_eq!(exact(at), k, "the formula skips byte {k}");
        for bits in [below, at] {
            let c = f32::from_bits(bits);
            assert_eq!(to_byte_srgb(c), exact(bits), "c = {c:e} ({bits:#x})");
        }
    }
    let mut last = 0u8;
    for bits in 0..=1.0f32.to_bits() {
        let b = to_byte_srgb(f32::from_bits(bits));
        assert!(b >= last, "down at {bits:#x}");
        last = b;
    }
    assert_eq!(last, 255);
}

#[test]
fn the_key_defaults_to_linear_parses_srgb_and_refuses_others_with_the_position() {
    let sphere = "\n[[sphere]]\ncenter = [0, 0, -2]\nradius = 0.5\n";
    let load = |image: &str| Scene::from_toml_str(&format!("{image}{sphere}"), "e.toml");
    let plain = load("").unwrap();
    assert_eq!(plain.image.encoding, None);
    assert_eq!(plain.settings().encoding, Encoding::Linear);
    let srgb = load("[image]\nencoding = \"srgb\"\n").unwrap();
    assert_eq!(srgb.settings().encoding, Encoding::Srgb);
    let linear = load("[image]\nencoding = \"linear\"\n").unwrap();
    assert_eq!(linear.image.encoding, Some(Encoding::Linear));
    // The written scene keeps the key and loads back the same.
    let again = Scene::from_toml_str(&whitted::scene::to_toml(&srgb), "w.toml").unwrap();
    assert_eq!(again, srgb);

    let e = load("[image]\nwidth = 8\nencoding = \"gamma\"\n").unwrap_err();
    assert_eq!(
        e.to_string(),
        "e.toml:3:12: image.encoding: unknown encoding \"gamma\": expected linear or srgb"
    );
    let e = load("[image]\nencoding = 2.2\n").unwrap_err().to_string();
    assert!(e.starts_with("e.toml:2:12") && e.contains("string"), "{e}");
}

/// A 4×2 frame with hand-picked values; bottom row first.
fn frame() -> Frame {
    let mut f = Frame::new(4, 2);
    let values = [0.0, 0.0031308, 0.5, 1.0, 0.2, 0.04, 0.8, 2.0];
    for (p, v) in f.pixels.iter_mut().zip(values) {
        *p = Vec3::new(v, v * 0.5, 1.0 - v.min(1.0));
    }
    f
}

#[test]
fn files_hold_srgb_bytes_and_exr_stays_linear() {
    let f = frame();
    let dir = tempfile::tempdir().unwrap();
    for (name, format) in [
        ("a.png", Format::Png),
        ("a.ppm", Format::Ppm { binary: false }),
        ("a.bmp", Format::Bmp),
    ] {
        let path = dir.path().join(name);
        image_io::save(&f, &path, format, Encoding::Srgb).unwrap();
        let img = image::open(&path).unwrap().into_rgb8();
        for j in 0..2 {
            for i in 0..4 {
                let want = f.get(i, j).to_array().map(to_byte_srgb);
                // Files count rows from the top.
                assert_eq!(img.get_pixel(i, 1 - j).0, want, "{name} ({i}, {j})");
            }
        }
    }
    let linear_exr = image_io::encode(&f, Format::Exr, Encoding::Linear).unwrap();
    let srgb_exr = image_io::encode(&f, Format::Exr, Encoding::Srgb).unwrap();
    assert_eq!(linear_exr, srgb_exr);
}

#[test]
fn without_the_key_files_hold_the_linear_bytes() {
    let f = frame();
    let scene = hw3_scene(HW3_DEFAULT_SEED);
    assert_eq!(scene.settings().encoding, Encoding::Linear);
    // A PNG written with the scene's own encoding, decoded: the linear bytes.
    let png = image_io::encode(&f, Format::Png, scene.settings().encoding).unwrap();
    let decoded = image::load_from_memory(&png).unwrap().into_rgb8();
    for (p, px) in f.pixels.chunks(4).rev().flatten().zip(decoded.pixels()) {
        assert_eq!(px.0, p.to_array().map(to_byte));
    }
}

#[cfg(all(feature = "cli", feature = "viewer"))]
#[test]
fn the_command_line_option_overrides_the_scene_file() {
    use std::process::Command;
    use whitted::render::{render, RenderControl};
    let bin = env!("CARGO_BIN_EXE_whitted");
    let dir = tempfile::tempdir().unwrap();
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    scene.image.width = Some(48);
    scene.image.height = Some(27);
    scene.image.encoding = Some(Encoding::Srgb);
    let file = dir.path().join("s.toml");
    std::fs::write(&file, whitted::scene::to_toml(&scene)).unwrap();
    let run = |args: &[&str], name: &str| {
        let out = dir.path().join(name);
        let o = Command::new(bin)
            .arg("render")
            .arg(&file)
            .arg("-q")
            .arg("-o")
            .arg(&out)
            .args(args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        image::open(&out).unwrap().into_rgb8()
    };
    let (frame, _) = render(&scene, &scene.settings(), &RenderControl::default()).unwrap();
    assert_eq!(
        run(&[], "file.png"),
        image_io::to_rgb8(&frame, Encoding::Srgb)
    );
    assert_eq!(
        run(&["--encoding", "linear"], "cli.png"),
        image_io::to_rgb8(&frame, Encoding::Linear)
    );
    let o = Command::new(bin)
        .args(["render", "-q", "--encoding", "gamma"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("expected linear or srgb"), "{err}");
}
