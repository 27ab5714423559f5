//! `whitted compare A B` (SPEC §5): one line of numbers, a heat map, exit status 1
//! past a threshold or for images that cannot be compared.
#![cfg(all(feature = "cli", feature = "viewer"))]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use image::{Rgb, Rgb32FImage, RgbImage};

fn compare(args: &[&Path], options: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .arg("compare")
        .args(args)
        .args(options)
        .output()
        .unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A 64×48 gradient, different in every pixel.
fn gradient() -> RgbImage {
    RgbImage::from_fn(64, 48, |x, y| Rgb([(x * 4) as u8, (y * 5) as u8, 100]))
}

fn save(dir: &Path, name: &str, img: &RgbImage) -> PathBuf {
    let path = dir.join(name);
    img.save(&path).unwrap();
    path
}

/// The value of `key=` in the line.
fn field(line: &str, key: &str) -> String {
    line.split_whitespace()
        .find_map(|f| f.strip_prefix(&format!("{key}=")))
        .unwrap_or_else(|| panic!("no {key} in {line:?}"))
        .to_string()
}

#[test]
fn identical_images_give_rmse_0_and_exit_0() {
    let dir = tempfile::tempdir().unwrap();
    let a = save(dir.path(), "a.png", &gradient());
    // The same pixels in another format.
    let b = save(dir.path(), "b.ppm", &gradient());
    let o = compare(&[&a, &b], &["--max-rmse", "0", "--max-over1", "0"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        stdout(&o),
        "rmse=0.0000 psnr=inf max=0 over1=0.0000% flip=0.00000\n"
    );
}

#[test]
fn a_one_level_change_of_one_pixel_is_reported_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let mut changed = gradient();
    changed.get_pixel_mut(10, 20).0[1] += 1;
    let a = save(dir.path(), "a.png", &gradient());
    let b = save(dir.path(), "b.png", &changed);
    let o = compare(&[&a, &b], &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line = stdout(&o);
    // One channel of one pixel out of 64·48·3 values, one level off.
    let rmse = (1.0f64 / (64.0 * 48.0 * 3.0)).sqrt();
    assert_eq!(field(&line, "rmse"), format!("{rmse:.4}"), "{line}");
    let psnr = 20.0 * (255.0 / rmse).log10();
    assert_eq!(field(&line, "psnr"), format!("{psnr:.2}"), "{line}");
    assert_eq!(field(&line, "max"), "1", "{line}");
    // Off by one is not off by more than one.
    assert_eq!(field(&line, "over1"), "0.0000%", "{line}");

    // Two levels: now one pixel of 3072 is over one level.
    changed.get_pixel_mut(10, 20).0[1] += 1;
    let c = save(dir.path(), "c.png", &changed);
    let line = stdout(&compare(&[&a, &c], &[]));
    assert_eq!(field(&line, "max"), "2", "{line}");
    assert_eq!(field(&line, "over1"), format!("{:.4}%", 100.0 / 3072.0));
}

#[test]
fn thresholds_exit_1_when_passed_and_0_when_kept() {
    let dir = tempfile::tempdir().unwrap();
    let mut changed = gradient();
    for x in 0..64 {
        changed.get_pixel_mut(x, 0).0[0] = 255;
    }
    let a = save(dir.path(), "a.png", &gradient());
    let b = save(dir.path(), "b.png", &changed);
    let line = stdout(&compare(&[&a, &b], &[]));
    let rmse: f64 = field(&line, "rmse").parse().unwrap();
    assert!(rmse > 1.0, "{line}");

    let o = compare(&[&a, &b], &["--max-rmse", "1"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(stdout(&o), line, "the line comes first");
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("above --max-rmse 1"), "{err}");

    // 64 of 3072 pixels (2.08%) are off.
    let o = compare(&[&a, &b], &["--max-over1", "2"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("above --max-over1 2%"),
        "{}",
        stderr(&o)
    );
    let o = compare(&[&a, &b], &["--max-over1", "2.1", "--max-rmse", "1000"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn images_of_different_sizes_or_unreadable_files_exit_1_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let a = save(dir.path(), "a.png", &gradient());
    let small = save(dir.path(), "small.png", &RgbImage::new(32, 48));
    let o = compare(&[&a, &small], &[]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stderr(&o),
        format!(
            "whitted: error: {} is 64x48 but {} is 32x48: only images of the same size can be \
             compared\n",
            a.display(),
            small.display()
        )
    );
    assert_eq!(stdout(&o), "");

    let broken = dir.path().join("broken.png");
    std::fs::write(&broken, b"not a png").unwrap();
    let missing = dir.path().join("missing.png");
    for bad in [&broken, &missing] {
        let o = compare(&[&a, bad], &[]);
        assert_eq!(o.status.code(), Some(1));
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with(&format!(
                "whitted: error: {}: cannot read the image",
                bad.display()
            )),
            "{err}"
        );
    }
}

#[test]
fn exr_is_compared_as_linear_values_times_255() {
    let dir = tempfile::tempdir().unwrap();
    // Linear values a quarter level above the bytes: rmse 0.25, the same bytes.
    let png = gradient();
    let exr = Rgb32FImage::from_fn(64, 48, |x, y| {
        Rgb(png.get_pixel(x, y).0.map(|b| (f32::from(b) + 0.25) / 255.0))
    });
    let a = save(dir.path(), "a.png", &png);
    let b = dir.path().join("b.exr");
    exr.save(&b).unwrap();
    let line = stdout(&compare(&[&a, &b], &[]));
    assert_eq!(field(&line, "rmse"), "0.2500", "{line}");
    assert_eq!(field(&line, "max"), "0", "{line}");
}

#[test]
fn the_heat_map_is_dark_where_equal_and_bright_where_different() {
    let dir = tempfile::tempdir().unwrap();
    let mut changed = gradient();
    for y in 20..28 {
        for x in 30..38 {
            *changed.get_pixel_mut(x, y) = Rgb([255, 0, 255]);
        }
    }
    let a = save(dir.path(), "a.png", &gradient());
    let b = save(dir.path(), "b.png", &changed);
    let heat = dir.path().join("heat.png");
    let o = compare(&[&a, &b], &["--heatmap", heat.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let map = image::open(&heat).unwrap().into_rgb8();
    assert_eq!(map.dimensions(), (64, 48));
    let brightness = |p: &Rgb<u8>| p.0.iter().map(|&c| u32::from(c)).sum::<u32>();
    // Magma: black (#000004) for no difference.
    assert_eq!(map.get_pixel(2, 2).0, [0, 0, 4]);
    assert!(
        brightness(map.get_pixel(34, 24)) > 300,
        "{:?}",
        map.get_pixel(34, 24)
    );

    let o = compare(&[&a, &b], &["--heatmap", "heat.exr"]);
    assert_eq!(o.status.code(), Some(2));
}

/// An EXR pixel that is NaN counts as 0, as every 8-bit file shows it: it used to make
/// the RMSE NaN, which passed any --max-rmse (found by the `image` fuzz target).
#[test]
fn a_nan_pixel_counts_as_black() {
    let dir = tempfile::tempdir().unwrap();
    let mut linear = Rgb32FImage::from_pixel(4, 3, Rgb([0.0, 0.0, 0.0]));
    linear.put_pixel(1, 2, Rgb([f32::NAN, 0.0, 0.0]));
    let nan = dir.path().join("nan.exr");
    linear.save(&nan).unwrap();
    let black = save(dir.path(), "black.png", &RgbImage::new(4, 3));
    let o = compare(&[&nan, &black], &["--max-rmse", "0"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(field(&stdout(&o), "rmse"), "0.0000");

    // Against white, every channel of every pixel is 255 levels off: the NaN too.
    let white = save(
        dir.path(),
        "white.png",
        &RgbImage::from_pixel(4, 3, Rgb([255, 255, 255])),
    );
    let o = compare(&[&nan, &white], &["--max-rmse", "254"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert_eq!(field(&stdout(&o), "rmse"), "255.0000");
}
