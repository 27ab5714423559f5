//! Where on the film each sample of a pixel lands (SPEC §2, "Camera and pixels"):
//! `s = (i + sx)/W`, `t = (j + sy)/H`, with `j` counted from the bottom and the
//! offsets of [`crate::sampling`]. One sample a pixel is the pixel's centre.

use crate::sampling::sample_offset;
use crate::settings::{Region, Settings};

/// The film abscissae of the centres of the area's columns: `film`'s `s` for one
/// sample a pixel (the same values), worked out once.
pub(super) fn pixel_centres(settings: &Settings, area: Region) -> Vec<f32> {
    let columns: Vec<u32> = (area.x..area.x + area.width).collect();
    centres_of(settings, &columns)
}

/// [`pixel_centres`] of some columns.
pub(crate) fn centres_of(settings: &Settings, columns: &[u32]) -> Vec<f32> {
    columns
        .iter()
        .map(|&i| (i as f32 + 0.5) / settings.width as f32)
        .collect()
}

/// `film`'s `t` for one sample a pixel in row `j`.
pub(crate) fn centre_height(settings: &Settings, j: u32) -> f32 {
    (j as f32 + 0.5) / settings.height as f32
}

/// The film position of sample `k` of pixel `(i, j)`.
#[inline]
pub(crate) fn film(settings: &Settings, i: u32, j: u32, k: u32) -> (f32, f32) {
    let (sx, sy) = sample_offset(i, j, k, settings.quality.spp, settings.seed);
    (
        (i as f32 + sx) / settings.width as f32,
        (j as f32 + sy) / settings.height as f32,
    )
}
