//! Primary rays in bundles. The rays of a run of pixels leave the eye side by side, so
//! they walk the hierarchy as one: each node's boxes are tested once for the bundle
//! (against the interval of its rays' directions), each sphere of a leaf it reaches
//! once for all its rays (the quick test in eight lanes), and only the rays that pass
//! run the exact test. In scenes too large for the eye's grid to pay for its build,
//! a node or leaf record then serves eight rays for one load.

use glam::{DVec3, Vec3};
use wide::{f32x8, CmpGt, CmpLe, CmpLt};

use super::{crossing_of, unit64, Best, Hit, Query, Ray, Spheres, LINE_SLACK, QUICK_SLACK, U32};

/// The most rays of a bundle: a lane each of the quick test.
pub(crate) const BUNDLE: usize = 8;

impl Spheres {
    /// The closest hits of the rays from `origin` with unit directions `dirs` (at most
    /// [`BUNDLE`]; rays with no spawn sphere, such as primary rays), into `hits`: the
    /// same hits as [`Spheres::closest`] of each ray, each sphere the walk reaches
    /// tested for each ray as that walk tests it (of two spheres crossed at exactly
    /// one distance, each walk keeps the first it meets: a leaf's spheres come in one
    /// order to both).
    pub(crate) fn closest_bundle(&self, origin: DVec3, dirs: &[Vec3], hits: &mut [Option<Hit>]) {
        assert!(!dirs.is_empty() && dirs.len() <= BUNDLE && hits.len() == dirs.len());
        // Lanes past the last ray repeat it; their results are not read.
        let ray = |i: usize| {
            Ray::new(&Query {
                origin,
                dir: dirs[i.min(dirs.len() - 1)],
                from: None,
            })
        };
        let rays: [Ray; BUNDLE] = std::array::from_fn(ray);
        let d64 = rays.map(|ray| unit64(ray.d32));
        let lanes = Lanes::new(&rays, dirs.len());
        let (mut inv_lo, mut inv_hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for inv in dirs.iter().map(|d| d.recip()) {
            inv_lo = inv_lo.min(inv);
            inv_hi = inv_hi.max(inv);
        }
        let mut best = [Best::NONE; BUNDLE];
        // Each ray's bound, as its own walk keeps it: its closest hit so far, rounded up.
        let mut t_max = [f32::INFINITY; BUNDLE];
        self.bvh
            .traverse_bundle(origin.as_vec3(), inv_lo, inv_hi, |slot| {
                let s = &self.leaf[slot as usize];
                let k = s.k as usize;
                let mut pass = lanes.may_cross(origin, s.exact.center, s.quick_radius, &t_max);
                while pass != 0 {
                    let i = pass.trailing_zeros() as usize;
                    pass &= pass - 1;
                    if let Some((t, entering, normal)) =
                        crossing_of(k, &s.exact, &rays[i], d64[i], best[i].t)
                    {
                        t_max[i] = best[i].take(t, k, entering, normal).unwrap_or(t_max[i]);
                    }
                }
                lanes.largest(&t_max)
            });
        for (hit, best) in hits.iter_mut().zip(best) {
            *hit = self.finish(best);
        }
    }
}

/// A bundle's directions, a lane per ray, for [`super::may_cross`] of all its rays at once.
struct Lanes {
    d: [f32x8; 3],
    /// The lanes that hold a ray.
    used: u32,
}

impl Lanes {
    fn new(rays: &[Ray; BUNDLE], len: usize) -> Lanes {
        Lanes {
            d: [0, 1, 2].map(|a| f32x8::from(rays.map(|ray| ray.d32[a]))),
            used: (1 << len) - 1,
        }
    }

