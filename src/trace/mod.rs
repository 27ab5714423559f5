//! The model of SPEC §2 in two implementations that compute the same function:
//! [`fast`], the `f32` tracer used for every image, and [`reference`](mod@reference), a plain `f64`
//! tracer written for clarity, against which the tests measure the fast one.

pub mod fast;
pub mod reference;
mod row;

pub(crate) use row::RUN;

use glam::Vec3;

/// Rays cast while rendering, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Rays from the eye.
    pub primary: u64,
    /// Reflected and transmitted rays.
    pub secondary: u64,
    /// Rays towards a light.
    pub shadow: u64,
}

impl RayCounts {
    /// Rays of every kind.
    pub fn total(&self) -> u64 {
        self.primary + self.secondary + self.shadow
    }

    /// Adds the counts of `other`.
    pub fn add(&mut self, other: &RayCounts) {
        self.primary += other.primary;
        self.secondary += other.secondary;
        self.shadow += other.shadow;
    }
}

/// A rectangle of the film, `[s[0], s[1]] × [t[0], t[1]]` (`t` from the bottom): the
/// square of one pixel, which all its samples lie in, or the squares of a few pixels
/// of a row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmRect {
    /// The least and the greatest abscissa.
    pub s: [f32; 2],
    /// The least and the greatest height.
    pub t: [f32; 2],
}

/// Something that computes the linear RGB of one sample.
pub trait SampleTracer: Sync {
    /// The colour of the ray through film position `(s, t)` ∈ \[0, 1\]² (`t` from the bottom).
    /// Positions outside the film are outside the camera's view, which the fast
    /// tracer's eye grid is built for (it lists only the spheres reaching into it).
    fn sample(&self, s: f32, t: f32, counts: &mut RayCounts) -> Vec3;

    /// The sample and a bound of its error from skipped work (quality settings such as
    /// the contribution cutoff): `|exact − returned| ≤ bound` in every component.
    fn sample_bounded(&self, s: f32, t: f32, counts: &mut RayCounts) -> (Vec3, f32) {
        (self.sample(s, t, counts), 0.0)
    }

    /// `[sample_bounded(s[0], t[0]), sample_bounded(s[1], t[1])]`: two samples at once,
    /// the same values as one by one (a tracer may overlap the two samples' work).
    fn sample_bounded_pair(
        &self,
        s: [f32; 2],
        t: [f32; 2],
        counts: &mut RayCounts,
    ) -> [(Vec3, f32); 2] {
        one_by_one(self, s, t, counts)
    }

    /// `out[n] = sample_bounded(at[n].0, at[n].1)` for film positions `at` that all lie
    /// in `area` (the samples of one pixel, or of a few neighbours in a row): the same
    /// values as one by one (a tracer may share work between the samples of one small
    /// area).
    fn sample_bounded_in(
        &self,
        area: FilmRect,
        at: &[(f32, f32)],
        out: &mut [(Vec3, f32)],
        counts: &mut RayCounts,
    ) {
        let _ = area;
        slice_in_pairs(self, at, out, counts);
    }

    /// `out[i] = sample(s[i], t)`: a row of samples at one height, the same colours
    /// as one by one (a tracer may share work between neighbours).
    fn sample_row(&self, s: &[f32], t: f32, out: &mut [Vec3], counts: &mut RayCounts) {
        for (o, &s) in out.iter_mut().zip(s) {
            *o = self.sample(s, t, counts);
        }
    }

    /// `out[i] = sample_bounded(s[i], t)`: [`SampleTracer::sample_row`] with each
    /// sample's bound.
    fn sample_row_bounded(
        &self,
        s: &[f32],
        t: f32,
        out: &mut [(Vec3, f32)],
        counts: &mut RayCounts,
    ) {
        for (o, &s) in out.iter_mut().zip(s) {
            *o = self.sample_bounded(s, t, counts);
        }
    }
}

/// [`SampleTracer::sample_bounded_pair`] as two samples, one after the other.
pub(crate) fn one_by_one<T: SampleTracer + ?Sized>(
    tracer: &T,
    s: [f32; 2],
    t: [f32; 2],
    counts: &mut RayCounts,
) -> [(Vec3, f32); 2] {
    let first = tracer.sample_bounded(s[0], t[0], counts);
    [first, tracer.sample_bounded(s[1], t[1], counts)]
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

/// `out[n] = sample_bounded(at[n].0, at[n].1)`, two at a time ([`in_pairs`]).
pub(crate) fn slice_in_pairs<T: SampleTracer + ?Sized>(
    tracer: &T,
    at: &[(f32, f32)],
    out: &mut [(Vec3, f32)],
    counts: &mut RayCounts,
) {
    let at = out.iter_mut().zip(at.iter().copied());
    in_pairs(tracer, at, counts, |out, value| *out = value);
}
