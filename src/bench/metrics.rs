//! The difference of two images as displayed: RMSE, PSNR, the share of pixels off by
//! more than one level, the largest difference, and mean FLIP, with FLIP's per-pixel
//! map as a heat map. The study measures renders against its reference with them
//! ([`compare`]); `whitted compare` measures image files ([`Levels::from_image`]).

use image::{DynamicImage, RgbImage};

use crate::image_io::{to_byte, to_rgb32f};
use crate::render::Frame;

/// Errors of an image against the reference, both clamped to \[0, 1\] as displayed.
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

/// An RGB image as the metrics see it, row 0 at the top: its values in 8-bit levels
/// (clamped to [0, 255]; fractional when they come from linear values) and the bytes
/// that display it.
#[derive(Clone, Debug, PartialEq)]
pub struct Levels {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// R, G, B of each pixel, in 8-bit levels.
    pub values: Vec<f64>,
    /// The 8-bit image.
    pub bytes: RgbImage,
}

impl Levels {
    /// A render, as its linear 8-bit file shows it (values: `clamp(c)·255`).
    pub fn from_frame(frame: &Frame) -> Levels {
        Levels::from_image(DynamicImage::ImageRgb32F(to_rgb32f(frame)))
    }

    /// A decoded image file: 8-bit (or 16-bit) images by their bytes, floating-point
    /// ones (EXR) as linear values × 255, as their linear 8-bit file would show them.
    pub fn from_image(image: DynamicImage) -> Levels {
        let (width, height) = (image.width(), image.height());
        let float = matches!(
            image,
            DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
        );
        if float {
            let linear = image.into_rgb32f();
            // NaN counts as 0, as `to_byte` shows it: `max` drops a NaN, `clamp` would
            // keep it and make every error NaN, which no threshold catches.
            #[allow(clippy::manual_clamp)]
            let values = linear
                .as_raw()
                .iter()
                .map(|&c| f64::from(c.max(0.0).min(1.0)) * 255.0)
                .collect();
            let bytes = linear.as_raw().iter().map(|&c| to_byte(c)).collect();
            Levels {
                width,
                height,
                values,
                bytes: RgbImage::from_raw(width, height, bytes).expect("w*h*3 bytes"),
            }
        } else {
            let bytes = image.into_rgb8();
            Levels {
                width,
                height,
                values: bytes.as_raw().iter().map(|&b| f64::from(b)).collect(),
                bytes,
            }
        }
    }
}

/// Two images measured against each other.
pub struct Comparison {
    /// The numbers.
    pub errors: Errors,
    /// FLIP's error of each pixel, in [0, 1].
    flip_map: nv_flip::FlipImageFloat,
}

impl Comparison {
    /// FLIP's per-pixel error through the magma colour map (black: no difference,
    /// through purple and orange to light yellow: the largest), row 0 at the top.
    pub fn heat_map(&self) -> RgbImage {
        let map = self.flip_map.apply_color_lut(&nv_flip::magma_lut());
        RgbImage::from_raw(map.width(), map.height(), map.to_vec()).expect("w*h*3 bytes")
    }
}

/// Measures `test` against `reference`; `None` when their sizes differ.
pub fn measure(test: &Levels, reference: &Levels) -> Option<Comparison> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return None;
    }
    let mut sq = 0.0;
    let mut off = 0usize;
    let mut max = 0u32;
    fn pixels(l: &Levels) -> impl Iterator<Item = (&[f64], &image::Rgb<u8>)> {
        l.values.chunks_exact(3).zip(l.bytes.pixels())
    }
    for ((a, a8), (b, b8)) in pixels(test).zip(pixels(reference)) {
        let mut pixel_off = false;
        for c in 0..3 {
            let d = a[c] - b[c];
            sq += d * d;
            let levels = u32::from(a8[c].abs_diff(b8[c]));
            max = max.max(levels);
            pixel_off |= levels > 1;
        }
        off += usize::from(pixel_off);
    }
    let n = (test.values.len() / 3).max(1);
    let rmse = (sq / (3 * n) as f64).sqrt();
    let rgb = |l: &Levels| nv_flip::FlipImageRgb8::with_data(l.width, l.height, &l.bytes);
    let flip_map = nv_flip::flip(
        rgb(reference),
        rgb(test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let flip = f64::from(nv_flip::FlipPool::from_image(&flip_map).mean());
    Some(Comparison {
        errors: Errors {
            rmse,
            psnr: 20.0 * (255.0 / rmse).log10(),
            off_by_more_than_1: off as f64 / n as f64,
            max,
            flip,
        },
        flip_map,
    })
}

/// Measures render `test` against render `reference` (same size).
pub fn compare(test: &Frame, reference: &Frame) -> Errors {
    measure(&Levels::from_frame(test), &Levels::from_frame(reference))
        .expect("images of the same size")
        .errors
}
