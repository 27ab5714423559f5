//! The `f64` reference renderer: the model of SPEC §2 written for clarity, not speed.
//! It tests every sphere for every ray. Tests and benchmarks measure the fast tracer's
//! error against it, so it uses no tolerance that could lose a real hit: spawned rays
//! handle their own sphere exactly (see [`Side`]) and ignore other spheres only within
//! the rounding error of the spawn point.

use glam::{DVec3, Vec3};

use super::{RayCounts, SampleTracer};
use crate::camera::Camera;
use crate::intersect::{power, roots};
use crate::model::{self, Branches, Side};

use crate::scene::{Scene, Sphere};

/// The `f64` reference tracer: the model of SPEC §2 written for clarity, sphere by sphere.
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

/// Which way a ray of the ray tree was cast.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// From the eye.
    Primary,
    /// Reflected (step 5).
    Reflect,
    /// Transmitted or totally internally reflected (step 6).
    Transmit,
}

impl RayKind {
    /// The kind in lower case, for the viewer.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Primary => "primary",
            RayKind::Reflect => "reflect",
            RayKind::Transmit => "transmit",
        }
    }
}

/// Where a recorded ray hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRecord {
    /// The sphere hit (its index in the scene, from 0).
    pub sphere: usize,
    /// The hit point.
    pub point: DVec3,
    /// The outward unit normal there.
    pub normal: DVec3,
    /// The ray enters the sphere here (near root).
    pub entering: bool,
}

/// One shadow ray towards a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowRecord {
    /// The light (its index in the scene, from 0).
    pub light: usize,
    /// The occluder that set the shadow factor (the smallest one), if any.
    pub occluder: Option<usize>,
    /// The shadow factor `s` of step 4.
    pub factor: f64,
    /// This light's diffuse term `kd ⊙ I · cos · s`.
    pub colour: DVec3,
    /// The weight of that term in the pixel.
    pub weight: f64,
}

/// One ray of a ray tree, with what it hit, its shadow rays and its children.
#[derive(Clone, Debug, PartialEq)]
pub struct RayNode {
    /// Which way the ray was cast.
    pub kind: RayKind,
    /// Its depth (0 for a primary ray).
    pub depth: u32,
    /// Its origin.
    pub origin: DVec3,
    /// Its unit direction.
    pub dir: DVec3,
    /// The weight of this ray's colour in the pixel (the product of the mixing weights
    /// of step 7 along the path).
    pub weight: f64,
    /// `None`: the ray saw the sky (or reached the depth limit).
    pub hit: Option<HitRecord>,
    /// The ray was not traced because `depth ≥ max_depth`: its colour is the sky's.
    pub depth_limited: bool,
    /// The shadow rays of the hit, one a light.
    pub shadows: Vec<ShadowRecord>,
    /// The reflected and transmitted rays of the hit.
    pub children: Vec<RayNode>,
    /// The colour `trace` returned for this ray.
    pub colour: DVec3,
}

/// Watches [`ReferenceTracer`] trace a ray. The no-op `()` is what rendering uses; the
/// tracer calls it the same way either way, so recording cannot change a result.
pub trait Recorder {
    /// A ray starts; `mix` is its weight in its parent's colour (1 for a primary ray).
    fn begin(&mut self, _kind: RayKind, _depth: u32, _origin: DVec3, _dir: DVec3, _mix: f64) {}
    /// The ray reached the depth limit.
    fn depth_limit(&mut self) {}
    /// The ray hit a sphere.
    fn hit(&mut self, _hit: &HitRecord) {}
    /// A shadow ray; `mix` is the weight of the local term in this ray's colour.
    fn shadow(
        &mut self,
        _light: usize,
        _occluder: Option<usize>,
        _factor: f64,
        _colour: DVec3,
        _mix: f64,
    ) {
    }
    /// The ray's colour is known.
    fn end(&mut self, _colour: DVec3) {}
}

impl Recorder for () {}

/// Builds the [`RayNode`] tree of one sample.
#[derive(Default)]
pub struct TreeRecorder {
    stack: Vec<RayNode>,
    root: Option<RayNode>,
}

impl TreeRecorder {
    /// The tree recorded so far (the primary ray), once it has finished.
    pub fn into_tree(self) -> Option<RayNode> {
        self.root
    }
}

impl Recorder for TreeRecorder {
    fn begin(&mut self, kind: RayKind, depth: u32, origin: DVec3, dir: DVec3, mix: f64) {
        let parent_weight = self.stack.last().map_or(1.0, |p| p.weight);
        self.stack.push(RayNode {
            kind,
            depth,
            origin,
            dir,
            weight: parent_weight * mix,
            hit: None,
            depth_limited: false,
            shadows: Vec::new(),
            children: Vec::new(),
            colour: DVec3::ZERO,
        });
    }

    fn depth_limit(&mut self) {
        if let Some(node) = self.stack.last_mut() {
            node.depth_limited = true;
        }
    }

    fn hit(&mut self, hit: &HitRecord) {
        if let Some(node) = self.stack.last_mut() {
            node.hit = Some(*hit);
        }
    }

    fn shadow(
        &mut self,
        light: usize,
        occluder: Option<usize>,
        factor: f64,
        colour: DVec3,
        mix: f64,
    ) {
        if let Some(node) = self.stack.last_mut() {
            let weight = node.weight * mix;
            node.shadows.push(ShadowRecord {
                light,
                occluder,
                factor,
                colour,
                weight,
            });
        }
    }

