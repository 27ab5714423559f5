//! What makes the fast tracer fast, invisible to the model: the spheres compiled into
//! the layout the queries want. Every query answers exactly what a test of every
//! sphere would answer; only the work to get there differs.

mod bundle;
mod bvh;
mod dirgrid;
mod point;
mod view;

use std::ops::ControlFlow;
use std::sync::{Arc, OnceLock};

use glam::{DVec3, Vec3, Vec3A};
use rayon::prelude::*;

pub(crate) use bundle::BUNDLE;
use bvh::{Aabb, Bvh};
use dirgrid::DirGrid;
pub(crate) use point::{EyeArea, EyeGrid, PointGrid};
pub(crate) use view::ViewPyramid;

use crate::intersect::{power, roots};
use crate::model::Side;
use crate::scene::Sphere;

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    pub(crate) sphere: u32,
    /// The hit point re-projected onto the sphere, in `f64`.
    pub(crate) point: DVec3,
    /// Outward unit normal.
    pub(crate) normal: DVec3,
    /// Hit at the near root: the ray enters the sphere here.
    pub(crate) entering: bool,
}

/// A ray as the queries see it: origin (in `f64`: a spawn point keeps the precision of
/// its re-projection onto its sphere), unit direction, and the sphere it was spawned on
/// with the way it leaves it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Query {
    pub(crate) origin: DVec3,
    pub(crate) dir: Vec3,
    pub(crate) from: Option<(u32, Side)>,
}

impl Query {
    /// Crossings of other spheres closer than this are lost in the rounding of the
    /// spawn point's coordinates and ignored.
    #[inline]
    pub(crate) fn t_min(&self) -> f64 {
        match self.from {
            None => 0.0,
            Some(_) => 16.0 * f64::EPSILON * self.origin.abs().max_element(),
        }
    }
}

/// A query with what every sphere test needs, computed once.
#[derive(Clone, Copy)]
struct Ray {
    o64: DVec3,
    d32: Vec3,
    from: Option<(u32, Side)>,
    t_min: f64,
}

impl Ray {
    #[inline]
    fn new(q: &Query) -> Ray {
        Ray {
            o64: q.origin,
            d32: q.dir,
            from: q.from,
            t_min: q.t_min(),
        }
    }
}

/// Relative slack of the `f32` quick reject: many times its rounding error, so that it
/// never rejects a sphere the exact `f64` test would hit.
const QUICK_SLACK: f32 = 1.0 / (1 << 18) as f32;

/// Cells per face of the eye's grid: coarser than the lights' below 4k spheres. Larger
/// cells leave more of them empty, so more runs of sky pixels skip the query, and put
/// more runs of pixels in one cell to share its lookup; smaller cells keep a primary
/// ray's list short. The steps grow with the scene, each at the fastest resolution
/// measured for its size (up to [`EYE_GRID_UP_TO`] spheres: above, the eye has none).
fn eye_resolution(spheres: usize) -> u32 {
    match spheres {
        0..=64 => 12,
        65..=256 => 32,
        257..=4096 => 64,
        _ => 128,
    }
}

/// The directional grid around the eye at `eye` for the spheres `view` may see; none
/// above [`EYE_GRID_UP_TO`] spheres, where primary rays walk the hierarchy in bundles
/// ([`Spheres::closest_bundle`]).
fn eye_dir_grid(
    eye: DVec3,
    spheres: &[(DVec3, f64)],
    view: Option<&ViewPyramid>,
) -> Option<DirGrid> {
    if spheres.len() > EYE_GRID_UP_TO {
        return None;
    }
    DirGrid::build(eye, spheres, eye_resolution(spheres.len()), view)
}

/// The most spheres for which the eye has a grid. Above, bundles of primary rays
/// walking the hierarchy ([`Spheres::closest_bundle`]) answer as fast without a build
/// (cold renders, the bundles against the grid: 30,000 balls 1.06, 50,000 1.03,
/// 100,000 0.99, 300,000 0.96, a million 0.90).
const EYE_GRID_UP_TO: usize = 1 << 16;

