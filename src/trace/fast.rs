//! The fast tracer: the model of SPEC §2 in `f32` colours and directions, with the
//! scene compiled once (`crate::accel`) and the intersection maths in `f64` where
//! `f32` cannot hold.

use std::sync::Arc;

use glam::{DVec3, Vec3};

use super::row::{self, RowCamera, RUN};
use super::{FilmRect, RayCounts, SampleTracer};
use crate::accel::BUNDLE;

// A bundle is a run of a row's pixels.
const _: () = assert!(BUNDLE == RUN);
use crate::accel::{EyeArea, EyeGrid, Hit, Query, Spheres, ViewPyramid};
use crate::camera::Camera;
use crate::model::{self, Branches, Side};
use crate::scene::Scene;

#[derive(Clone, Copy)]
struct Material {
    color: Vec3,
    w_r: f32,
    w_t: f32,
    ior: f32,
    branches: Branches,
    /// Diffuse only (local shading, no reflection nor transmission): one flag, not
    /// three tests, where a pair of hits is classified.
    only_local: bool,
}

#[derive(Clone, Copy)]
struct Light {
    position: DVec3,
    intensity: Vec3,
}

/// The scene compiled for the fast tracer: everything that does not depend on the
/// camera, shared by the tracers of every view (the viewer builds it once).
struct Compiled {
    spheres: Spheres,
    materials: Vec<Material>,
    lights: Vec<Light>,
    sky_down: Vec3,
    sky_up: Vec3,
    value_bound: f32,
}

/// The fast `f32` tracer: the scene compiled into acceleration structures for one camera.
pub struct FastTracer {
    compiled: Arc<Compiled>,
    /// The camera-dependent part of the acceleration structures.
    eye: EyeGrid,
    origin: DVec3,
    /// `LL − O`, rounded once from `f64`.
    corner: Vec3,
    horizontal: Vec3,
    vertical: Vec3,
    max_depth: u32,
    /// Contribution cutoff: a branch whose path weight is below it is not traced.
    cutoff: f32,
}

/// The directions of `camera`'s primary rays, the only rays its eye grid answers.
fn view_of(camera: &Camera) -> Option<ViewPyramid> {
    ViewPyramid::new(
        camera.origin,
        camera.lower_left,
        camera.horizontal,
        camera.vertical,
    )
}

/// What a sample skipped under the contribution cutoff.
#[derive(Clone, Copy, Debug, Default)]
struct Skipped {
    weight: f32,
}

impl FastTracer {
    /// Compiles `scene` for `camera`, tracing to depth `max_depth`.
    pub fn new(scene: &Scene, camera: &Camera, max_depth: u32) -> Self {
        let lights: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
        let (spheres, eye) = Spheres::build_for_view(
            &scene.spheres,
            &lights,
            camera.origin,
            view_of(camera).as_ref(),
        );
        let compiled = Compiled {
            spheres,
            materials: scene
                .spheres
                .iter()
                .map(|s| {
                    let branches = Branches::of(s.reflect, s.transmit);
                    Material {
                        color: s.color.as_vec3(),
                        w_r: s.reflect as f32,
                        w_t: s.transmit as f32,
                        ior: s.ior as f32,
                        branches,
                        only_local: branches.only_local(),
                    }
                })
                .collect(),
            lights: scene
                .lights
                .iter()
                .map(|l| Light {
                    position: l.position,
                    intensity: l.intensity.as_vec3(),
                })
                .collect(),
            sky_down: scene.sky.down.as_vec3(),
            sky_up: scene.sky.up.as_vec3(),
            value_bound: value_bound(scene),
        };
        Self::with_compiled(Arc::new(compiled), eye, camera, max_depth)
    }

    fn with_compiled(
        compiled: Arc<Compiled>,
        eye: EyeGrid,
        camera: &Camera,
        max_depth: u32,
    ) -> Self {
        FastTracer {
            eye,
            compiled,
            origin: camera.origin,
            corner: (camera.lower_left - camera.origin).as_vec3(),
            horizontal: camera.horizontal.as_vec3(),
            vertical: camera.vertical.as_vec3(),
            max_depth,
            cutoff: 0.0,
        }
    }

    /// The same scene seen by another camera (and depth): shares the compiled scene and
    /// rebuilds only the camera's grid, so views of one scene compile it once.
    pub fn with_camera(&self, camera: &Camera, max_depth: u32) -> Self {
        let eye = self
            .compiled
            .spheres
            .eye_grid(camera.origin, view_of(camera).as_ref());
        Self::with_compiled(Arc::clone(&self.compiled), eye, camera, max_depth)
            .with_cutoff(self.cutoff)
    }

    /// Skip every branch whose path weight (the product of the mix weights of step 7
    /// down to it) is below `cutoff`; 0 traces everything (exact).
    pub fn with_cutoff(mut self, cutoff: f32) -> Self {
        self.cutoff = cutoff.max(0.0);
        self
    }

    /// Whether a branch of path weight `w` is traced; if not, its weight is recorded.
    #[inline]
    fn keep(&self, w: f32, skipped: &mut Skipped) -> bool {
        if w == 0.0 {
            return false;
        }
        if w < self.cutoff {
            skipped.weight += w;
            return false;
        }
        true
    }

