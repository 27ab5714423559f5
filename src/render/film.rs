//! Where on the film each sample of a pixel lands (SPEC §2, "Camera and pixels"):
//! `s = (i + sx)/W`, `t = (j + sy)/H`, with `j` counted from the bottom and the
//! offsets of [`crate::sampling`]. One sample a pixel is the pixel's centre.

use std::ops::Range;

use glam::Vec3;

use crate::sampling::{PixelStrata, Strata};
use crate::settings::{Region, Settings};
use crate::trace::{in_pairs, FilmRect, RayCounts, SampleTracer, RUN};

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

/// Where on the film each sample of a render lands ([`FilmPixel::at`]), with what that
/// takes of the settings worked out once.
pub(crate) struct Film {
    width: f32,
    height: f32,
    strata: Strata,
    seed: u64,
}

impl Film {
    pub(crate) fn new(settings: &Settings) -> Film {
        Film {
            width: settings.width as f32,
            height: settings.height as f32,
            strata: Strata::new(settings.quality.spp),
            seed: settings.seed,
        }
    }

    /// The film positions of pixel `(i, j)`'s samples ([`FilmPixel::at`]).
    #[inline]
    fn pixel(&self, i: u32, j: u32) -> FilmPixel<'_> {
        FilmPixel {
            film: self,
            strata: self.strata.of_pixel(i, j, self.seed),
            origin: (i as f32, j as f32),
        }
    }

    /// The film rectangle of pixel `(i, j)`: every position [`FilmPixel::at`] gives its
    /// samples lies in it (`i + sx` rounds to at most `i + 1`, and the division keeps
    /// the order).
    fn pixel_area(&self, i: u32, j: u32) -> FilmRect {
        self.pixels_area(i, 1, j)
    }

    /// The film rectangle of the `n` pixels from `(i, j)` rightwards, which holds each
    /// one's [`Film::pixel_area`] (the division keeps the order).
    fn pixels_area(&self, i: u32, n: u32, j: u32) -> FilmRect {
        let (i, n, j) = (i as f32, n as f32, j as f32);
        FilmRect {
            s: [i / self.width, (i + n) / self.width],
            t: [j / self.height, (j + 1.0) / self.height],
        }
    }
}

/// The film positions of one pixel's samples, with what they share worked out once.
struct FilmPixel<'a> {
    film: &'a Film,
    strata: PixelStrata,
    /// The pixel's lower left corner, `(i, j)`.
    origin: (f32, f32),
}

impl FilmPixel<'_> {
    /// The film position of sample `k`: `s = (i + sx)/W`, `t = (j + sy)/H`.
    #[inline]
    fn at(&self, k: u32) -> (f32, f32) {
        let (sx, sy) = self.strata.offset(k);
        let (i, j) = self.origin;
        ((i + sx) / self.film.width, (j + sy) / self.film.height)
    }
}

/// The samples `ks` of pixel `(i, j)` in their order, each index with its (colour,
/// cutoff bound) given to `each`: up to [`CHUNK`] at a time through
/// [`SampleTracer::sample_bounded_in`] the pixel's square, or, fewer than four, two at
/// a time ([`in_pairs`]: too few to pay for what the tracer would share).
#[inline]
pub(crate) fn each_sample<T: SampleTracer + ?Sized>(
    tracer: &T,
    film: &Film,
    (i, j): (u32, u32),
    ks: impl IntoIterator<Item = u32>,
    counts: &mut RayCounts,
    mut each: impl FnMut(u32, (Vec3, f32)),
) {
    let mut ks = ks.into_iter();
    if ks.size_hint().1.is_some_and(|most| most < 4) {
        let pixel = film.pixel(i, j);
        return in_pairs(tracer, ks.map(|k| (k, pixel.at(k))), counts, each);
    }
    loop {
        let (tags, values, n) = chunk_in_area(tracer, film, (i, j), &mut ks, counts);
        for (&k, &value) in tags[..n].iter().zip(&values[..n]) {
            each(k, value);
        }
        if n < CHUNK {
            return;
        }
    }
}

/// The most samples handed to a tracer at once.
const CHUNK: usize = 16;

