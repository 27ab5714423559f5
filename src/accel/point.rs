//! Rays through one point — primary rays through the eye, shadow rays ending at a
//! light — and the directional grid around that point, with what their tests need of
//! each sphere worked out once per point: only the direction varies between them.
//! The answers are those of the general queries of [`Spheres`], to the bit.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::dirgrid::{DirGrid, Listed};
use super::{
    quick_radius, round_down, round_up, unit64, Best, Hit, Query, Ray, Spheres, LINE_SLACK,
    QUICK_SLACK, U32,
};
use crate::intersect::{power, roots_from};
use crate::model::Side;

/// The directional grid around a light, with what the quick test of a shadow ray
/// towards it needs of each sphere worked out once and kept in the sphere's entries,
/// so that a shadow ray reads its cell's list in order and nothing else until a
/// sphere passes: only the direction varies between such rays. Without a grid (the
/// spheres would fill even the coarsest past its bound), shadow rays walk the
/// hierarchy.
pub(crate) struct PointGrid {
    centre: DVec3,
    grid: Option<DirGrid<ShadowQuick>>,
}

/// An entry of a light's grid: a sphere, its nearest distance and its quick test's
/// constants.
type Candidate = Listed<ShadowQuick>;

// A light's entry: 24 bytes, as `ShadowQuick`'s comment says (its tail is derived).
const _: () = assert!(size_of::<Candidate>() == 24);

impl PointGrid {
    /// The grid around `point` for spheres `(centre, radius)` within `bound`
    /// ([`DirGrid::build_with`]), each entry with its sphere's [`ShadowQuick`] from
    /// `point`.
    pub(super) fn build(point: DVec3, spheres: &[(DVec3, f64)], n: u32, bound: usize) -> PointGrid {
        let quick = |c: DVec3, r: f64| ShadowQuick::new(point, c, quick_radius(c, r));
        PointGrid {
            centre: point,
            grid: DirGrid::build_with(point, spheres, n, None, quick, bound, true),
        }
    }

    /// The light the grid is around.
    #[cfg(test)]
    pub(crate) fn centre(&self) -> DVec3 {
        self.centre
    }

    /// Whether shadow rays to this light read a grid (else they walk the hierarchy).
    #[cfg(test)]
    pub(crate) fn has_grid(&self) -> bool {
        self.grid.is_some()
    }

    /// The spheres the grid lists apart from its cells (see [`DirGrid::build_with`]).
    #[cfg(test)]
    pub(crate) fn wide(&self) -> usize {
        self.grid.as_ref().map_or(0, |g| g.wide.len())
    }

    /// The grid's cells a face side and the room it takes in the unit of its bound
    /// (entries), if it has one.
    #[cfg(test)]
    pub(crate) fn size(&self) -> Option<(u32, usize)> {
        self.grid.as_ref().map(|g| (g.resolution(), g.places()))
    }
}

/// The directional grid around a camera origin (see [`Spheres::eye_grid`]), with
/// every sphere's record of what a primary ray's tests read of it. (A sphere lies in
/// several of this grid's cells, about five at a million spheres: its record kept
/// once, apart from the lists, costs a primary ray a load, where copies in the
/// entries, as the lights' grids keep them, would cost the build 200 MB.) Without a
/// grid (the spheres would fill even the coarsest past its bound), primary rays walk
/// the hierarchy.
pub(crate) struct EyeGrid {
    centre: DVec3,
    grid: Option<DirGrid>,
    exact: Vec<EyeSphere>,
}

impl EyeGrid {
    /// Whether the eye has no grid: its primary rays walk the hierarchy in bundles
    /// ([`Spheres::closest_bundle`]).
    pub(crate) fn walks_in_bundles(&self) -> bool {
        self.grid.is_none()
    }