    fn trace(
        &self,
        ray: &Query,
        depth: u32,
        weight: f32,
        counts: &mut RayCounts,
        skipped: &mut Skipped,
    ) -> Vec3 {
        if depth >= self.max_depth {
            return model::sky(ray.dir, self.compiled.sky_down, self.compiled.sky_up);
        }
        if depth == 0 {
            counts.primary += 1;
        } else {
            counts.secondary += 1;
        }
        let hit = if depth == 0 {
            self.compiled.spheres.closest_from_eye(&self.eye, ray.dir)
        } else {
            self.compiled.spheres.closest(ray)
        };
        self.shade(ray.dir, hit, depth, weight, counts, skipped)
    }

    /// The colour seen along direction `dir` when its ray's closest hit is `hit` (the
    /// part of `trace` after the query).
    fn shade(
        &self,
        dir: Vec3,
        hit: Option<Hit>,
        depth: u32,
        weight: f32,
        counts: &mut RayCounts,
        skipped: &mut Skipped,
    ) -> Vec3 {
        let Some(hit) = hit else {
            return model::sky(dir, self.compiled.sky_down, self.compiled.sky_up);
        };
        let m = &self.compiled.materials[hit.sphere as usize];
        let front = hit.entering;
        let n = hit.normal.as_vec3();
        let nf = if front { n } else { -n };
        let spawn = |dir: Vec3, inside: bool| Query {
            origin: hit.point,
            dir,
            from: Some((hit.sphere, Side::inside(inside))),
        };

        let mut local = Vec3::ZERO;
        let w_local = weight * (1.0 - m.w_t) * (1.0 - m.w_r);
        if m.branches.local && self.keep(w_local, skipped) {
            for (index, light) in self.compiled.lights.iter().enumerate() {
                // From the f64 point, which lies on the sphere.
                let to_light = light.position - hit.point;
                let dist = to_light.length();
                let l = (to_light * (1.0 / dist)).as_vec3();
                let cos = nf.dot(l);
                if cos > 0.0 {
                    counts.shadow += 1;
                    let shadow =
                        self.compiled
                            .spheres
                            .shadow_to_light(&spawn(l, !front), dist, index);
                    local += model::diffuse(m.color, light.intensity, cos, shadow);
                }
            }
        }
        if m.only_local {
            // A diffuse surface: step 7 mixes `local` with weights 1 and 0, which gives
            // `local` exactly.
            return local;
        }
        let w_reflect = weight * (1.0 - m.w_t) * m.w_r;
        let reflected = if m.branches.reflect && self.keep(w_reflect, skipped) {
            let dir = model::reflect(dir, n).normalize();
            self.trace(&spawn(dir, !front), depth + 1, w_reflect, counts, skipped)
        } else {
            Vec3::ZERO
        };
        let w_transmit = weight * m.w_t;
        let transmitted = if m.branches.transmit && self.keep(w_transmit, skipped) {
            let (dir, crosses) = model::transmit(dir, n, front, m.ior);
            self.trace(
                &spawn(dir, front == crosses),
                depth + 1,
                w_transmit,
                counts,
                skipped,
            )
        } else {
            Vec3::ZERO
        };
        model::combine(m.w_r, m.w_t, local, reflected, transmitted)
    }
}

impl FastTracer {
    /// Shades the samples of a run in directions `dirs` into `out`, two at a time as
    /// `shade_pair` (an odd last one as `shade`), each pair's primary hits from
    /// `hits(a, b)`; with `SKIPS` (under a contribution cutoff), each sample's cutoff
    /// bound into `bounds`, as long as `out` (not read without).
    #[inline(always)]
    fn shade_run<const SKIPS: bool>(
        &self,
        dirs: &[Vec3],
        out: &mut [Vec3],
        bounds: &mut [f32],
        counts: &mut RayCounts,
        mut hits: impl FnMut(Vec3, Vec3) -> [Option<Hit>; 2],
    ) {
        let mut skipped = Skipped::default();
        for (k, (o, d)) in out.chunks_mut(2).zip(dirs.chunks(2)).enumerate() {
            let (a, b) = (d[0], d[o.len() - 1]);
            let hits = hits(a, b);
            if o.len() == 2 {
                counts.primary += 2;
                let [(ca, ba), (cb, bb)] = self.shade_pair::<SKIPS>([a, b], &hits, counts);
                [o[0], o[1]] = [ca, cb];
                if SKIPS {
                    [bounds[2 * k], bounds[2 * k + 1]] = [ba, bb];
                }
            } else {
                counts.primary += 1;
                if SKIPS {
                    skipped = Skipped::default();
                }
                o[0] = self.shade(a, hits[0], 0, 1.0, counts, &mut skipped);
                if SKIPS {
                    bounds[2 * k] = self.bound(skipped);
                }
            }
        }
    }

    /// The cutoff bound of a sample that skipped `skipped`: no colour a skipped branch
    /// could have added exceeds its weight times the largest value a trace returns.
    #[inline(always)]
    fn bound(&self, skipped: Skipped) -> f32 {
        skipped.weight * self.compiled.value_bound
    }