    /// [`super::may_cross`] of the sphere of centre `c` and widened radius `w` for each
    /// ray, its bound `t_max[i]`: bit `i` set when ray `i` may cross it. The same
    /// arithmetic, in the same order, lane by lane: the same answers.
    #[inline(always)]
    fn may_cross(&self, origin: DVec3, c: DVec3, w: f32, t_max: &[f32; BUNDLE]) -> u32 {
        let f = (origin - c).as_vec3();
        let fl = f.dot(f).sqrt();
        let widened = w + LINE_SLACK * fl;
        let rr = f32x8::splat(widened * widened * (1.0 + 8.0 * U32));
        let [dx, dy, dz] = self.d;
        let (fx, fy, fz) = (f32x8::splat(f.x), f32x8::splat(f.y), f32x8::splat(f.z));
        let bp = -(fx * dx + fy * dy + fz * dz);
        let (lx, ly, lz) = (fx + dx * bp, fy + dy * bp, fz + dz * bp);
        let ll = lx * lx + ly * ly + lz * lz;
        let reach = (rr - ll).sqrt() + f32x8::splat(QUICK_SLACK * (fl + w));
        let pass = ll.cmp_le(rr)
            & (bp + reach).cmp_gt(f32x8::ZERO)
            & (bp - reach).cmp_lt(f32x8::from(*t_max));
        pass.move_mask() as u32 & self.used
    }