    /// The grid, when the eye's shortcuts ([`Spheres::closest_from_eye`],
    /// [`Spheres::eye_run`]) apply to a scene of `spheres` spheres: an eye grid (with the
    /// per-sphere records, even when there is no sphere), and the eye inside no sphere
    /// (else the general query runs).
    pub(super) fn shortcut(&self, spheres: usize) -> Option<&DirGrid> {
        self.grid
            .as_ref()
            .filter(|grid| grid.always.is_empty() && self.exact.len() == spheres)
    }

    /// Every sphere the grid lists, in index order (none without a grid).
    #[cfg(test)]
    pub(crate) fn spheres_listed(&self) -> Vec<u32> {
        self.grid
            .as_ref()
            .map_or(Vec::new(), DirGrid::spheres_listed)
    }

    /// Whether primary rays read a grid (else they walk the hierarchy).
    #[cfg(test)]
    pub(crate) fn has_grid(&self) -> bool {
        self.grid.is_some()
    }

    /// The run of directions in `area` (from [`Spheres::eye_area`] of this grid).
    #[inline]
    pub(crate) fn run(&self, area: EyeArea) -> EyeRun<'_> {
        match area {
            EyeArea::Sky => EyeRun { candidates: &[] },
            EyeArea::Cell(cell) => {
                let grid = self.grid.as_ref().expect("a cell of this grid");
                EyeRun::of_cell(grid, cell as usize)
            }
        }
    }

    fn query(&self, d: Vec3) -> Query {
        Query {
            origin: self.centre,
            dir: d,
            from: None,
        }
    }
}

/// What a primary ray needs before its candidates are tested.
struct EyeStart<'a> {
    /// As in `crossing`: the direction renormalised in `f64`, once, first: its square
    /// root and division then run while the grid is read, off the hit's critical path.
    d64: DVec3,
    /// The spheres of its cell, nearest first.
    candidates: &'a [Listed<()>],
}

impl<'a> EyeStart<'a> {
    #[inline(always)]
    fn new(grid: &'a DirGrid, d: Vec3) -> Self {
        EyeStart::in_run(&EyeRun::of_cell(grid, grid.cell(d)), d)
    }

    /// For a direction of `run`: its cell's list is the run's.
    #[inline(always)]
    fn in_run(run: &EyeRun<'a>, d: Vec3) -> Self {
        EyeStart {
            d64: d.as_dvec3().normalize(),
            candidates: run.candidates,
        }
    }
}

/// Where some directions from the eye all fall ([`Spheres::eye_area`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum EyeArea {
    /// Nowhere a sphere can be met.
    Sky,
    /// In this one cell of the eye grid.
    Cell(u32),
}

/// Directions from the eye that share one cell of its grid, such as the pixels of a
/// row between two that fall in one cell (see [`Spheres::eye_run`]): one cell lookup
/// serves them all.
#[derive(Clone, Copy)]
pub(crate) struct EyeRun<'a> {
    /// The cell's spheres, nearest first.
    candidates: &'a [Listed<()>],
}

impl<'a> EyeRun<'a> {
    #[inline(always)]
    fn of_cell(grid: &'a DirGrid, cell: usize) -> Self {
        EyeRun {
            candidates: grid.candidates(cell),
        }
    }

    /// No direction of the run meets a sphere: they all see the sky.
    #[inline]
    pub(crate) fn sees_nothing(&self) -> bool {
        self.candidates.is_empty()
    }
}

/// A sphere as primary rays test it: the quick test's constants and the origin's part
/// of the exact test (`eye − centre` and `|eye − centre|² − r²` in `f64`), side by side.
#[derive(Clone, Copy)]
struct EyeSphere {
    quick: EyeQuick,
    f: DVec3,
    cterm: f64,
    radius: f64,
    inv_radius: f64,
}

/// One sphere as the quick test of primary rays sees it ([`EyeQuick::may_cross`]).
#[derive(Clone, Copy)]
pub(super) struct EyeQuick {
    /// `eye − centre` in `f32`.
    f: Vec3,
    /// A ray of unit direction `d` misses when `(f·d)²` is below this: the closest
    /// point of its line is then farther than the (widened) radius plus the slack.
    min_bp2: f32,
    /// The crossings lie within this of `−f·d`: the widened radius and the slack of
    /// `−f·d` itself.
    reach: f32,
}