    /// `shade` of each of two primary hits, with each one's cutoff bound under `SKIPS`
    /// (else 0).
    #[inline(always)]
    fn shade_each<const SKIPS: bool>(
        &self,
        dirs: [Vec3; 2],
        hits: &[Option<Hit>; 2],
        counts: &mut RayCounts,
    ) -> [(Vec3, f32); 2] {
        let mut skipped = Skipped::default();
        [0, 1].map(|k| {
            if SKIPS {
                skipped = Skipped::default();
            }
            let colour = self.shade(dirs[k], hits[k], 0, 1.0, counts, &mut skipped);
            (colour, if SKIPS { self.bound(skipped) } else { 0.0 })
        })
    }

    /// [`SampleTracer::sample_row`] when the eye has no grid: each run's rays walk the
    /// hierarchy as one bundle ([`crate::accel::Spheres::closest_bundle`]), or two at a
    /// time alone when they part too far ([`close_enough_to_bundle`]). Out of
    /// line, so that `sample_row`'s loop for the eye's grid compiles as it would
    /// alone (with this loop inside it, hw3 took 2% more instructions; with
    /// `shade_run` for its own shading, 0.5% more).
    #[inline(never)]
    fn sample_row_in_bundles(
        &self,
        camera: &RowCamera,
        s: &[f32],
        out: &mut [Vec3],
        counts: &mut RayCounts,
    ) {
        let spheres = &self.compiled.spheres;
        let mut dirs = [Vec3::ZERO; RUN];
        for (s, out) in s.chunks(RUN).zip(out.chunks_mut(RUN)) {
            camera.directions(s, &mut dirs);
            let dirs = &dirs[..s.len()];
            if !close_enough_to_bundle(dirs[0], dirs[s.len() - 1]) {
                self.shade_run::<false>(dirs, out, &mut [], counts, |a, b| {
                    spheres.closest_from_eye_pair(&self.eye, a, b)
                });
                continue;
            }
            let mut hits = [None; BUNDLE];
            spheres.closest_bundle(self.origin, dirs, &mut hits[..s.len()]);
            let mut pairs = hits.chunks(2);
            self.shade_run::<false>(dirs, out, &mut [], counts, |_, _| {
                let h = pairs.next().expect("a pair of hits a pair of directions");
                [h[0], h[1]]
            });
        }
    }

    /// Where every direction through film rectangle `area` falls in the eye grid
    /// (`Spheres::eye_area` of its corners), if in one cell or in the sky.
    fn eye_area_of(&self, area: FilmRect) -> Option<EyeArea> {
        let ([s0, s1], [t0, t1]) = (area.s, area.t);
        // The corners' directions unnormalised: where a direction falls in the grid
        // does not depend on its length (and the cells' widened cones cover the
        // rounding).
        let toward = |(s, t): (f32, f32)| (self.corner + self.horizontal * s) + self.vertical * t;
        let corners = [(s0, t0), (s1, t0), (s0, t1), (s1, t1)].map(toward);
        self.compiled.spheres.eye_area(&self.eye, corners)
    }

    /// Two primary rays' colours, given their hits: `shade` of each, except that when
    /// both hit diffuse surfaces under a single light, the two are worked out side by
    /// side and their shadow queries run as a pair (`Spheres::shadow_to_light_pair`),
    /// so that the two chains of square roots, divisions and loads overlap. The sums
    /// are `shade`'s, term for term.
    ///
    /// The hits come by reference: moved by value, the pair goes through the stack
    /// whenever the compiler's inlining shifts (2.7% more instructions on hw3).
    ///
    /// With `SKIPS` (under a contribution cutoff) each colour comes with its cutoff
    /// bound: the pair's own path skips nothing (a diffuse primary hit's local term
    /// has weight 1), unless the cutoff is above 1, where each goes through `shade`.
    #[inline(always)]
    fn shade_pair<const SKIPS: bool>(
        &self,
        dirs: [Vec3; 2],
        hits: &[Option<Hit>; 2],
        counts: &mut RayCounts,
    ) -> [(Vec3, f32); 2] {
        if SKIPS && self.cutoff > 1.0 {
            return self.shade_each::<SKIPS>(dirs, hits, counts);
        }
        let c = &self.compiled;
        let diffuse = |hit: Option<Hit>| {
            let h = hit?;
            let m = &c.materials[h.sphere as usize];
            m.only_local.then_some((h, m))
        };
        let (Some((ha, ma)), Some((hb, mb)), [light]) =
            (diffuse(hits[0]), diffuse(hits[1]), c.lights.as_slice())
        else {
            return self.shade_each::<SKIPS>(dirs, hits, counts);
        };
        // `shade`'s light loop up to the shadow query, for each hit.
        let towards_light = |h: &Hit| {
            let n = h.normal.as_vec3();
            let nf = if h.entering { n } else { -n };
            let to_light = light.position - h.point;
            let dist = to_light.length();
            let l = (to_light * (1.0 / dist)).as_vec3();
            let q = Query {
                origin: h.point,
                dir: l,
                from: Some((h.sphere, Side::inside(!h.entering))),
            };
            (nf.dot(l), q, dist)
        };
        let ((cos_a, qa, dist_a), (cos_b, qb, dist_b)) = (towards_light(&ha), towards_light(&hb));
        let spheres = &c.spheres;
        let shadows = match (cos_a > 0.0, cos_b > 0.0) {
            (true, true) => spheres.shadow_to_light_pair((&qa, dist_a), (&qb, dist_b), 0),
            (true, false) => [spheres.shadow_to_light(&qa, dist_a, 0), 0.0],
            (false, true) => [0.0, spheres.shadow_to_light(&qb, dist_b, 0)],
            (false, false) => [0.0, 0.0],
        };
        let mut local = |m: &Material, cos: f32, shadow: f32| {
            if cos > 0.0 {
                counts.shadow += 1;
                Vec3::ZERO + model::diffuse(m.color, light.intensity, cos, shadow)
            } else {
                Vec3::ZERO
            }
        };
        [
            (local(ma, cos_a, shadows[0]), 0.0),
            (local(mb, cos_b, shadows[1]), 0.0),
        ]
    }

