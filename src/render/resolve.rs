//! Sums of samples to pixel values: the mean, and nothing non-finite (SPEC §2, "Every
//! output pixel is finite").

use glam::Vec3;
use rayon::prelude::*;

use super::Frame;

/// Divides sums of `samples` samples into pixel values; anything non-finite becomes 0
/// so that no NaN or infinity can reach a file or the window.
pub fn resolve(sums: &[Vec3], samples: u32, width: u32, height: u32) -> Frame {
    // In parallel, in runs through `pixel_values` (for one sample a copy).
    let mut pixels = vec![Vec3::ZERO; sums.len()];
    pixels
        .par_chunks_mut(4096)
        .zip(sums.par_chunks(4096))
        .for_each(|(out, sums)| pixel_values(sums, samples, out));
    Frame {
        width,
        height,
        pixels,
    }
}

/// [`pixel_value`] of each of `sums` into `out`: for one sample a copy, mended where
/// not finite (looked for without a branch a pixel, as `render` does).
pub fn pixel_values(sums: &[Vec3], samples: u32, out: &mut [Vec3]) {
    if samples > 1 {
        for (p, &sum) in out.iter_mut().zip(sums) {
            *p = pixel_value(sum, samples);
        }
        return;
    }
    out.copy_from_slice(sums);
    mend_non_finite(out);
}

/// The values of one-sample pixels in place: anything non-finite becomes 0. Looked
/// for without a branch a pixel (it never happens in a sound scene): p − p is 0 for a
/// finite p and NaN otherwise, and a NaN stays in the sum.
pub fn mend_non_finite(values: &mut [Vec3]) {
    #[allow(clippy::eq_op)] // p − p is the point
    let poison = values.iter().fold(Vec3::ZERO, |sum, &p| sum + (p - p));
    if poison != Vec3::ZERO {
        for p in values.iter_mut().filter(|p| !p.is_finite()) {
            *p = Vec3::ZERO;
        }
    }
}

/// A sum of `samples` samples as a finite pixel value.
#[inline]
pub fn pixel_value(sum: Vec3, samples: u32) -> Vec3 {
    let c = sum / samples.max(1) as f32;
    if c.is_finite() {
        c
    } else {
        Vec3::ZERO
    }
}