/// Samples `ks` of the pixels `columns` of row `j`, each pixel's in the order of `ks`,
/// each given to `each(a, k, value)` with the pixel's place `a` in `columns`: from
/// four samples a pixel on, a pixel at a time ([`each_sample`]); with fewer, the
/// samples of [`RUN`] (about) neighbouring pixels at once through
/// [`SampleTracer::sample_bounded_in`] the rectangle of their squares, so that the
/// tracer shares work between neighbours as it does between a pixel's samples (two
/// samples a pixel, a pixel at a time in pairs, cost 2.9 times one sample a pixel on
/// hw3).
pub(crate) fn each_sample_of_row<T: SampleTracer + ?Sized>(
    tracer: &T,
    film: &Film,
    columns: &[u32],
    j: u32,
    ks: Range<u32>,
    counts: &mut RayCounts,
    mut each: impl FnMut(usize, u32, (Vec3, f32)),
) {
    let per_pixel = ks.len();
    if per_pixel == 0 || per_pixel >= 4 {
        for (a, &i) in columns.iter().enumerate() {
            each_sample(tracer, film, (i, j), ks.clone(), counts, |k, v| {
                each(a, k, v);
            });
        }
        return;
    }
    let group = RUN.div_ceil(per_pixel);
    let mut at = [(0.0, 0.0); CHUNK];
    let mut values = [(Vec3::ZERO, 0.0); CHUNK];
    for (g, pixels) in columns.chunks(group).enumerate() {
        let mut m = 0;
        for &i in pixels {
            let pixel = film.pixel(i, j);
            for k in ks.clone() {
                at[m] = pixel.at(k);
                m += 1;
            }
        }
        let (least, most) = pixels
            .iter()
            .fold((u32::MAX, 0), |(l, h), &i| (l.min(i), h.max(i)));
        let area = film.pixels_area(least, most - least + 1, j);
        tracer.sample_bounded_in(area, &at[..m], &mut values[..m], counts);
        let samples = (0..pixels.len()).flat_map(|a| ks.clone().map(move |k| (a, k)));
        for ((a, k), &value) in samples.zip(&values[..m]) {
            each(g * group + a, k, value);
        }
    }
}