    /// [`SampleTracer::sample_bounded_pair`]'s two samples through the eye's query as
    /// a pair, their hits shaded as a pair (`shade_pair`): the chains of square roots,
    /// divisions and loads of the two overlap. With `SKIPS`, under a contribution
    /// cutoff (whose bounds it reports); without, every bound is 0.
    #[inline(always)]
    fn pair<const SKIPS: bool>(
        &self,
        s: [f32; 2],
        t: [f32; 2],
        counts: &mut RayCounts,
    ) -> [(Vec3, f32); 2] {
        let dir = |k: usize| {
            model::primary_direction(self.corner, self.horizontal, self.vertical, s[k], t[k])
        };
        let (a, b) = (dir(0), dir(1));
        let hits = self.compiled.spheres.closest_from_eye_pair(&self.eye, a, b);
        counts.primary += 2;
        self.shade_pair::<SKIPS>([a, b], &hits, counts)
    }

    /// [`FastTracer::pair`] under a contribution cutoff. (Out of line, as the other
    /// paths under a cutoff, so that the pixel loops compile as they do without one.)
    #[inline(never)]
    fn pair_skipping(&self, s: [f32; 2], t: [f32; 2], counts: &mut RayCounts) -> [(Vec3, f32); 2] {
        self.pair::<true>(s, t, counts)
    }

    /// [`SampleTracer::sample_row`] for a tracer that traces rays (depth above 0):
    /// runs of a few samples whose end directions fall in one cell of the eye grid
    /// share that cell's spheres (`Spheres::eye_run`): an empty cell means sky, as
    /// `trace` would return it, without the per-ray query; else one cell lookup serves
    /// the run. With `SKIPS`, under a contribution cutoff, each sample's bound goes to
    /// `bounds` (as long as `out`; not read without).
    #[inline(always)]
    fn row<const SKIPS: bool>(
        &self,
        s: &[f32],
        t: f32,
        out: &mut [Vec3],
        bounds: &mut [f32],
        counts: &mut RayCounts,
    ) {
        let camera = RowCamera::new(self.corner, self.horizontal, self.vertical, t);
        // Under a cutoff, a scene whose eye has no grid is walked in pairs of rays (the
        // loop below, whose runs then see no cell): one copy of the bundles' walk
        // keeps its code as it compiles alone.
        if !SKIPS && self.eye.walks_in_bundles() {
            return self.sample_row_in_bundles(&camera, s, out, counts);
        }
        let spheres = &self.compiled.spheres;
        let mut dirs = [Vec3::ZERO; RUN];
        let mut bounds = bounds.chunks_mut(RUN);
        for (s, out) in s.chunks(RUN).zip(out.chunks_mut(RUN)) {
            camera.directions(s, &mut dirs);
            let dirs = &dirs;
            let (first, last) = (dirs[0], dirs[s.len() - 1]);
            let run = spheres.eye_run(&self.eye, [first, last]);
            let hits = |a, b| match &run {
                Some(run) => spheres.closest_in_run_pair(&self.eye, run, a, b),
                None => spheres.closest_from_eye_pair(&self.eye, a, b),
            };
            if run.is_some_and(|r| r.sees_nothing()) {
                row::sky(dirs, self.compiled.sky_down, self.compiled.sky_up, out);
                counts.primary += s.len() as u64;
                if SKIPS {
                    // The sky skips nothing.
                    bounds.next().unwrap_or_default().fill(0.0);
                }
            } else {
                // Two rays at a time through the eye query (see
                // `Spheres::closest_from_eye_pair`), their hits shaded as a pair.
                let bounds = bounds.next().unwrap_or_default();
                self.shade_run::<SKIPS>(dirs, out, bounds, counts, hits);
            }
        }
    }

    /// [`FastTracer::row`] under a contribution cutoff (out of line, as
    /// [`FastTracer::pair_skipping`]); its callers hand it a run of at most [`RUN`]
    /// samples at a time, their bounds in an array on the stack.
    #[inline(never)]
    fn row_skipping(
        &self,
        s: &[f32],
        t: f32,
        out: &mut [Vec3],
        bounds: &mut [f32],
        counts: &mut RayCounts,
    ) {
        self.row::<true>(s, t, out, bounds, counts);
    }
}

