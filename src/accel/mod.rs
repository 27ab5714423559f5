//! What makes the fast tracer fast, invisible to the model: the spheres compiled into
//! the layout the queries want. Every query answers exactly what a test of every
//! sphere would answer; only the work to get there differs.

use glam::{DVec3, Vec3};

use crate::model::Side;
use crate::scene::Sphere;
use crate::trace::intersect::roots;

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub sphere: u32,
    /// The hit point re-projected onto the sphere, in `f64`.
    pub point: DVec3,
    /// Outward unit normal.
    pub normal: DVec3,
    /// Hit at the near root: the ray enters the sphere here.
    pub entering: bool,
}

/// A ray as the queries see it: `f32` origin and unit direction, and the sphere it was
/// spawned on with the way it leaves it.
#[derive(Clone, Copy, Debug)]
pub struct Query {
    pub origin: Vec3,
    pub dir: Vec3,
    pub from: Option<(u32, Side)>,
}

impl Query {
    /// Crossings of other spheres closer than this are lost in the rounding of the
    /// spawn point's `f32` coordinates and ignored.
    #[inline]
    pub fn t_min(&self) -> f64 {
        match self.from {
            None => 0.0,
            Some(_) => 4.0 * f64::from(f32::EPSILON) * f64::from(self.origin.abs().max_element()),
        }
    }
}

/// The spheres, for the fast tracer's queries.
pub struct Spheres {
    center: Vec<DVec3>,
    radius: Vec<f64>,
}

impl Spheres {
    pub fn new(spheres: &[Sphere]) -> Self {
        Spheres {
            center: spheres.iter().map(|s| s.center).collect(),
            radius: spheres.iter().map(|s| s.radius).collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.center.len()
    }

    pub fn is_empty(&self) -> bool {
        self.center.is_empty()
    }

    /// The first crossing of sphere `k` in `(t_min, t_max)`: `(t, entering, normal)`.
    #[inline]
    fn crossing(
        &self,
        k: usize,
        o: DVec3,
        d: DVec3,
        from: Option<(u32, Side)>,
        t_min: f64,
        t_max: f64,
    ) -> Option<(f64, bool, DVec3)> {
        let (c, r) = (self.center[k], self.radius[k]);
        let own = from.filter(|&(s, _)| s as usize == k).map(|(_, side)| side);
        if own == Some(Side::Outward) {
            return None;
        }
        let rt = roots(o, d, c, r)?;
        if own == Some(Side::Inward) {
            return (rt.far > 0.0 && rt.far < t_max).then(|| (rt.far, false, rt.normal_far(d, r)));
        }
        if rt.near > t_min && rt.near < t_max {
            Some((rt.near, true, rt.normal_near(d, r)))
        } else if rt.far > t_min && rt.far < t_max {
            Some((rt.far, false, rt.normal_far(d, r)))
        } else {
            None
        }
    }

    pub fn closest(&self, q: &Query) -> Option<Hit> {
        let (o, d) = (q.origin.as_dvec3(), q.dir.as_dvec3());
        let t_min = q.t_min();
        let mut best: Option<(f64, usize, bool, DVec3)> = None;
        for k in 0..self.len() {
            let t_max = best.map_or(f64::INFINITY, |b| b.0);
            if let Some((t, entering, normal)) = self.crossing(k, o, d, q.from, t_min, t_max) {
                best = Some((t, k, entering, normal));
            }
        }
        let (_, k, entering, normal) = best?;
        let normal = normal.normalize();
        Some(Hit {
            sphere: k as u32,
            point: self.center[k] + normal * self.radius[k],
            normal,
            entering,
        })
    }

    /// The shadow factor along the segment of length `dist` (step 4 of the model).
    pub fn shadow(&self, q: &Query, dist: f64) -> f32 {
        let (o, d) = (q.origin.as_dvec3(), q.dir.as_dvec3());
        let t_min = q.t_min();
        let mut factor = 1.0f32;
        for k in 0..self.len() {
            if let Some((_, _, n_k)) = self.crossing(k, o, d, q.from, t_min, dist) {
                factor = factor.min(crate::model::occluder_factor(q.dir, n_k.as_vec3()));
                if factor <= 0.0 {
                    break;
                }
            }
        }
        factor
    }
}