    /// The largest of the rays' bounds: the bundle's.
    fn largest(&self, t_max: &[f32; BUNDLE]) -> f32 {
        let mut used = self.used;
        let mut largest = 0.0f32;
        while used != 0 {
            largest = largest.max(t_max[used.trailing_zeros() as usize]);
            used &= used - 1;
        }
        largest
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::may_cross;

    /// The lanes' quick test answers as [`may_cross`] does for each ray, bit for bit:
    /// spheres from 10⁻³ to 10³ in radius, 10⁻² to 10⁴ away, near and far from the
    /// rays, bounds from none to within the sphere; lanes past the last ray never pass.
    #[test]
    fn the_lanes_quick_test_is_may_cross_ray_by_ray() {
        let mut unit = crate::accel::tests::uniform(5);
        let (mut passed, mut failed) = (0u32, 0u32);
        for case in 0..20_000 {
            let origin = DVec3::new(unit(), unit(), unit()) * 200.0 - 100.0;
            let len = 1 + case % BUNDLE;
            let aim = (DVec3::new(unit(), unit(), unit()) * 2.0 - 1.0).normalize();
            let r = 10f64.powf(unit() * 6.0 - 3.0);
            let dist = 10f64.powf(unit() * 6.0 - 2.0);
            let c = origin + aim * dist;
            // Rays that pass within a few radii of the centre, or, one case in four,
            // anywhere.
            let spread = if case % 4 == 0 { 1.0 } else { 3.0 * r / dist };
            let rays: [Ray; BUNDLE] = std::array::from_fn(|_| {
                let d = aim + (DVec3::new(unit(), unit(), unit()) - 0.5) * spread;
                Ray::new(&Query {
                    origin,
                    dir: d.normalize().as_vec3().normalize(),
                    from: None,
                })
            });
            let w = crate::accel::quick_radius(c, r);
            let t_max: [f32; BUNDLE] = std::array::from_fn(|i| match (case + i) % 3 {
                0 => f32::INFINITY,
                1 => (dist * unit()) as f32,
                _ => (dist + r * (2.0 * unit() - 1.0)) as f32,
            });
            let lanes = Lanes::new(&rays, len);
            let got = lanes.may_cross(origin, c, w, &t_max);
            for (i, ray) in rays.iter().enumerate() {
                let want = i < len && may_cross(c, w, ray, t_max[i]);
                assert_eq!(got >> i & 1 == 1, want, "case {case}, lane {i}");
                passed += u32::from(want);
                failed += u32::from(i < len && !want);
            }
        }
        println!("{passed} lanes passed, {failed} failed");
        assert!(passed > 10_000 && failed > 10_000, "{passed} {failed}");
    }

    /// The lanes' quick test agrees with [`may_cross`] at the edge of its sphere too:
    /// rays bisected, one `f32` direction at a time, to the last that passes the line
    /// test (the line's squared distance from the centre within a few roundings of
    /// the widened radius's square), with its neighbour that fails beside it in the
    /// bundle; and bounds bisected to the least that the ray through the centre
    /// passes with, beside the one below.
    #[test]
    fn the_lanes_quick_test_is_may_cross_at_the_sphere_s_edge() {
        let mut unit = crate::accel::tests::uniform(11);
        let mut edges = 0;
        for case in 0..2_000 {
            let origin = DVec3::new(unit(), unit(), unit()) * 20.0 - 10.0;
            let aim = (DVec3::new(unit(), unit(), unit()) * 2.0 - 1.0).normalize();
            let side = aim.any_orthonormal_vector();
            let r = 10f64.powf(unit() * 2.0 - 1.0);
            let c = origin + aim * r * (1.5 + 2.0 * unit());
            let w = crate::accel::quick_radius(c, r);
            let ray = |s: f64| {
                Ray::new(&Query {
                    origin,
                    dir: (aim + side * s).normalize().as_vec3().normalize(),
                    from: None,
                })
            };
            let passes = |s: f64| may_cross(c, w, &ray(s), f32::INFINITY);
            // From the centre's line (passing) to well outside the sphere (failing).
            let (mut inside, mut outside) = (0.0, 2.0);
            assert!(passes(inside) && !passes(outside), "case {case}");
            for _ in 0..80 {
                let mid = 0.5 * (inside + outside);
                if passes(mid) {
                    inside = mid;
                } else {
                    outside = mid;
                }
            }
            let rays: [Ray; BUNDLE] =
                std::array::from_fn(|i| ray(if i % 2 == 0 { inside } else { outside }));
            let lanes = Lanes::new(&rays, BUNDLE);
            let got = lanes.may_cross(origin, c, w, &[f32::INFINITY; BUNDLE]);
            for (i, ray) in rays.iter().enumerate() {
                let want = may_cross(c, w, ray, f32::INFINITY);
                assert_eq!(got >> i & 1 == 1, want, "case {case}, lane {i}");
            }
            edges += usize::from(rays[0].d32 != rays[1].d32);
            // And at the bound: the least `f32` bound the ray through the centre
            // passes with (bisected on the bits, monotone for positive floats),
            // beside the one below it.
            let centre_ray = ray(0.0);
            let reaches = |bits: u32| may_cross(c, w, &centre_ray, f32::from_bits(bits));
            let (mut short, mut long) = (0.0f32.to_bits(), 1e4f32.to_bits());
            assert!(!reaches(short) && reaches(long), "case {case}");
            while long - short > 1 {
                let mid = short + (long - short) / 2;
                if reaches(mid) {
                    long = mid;
                } else {
                    short = mid;
                }
            }
            let t_max: [f32; BUNDLE] =
                std::array::from_fn(|i| f32::from_bits(if i % 2 == 0 { long } else { short }));
            let lanes = Lanes::new(&[centre_ray; BUNDLE], BUNDLE);
            assert_eq!(
                lanes.may_cross(origin, c, w, &t_max),
                0b0101_0101,
                "case {case}: the bound's edge"
            );
        }
        assert!(edges > 1_900, "{edges} edges between two directions");
    }

    /// The bundle's bound is the largest of its rays' bounds, lanes past the last
    /// left out.
    #[test]
    fn the_bundle_s_bound_is_the_largest_of_its_rays() {
        let t_max = [3.0, 1.0, 7.0, 2.0, f32::INFINITY, 0.5, 9.0, 4.0];
        let ray = Ray::new(&Query {
            origin: DVec3::ZERO,
            dir: Vec3::X,
            from: None,
        });
        let largest = |len| Lanes::new(&[ray; BUNDLE], len).largest(&t_max);
        assert_eq!(largest(1), 3.0);
        assert_eq!(largest(2), 3.0);
        assert_eq!(largest(3), 7.0);
        assert_eq!(largest(4), 7.0);
        assert_eq!(largest(5), f32::INFINITY);
        assert_eq!(largest(8), f32::INFINITY);
    }
}
