//! The error of an image against the reference, as displayed: RMSE, PSNR, the share
//! of pixels off by more than one level, the largest difference, and mean FLIP.

use crate::image_io::{to_byte, to_rgb8};
use crate::render::Frame;

/// Errors of an image against the reference, both clamped to [0,1] as displayed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Errors {
    /// Root mean square error over pixels and channels, in 8-bit levels.
    pub rmse: f64,
    /// 20·log10(255 / rmse) in dB (infinite for identical images).
    pub psnr: f64,
    /// Share of pixels with a channel more than one 8-bit level off.
    pub off_by_more_than_1: f64,
    /// The largest difference of any channel, in 8-bit levels.
    pub max: u32,
    /// Mean FLIP error (NVIDIA's perceptual metric, 0 = identical, 1 = most different),
    /// on the 8-bit images as displayed.
    pub flip: f64,
}

/// Measures `test` against `reference` (same size).
pub fn compare(test: &Frame, reference: &Frame) -> Errors {
    assert_eq!(
        (test.width, test.height),
        (reference.width, reference.height),
        "images of different sizes"
    );
    let shown = |c: f32| f64::from(c.clamp(0.0, 1.0)) * 255.0;
    let mut sq = 0.0;
    let mut off = 0usize;
    let mut max = 0u32;
    for (a, b) in test.pixels.iter().zip(&reference.pixels) {
        let mut pixel_off = false;
        for c in 0..3 {
            let d = shown(a[c]) - shown(b[c]);
            sq += d * d;
            let levels = u32::from(to_byte(a[c]).abs_diff(to_byte(b[c])));
            max = max.max(levels);
            pixel_off |= levels > 1;
        }
        off += usize::from(pixel_off);
    }
    let n = test.pixels.len().max(1);
    let rmse = (sq / (3 * n) as f64).sqrt();
    let flip = {
        let rgb = |f: &Frame| nv_flip::FlipImageRgb8::with_data(f.width, f.height, &to_rgb8(f));
        let map = nv_flip::flip(
            rgb(reference),
            rgb(test),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        );
        f64::from(nv_flip::FlipPool::from_image(&map).mean())
    };
    Errors {
        rmse,
        psnr: 20.0 * (255.0 / rmse).log10(),
        off_by_more_than_1: off as f64 / n as f64,
        max,
        flip,
    }
}