impl EyeQuick {
    pub(super) fn new(eye: DVec3, centre: DVec3, quick_radius: f32) -> Self {
        // `may_cross`'s `|l|² > r² + slack` rewritten as `(f·d)² < |f|² − r² − slack`
        // (`|l|² = |f|² − (f·d)²`): one dot product a candidate. The rewrite adds
        // rounding of a few ε·|f|², far below the slack of 2⁻¹⁸·(r² + |f|²), and the
        // bound is rounded down. (Looser than `ShadowQuick`'s for small balls far
        // away; but the eye's candidates mostly pass and its exact test is short, so
        // the one dot product costs less than the tighter test would save.)
        let f = (eye - centre).as_vec3();
        let ff = f.dot(f);
        let w = f64::from(quick_radius);
        let slack = f64::from(QUICK_SLACK) * (w * w + f64::from(ff));
        let min_bp2 = round_down(f64::from(ff) - w * w - 2.0 * slack);
        let reach = quick_radius + QUICK_SLACK * (ff.sqrt() + quick_radius);
        EyeQuick { f, min_bp2, reach }
    }

    /// `false` when a ray from the eye with unit direction `d` certainly misses the
    /// sphere in `(0, t_max)`.
    #[inline(always)]
    pub(super) fn may_cross(&self, d: Vec3, t_max: f32) -> bool {
        let bp = -self.f.dot(d);
        // `&`, not `&&`: one branch on the outcome, not three on its parts.
        (bp * bp >= self.min_bp2) & (bp + self.reach > 0.0) & (bp - self.reach < t_max)
    }
}

/// One sphere as the quick test of shadow rays towards a light sees it
/// ([`ShadowQuick::may_cross_near`]), kept in each of its entries in the light's grid
/// (24 bytes an entry with its index and distance).
#[derive(Clone, Copy)]
pub(super) struct ShadowQuick {
    /// `light − centre` in `f32`.
    f: Vec3,
    /// The widened radius grown by the error bound of the line's distance from the
    /// centre worked out without cancellation, as [`super::may_cross`] grows it (here
    /// with `|f|` from `f64`, rounded up).
    wide: f32,
}

impl ShadowQuick {
    pub(super) fn new(light: DVec3, centre: DVec3, quick_radius: f32) -> Self {
        // `f` is rounded from `f64` as in `may_cross`, so the line's distance from the
        // centre as `|f + d·(−f·d)|` errs by at most 13u·|f| there too.
        let rel = light - centre;
        let f = rel.as_vec3();
        let w = f64::from(quick_radius);
        let wide = round_up(w + f64::from(LINE_SLACK) * rel.length());
        ShadowQuick { f, wide }
    }

    /// The slack of `−f·d` itself: the crossings lie within the half chord plus this.
    /// `may_cross`'s `QUICK_SLACK·(|f| + r)`, with `|f|` bounded by `1.75·|f|∞` (`|f|`
    /// is at most √3·`|f|∞`) and `r` by the widened radius: derived from the entry, not
    /// kept in it, for a smaller entry. A larger tail only lets more candidates through
    /// to the exact test.
    #[inline(always)]
    pub(super) fn tail(&self) -> f32 {
        QUICK_SLACK * (1.75 * self.f.abs().max_element() + self.wide)
    }

    /// `false` when a ray from the light with unit direction `d`, whose line may pass
    /// up to `offset` from the light (the sphere is widened by `offset`), certainly
    /// misses the sphere in `(0, t_max)`. The crossings are bounded by the half chord
    /// rather than the radius (bounded by the radius, most spheres that pass lie just
    /// beyond the hit point and are not crossed by the segment), and the line's
    /// distance from the centre is worked out without cancellation: a slack relative
    /// to `|f|²` would pass lines well outside a small ball far from the light, each
    /// a shadow ray's exact test.
    #[inline(always)]
    pub(super) fn may_cross_near(&self, d: Vec3, t_max: f32, offset: f32) -> bool {
        let bp = -self.f.dot(d);
        let l = self.f + d * bp;
        let wide = self.wide + offset;
        let chord2 = wide * wide * (1.0 + 8.0 * U32) - l.dot(l);
        // NaN when the line misses (chord2 < 0): it fails every comparison.
        let reach = chord2.sqrt() + self.tail() + offset;
        (chord2 >= 0.0) & (bp + reach > 0.0) & (bp - reach < t_max)
    }
}