/// The next [`CHUNK`] samples of `ks` (or what is left of them) of pixel `(i, j)`,
/// traced through [`SampleTracer::sample_bounded_in`] the pixel's square: their
/// indices, their (colour, cutoff bound) and how many. (Out of line, and handing the
/// values back rather than to `each`, so that the pairs' loop beside it in
/// `each_sample` compiles as it would alone: inlined there, or given `each`, it made
/// two samples a pixel 8–10% slower.)
#[inline(never)]
#[allow(clippy::type_complexity)]
fn chunk_in_area<T: SampleTracer + ?Sized>(
    tracer: &T,
    film: &Film,
    (i, j): (u32, u32),
    ks: &mut impl Iterator<Item = u32>,
    counts: &mut RayCounts,
) -> ([u32; CHUNK], [(Vec3, f32); CHUNK], usize) {
    let mut tags = [0; CHUNK];
    let mut at = [(0.0, 0.0); CHUNK];
    let mut values = [(Vec3::ZERO, 0.0); CHUNK];
    let mut n = 0;
    let pixel = film.pixel(i, j);
    for k in ks.take(CHUNK) {
        (tags[n], at[n]) = (k, pixel.at(k));
        n += 1;
    }
    if n > 0 {
        let area = film.pixel_area(i, j);
        tracer.sample_bounded_in(area, &at[..n], &mut values[..n], counts);
    }
    (tags, values, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::sample_offset;

    /// `FilmPixel::at` is SPEC §2's `s = (i + sx)/W`, `t = (j + sy)/H` with the offsets of
    /// `sample_offset`, to the bit, and every sample of a pixel lies in the pixel's
    /// square, whose corners are the film positions of the pixel's corners: over sizes
    /// up to 8192 across, 1 to 64 samples, and the pixels at the edges.
    #[test]
    fn a_pixel_s_samples_lie_in_its_square() {
        let mut rng = rand_mt::Mt64::new(3);
        let mut below = move |n: u32| (rng.next_u64() % u64::from(n)) as u32;
        let mut inside = 0;
        for _ in 0..400 {
            let mut settings = Settings::default();
            (settings.width, settings.height) = (1 + below(8192), 1 + below(8192));
            settings.quality.spp = 1 + below(64);
            settings.seed = u64::from(below(u32::MAX));
            let film = Film::new(&settings);
            let (w, h) = (settings.width, settings.height);
            for (i, j) in [(0, 0), (w - 1, h - 1), (below(w), below(h))] {
                let area = film.pixel_area(i, j);
                let (wf, hf) = (w as f32, h as f32);
                let corners = (
                    [i as f32 / wf, (i + 1) as f32 / wf],
                    [j as f32 / hf, (j + 1) as f32 / hf],
                );
                assert_eq!((area.s, area.t), corners);
                for k in 0..settings.quality.spp {
                    let (sx, sy) = sample_offset(i, j, k, settings.quality.spp, settings.seed);
                    let want = ((i as f32 + sx) / wf, (j as f32 + sy) / hf);
                    let (s, t) = film.pixel(i, j).at(k);
                    assert_eq!(
                        (s.to_bits(), t.to_bits()),
                        (want.0.to_bits(), want.1.to_bits())
                    );
                    assert!(area.s[0] <= s && s <= area.s[1], "{s} in {area:?}");
                    assert!(area.t[0] <= t && t <= area.t[1], "{t} in {area:?}");
                    inside += 1;
                }
            }
        }
        assert!(inside > 20_000, "{inside} samples");
    }

    /// The samples of a row's pixels through `each_sample_of_row` are each sample
    /// alone (`sample_bounded` at `FilmPixel::at`), to the bit, each pixel's in the
    /// order of `ks`, with the same ray counts: hw3 at 64×36 and 1280×720 (groups in
    /// one cell of the eye grid, in the sky and across cells), whole rows and a
    /// preview's lattice of every third column, one to five samples a pixel from the
    /// first and from later ones.
    #[test]
    fn a_row_s_samples_are_each_sample_alone() {
        use crate::trace::fast::FastTracer;
        let scene = crate::scene::hw3_scene(crate::scene::HW3_DEFAULT_SEED);
        let bits = |(c, b): (Vec3, f32)| (c.to_array().map(f32::to_bits), b.to_bits());
        let mut groups = 0;
        for (w, h) in [(64, 36), (1280, 720)] {
            let camera = scene.camera(w, h).unwrap();
            let tracer = FastTracer::new(&scene, &camera, 5);
            let mut settings = Settings::default();
            (settings.width, settings.height, settings.quality.spp) = (w, h, 8);
            let film = Film::new(&settings);
            let whole: Vec<u32> = (0..w).collect();
            let lattice: Vec<u32> = (1..w).step_by(3).collect();
            for columns in [&whole, &lattice] {
                for ks in [0..1, 1..2, 0..2, 2..4, 0..3, 3..8] {
                    for j in [0, h / 3, h / 2, h - 1] {
                        let (mut shared, mut alone) = (RayCounts::default(), RayCounts::default());
                        let mut got = Vec::new();
                        let each = |a, k, v| got.push((a, k, bits(v)));
                        each_sample_of_row(
                            &tracer,
                            &film,
                            columns,
                            j,
                            ks.clone(),
                            &mut shared,
                            each,
                        );
                        // Stable: each pixel's samples stay in the order they came in.
                        got.sort_by_key(|&(a, _, _)| a);
                        let mut want = Vec::new();
                        for (a, &i) in columns.iter().enumerate() {
                            for k in ks.clone() {
                                let (s, t) = film.pixel(i, j).at(k);
                                want.push((a, k, bits(tracer.sample_bounded(s, t, &mut alone))));
                            }
                        }
                        assert!(got == want, "{w}x{h} row {j}, samples {ks:?}");
                        assert_eq!(shared, alone);
                        groups += columns.len().div_ceil(RUN.div_ceil(ks.len().min(4)));
                    }
                }
            }
        }
        assert!(groups > 3000, "{groups} groups");
    }
}
