//! The model of SPEC §2 in two implementations that compute the same function:
//! [`fast`], the `f32` tracer used for every image, and [`reference`](mod@reference), a plain `f64`
//! tracer written for clarity, against which the tests measure the fast one.

pub mod fast;
pub mod reference;
mod row;

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

    /// `out[i] = sample(s[i], t)`: a row of samples at one height, the same colours
    /// as one by one (a tracer may share work between neighbours).
    fn sample_row(&self, s: &[f32], t: f32, out: &mut [Vec3], counts: &mut RayCounts) {
        for (o, &s) in out.iter_mut().zip(s) {
            *o = self.sample(s, t, counts);
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