/// Cells per face of the lights' directional grids. A render pays for every cell once
/// (its offset is fresh memory, its cone worked out once per process), which a warm
/// frame does not show: hw3's shadow rays are as fast with 64 cells as with 128, and
/// its cold build takes a third of the time.
fn grid_resolution(spheres: usize) -> u32 {
    match spheres {
        0..=64 => 64,
        65..=4096 => 128,
        _ => 256,
    }
}

/// Each sphere's centre and radius.
fn geometry_of(spheres: &[Sphere]) -> Vec<(DVec3, f64)> {
    spheres.par_iter().map(|s| (s.center, s.radius)).collect()
}

/// A directional grid around each light for spheres `(centre, radius)`: the lights
/// share one grid's bound ([`dirgrid::most_entries_each`]).
fn light_grids(spheres: &[(DVec3, f64)], lights: &[DVec3]) -> Vec<PointGrid> {
    let n = grid_resolution(spheres.len());
    let bound = dirgrid::most_entries_each(spheres.len(), lights.len());
    lights
        .par_iter()
        .map(|&p| PointGrid::build(p, spheres, n, bound))
        .collect()
}

/// The radius of the quick tests in `f32`, widened to cover the rounding of the
/// centre (or its offset from a ray's origin) to `f32`.
fn quick_radius(c: DVec3, r: f64) -> f32 {
    let widen = 4.0 * f64::from(f32::EPSILON) * (c.abs().max_element() + r);
    (r + widen) as f32
}

/// The `f32` box of a sphere in the hierarchy: widened by a little more than `f32`'s
/// rounding of the centre and radius, and rounded outwards.
fn sphere_box(c: DVec3, r: f64) -> Aabb {
    let widen = r * 1e-6 + 1e-6 * c.abs().max_element();
    let (lo, hi) = (c - DVec3::splat(r + widen), c + DVec3::splat(r + widen));
    Aabb {
        min: Vec3A::new(round_down(lo.x), round_down(lo.y), round_down(lo.z)),
        max: Vec3A::new(round_up(hi.x), round_up(hi.y), round_up(hi.z)),
    }
}

/// What the exact test reads of a sphere.
#[derive(Clone, Copy)]
struct Exact {
    center: DVec3,
    radius: f64,
    /// `1/radius`, for the normals.
    inv_radius: f64,
}

/// A sphere in the hierarchy's leaf order: all that a query through the hierarchy
/// reads of it, side by side (in a large scene, each array read in the scene's order
/// instead would be one more cache miss an exact test).
#[derive(Clone, Copy)]
struct LeafSphere {
    exact: Exact,
    /// The widened `f32` radius of the quick test.
    quick_radius: f32,
    k: u32,
}

/// The spheres, for the fast tracer's queries.
pub(crate) struct Spheres {
    /// Each sphere's centre and radius, shared with the grids' builds.
    geometry: Arc<Vec<(DVec3, f64)>>,
    /// `1/radius`, for the normals.
    inv_radius: Vec<f64>,
    /// The quick tests' radius ([`quick_radius`]).
    quick_radius: Vec<f32>,
    bvh: Bvh,
    /// What the hierarchy's queries read of each sphere, in its leaf order: a leaf's
    /// spheres sit side by side in memory instead of scattered over the scene's order.
    leaf: Vec<LeafSphere>,
    /// Around each light, for shadow rays.
    lights: Vec<PointGrid>,
    /// The lists of the spheres that overlap a sphere, for rays inside it.
    inside: InsideLists,
}

/// For the spheres that keep one, the other spheres that overlap it, if at most
/// [`MOST_OVERLAPS`]: all that a ray travelling inside it can meet before its far
/// side (see [`Spheres::closest_inside`]). Every sphere keeps one in a scene of up
/// to [`WALK_INSIDE_FROM`] spheres, else those of at least [`list_radius`]; rays
/// inside the others walk the hierarchy up to the far side instead.
struct InsideLists {
    /// The spheres that keep a list, in increasing order; `None` when all do.
    keepers: Option<Vec<u32>>,
    /// A keeper's list, at its place in `keepers` (or its index), worked out when a
    /// ray first goes inside the sphere: most spheres never see one.
    lists: Vec<OnceLock<Option<Box<[u32]>>>>,
}