impl Spheres {
    /// `grid` around the eye at `eye`, with the tests' constants of every sphere (none
    /// without a grid).
    pub(super) fn eye_point_grid(&self, eye: DVec3, grid: Option<DirGrid>) -> EyeGrid {
        let exact = match grid {
            None => Vec::new(),
            Some(_) => self
                .geometry
                .par_iter()
                .zip(&self.quick_radius)
                .map(|(&(c, radius), &quick_radius)| EyeSphere {
                    quick: EyeQuick::new(eye, c, quick_radius),
                    f: eye - c,
                    cterm: power(eye, c, radius),
                    radius,
                    inv_radius: 1.0 / radius,
                })
                .collect(),
        };
        EyeGrid {
            centre: eye,
            grid,
            exact,
        }
    }

    /// The closest hit of a primary ray: a ray from the centre of `eye`.
    pub(crate) fn closest_primary(&self, eye: &EyeGrid, q: &Query) -> Option<Hit> {
        let Some(grid) = eye
            .grid
            .as_ref()
            .filter(|_| eye.centre == q.origin && q.from.is_none())
        else {
            return self.closest(q);
        };
        let ray = Ray::new(q);
        let mut best = Best::NONE;
        for &k in &grid.always {
            self.consider(k, &ray, &mut best);
        }
        let mut t_max = round_up(best.t);
        for &Listed { k, near, .. } in grid.candidates(grid.cell(q.dir)) {
            if near >= t_max {
                break; // the rest are all farther
            }
            if eye.exact[k as usize].quick.may_cross(q.dir, t_max) {
                if let Some(t) = self.consider_exactly(k, &ray, unit64(q.dir), &mut best) {
                    t_max = t;
                }
            }
        }
        self.finish(best)
    }

    /// [`Spheres::closest_primary`] for the ray from the eye with unit direction `d`,
    /// with the origin's part of every test worked out beforehand (same results).
    pub(crate) fn closest_from_eye(&self, eye: &EyeGrid, d: Vec3) -> Option<Hit> {
        let Some(grid) = eye.shortcut(self.len()) else {
            return self.closest_primary(eye, &eye.query(d));
        };
        let start = EyeStart::new(grid, d);
        self.closest_from_start(eye, d, start)
    }

    /// [`Spheres::closest_from_eye`] of two rays at once: each ray's answer is a chain
    /// of long-latency steps (square roots, divisions, dependent loads); set side by
    /// side, the processor overlaps the two chains.
    // Out of line, as each of the ray-pair queries: inlined into the row loop of
    // `FastTracer::sample_row` they leave the instruction count as it is but make hw3's
    // render about 7% slower (a larger loop body, worse register use).
    #[inline(never)]
    pub(crate) fn closest_from_eye_pair(
        &self,
        eye: &EyeGrid,
        a: Vec3,
        b: Vec3,
    ) -> [Option<Hit>; 2] {
        let Some(grid) = eye.shortcut(self.len()) else {
            return [
                self.closest_primary(eye, &eye.query(a)),
                self.closest_primary(eye, &eye.query(b)),
            ];
        };
        let (start_a, start_b) = (EyeStart::new(grid, a), EyeStart::new(grid, b));
        [
            self.closest_from_start(eye, a, start_a),
            self.closest_from_start(eye, b, start_b),
        ]
    }

