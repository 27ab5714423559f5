//! An image depends only on the scene and its settings: not on the thread count, not on
//! the render region (a region equals the same crop of the whole image bit for bit),
//! and with anti-aliasing only on the seed. Checked through the `whitted` binary.

mod common;
use common::whitted;

use std::path::{Path, PathBuf};

use image::{GenericImageView, Rgb32FImage};
use whitted::image_io::parts::{self, PartPixels};
use whitted::settings::Region;

/// Renders the built-in scene at 160×90 with `extra` options into `dir/name`.
fn render(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let path = dir.join(name);
    let mut args = vec![
        "render",
        "--quiet",
        "--width",
        "160",
        "--height",
        "90",
        "-o",
        path.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    whitted(&args);
    path
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap()
}

fn exr(path: &Path) -> Rgb32FImage {
    image::open(path).unwrap().into_rgb32f()
}

/// A region's EXR file: its pixels (the data window) and where it says they belong.
fn exr_part(path: &Path) -> (Rgb32FImage, Region) {
    let part = parts::read_part(path).unwrap();
    match part.pixels {
        PartPixels::Linear(image) => (image, part.placement.region),
        PartPixels::Bytes(_) => panic!("an EXR part holds linear values"),
    }
}

#[test]
fn thread_count_does_not_change_a_byte() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for spp in ["1", "4"] {
        let one = render(
            d,
            &format!("t1-{spp}.ppm"),
            &["--threads", "1", "--spp", spp],
        );
        let two = render(
            d,
            &format!("t2-{spp}.ppm"),
            &["--threads", "2", "--spp", spp],
        );
        let many = render(
            d,
            &format!("t7-{spp}.ppm"),
            &["--threads", "7", "--spp", spp],
        );
        let exr1 = render(
            d,
            &format!("t1-{spp}.exr"),
            &["--threads", "1", "--spp", spp],
        );
        let exr2 = render(
            d,
            &format!("t2-{spp}.exr"),
            &["--threads", "2", "--spp", spp],
        );
        assert_eq!(read(&one), read(&two), "spp {spp}: 1 vs 2 threads");
        assert_eq!(read(&one), read(&many), "spp {spp}: 1 vs 7 threads");
        assert_eq!(read(&exr1), read(&exr2), "spp {spp}: 1 vs 2 threads (exr)");
    }
}

#[test]
fn region_equals_the_crop_of_the_whole_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let aa = ["--spp", "4", "--seed", "3"];
    let full = exr(&render(d, "full.exr", &aa));
    assert_eq!(full.dimensions(), (160, 90));
    // Corners, single pixels, odd sizes, strips that cut across the 8-row bands.
    for (x, y, w, h) in [
        (0, 0, 160, 90),
        (0, 0, 1, 1),
        (159, 89, 1, 1),
        (37, 11, 50, 40),
        (100, 0, 60, 90),
        (0, 83, 160, 7),
        (5, 3, 1, 77),
    ] {
        let region = format!("{x},{y},{w},{h}");
        let mut args = aa.to_vec();
        args.extend(["--region", &region]);
        let file = render(d, &format!("r-{x}-{y}-{w}-{h}.exr"), &args);
        let (part, placed) = exr_part(&file);
        assert_eq!(part.dimensions(), (w, h), "region {region}");
        let (width, height) = (w, h);
        assert_eq!(
            placed,
            Region {
                x,
                y,
                width,
                height
            }
        );
        let crop = full.view(x, y, w, h).to_image();
        // Another reader (the `image` crate) shows the part in its place of the whole
        // image: the data window inside the display window.
        let shown = exr(&file);
        assert_eq!(shown.dimensions(), full.dimensions(), "region {region}");
        assert!(
            shown.view(x, y, w, h).to_image().as_raw() == crop.as_raw(),
            "region {region} is not shown in its place"
        );
        let same = part
            .as_raw()
            .iter()
            .zip(crop.as_raw())
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(
            same,
            "region {region} differs from the crop of the whole image"
        );
    }
    // The region's origin is the top-left, as in image tools: the top strip is sky.
    let top = exr_part(&render(d, "top.exr", &["--region", "0,0,160,1"])).0;
    assert!(
        top.pixels().all(|p| p.0[2] > p.0[0]),
        "top strip is not sky"
    );
}

#[test]
fn the_seed_alone_decides_the_anti_aliased_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = read(&render(d, "a.ppm", &["--spp", "4", "--seed", "7"]));
    let b = read(&render(
        d,
        "b.ppm",
        &["--spp", "4", "--seed", "7", "--threads", "1"],
    ));
    let c = read(&render(d, "c.ppm", &["--spp", "4", "--seed", "8"]));
    let one = read(&render(d, "one.ppm", &["--spp", "1"]));
    assert_eq!(a, b, "same seed, same image");
    // The test can tell images apart: another seed and no anti-aliasing both differ.
    assert_ne!(a, c, "another seed jitters the samples differently");
    assert_ne!(a, one, "4 samples per pixel smooth the edges");
}