impl InsideLists {
    fn new(geometry: &[(DVec3, f64)]) -> Self {
        let fresh = |n: usize| (0..n).into_par_iter().map(|_| OnceLock::new()).collect();
        if geometry.len() <= WALK_INSIDE_FROM {
            return InsideLists {
                keepers: None,
                lists: fresh(geometry.len()),
            };
        }
        let radius = list_radius(geometry);
        let keepers: Vec<u32> = (0..geometry.len() as u32)
            .into_par_iter()
            .filter(|&k| geometry[k as usize].1 >= radius)
            .collect();
        InsideLists {
            lists: fresh(keepers.len()),
            keepers: Some(keepers),
        }
    }

    /// Sphere `s`'s list, if it keeps one.
    fn of(&self, s: u32) -> Option<&OnceLock<Option<Box<[u32]>>>> {
        let place = match &self.keepers {
            None => s as usize,
            Some(keepers) => keepers.binary_search(&s).ok()?,
        };
        Some(&self.lists[place])
    }
}

impl Spheres {
    /// The spheres with a hierarchy for rays of any origin (the tracer builds them
    /// with its grids, [`Spheres::build_for_view`]).
    #[cfg(any(test, all(feature = "cli", feature = "viewer")))]
    pub(crate) fn new(spheres: &[Sphere]) -> Self {
        Spheres::of_geometry(Arc::new(geometry_of(spheres)))
    }

    /// [`Spheres::new`] from each sphere's centre and radius.
    fn of_geometry(geometry: Arc<Vec<(DVec3, f64)>>) -> Self {
        let quick_radius: Vec<f32> = geometry
            .par_iter()
            .map(|&(c, r)| quick_radius(c, r))
            .collect();
        let (bvh, leaf) = Bvh::build(
            geometry.len(),
            |k| {
                let (center, radius) = geometry[k];
                LeafSphere {
                    exact: Exact {
                        center,
                        radius,
                        inv_radius: 1.0 / radius,
                    },
                    quick_radius: quick_radius[k],
                    k: k as u32,
                }
            },
            |leaf| sphere_box(leaf.exact.center, leaf.exact.radius),
        );
        Spheres {
            inside: InsideLists::new(&geometry),
            bvh,
            leaf,
            inv_radius: geometry.par_iter().map(|&(_, r)| 1.0 / r).collect(),
            geometry,
            quick_radius,
            lights: Vec::new(),
        }
    }

    /// Adds a directional grid around each light, so that shadow rays test only the
    /// spheres seen in their direction from the light. The tests build the grids one
    /// part at a time with it; the tracer builds all at once ([`Spheres::build_for_view`]).
    #[cfg(test)]
    pub(crate) fn with_light_grids(mut self, lights: &[DVec3]) -> Self {
        self.lights = light_grids(&self.geometry, lights);
        self
    }

    /// The spheres with their hierarchy and light grids, and the eye grid of a first
    /// camera (see [`Spheres::eye_grid`]), built side by side on the pool's threads
    /// (they are independent).
    pub(crate) fn build_for_view(
        spheres: &[Sphere],
        lights: &[DVec3],
        eye: DVec3,
        view: Option<&ViewPyramid>,
    ) -> (Spheres, EyeGrid) {
        let geometry = Arc::new(geometry_of(spheres));
        let list = geometry.as_slice();
        // The lights' grids before the eye's (which scenes above `EYE_GRID_UP_TO`
        // spheres do not have): whichever thread is done first shares the other's
        // parallel parts.
        let (base, (lights, eye_grid)) = rayon::join(
            || Spheres::of_geometry(Arc::clone(&geometry)),
            || {
                rayon::join(
                    || light_grids(list, lights),
                    || eye_dir_grid(eye, list, view),
                )
            },
        );
        let eye_grid = base.eye_point_grid(eye, eye_grid);
        (Spheres { lights, ..base }, eye_grid)
    }

    /// The directional grid around a camera origin, for [`Spheres::closest_primary`]:
    /// the only part of the structures that depends on the camera. With `view`, it
    /// answers rays through that pyramid only (a camera's primary rays).
    pub(crate) fn eye_grid(&self, eye: DVec3, view: Option<&ViewPyramid>) -> EyeGrid {
        let list = self.geometry.as_slice();
        self.eye_point_grid(eye, eye_dir_grid(eye, list, view))
    }

