//! The `f64` reference renderer: the model of SPEC §2 written for clarity, not speed.
//! It tests every sphere for every ray. Tests and benchmarks measure the fast tracer's
//! error against it, so it uses no tolerance that could lose a real hit: spawned rays
//! handle their own sphere exactly (see [`Side`]) and ignore other spheres only within
//! the rounding error of the spawn point.

use glam::{DVec3, Vec3};

use super::intersect::roots;
use super::{RayCounts, SampleTracer};
use crate::camera::Camera;
use crate::model::{self, Branches, Side};

use crate::scene::{Scene, Sphere};

pub struct ReferenceTracer<'a> {
    scene: &'a Scene,
    camera: Camera,
    max_depth: u32,
}

/// A ray with unit direction; `from` is the sphere it was spawned on and which way it
/// leaves it (`None` for primary rays).
#[derive(Clone, Copy)]
struct Ray {
    origin: DVec3,
    dir: DVec3,
    from: Option<(usize, Side)>,
}

struct Hit {
    sphere: usize,
    point: DVec3,
    /// Outward unit normal.
    normal: DVec3,
    /// Hit at the near root: the ray enters the sphere here.
    entering: bool,
}

/// The distance below which a spawned ray ignores *other* spheres: a few rounding
/// errors of the spawn point's coordinates.
fn spawn_tolerance(p: DVec3) -> f64 {
    16.0 * f64::EPSILON * p.abs().max_element()
}

impl<'a> ReferenceTracer<'a> {
    pub fn new(scene: &'a Scene, camera: Camera, max_depth: u32) -> Self {
        ReferenceTracer {
            scene,
            camera,
            max_depth,
        }
    }

    /// The nearest crossing of the ray with sphere `k` beyond `t_min` and below `t_max`,
    /// with whether it is the near (entering) root.
    fn crossing(&self, ray: &Ray, k: usize, t_min: f64, t_max: f64) -> Option<(f64, bool)> {
        let s = &self.scene.spheres[k];
        let r = roots(ray.origin, ray.dir, s.center, s.radius)?;
        let in_range = |t: f64| t > t_min && t < t_max;
        match ray.from {
            Some((own, Side::Outward)) if own == k => None,
            Some((own, Side::Inward)) if own == k => {
                (r.far > 0.0 && r.far < t_max).then_some((r.far, false))
            }
            _ if in_range(r.near) => Some((r.near, true)),
            _ if in_range(r.far) => Some((r.far, false)),
            _ => None,
        }
    }

    fn t_min(ray: &Ray) -> f64 {
        match ray.from {
            None => 0.0,
            Some(_) => spawn_tolerance(ray.origin),
        }
    }

    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        let t_min = Self::t_min(ray);
        let mut best: Option<(f64, usize, bool)> = None;
        for k in 0..self.scene.spheres.len() {
            let t_max = best.map_or(f64::INFINITY, |b| b.0);
            if let Some((t, entering)) = self.crossing(ray, k, t_min, t_max) {
                best = Some((t, k, entering));
            }
        }
        let (t, k, entering) = best?;
        let s = &self.scene.spheres[k];
        // Re-project the hit onto the sphere so that spawned rays start on it.
        let normal = (ray.origin + ray.dir * t - s.center).normalize();
        Some(Hit {
            sphere: k,
            point: s.center + normal * s.radius,
            normal,
            entering,
        })
    }

    /// The shadow factor `s` of step 4 along the segment from the hit to the light.
    fn shadow(&self, from: &Ray, dist: f64) -> f64 {
        let t_min = Self::t_min(from);
        let mut factor = 1.0f64;
        for (k, s) in self.scene.spheres.iter().enumerate() {
            if let Some((t, _)) = self.crossing(from, k, t_min, dist) {
                let n_k = (from.origin + from.dir * t - s.center) / s.radius;
                factor = factor.min(model::occluder_factor(from.dir, n_k));
            }
        }
        factor
    }

    fn trace(&self, ray: &Ray, depth: u32, counts: &mut RayCounts) -> DVec3 {
        let sky = &self.scene.sky;
        if depth >= self.max_depth {
            return model::sky(ray.dir, sky.down, sky.up);
        }
        if depth == 0 {
            counts.primary += 1;
        } else {
            counts.secondary += 1;
        }
        let Some(hit) = self.closest_hit(ray) else {
            return model::sky(ray.dir, sky.down, sky.up);
        };
        let s: &Sphere = &self.scene.spheres[hit.sphere];
        let front = hit.entering;
        let n = hit.normal;
        let nf = if front { n } else { -n };
        let branches = Branches::of(s.reflect, s.transmit);
        let spawn = |dir: DVec3, inside: bool| Ray {
            origin: hit.point,
            dir,
            from: Some((hit.sphere, Side::inside(inside))),
        };

        let mut local = DVec3::ZERO;
        if branches.local {
            for light in &self.scene.lights {
                let to_light = light.position - hit.point;
                let dist = to_light.length();
                let l = to_light / dist;
                let cos = nf.dot(l);
                if cos > 0.0 {
                    counts.shadow += 1;
                    let shadow = self.shadow(&spawn(l, !front), dist);
                    local += model::diffuse(s.color, light.intensity, cos, shadow);
                }
            }
        }
        let reflected = if branches.reflect {
            let dir = model::reflect(ray.dir, n).normalize();
            self.trace(&spawn(dir, !front), depth + 1, counts)
        } else {
            DVec3::ZERO
        };
        let transmitted = if branches.transmit {
            let (dir, crosses) = model::transmit(ray.dir, n, front, s.ior);
            self.trace(&spawn(dir, front == crosses), depth + 1, counts)
        } else {
            DVec3::ZERO
        };
        model::combine(s.reflect, s.transmit, local, reflected, transmitted)
    }

    /// The linear colour of the ray through film position `(s, t)`, in `f64`.
    pub fn sample_f64(&self, s: f64, t: f64, counts: &mut RayCounts) -> DVec3 {
        let c = &self.camera;
        let dir = model::primary_direction(c.lower_left - c.origin, c.horizontal, c.vertical, s, t);
        let ray = Ray {
            origin: c.origin,
            dir,
            from: None,
        };
        self.trace(&ray, 0, counts)
    }
}

impl SampleTracer for ReferenceTracer<'_> {
    fn sample(&self, s: f32, t: f32, counts: &mut RayCounts) -> Vec3 {
        self.sample_f64(f64::from(s), f64::from(t), counts)
            .as_vec3()
    }
}