/// Whether the rays of a run, its end directions `first` and `last` (unit vectors), part
/// by little enough to walk the hierarchy as a bundle: by at most about 1.4° (a run of
/// 8 pixels of a row at a 68° field of view and 320 pixels across). A bundle's boxes are
/// tested against the interval of its rays' directions, which at wider angles (a small
/// image, or the viewer's preview, one pixel of each block) lets through much of the
/// hierarchy (a million balls at 16×9 take 50 times as long in bundles as ray by ray).
fn close_enough_to_bundle(first: Vec3, last: Vec3) -> bool {
    first.dot(last) >= BUNDLE_LEAST_COS
}

/// The least cosine between a bundle's end directions ([`close_enough_to_bundle`]).
const BUNDLE_LEAST_COS: f32 = 0.9997;

/// The largest colour component any trace can return: sky colours and, for local
/// shading, the sum over lights of the brightest component (kd ≤ 1, cos ≤ 1, s ≤ 1).
fn value_bound(scene: &Scene) -> f32 {
    let sky = scene.sky.down.max_element().max(scene.sky.up.max_element());
    let lights: f64 = scene.lights.iter().map(|l| l.intensity.max_element()).sum();
    sky.max(lights) as f32
}

impl SampleTracer for FastTracer {
    fn sample(&self, s: f32, t: f32, counts: &mut RayCounts) -> Vec3 {
        self.sample_bounded(s, t, counts).0
    }

    /// Two samples' primary rays through the eye's query as a pair, their hits shaded
    /// as a pair (`FastTracer::pair`).
    fn sample_bounded_pair(
        &self,
        s: [f32; 2],
        t: [f32; 2],
        counts: &mut RayCounts,
    ) -> [(Vec3, f32); 2] {
        if self.max_depth == 0 {
            return super::one_by_one(self, s, t, counts);
        }
        if self.cutoff != 0.0 {
            return self.pair_skipping(s, t, counts);
        }
        self.pair::<false>(s, t, counts)
    }

    /// The area's corners looked up in the eye grid once for all its samples
    /// (`Spheres::eye_area`): when they fall in one cell, each pair of samples reads
    /// that cell's spheres without a lookup of its own; in cells of one face that list
    /// nothing, every sample sees the sky, without a query. Under a contribution
    /// cutoff, the samples in pairs (`sample_bounded_pair`): a second copy of the
    /// area's path changed how the compiler inlines the first.
    fn sample_bounded_in(
        &self,
        area: FilmRect,
        at: &[(f32, f32)],
        out: &mut [(Vec3, f32)],
        counts: &mut RayCounts,
    ) {
        // Four lookups for the corners pay from four samples on.
        let shared = (self.cutoff == 0.0 && self.max_depth > 0 && at.len() >= 4)
            .then(|| self.eye_area_of(area))
            .flatten();
        let Some(shared) = shared else {
            return super::slice_in_pairs(self, at, out, counts);
        };
        let dir = |(s, t): (f32, f32)| {
            model::primary_direction(self.corner, self.horizontal, self.vertical, s, t)
        };
        let run = self.eye.run(shared);
        let (mut dirs, mut colours) = ([Vec3::ZERO; RUN], [Vec3::ZERO; RUN]);
        for (at, out) in at.chunks(RUN).zip(out.chunks_mut(RUN)) {
            let n = at.len();
            for (d, &p) in dirs.iter_mut().zip(at) {
                *d = dir(p);
            }
            let colours = &mut colours[..n];
            if run.sees_nothing() {
                row::sky(&dirs, self.compiled.sky_down, self.compiled.sky_up, colours);
                counts.primary += n as u64;
            } else {
                self.shade_run::<false>(&dirs[..n], colours, &mut [], counts, |a, b| {
                    self.compiled
                        .spheres
                        .closest_in_run_pair(&self.eye, &run, a, b)
                });
            }
            // No cutoff: nothing is skipped, so each bound is `sample_bounded`'s, zero.
            for (o, &c) in out.iter_mut().zip(&*colours) {
                *o = (c, 0.0);
            }
        }
    }

    fn sample_row(&self, s: &[f32], t: f32, out: &mut [Vec3], counts: &mut RayCounts) {
        if self.max_depth == 0 {
            // Nothing to share: every sample as `sample` takes it.
            for (o, &s) in out.iter_mut().zip(s) {
                *o = self.sample(s, t, counts);
            }
            return;
        }
        if self.cutoff != 0.0 {
            // The bounds are not wanted.
            let mut bounds = [0.0; RUN];
            for (s, out) in s.chunks(RUN).zip(out.chunks_mut(RUN)) {
                self.row_skipping(s, t, out, &mut bounds[..s.len()], counts);
            }
            return;
        }
        self.row::<false>(s, t, out, &mut [], counts);
    }

    fn sample_row_bounded(
        &self,
        s: &[f32],
        t: f32,
        out: &mut [(Vec3, f32)],
        counts: &mut RayCounts,
    ) {
        let (mut colours, mut bounds) = ([Vec3::ZERO; RUN], [0.0; RUN]);
        for (s, out) in s.chunks(RUN).zip(out.chunks_mut(RUN)) {
            let n = s.len();
            if self.cutoff != 0.0 && self.max_depth > 0 {
                self.row_skipping(s, t, &mut colours[..n], &mut bounds[..n], counts);
            } else {
                // Nothing is skipped (no cutoff, or no ray traced): every bound is 0.
                self.sample_row(s, t, &mut colours[..n], counts);
            }
            for ((o, &c), &b) in out.iter_mut().zip(&colours).zip(&bounds) {
                *o = (c, b);
            }
        }
    }