    pub(crate) fn len(&self) -> usize {
        self.geometry.len()
    }

    /// `false` when sphere `k` certainly has no crossing in `(0, t_max)` (cheap, `f32`
    /// after one `f64` subtraction, which keeps origins far from the world's origin exact
    /// enough).
    #[inline(always)]
    fn may_cross(&self, k: usize, ray: &Ray, t_max: f32) -> bool {
        may_cross(self.geometry[k].0, self.quick_radius[k], ray, t_max)
    }

    /// The first crossing of sphere `k` in `(t_min, t_max)`: `(t, entering, normal)`.
    #[inline(never)]
    fn crossing(&self, k: usize, ray: &Ray, t_max: f64) -> Option<(f64, bool, DVec3)> {
        // Renormalised here, for the few spheres that pass the quick test (shadow rays
        // mostly have none). Not inlined: inlined into the shadow loops, the
        // normalisation would be hoisted out of them, onto every shadow ray.
        self.crossing_along(k, ray, unit64(ray.d32), t_max)
    }

    /// [`Spheres::crossing`] given the direction renormalised in `f64` ([`unit64`]).
    #[inline]
    fn crossing_along(
        &self,
        k: usize,
        ray: &Ray,
        d: DVec3,
        t_max: f64,
    ) -> Option<(f64, bool, DVec3)> {
        let (center, radius) = self.geometry[k];
        let sphere = Exact {
            center,
            radius,
            inv_radius: self.inv_radius[k],
        };
        crossing_of(k, &sphere, ray, d, t_max)
    }

    /// Tests sphere `k` for the closest hit so far; returns the new `t` if it is closer.
    #[inline(always)]
    fn consider(&self, k: u32, ray: &Ray, best: &mut Best) -> Option<f32> {
        let own_outward = ray.from == Some((k, Side::Outward));
        if own_outward || !self.may_cross(k as usize, ray, round_up(best.t)) {
            return None;
        }
        self.consider_exactly(k, ray, unit64(ray.d32), best)
    }

    /// [`Spheres::consider`] after the quick test passed.
    #[inline(always)]
    fn consider_exactly(&self, k: u32, ray: &Ray, d: DVec3, best: &mut Best) -> Option<f32> {
        let k = k as usize;
        let (t, entering, normal) = self.crossing_along(k, ray, d, best.t)?;
        best.take(t, k, entering, normal)
    }

    fn finish(&self, best: Best) -> Option<Hit> {
        if best.k == usize::MAX {
            return None;
        }
        // (l ∓ √disc·d)/r is a unit vector up to rounding (|l|² + disc = r², l ⊥ d):
        // no need to normalise again.
        let normal = best.normal;
        let (center, radius) = self.geometry[best.k];
        Some(Hit {
            sphere: best.k as u32,
            point: center + normal * radius,
            normal,
            entering: best.entering,
        })
    }

    /// The closest hit of a ray of any origin.
    pub(crate) fn closest(&self, q: &Query) -> Option<Hit> {
        if let Some((s, Side::Inward)) = q.from {
            if let Some(hit) = self.closest_inside(s, q) {
                return Some(hit);
            }
        }
        let ray = Ray::new(q);
        // Worked out first (most such rays test a sphere exactly, some several): its
        // square root and division overlap the traversal.
        let d64 = unit64(q.dir);
        let mut best = Best::NONE;
        self.walk::<false>(&ray, q, d64, f32::INFINITY, 0, &mut best);
        self.finish(best)
    }

    /// The hierarchy's walk for the closest hit before `t_max`, into `best`; with
    /// `SKIP`, leaving out sphere `skip`. (One instance for each use, so that each
    /// inlines its walk.)
    #[inline(always)]
    fn walk<const SKIP: bool>(
        &self,
        ray: &Ray,
        q: &Query,
        d64: DVec3,
        t_max: f32,
        skip: u32,
        best: &mut Best,
    ) {
        self.bvh
            .traverse(q.origin.as_vec3(), q.dir.recip(), t_max, |slot, t_max| {
                let s = &self.leaf[slot as usize];
                let own_outward = ray.from == Some((s.k, Side::Outward));
                if own_outward
                    || (SKIP && s.k == skip)
                    || !may_cross(s.exact.center, s.quick_radius, ray, t_max)
                {
                    return None;
                }
                let k = s.k as usize;
                let (t, entering, normal) = crossing_of(k, &s.exact, ray, d64, best.t)?;
                best.take(t, k, entering, normal)
            });
    }

