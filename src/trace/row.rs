//! The primary directions of a run of pixels in one image row, and the sky seen along
//! them, four at a time in `f32` lanes. Each lane does the operations of
//! [`model::primary_direction`] and [`model::sky`] in the same order, and the lanes'
//! additions, products, square roots and divisions round as the scalar ones do, so
//! the values are the same to the bit.

use glam::Vec3;
use wide::f32x4;

#[cfg(doc)]
use crate::model;

/// Pixels in a run: two groups of four lanes.
pub const RUN: usize = 8;

/// A row's camera terms: the film corner and spans, with the row's height applied.
#[derive(Clone, Copy)]
pub struct RowCamera {
    corner: Vec3,
    horizontal: Vec3,
    /// `vertical · t` for the row's film height `t`.
    up: Vec3,
}

impl RowCamera {
    pub fn new(corner: Vec3, horizontal: Vec3, vertical: Vec3, t: f32) -> Self {
        RowCamera {
            corner,
            horizontal,
            up: vertical * t,
        }
    }

    /// `model::primary_direction` of `s` (at most [`RUN`] film abscissae) into `out`.
    #[inline(always)]
    pub fn directions(&self, s: &[f32], out: &mut [Vec3; RUN]) {
        debug_assert!(!s.is_empty() && s.len() <= RUN);
        let last = s[s.len() - 1];
        let s_at = |i: usize| s.get(i).copied().unwrap_or(last);
        for (g, out) in out.chunks_exact_mut(4).enumerate() {
            let s = f32x4::new(std::array::from_fn(|i| s_at(4 * g + i)));
            // ((corner + h·s) + v·t), then · 1/√(d·d) with d·d = (x² + y²) + z².
            let along = |c: f32, h: f32, v: f32| (f32x4::splat(c) + f32x4::splat(h) * s) + v;
            let (c, h, v) = (self.corner, self.horizontal, self.up);
            let x = along(c.x, h.x, v.x);
            let y = along(c.y, h.y, v.y);
            let z = along(c.z, h.z, v.z);
            let inv = f32x4::ONE / (x * x + y * y + z * z).sqrt();
            let (x, y, z) = (
                (x * inv).to_array(),
                (y * inv).to_array(),
                (z * inv).to_array(),
            );
            for (i, o) in out.iter_mut().enumerate() {
                *o = Vec3::new(x[i], y[i], z[i]);
            }
        }
    }
}

/// `model::sky` of each direction of `d` into `out`, four lanes at a time.
pub fn sky(d: &[Vec3; RUN], down: Vec3, up: Vec3, out: &mut [Vec3]) {
    for (d, out) in d.chunks_exact(4).zip(out.chunks_mut(4)) {
        let y = f32x4::new(std::array::from_fn(|i| d[i].y));
        // t = ½(y + 1); down·(1 − t) + up·t.
        let t = f32x4::splat(0.5) * (y + f32x4::ONE);
        let rest = f32x4::ONE - t;
        let mix = |a: f32, b: f32| (f32x4::splat(a) * rest + f32x4::splat(b) * t).to_array();
        let (r, g, b) = (mix(down.x, up.x), mix(down.y, up.y), mix(down.z, up.z));
        for (i, o) in out.iter_mut().enumerate() {
            *o = Vec3::new(r[i], g[i], b[i]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model;

    #[test]
    fn lanes_give_the_scalar_directions_and_sky_to_the_bit() {
        let (corner, h, v) = (
            Vec3::new(-4.0, -2.25, -1.0),
            Vec3::new(8.0, 0.0, 0.0),
            Vec3::new(0.0, 4.5, 0.0),
        );
        let (down, up) = (Vec3::ONE, Vec3::new(0.5, 0.7, 1.0));
        for j in 0..97 {
            let t = (j as f32 + 0.5) / 97.0;
            let row = RowCamera::new(corner, h, v, t);
            for len in 1..=RUN {
                for start in [0.0f32, 0.013, 0.5, 0.97] {
                    let s: Vec<f32> = (0..len).map(|i| start + i as f32 * 0.0071).collect();
                    let mut d = [Vec3::ZERO; RUN];
                    row.directions(&s, &mut d);
                    let mut colours = vec![Vec3::ZERO; len];
                    sky(&d, down, up, &mut colours);
                    for (i, &s) in s.iter().enumerate() {
                        let want = model::primary_direction(corner, h, v, s, t);
                        assert_eq!(
                            d[i].to_array().map(f32::to_bits),
                            want.to_array().map(f32::to_bits)
                        );
                        let sky = model::sky(want, down, up);
                        assert_eq!(
                            colours[i].to_array().map(f32::to_bits),
                            sky.to_array().map(f32::to_bits)
                        );
                    }
                }
            }
        }
    }
}
