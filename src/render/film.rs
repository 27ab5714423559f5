//! Where on the film each sample of a pixel lands (SPEC §2, "Camera and pixels"):
//! `s = (i + sx)/W`, `t = (j + sy)/H`, with `j` counted from the bottom and the
//! offsets of [`crate::sampling`]. One sample a pixel is the pixel's centre.

use glam::Vec3;

use crate::sampling::sample_offset;
use crate::settings::{Region, Settings};
use crate::trace::{RayCounts, SampleTracer};

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

/// The samples `ks` of pixel `(i, j)` in their order, each index with its (colour,
/// cutoff bound) given to `each`, two at a time ([`in_pairs`]).
#[inline]
pub(crate) fn each_sample<T: SampleTracer + ?Sized>(
    tracer: &T,
    settings: &Settings,
    (i, j): (u32, u32),
    ks: impl IntoIterator<Item = u32>,
    counts: &mut RayCounts,
    each: impl FnMut(u32, (Vec3, f32)),
) {
    let at = ks.into_iter().map(|k| (k, film(settings, i, j, k)));
    in_pairs(tracer, at, counts, each);
}

/// Each film position of `at` traced, in order, its (colour, cutoff bound) given to
/// `each` with its tag: two at a time through [`SampleTracer::sample_bounded_pair`],
/// the same values as one by one.
#[inline]
pub(crate) fn in_pairs<T: SampleTracer + ?Sized, Tag>(
    tracer: &T,
    at: impl IntoIterator<Item = (Tag, (f32, f32))>,
    counts: &mut RayCounts,
    mut each: impl FnMut(Tag, (Vec3, f32)),
) {
    let mut at = at.into_iter();
    while let Some((tag, (s, t))) = at.next() {
        match at.next() {
            Some((next, (s_next, t_next))) => {
                let [a, b] = tracer.sample_bounded_pair([s, s_next], [t, t_next], counts);
                each(tag, a);
                each(next, b);
            }
            None => each(tag, tracer.sample_bounded(s, t, counts)),
        }
    }
}
