//! A directional grid around one point: a cube map whose cells list the spheres seen
//! in that cell's directions, nearest first. Rays through the point — primary rays
//! from the camera, shadow rays to a point light — test only their cell's spheres:
//! the "light buffer" of Haines and Greenberg (1986), used for the eye as well.
//!
//! Cells are filled conservatively (a sphere's bounding box, widened), so a query
//! sees every sphere it could hit: the grid changes the work, never the answer.

use glam::{DVec3, Vec3};

pub struct DirGrid {
    /// The point every ray of the grid passes through.
    pub centre: Vec3,
    /// Cells per face side.
    n: u32,
    /// Cell `c` lists `items[offsets[c]..offsets[c+1]]`.
    offsets: Vec<u32>,
    items: Vec<u32>,
    /// Per item entry: the sphere's nearest distance from the centre, rounded down.
    near: Vec<f32>,
    /// Spheres that contain the centre: seen in every direction.
    pub always: Vec<u32>,
}

/// Widening of each sphere's range in face coordinates (cells are `2/n` wide): covers
/// the rounding of query directions many times over.
const WIDEN: f64 = 1e-4;

impl DirGrid {
    /// Builds the grid around `centre` for spheres `(centre, radius)`.
    pub fn build(centre: DVec3, spheres: &[(DVec3, f64)], n: u32) -> DirGrid {
        let faces = 6 * (n as usize) * (n as usize);
        let mut always = Vec::new();
        // Each sphere's cell rectangles per face: (face, u0, u1, v0, v1), inclusive.
        let mut rects: Vec<(u32, [u32; 5])> = Vec::new();
        for (k, &(c, r)) in spheres.iter().enumerate() {
            let rel = c - centre;
            let reach = r * (1.0 + 1e-6) + 1e-9 * rel.abs().max_element();
            if rel.length() <= reach {
                always.push(k as u32);
                continue;
            }
            let lo = rel - DVec3::splat(reach);
            let hi = rel + DVec3::splat(reach);
            for face in 0..6u32 {
                if let Some(rect) = face_rect(face, lo, hi, n) {
                    rects.push((k as u32, rect));
                }
            }
        }
        // Count, then fill (CSR).
        let mut counts = vec![0u32; faces + 1];
        for (_, [f, u0, u1, v0, v1]) in &rects {
            for v in *v0..=*v1 {
                for u in *u0..=*u1 {
                    counts[cell_index(*f, u, v, n)] += 1;
                }
            }
        }
        let mut offsets = Vec::with_capacity(faces + 1);
        let mut total = 0u32;
        for &c in &counts[..faces] {
            offsets.push(total);
            total += c;
        }
        offsets.push(total);
        let mut fill = offsets.clone();
        let mut items = vec![0u32; total as usize];
        for (k, [f, u0, u1, v0, v1]) in &rects {
            for v in *v0..=*v1 {
                for u in *u0..=*u1 {
                    let cell = cell_index(*f, u, v, n);
                    items[fill[cell] as usize] = *k;
                    fill[cell] += 1;
                }
            }
        }
        // Nearest first in every cell, so closest-hit queries can stop early.
        let near_of = |k: u32| {
            let (c, r) = spheres[k as usize];
            let d = ((c - centre).length() - r)
                - 1e-6 * ((c - centre).length() + r + centre.abs().max_element());
            // Round down so the early exit stays conservative.
            let f = d as f32;
            if f64::from(f) > d {
                f.next_down()
            } else {
                f
            }
        };
        let mut near = vec![0.0f32; items.len()];
        for cell in 0..faces {
            let range = offsets[cell] as usize..offsets[cell + 1] as usize;
            let list = &mut items[range.clone()];
            list.sort_unstable_by(|&a, &b| near_of(a).total_cmp(&near_of(b)));
            for (slot, &k) in near[range].iter_mut().zip(list.iter()) {
                *slot = near_of(k);
            }
        }
        DirGrid {
            centre: centre.as_vec3(),
            n,
            offsets,
            items,
            near,
            always,
        }
    }

    /// The cell of direction `d` (any length, not zero).
    #[inline]
    pub fn cell(&self, d: Vec3) -> usize {
        let a = d.abs();
        let (face, major, u, v) = if a.x >= a.y && a.x >= a.z {
            (u32::from(d.x < 0.0), a.x, d.y, d.z)
        } else if a.y >= a.z {
            (2 + u32::from(d.y < 0.0), a.y, d.x, d.z)
        } else {
            (4 + u32::from(d.z < 0.0), a.z, d.x, d.y)
        };
        let n = self.n as f32;
        let to_cell = |x: f32| (((x / major + 1.0) * 0.5 * n) as u32).min(self.n - 1);
        cell_index(face, to_cell(u), to_cell(v), self.n)
    }

    /// The spheres of a cell, nearest first, with their nearest distances.
    #[inline]
    pub fn candidates(&self, cell: usize) -> (&[u32], &[f32]) {
        let range = self.offsets[cell] as usize..self.offsets[cell + 1] as usize;
        (&self.items[range.clone()], &self.near[range])
    }
}

#[inline]
fn cell_index(face: u32, u: u32, v: u32, n: u32) -> usize {
    ((face * n + v) * n + u) as usize
}

/// The cells of `face` that the box `[lo, hi]` (relative to the centre) may be seen in,
/// as `[face, u0, u1, v0, v1]`, or `None` when the box is not seen in that face.
fn face_rect(face: u32, lo: DVec3, hi: DVec3, n: u32) -> Option<[u32; 5]> {
    let axis = (face / 2) as usize;
    let (b, c) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    // Coordinates with the face's axis pointing outwards.
    let (a_lo, a_hi) = if face % 2 == 0 {
        (lo[axis], hi[axis])
    } else {
        (-hi[axis], -lo[axis])
    };
    if a_hi <= 0.0 {
        return None;
    }
    let range = |x_lo: f64, x_hi: f64| -> (f64, f64) {
        if a_lo <= 0.0 {
            return (-1.0, 1.0);
        }
        // x/a over the box: smallest with the largest a when x ≥ 0, and so on.
        let min = x_lo / if x_lo >= 0.0 { a_hi } else { a_lo };
        let max = x_hi / if x_hi >= 0.0 { a_lo } else { a_hi };
        (min, max)
    };
    let (u_lo, u_hi) = range(lo[b], hi[b]);
    let (v_lo, v_hi) = range(lo[c], hi[c]);
    let (u_lo, u_hi, v_lo, v_hi) = (u_lo - WIDEN, u_hi + WIDEN, v_lo - WIDEN, v_hi + WIDEN);
    if u_lo > 1.0 || u_hi < -1.0 || v_lo > 1.0 || v_hi < -1.0 {
        return None;
    }
    let to_cell = |x: f64| {
        let x = x.clamp(-1.0, 1.0);
        (((x + 1.0) * 0.5 * f64::from(n)) as u32).min(n - 1)
    };
    Some([
        face,
        to_cell(u_lo),
        to_cell(u_hi),
        to_cell(v_lo),
        to_cell(v_hi),
    ])
}