    /// [`Spheres::closest_from_eye_pair`] of two directions of `run` (from
    /// [`Spheres::eye_run`] of this grid): the same hits, without a cell lookup each.
    // Out of line, as each of the ray-pair queries: inlined into the row loop of
    // `FastTracer::sample_row` they leave the instruction count as it is but make hw3's
    // render about 7% slower (a larger loop body, worse register use).
    #[inline(never)]
    pub(crate) fn closest_in_run_pair(
        &self,
        eye: &EyeGrid,
        run: &EyeRun<'_>,
        a: Vec3,
        b: Vec3,
    ) -> [Option<Hit>; 2] {
        let (start_a, start_b) = (EyeStart::in_run(run, a), EyeStart::in_run(run, b));
        [
            self.closest_from_start(eye, a, start_a),
            self.closest_from_start(eye, b, start_b),
        ]
    }

    /// When every direction from the eye among `ends` (unit vectors: the directions
    /// of one image row between two pixels) lies in one cell of the eye grid, that
    /// cell, for [`Spheres::closest_in_run_pair`]; when they all see nothing, a run
    /// that sees nothing ([`Spheres::eye_area`]).
    #[inline(never)]
    pub(crate) fn eye_run<'a, const N: usize>(
        &self,
        eye: &'a EyeGrid,
        ends: [Vec3; N],
    ) -> Option<EyeRun<'a>> {
        let area = self.eye_area(eye, ends)?;
        Some(eye.run(area))
    }

    /// Where every direction from the eye among `ends` (any length: the directions of
    /// one image row between two pixels, or the corners of a pixel's square) falls in
    /// the eye grid: in one cell when the ends do (a cell is a square in its face's
    /// plane, and the directions among the ends project to the segment or the
    /// quadrilateral they span, inside it; cells list every sphere seen within a
    /// widened cone, which covers the rounding of the directions many times over) and
    /// the eye is inside no sphere; in the sky when the ends fall in cells of one face
    /// and no cell among them lists a sphere. `None` otherwise.
    #[inline]
    pub(crate) fn eye_area<const N: usize>(
        &self,
        eye: &EyeGrid,
        ends: [Vec3; N],
    ) -> Option<EyeArea> {
        let grid = eye.shortcut(self.len())?;
        let places = ends.map(|d| grid.place(d));
        if places.iter().all(|&p| p == places[0]) {
            return Some(EyeArea::Cell(grid.cell_at(places[0]) as u32));
        }
        // Across cells, the run is sky if none of them lists a sphere: in a large
        // scene a cell is narrower than a run, and the sky above the balls is many
        // runs.
        grid.lists_nothing_among(&places).then_some(EyeArea::Sky)
    }

    #[inline(always)]
    fn closest_from_start(&self, eye: &EyeGrid, d: Vec3, start: EyeStart<'_>) -> Option<Hit> {
        let d64 = start.d64;
        let mut best = Best::NONE;
        let mut t_max = f32::INFINITY;
        for &Listed { k, near, .. } in start.candidates {
            if near >= t_max {
                break; // the rest are all farther
            }
            let k = k as usize;
            let sphere = &eye.exact[k];
            if !sphere.quick.may_cross(d, t_max) {
                continue;
            }
            let r = sphere.radius;
            let Some(rt) = roots_from(sphere.f, sphere.cterm, d64, r) else {
                continue;
            };
            // `crossing` for a ray with no spawn sphere and `t_min = 0`, from outside
            // the sphere (a sphere around the eye is in the grid's `always`, and then
            // the general query runs): `cterm > 0`, both roots have one sign, and a
            // sphere in front is met at its near root.
            if !(rt.near > 0.0 && rt.near < best.t) {
                continue;
            }
            best = Best {
                t: rt.near,
                k,
                entering: true,
                normal: rt.normal_near_scaled(d64, sphere.inv_radius),
            };
            t_max = round_up(rt.near);
        }
        self.finish(best)
    }

    /// `true` when no ray from the eye with a direction between `a` and `b` can meet a
    /// sphere: their [`Spheres::eye_run`] is an empty cell. (The tracer asks the run
    /// itself, [`EyeRun::sees_nothing`]; the tests ask this.)
    #[cfg(test)]
    pub(crate) fn eye_sees_nothing_between(&self, eye: &EyeGrid, a: Vec3, b: Vec3) -> bool {
        self.eye_run(eye, [a, b])
            .is_some_and(|run| run.sees_nothing())
    }

    /// The shadow factor along the segment of length `dist` towards light `light`,
    /// through the light's grid (the tracer builds one for every light, unless the
    /// spheres would fill even the coarsest past its bound: then through the
    /// hierarchy).
    pub(crate) fn shadow_to_light(&self, q: &Query, dist: f64, light: usize) -> f32 {
        let lg = &self.lights[light];
        let Some(grid) = &lg.grid else {
            return self.shadow(q, dist, lg.centre);
        };
        let start = ShadowStart::new(grid, q, dist);
        self.shadow_from_start(grid, &start)
    }

    /// [`Spheres::shadow_to_light`] of two segments at once (see
    /// [`Spheres::closest_from_eye_pair`]).
    // Out of line, as each of the ray-pair queries: inlined into the row loop of
    // `FastTracer::sample_row` they leave the instruction count as it is but make hw3's
    // render about 7% slower (a larger loop body, worse register use).
    #[inline(never)]
    pub(crate) fn shadow_to_light_pair(
        &self,
        a: (&Query, f64),
        b: (&Query, f64),
        light: usize,
    ) -> [f32; 2] {
        let lg = &self.lights[light];
        let Some(grid) = &lg.grid else {
            return [
                self.shadow(a.0, a.1, lg.centre),
                self.shadow(b.0, b.1, lg.centre),
            ];
        };
        let (start_a, start_b) = (
            ShadowStart::new(grid, a.0, a.1),
            ShadowStart::new(grid, b.0, b.1),
        );
        [
            self.shadow_from_start(grid, &start_a),
            self.shadow_from_start(grid, &start_b),
        ]
    }

    #[inline(always)]
    fn shadow_from_start(&self, grid: &DirGrid<ShadowQuick>, start: &ShadowStart<'_>) -> f32 {
        let (ray, dist, light) = (&start.ray, start.dist, grid.centre);
        let mut factor = 1.0f32;
        for &k in &grid.always {
            self.occlude(k, ray, dist, light, &mut factor);
        }
        // The factor is the least of the occluders', whatever their order.
        for list in [&grid.wide[..], start.candidates] {
            for &Listed { k, near, data } in list {
                if f64::from(near) >= dist || factor <= 0.0 {
                    break; // beyond the hit point, seen from the light
                }
                if ray.from == Some((k, Side::Outward))
                    || !data.may_cross_near(start.back, start.dist32, start.offset)
                {
                    continue;
                }
                if let Some(n_k) = self.occluder_normal(k as usize, ray, dist, light) {
                    factor = factor.min(crate::model::occluder_factor(ray.d32, n_k.as_vec3()));
                }
            }
        }
        factor
    }
}

/// What a shadow segment needs before its candidates are tested.
struct ShadowStart<'a> {
    ray: Ray,
    dist: f64,
    dist32: f32,
    /// The segment seen from the light.
    back: Vec3,
    /// The quick test runs from the light, back along the segment: the line through
    /// the light with the (rounded) direction passes within this of the segment's
    /// start (the direction is off by at most ~1.5e-7 radians).
    offset: f32,
    /// The spheres of its cell of the light's grid, nearest the light first.
    candidates: &'a [Candidate],
}

impl<'a> ShadowStart<'a> {
    #[inline(always)]
    fn new(grid: &'a DirGrid<ShadowQuick>, q: &Query, dist: f64) -> Self {
        ShadowStart {
            ray: Ray::new(q),
            dist,
            dist32: round_up(dist),
            back: -q.dir,
            offset: (4e-7 * dist) as f32,
            candidates: grid.candidates(grid.cell((q.origin - grid.centre).as_vec3())),
        }
    }
}