    /// [`Spheres::closest`] of a ray going into sphere `s` from its surface (refracted
    /// into glass, or reflected inside it): until it leaves by the far side, it is
    /// inside `s`, where only `s` and the spheres that overlap it can be met; so the
    /// closest of those is the closest of all: from the list of those (a large
    /// sphere, which many rays enter, overlapped by a few) or from the hierarchy's walk
    /// up to the far side (a small one, which few rays enter: making its list would
    /// cost more; or one overlapped by many, whose list would be longer than the
    /// walk). `None` when the far side is not found (lost to rounding at a grazing
    /// angle): the hierarchy then decides.
    fn closest_inside(&self, s: u32, q: &Query) -> Option<Hit> {
        let ray = Ray::new(q);
        let d64 = unit64(q.dir);
        let mut best = Best::NONE;
        let t_exit = self.consider_exactly(s, &ray, d64, &mut best)?;
        let list = self.inside.of(s).and_then(|list| {
            list.get_or_init(|| self.overlapping(s, MOST_OVERLAPS))
                .as_deref()
        });
        match list {
            Some(overlaps) => {
                for &k in overlaps {
                    self.consider(k, &ray, &mut best);
                }
            }
            None => self.walk_inside(&ray, q, d64, t_exit, s, &mut best),
        }
        self.finish(best)
    }

    /// The walk of [`Spheres::closest_inside`] for a small sphere `s`, out of line: the
    /// hot loops of scenes whose spheres all keep lists stay as they are.
    #[inline(never)]
    fn walk_inside(&self, ray: &Ray, q: &Query, d64: DVec3, t_exit: f32, s: u32, best: &mut Best) {
        self.walk::<true>(ray, q, d64, t_exit, s, best);
    }

    /// The spheres that overlap sphere `s` (or touch it, up to rounding), if there
    /// are at most `most` of them.
    fn overlapping(&self, s: u32, most: usize) -> Option<Box<[u32]>> {
        let s = s as usize;
        let (c, r) = self.geometry[s];
        let bounds = sphere_box(c, r);
        let mut list = Vec::new();
        self.bvh.overlapping(bounds.min, bounds.max, |slot| {
            let k = self.leaf[slot as usize].k as usize;
            let (ck, rk) = self.geometry[k];
            let reach =
                (r + rk) * (1.0 + 1e-6) + 1e-9 * (c.abs().max_element() + ck.abs().max_element());
            if k != s && (ck - c).length() <= reach {
                list.push(k as u32);
                if list.len() > most {
                    return ControlFlow::Break(());
                }
            }
            ControlFlow::Continue(())
        });
        (list.len() <= most).then(|| {
            list.sort_unstable();
            list.into_boxed_slice()
        })
    }

    /// Sphere `k`'s outward normal where the shadow segment of length `dist` first
    /// crosses it, if it does before its end at the light at `light`
    /// ([`crate::model::crosses_before_light`]).
    #[inline(always)]
    fn occluder_normal(&self, k: usize, ray: &Ray, dist: f64, light: DVec3) -> Option<DVec3> {
        let (t, entering, n_k) = self.crossing(k, ray, dist)?;
        let light_power = || {
            let (c, r) = self.geometry[k];
            power(light, c, r)
        };
        crate::model::crosses_before_light(t, dist, entering, light_power).then_some(n_k)
    }

    /// Lowers `factor` by sphere `k`'s occlusion of the shadow segment.
    #[inline(always)]
    fn occlude(&self, k: u32, ray: &Ray, dist: f64, light: DVec3, factor: &mut f32) {
        let k = k as usize;
        if ray.from == Some((k as u32, Side::Outward)) || !self.may_cross(k, ray, round_up(dist)) {
            return;
        }
        if let Some(n_k) = self.occluder_normal(k, ray, dist, light) {
            *factor = factor.min(crate::model::occluder_factor(ray.d32, n_k.as_vec3()));
        }
    }