    fn sample_bounded(&self, s: f32, t: f32, counts: &mut RayCounts) -> (Vec3, f32) {
        let dir = model::primary_direction(self.corner, self.horizontal, self.vertical, s, t);
        let ray = Query {
            origin: self.origin,
            dir,
            from: None,
        };
        let mut skipped = Skipped::default();
        let colour = self.trace(&ray, 0, 1.0, counts, &mut skipped);
        (colour, self.bound(skipped))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::exact_tests;
    use crate::scene::{hw3_scene, Sphere, HW3_DEFAULT_SEED};

    /// Above the eye grid's size the rows' primary rays walk the hierarchy in bundles,
    /// or alone where a run's rays part too far: each pixel of a row gets the colour
    /// `sample` gives it alone, to the bit, over the peers' scene of 70,000 balls (sky,
    /// small balls of every material, the big glass, mirror and diffuse balls, the
    /// ground), in rows of 1280, 317 (runs of eight and one of five) and 40 pixels, one
    /// primary ray a pixel; 65,536 spheres keep the grid.
    #[test]
    fn rows_in_bundles_give_each_pixel_its_own_colour() {
        let scene = crate::scene::many_scene(70_000);
        // Runs of 8 pixels as bundles (1280 across), ray by ray (40 across), and both
        // (317 across: the parting of a run's rays grows from the image's edges to
        // its centre).
        let (mut bundled, mut alone, mut sky) = (0, 0, 0);
        for (width, height) in [(1280u32, 6u32), (317, 30), (40, 40)] {
            let tracer = FastTracer::new(&scene, &scene.camera(width, height).unwrap(), 5);
            assert!(tracer.eye.walks_in_bundles());
            let s: Vec<f32> = (0..width)
                .map(|x| (x as f32 + 0.5) / width as f32)
                .collect();
            let mut counts = RayCounts::default();
            for j in 0..height {
                let t = (j as f32 + 0.5) / height as f32;
                let mut row = vec![Vec3::ZERO; s.len()];
                let mut row_counts = RayCounts::default();
                tracer.sample_row(&s, t, &mut row, &mut row_counts);
                assert_eq!(
                    row_counts.primary,
                    u64::from(width),
                    "a primary ray a pixel"
                );
                let dir = |s: f32| {
                    model::primary_direction(
                        tracer.corner,
                        tracer.horizontal,
                        tracer.vertical,
                        s,
                        t,
                    )
                };
                for run in s.chunks(RUN) {
                    if close_enough_to_bundle(dir(run[0]), dir(run[run.len() - 1])) {
                        bundled += 1;
                    } else {
                        alone += 1;
                    }
                }
                for (&s, got) in s.iter().zip(row) {
                    let want = tracer.sample(s, t, &mut counts);
                    assert_eq!(
                        got.to_array(),
                        want.to_array(),
                        "pixel at ({s}, {t}) of {width}×{height}"
                    );
                    sky += usize::from(
                        got == model::sky(dir(s), tracer.compiled.sky_down, tracer.compiled.sky_up),
                    );
                }
            }
        }
        assert!(
            bundled > 1000 && alone > 200,
            "{bundled} runs bundled, {alone} alone"
        );
        assert!(sky > 100 && sky < 15_000, "{sky} pixels of sky");
        // At the grid's size, the eye keeps its grid.
        let scene = crate::scene::many_scene(65_532);
        let tracer = FastTracer::new(&scene, &scene.camera(317, 60).unwrap(), 5);
        assert!(!tracer.eye.walks_in_bundles());
    }

    /// Two samples at once give what each gives alone, to the bit, with the same ray
    /// counts: pairs of film positions near each other (as a pixel's samples) and far
    /// apart, on hw3 (through the eye's grid), on 70,000 balls (no grid: the
    /// hierarchy), under contribution cutoffs (with each sample's bound; 1.5 skips even
    /// a primary hit's local term), and at depth 0 (every sample the sky).
    #[test]
    fn a_pair_of_samples_is_each_sample_alone() {
        let hw3 = hw3_scene(HW3_DEFAULT_SEED);
        let many = crate::scene::many_scene(70_000);
        let mut rng = rand_mt::Mt64::new(5);
        let mut unit = move || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
        for (scene, cutoff, depth) in [
            (&hw3, 0.0, 5),
            (&many, 0.0, 5),
            (&hw3, 0.05, 5),
            (&many, 0.2, 5),
            (&hw3, 1.5, 5),
            (&hw3, 0.0, 0),
        ] {
            let camera = scene.camera(64, 36).unwrap();
            let tracer = FastTracer::new(scene, &camera, depth).with_cutoff(cutoff);
            let (mut alone, mut paired) = (RayCounts::default(), RayCounts::default());
            let (mut hits, mut bounded) = (0, 0);
            for n in 0..4000 {
                let (s0, t0) = (unit(), unit());
                let (s1, t1) = if n % 2 == 0 {
                    (0.98 * s0 + 0.02 * unit(), 0.98 * t0 + 0.02 * unit())
                } else {
                    (unit(), unit())
                };
                let want = [
                    tracer.sample_bounded(s0, t0, &mut alone),
                    tracer.sample_bounded(s1, t1, &mut alone),
                ];
                let got = tracer.sample_bounded_pair([s0, s1], [t0, t1], &mut paired);
                for (got, want) in got.iter().zip(&want) {
                    assert_eq!(
                        (got.0.to_array(), got.1),
                        (want.0.to_array(), want.1),
                        "({s0}, {t0}) and ({s1}, {t1})"
                    );
                }
                let sky = |s: f32, t: f32, c: Vec3| {
                    let dir = model::primary_direction(
                        tracer.corner,
                        tracer.horizontal,
                        tracer.vertical,
                        s,
                        t,
                    );
                    c == model::sky(dir, tracer.compiled.sky_down, tracer.compiled.sky_up)
                };
                hits += usize::from(!sky(s0, t0, want[0].0) && !sky(s1, t1, want[1].0));
                bounded += usize::from(want[0].1 > 0.0);
            }
            assert_eq!(paired, alone);
            assert_eq!(
                hits > 1000,
                depth > 0,
                "{hits} pairs of hits at depth {depth}"
            );
            assert_eq!(bounded > 0, cutoff > 0.0, "{bounded} bounded");
        }
    }

    /// A pixel's samples at once (`sample_bounded_in` its square, or the squares of a
    /// few pixels of a row) give what each gives alone, to the bit, with the same ray
    /// counts: 1 to 16 samples at random in random pixels or runs of 2 to 8 pixels (and
    /// at their corners) of hw3 at 1280×720 and 64×36 (most areas in one cell of the
    /// eye grid or in the sky; many across cells), of 70,000 balls (no grid), under
    /// cutoffs (0.05, 0.2, 1.5), and at depth 0.
    #[test]
    fn a_pixel_s_samples_are_each_sample_alone() {
        let hw3 = hw3_scene(HW3_DEFAULT_SEED);
        let many = crate::scene::many_scene(70_000);
        let mut rng = rand_mt::Mt64::new(9);
        let mut below = move |n: u64| rng.next_u64() % n;
        for (scene, (w, h), cutoff, depth) in [
            (&hw3, (1280, 720), 0.0, 5),
            (&hw3, (64, 36), 0.0, 5),
            (&many, (64, 36), 0.0, 5),
            (&hw3, (64, 36), 0.05, 5),
            (&hw3, (1280, 720), 0.2, 5),
            (&hw3, (64, 36), 1.5, 5),
            (&hw3, (64, 36), 0.0, 0),
        ] {
            let camera = scene.camera(w, h).unwrap();
            let tracer = FastTracer::new(scene, &camera, depth).with_cutoff(cutoff);
            let (mut alone, mut shared) = (RayCounts::default(), RayCounts::default());
            let (mut in_cell, mut in_sky) = (0, 0);
            for _ in 0..1500 {
                // One pixel's square, or the squares of up to eight pixels of a row.
                let wide = [1, 1, 2, 3, 4, 8][below(6) as usize];
                let i = below(u64::from(w) - wide + 1) as f32;
                let (j, wide) = (below(h.into()) as f32, wide as f32);
                let (wf, hf) = (w as f32, h as f32);
                let area = FilmRect {
                    s: [i / wf, (i + wide) / wf],
                    t: [j / hf, (j + 1.0) / hf],
                };
                let n = 1 + below(16) as usize;
                let unit = |bits: u64| match bits % 8 {
                    0 => 0.0,
                    1 => 1.0,
                    _ => (bits >> 8) as f32 / (1u64 << 56) as f32,
                };
                let at: Vec<(f32, f32)> = (0..n)
                    .map(|_| {
                        let (u, v) = (unit(below(u64::MAX)), unit(below(u64::MAX)));
                        ((i + u * wide) / wf, (j + v) / hf)
                    })
                    .collect();
                let want: Vec<_> = at
                    .iter()
                    .map(|&(s, t)| tracer.sample_bounded(s, t, &mut alone))
                    .collect();
                let mut got = vec![(Vec3::NAN, f32::NAN); n];
                tracer.sample_bounded_in(area, &at, &mut got, &mut shared);
                for ((got, want), (s, t)) in got.iter().zip(&want).zip(&at) {
                    assert_eq!(
                        (got.0.to_array().map(f32::to_bits), got.1),
                        (want.0.to_array().map(f32::to_bits), want.1),
                        "({s}, {t}) of {n} in {area:?}"
                    );
                }
                if let Some(area) = tracer.eye_area_of(area).filter(|_| n >= 4) {
                    if tracer.eye.run(area).sees_nothing() {
                        in_sky += 1;
                    } else {
                        in_cell += 1;
                    }
                }
            }
            assert_eq!(shared, alone);
            if depth > 0 && cutoff == 0.0 && scene.spheres.len() < 1000 {
                assert!(
                    in_cell > 100 && in_sky > 100,
                    "{w}×{h}: {in_cell} squares in one cell, {in_sky} of sky"
                );
            }
        }
    }

    /// A row of samples gives what each sample gives alone, to the bit, with the same
    /// ray counts, with and without the bounds (`sample_row_bounded`, `sample_row`),
    /// under contribution cutoffs (0.05, 0.2, and 1.5, which skips even a primary
    /// hit's local term) and without: hw3 through the eye's grid (runs in one cell, in
    /// the sky, across cells), 70,000 balls through the hierarchy (runs as bundles
    /// without a cutoff, pairs of rays under one), a scene of glass balls (cut branches
    /// at every depth), and at depth 0; rows of 1280, 317 and 40 samples.
    #[test]
    fn a_row_with_its_bounds_is_each_sample_alone() {
        let hw3 = hw3_scene(HW3_DEFAULT_SEED);
        let many = crate::scene::many_scene(70_000);
        let mut glass = hw3.clone();
        for s in &mut glass.spheres[1..] {
            (s.transmit, s.reflect, s.ior) = (0.9, 0.3, 1.5);
        }
        for (scene, cutoff, depth) in [
            (&hw3, 0.0, 5),
            (&hw3, 0.05, 5),
            (&hw3, 1.5, 5),
            (&many, 0.0, 5),
            (&many, 0.2, 5),
            (&glass, 0.05, 8),
            (&hw3, 0.05, 0),
        ] {
            let mut bounded = 0;
            for (width, height) in [(1280u32, 7u32), (317, 11), (40, 23)] {
                let camera = scene.camera(width, height).unwrap();
                let tracer = FastTracer::new(scene, &camera, depth).with_cutoff(cutoff);
                let s: Vec<f32> = (0..width)
                    .map(|x| (x as f32 + 0.5) / width as f32)
                    .collect();
                let (mut alone, mut rows, mut plain) = <[RayCounts; 3]>::default().into();
                for j in 0..height {
                    let t = (j as f32 + 0.5) / height as f32;
                    let mut row = vec![(Vec3::NAN, f32::NAN); s.len()];
                    tracer.sample_row_bounded(&s, t, &mut row, &mut rows);
                    let mut colours = vec![Vec3::NAN; s.len()];
                    tracer.sample_row(&s, t, &mut colours, &mut plain);
                    for ((&s, got), colour) in s.iter().zip(&row).zip(&colours) {
                        let want = tracer.sample_bounded(s, t, &mut alone);
                        let bits = |c: Vec3| c.to_array().map(f32::to_bits);
                        assert_eq!(
                            (bits(got.0), got.1, bits(*colour)),
                            (bits(want.0), want.1, bits(want.0)),
                            "({s}, {t}) of {width}×{height}, cutoff {cutoff}"
                        );
                        bounded += usize::from(want.1 > 0.0);
                    }
                }
                assert_eq!((rows, plain), (alone, alone), "{width}×{height}");
            }
            assert_eq!(
                bounded > 0,
                cutoff > 0.0 && depth > 0,
                "{bounded} samples bounded"
            );
        }
    }

    /// The tracer builds its eye's grid for the camera's view: a ball behind the camera
    /// is left out of it (no primary ray could meet it), while the balls in front are
    /// listed.
    #[test]
    fn the_eye_s_grid_leaves_out_a_ball_behind_the_camera() {
        let mut scene = hw3_scene(HW3_DEFAULT_SEED);
        let camera = scene.camera(160, 90).unwrap();
        let film_centre = camera.lower_left + 0.5 * (camera.horizontal + camera.vertical);
        let ahead = (film_centre - camera.origin).normalize();
        let behind = scene.spheres.len() as u32;
        scene
            .spheres
            .push(Sphere::new(camera.origin - 10.0 * ahead, 1.0));
        let tracer = FastTracer::new(&scene, &camera, 5);
        let listed = tracer.eye.spheres_listed();
        assert!(!listed.contains(&behind), "{listed:?}");
        assert!((0..4).all(|k| listed.contains(&k)), "{listed:?}");
    }

    /// A pair of diffuse hits lit in their tangent plane (n·L = 0 exactly: the ball at
    /// (0, 0, −3) seen head-on at (0, 0, −2), the light at (5, 0, −2)) casts no shadow
    /// ray: a ball on the segment to the light costs no exact test (`hand_computed`
    /// counts the rays; this, the work a computed but unused factor would cost).
    #[test]
    fn diffuse_pairs_lit_in_their_tangent_plane_test_no_occluder() {
        let tests_with = |occluder: &str| {
            let toml = format!(
                "[camera]\norigin = [0, 0, 0]\nlower_left = [-1, -1, -1]\n\
                 horizontal = [2, 0, 0]\nvertical = [0, 2, 0]\n\
                 [image]\nwidth = 1\nheight = 1\n\
                 [[light]]\nposition = [5, 0, -2]\n\
                 [[sphere]]\ncenter = [0, 0, -3]\nradius = 1\n{occluder}"
            );
            let scene = Scene::from_toml_str(&toml, "test.toml").unwrap();
            let tracer = FastTracer::new(&scene, &scene.camera(1, 1).unwrap(), 5);
            let (mut out, mut rays) = ([Vec3::ONE; 2], RayCounts::default());
            let (tests, ()) =
                exact_tests(|| tracer.sample_row(&[0.5, 0.5], 0.5, &mut out, &mut rays));
            assert_eq!((out, rays.shadow), ([Vec3::ZERO; 2], 0));
            tests
        };
        let on_the_segment = "[[sphere]]\ncenter = [2.5, 0, -2]\nradius = 0.5\n";
        assert_eq!(tests_with(on_the_segment), tests_with(""));
    }
}