    fn end(&mut self, colour: DVec3) {
        let Some(mut node) = self.stack.pop() else {
            return;
        };
        node.colour = colour;
        match self.stack.last_mut() {
            Some(parent) => parent.children.push(node),
            None => self.root = Some(node),
        }
    }
}

/// The distance below which a spawned ray ignores *other* spheres: a few rounding
/// errors of the spawn point's coordinates.
fn spawn_tolerance(p: DVec3) -> f64 {
    16.0 * f64::EPSILON * p.abs().max_element()
}

impl<'a> ReferenceTracer<'a> {
    /// The tracer of `scene` through `camera`, tracing to depth `max_depth`.
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

    /// The shadow factor `s` of step 4 along the segment from the hit to the light at
    /// `light`, `dist` away, and the occluder that set it.
    fn shadow(&self, from: &Ray, dist: f64, light: DVec3) -> (f64, Option<usize>) {
        let t_min = Self::t_min(from);
        let mut factor = 1.0f64;
        let mut occluder = None;
        for (k, s) in self.scene.spheres.iter().enumerate() {
            let crossing = self
                .crossing(from, k, t_min, dist)
                .filter(|&(t, entering)| {
                    model::crosses_before_light(t, dist, entering, || {
                        power(light, s.center, s.radius)
                    })
                });
            if let Some((t, _)) = crossing {
                let n_k = (from.origin + from.dir * t - s.center) / s.radius;
                let f = model::occluder_factor(from.dir, n_k);
                if occluder.is_none() || f < factor {
                    occluder = Some(k);
                }
                factor = factor.min(f);
            }
        }
        (factor, occluder)
    }

    /// [`Self::trace_ray`] between the recorder's `begin` and `end`.
    fn trace<R: Recorder>(
        &self,
        ray: &Ray,
        depth: u32,
        counts: &mut RayCounts,
        rec: &mut R,
        kind: RayKind,
        mix: f64,
    ) -> DVec3 {
        rec.begin(kind, depth, ray.origin, ray.dir, mix);
        let colour = self.trace_ray(ray, depth, counts, rec);
        rec.end(colour);
        colour
    }

    fn trace_ray<R: Recorder>(
        &self,
        ray: &Ray,
        depth: u32,
        counts: &mut RayCounts,
        rec: &mut R,
    ) -> DVec3 {
        let sky = &self.scene.sky;
        if depth >= self.max_depth {
            rec.depth_limit();
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
        rec.hit(&HitRecord {
            sphere: hit.sphere,
            point: hit.point,
            normal: hit.normal,
            entering: hit.entering,
        });
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

        let local_mix = (1.0 - s.transmit) * (1.0 - s.reflect);
        let mut local = DVec3::ZERO;
        if branches.local {
            for (index, light) in self.scene.lights.iter().enumerate() {
                let to_light = light.position - hit.point;
                let dist = to_light.length();
                let l = to_light / dist;
                let cos = nf.dot(l);
                if cos > 0.0 {
                    counts.shadow += 1;
                    let (shadow, occluder) = self.shadow(&spawn(l, !front), dist, light.position);
                    let term = model::diffuse(s.color, light.intensity, cos, shadow);
                    rec.shadow(index, occluder, shadow, term, local_mix);
                    local += term;
                }
            }
        }
        let reflected = if branches.reflect {
            let dir = model::reflect(ray.dir, n).normalize();
            let mix = (1.0 - s.transmit) * s.reflect;
            let child = spawn(dir, !front);
            self.trace(&child, depth + 1, counts, rec, RayKind::Reflect, mix)
        } else {
            DVec3::ZERO
        };
        let transmitted = if branches.transmit {
            let (dir, crosses) = model::transmit(ray.dir, n, front, s.ior);
            let child = spawn(dir, front == crosses);
            self.trace(
                &child,
                depth + 1,
                counts,
                rec,
                RayKind::Transmit,
                s.transmit,
            )
        } else {
            DVec3::ZERO
        };
        model::combine(s.reflect, s.transmit, local, reflected, transmitted)
    }

    /// The linear colour of the ray through film position `(s, t)`, in `f64`.
    pub fn sample_f64(&self, s: f64, t: f64, counts: &mut RayCounts) -> DVec3 {
        self.sample_recorded(s, t, counts, &mut ())
    }

    /// [`Self::sample_f64`] with its ray tree (for the viewer's pixel inspector).
    pub fn inspect(&self, s: f64, t: f64) -> (DVec3, RayNode) {
        let mut rec = TreeRecorder::default();
        let colour = self.sample_recorded(s, t, &mut RayCounts::default(), &mut rec);
        let tree = rec.into_tree().expect("the primary ray was recorded");
        (colour, tree)
    }

    fn sample_recorded<R: Recorder>(
        &self,
        s: f64,
        t: f64,
        counts: &mut RayCounts,
        rec: &mut R,
    ) -> DVec3 {
        let c = &self.camera;
        let dir = model::primary_direction(c.lower_left - c.origin, c.horizontal, c.vertical, s, t);
        let ray = Ray {
            origin: c.origin,
            dir,
            from: None,
        };
        self.trace(&ray, 0, counts, rec, RayKind::Primary, 1.0)
    }
}

impl SampleTracer for ReferenceTracer<'_> {
    fn sample(&self, s: f32, t: f32, counts: &mut RayCounts) -> Vec3 {
        self.sample_f64(f64::from(s), f64::from(t), counts)
            .as_vec3()
    }
}