    /// The shadow factor along the segment of length `dist` to the light at `light`
    /// (step 4 of the model), through the hierarchy: for a light without a grid, and
    /// the tests' reference for those with one.
    pub(crate) fn shadow(&self, q: &Query, dist: f64, light: DVec3) -> f32 {
        let ray = Ray::new(q);
        let mut factor = 1.0f32;
        self.bvh.traverse(
            q.origin.as_vec3(),
            q.dir.recip(),
            round_up(dist),
            |slot, t_max| {
                let s = &self.leaf[slot as usize];
                let own_outward = ray.from == Some((s.k, Side::Outward));
                if !own_outward && may_cross(s.exact.center, s.quick_radius, &ray, t_max) {
                    if let Some(n_k) = self.occluder_normal(s.k as usize, &ray, dist, light) {
                        factor = factor.min(crate::model::occluder_factor(ray.d32, n_k.as_vec3()));
                    }
                }
                // A factor of 0 cannot go lower: stop looking.
                (factor <= 0.0).then_some(-1.0)
            },
        );
        factor
    }
}

#[cfg(test)]
thread_local! {
    /// The exact tests run on this thread: the tests count the work the culling skips.
    static EXACT_TESTS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// The exact tests `work` runs on this thread, and its result.
#[cfg(test)]
pub(crate) fn exact_tests<R>(work: impl FnOnce() -> R) -> (u64, R) {
    let before = EXACT_TESTS.with(|n| n.get());
    let result = work();
    (EXACT_TESTS.with(|n| n.get()) - before, result)
}

/// [`Spheres::crossing_along`] of sphere `k`, given what the exact test reads of it.
#[inline]
fn crossing_of(
    k: usize,
    sphere: &Exact,
    ray: &Ray,
    d: DVec3,
    t_max: f64,
) -> Option<(f64, bool, DVec3)> {
    #[cfg(test)]
    EXACT_TESTS.with(|n| n.set(n.get() + 1));
    let (o, t_min) = (ray.o64, ray.t_min);
    let (c, r, inv_r) = (sphere.center, sphere.radius, sphere.inv_radius);
    let own = ray
        .from
        .filter(|&(s, _)| s as usize == k)
        .map(|(_, side)| side);
    if own == Some(Side::Outward) {
        return None;
    }
    let rt = roots(o, d, c, r)?;
    if own == Some(Side::Inward) {
        return (rt.far > 0.0 && rt.far < t_max)
            .then(|| (rt.far, false, rt.normal_far_scaled(d, inv_r)));
    }
    if rt.near > t_min && rt.near < t_max {
        Some((rt.near, true, rt.normal_near_scaled(d, inv_r)))
    } else if rt.far > t_min && rt.far < t_max {
        Some((rt.far, false, rt.normal_far_scaled(d, inv_r)))
    } else {
        None
    }
}

/// The direction renormalised in `f64`: the exact tests assume `d·d = 1`, which an
/// `f32`-normalised direction misses by up to ~1e-7.
#[inline(always)]
fn unit64(d: Vec3) -> DVec3 {
    d.as_dvec3().normalize()
}

/// `false` when the sphere of centre `c` and widened `f32` radius `w` certainly has no
/// crossing with `ray` in `(0, t_max)` (see [`Spheres::may_cross`]).
#[inline(always)]
fn may_cross(c: DVec3, w: f32, ray: &Ray, t_max: f32) -> bool {
    let f = (ray.o64 - c).as_vec3();
    let d = ray.d32;
    let bp = -f.dot(d);
    let l = f + d * bp;
    let ll = l.dot(l);
    let fl = f.dot(f).sqrt();
    // |l| is the distance from the centre to the line, computed without cancellation:
    // it errs from the true one by at most 13u·|f| (u = 2⁻²⁴: f's rounding u|f|, the
    // direction's length off 1 by up to 3.5u, the products' and sums' rounding), and
    // l·l by 3u relative more. So the sphere is widened by 32u·|f| and its square by 8u,
    // with room to spare: a slack on |l| relative to |f|, not on l·l relative to |f|²,
    // which would let far small balls pass for lines well outside them.
    let widened = w + LINE_SLACK * fl;
    let rr = widened * widened * (1.0 + 8.0 * U32);
    // The crossings lie in [bp − h, bp + h] with h the half chord, up to rounding;
    // `rr` keeps this h above the true one, and the tail covers the rounding of bp.
    // (Bounded by r instead of h, a ray leaving a huge sphere's outside — up from the
    // ground — would pass and cost an exact test.) A line that passes too far gives
    // h = NaN, which fails every comparison; `&`, not `&&`: one branch on the outcome
    // (an early return on the first test is mispredicted often enough to cost more
    // than the square roots).
    let reach = (rr - ll).sqrt() + QUICK_SLACK * (fl + w);
    (ll <= rr) & (bp + reach > 0.0) & (bp - reach < t_max)
}

/// The unit roundoff of `f32`.
const U32: f32 = f32::EPSILON / 2.0;

/// The widening of [`may_cross`]'s sphere per unit of distance: 32u.
const LINE_SLACK: f32 = 32.0 * U32;

/// The closest crossing found so far.
#[derive(Clone, Copy)]
struct Best {
    t: f64,
    k: usize,
    entering: bool,
    normal: DVec3,
}

impl Best {
    const NONE: Best = Best {
        t: f64::INFINITY,
        k: usize::MAX,
        entering: false,
        normal: DVec3::ZERO,
    };

    /// Sphere `k`'s crossing at `t` is the closest so far: taken; returns `t` rounded
    /// up, the new bound of the search.
    #[inline(always)]
    fn take(&mut self, t: f64, k: usize, entering: bool, normal: DVec3) -> Option<f32> {
        *self = Best {
            t,
            k,
            entering,
            normal,
        };
        Some(round_up(t))
    }
}

/// Spheres from which the rays inside small spheres walk the hierarchy: with 100,000
/// small balls their lists cost fewer instructions than the walks (4.08 against 4.30
/// billion for a render of many_100000), with a million the walks take 13% less time
/// (making a million lists reads and allocates more than the walks).
const WALK_INSIDE_FROM: usize = 1 << 18;

/// The most spheres overlapping a sphere that its list holds: a ray inside a sphere
/// overlapped by more walks the hierarchy up to the far side. (A test a listed
/// sphere is cheap, but not free: in a clump of balls that all overlap, rays inside
/// them are answered as fast by lists as by the walk at 16 balls, and at 25 the walk
/// is faster.)
const MOST_OVERLAPS: usize = 16;

/// The radius from which a sphere keeps the list of the spheres overlapping it: every
/// sphere in a scene of up to [`WALK_INSIDE_FROM`] spheres, else those more than twice
/// the median radius (the few large balls, which many of the rays going in enter; the
/// small glass balls of such a scene are each entered by a ray or two).
fn list_radius(geometry: &[(DVec3, f64)]) -> f64 {
    if geometry.len() <= WALK_INSIDE_FROM {
        return 0.0;
    }
    let mut sorted: Vec<f64> = geometry.iter().map(|&(_, r)| r).collect();
    let middle = sorted.len() / 2;
    let (_, median, _) = sorted.select_nth_unstable_by(middle, f64::total_cmp);
    2.0 * *median
}

/// `t` as an `f32` no smaller than it.
#[inline(always)]
fn round_up(t: f64) -> f32 {
    // One step up is one more in the bits of a positive `f32` (of +0 the least
    // subnormal, of `f32::MAX` infinity) and one less in those of a negative one (a
    // cast to −0 never rounded down), chosen without a branch: whether the cast
    // rounded the other way is a coin toss, and a mispredicted branch costs more
    // than this.
    let f = t as f32;
    let step = u32::from(f64::from(f) < t);
    let (bits, positive) = (f.to_bits(), f.is_sign_positive());
    let stepped = if positive { bits + step } else { bits - step };
    f32::from_bits(stepped)
}

/// `t` as an `f32` no larger than it: [`round_up`] mirrored (negation is exact in
/// both widths).
#[inline(always)]
fn round_down(t: f64) -> f32 {
    -round_up(-t)
}

#[cfg(test)]
mod tests;
