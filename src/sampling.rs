//! Where in a pixel each sample goes: the centre for one sample, otherwise stratified
//! cells jittered by a counter-based hash of (pixel, sample, seed). No state, so an
//! image does not depend on threads, tile order or the render region.

/// A 64-bit finaliser (splitmix64): a good mix of every input bit.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// 64 random bits for sample `k` of pixel `(i, j)`.
#[inline]
pub fn hash(i: u32, j: u32, k: u32, seed: u64) -> u64 {
    mix(mix(mix(seed) ^ (u64::from(i) | u64::from(j) << 32)) ^ u64::from(k))
}

/// The largest `f32` below 1.
const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

/// The offset in `[0,1)²` of sample `k` of `spp` in pixel `(i, j)`.
#[inline]
pub fn sample_offset(i: u32, j: u32, k: u32, spp: u32, seed: u64) -> (f32, f32) {
    if spp <= 1 {
        return (0.5, 0.5);
    }
    // nx × ny cells cover the pixel. When spp < nx·ny some cells stay empty; so that
    // no part of the pixel is favoured, the spp cells taken run on from a start drawn
    // per pixel: every cell is then equally likely to be sampled (no bias).
    let nx = (spp as f32).sqrt().ceil() as u32;
    let ny = spp.div_ceil(nx);
    let cells = nx * ny;
    let start = (hash(i, j, u32::MAX, seed) % u64::from(cells)) as u32;
    let cell = (k + start) % cells;
    let (cx, cy) = (cell % nx, cell / nx);
    let h = hash(i, j, k, seed);
    let unit = |bits: u64| (bits & 0xff_ffff) as f32 * (1.0 / 16_777_216.0);
    let sx = (cx as f32 + unit(h)) / nx as f32;
    let sy = (cy as f32 + unit(h >> 32)) / ny as f32;
    (sx.min(BELOW_ONE), sy.min(BELOW_ONE))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell_of(i: u32, j: u32, k: u32, spp: u32) -> (u32, u32) {
        let nx = (spp as f32).sqrt().ceil() as u32;
        let ny = spp.div_ceil(nx);
        let (sx, sy) = sample_offset(i, j, k, spp, 7);
        ((sx * nx as f32) as u32, (sy * ny as f32) as u32)
    }

    #[test]
    fn one_sample_is_the_pixel_centre() {
        assert_eq!(sample_offset(3, 4, 0, 1, 9), (0.5, 0.5));
    }

    #[test]
    fn a_square_count_puts_one_sample_in_every_cell() {
        for (i, j) in [(0, 0), (5, 9), (1279, 719)] {
            let mut seen = [[0u32; 4]; 4];
            for k in 0..16 {
                let (cx, cy) = cell_of(i, j, k, 16);
                seen[cy as usize][cx as usize] += 1;
            }
            assert_eq!(seen, [[1; 4]; 4], "pixel ({i}, {j})");
        }
    }

    /// 8 samples in a 3×3 grid: each pixel misses one cell, and over many pixels every
    /// cell is missed about equally often (8/9 coverage everywhere, no bias).
    #[test]
    fn a_non_square_count_leaves_out_each_cell_equally_often() {
        let mut covered = [[0u32; 3]; 3];
        let pixels = 9000;
        for p in 0..pixels {
            let mut seen = [[false; 3]; 3];
            for k in 0..8 {
                let (cx, cy) = cell_of(p % 100, p / 100, k, 8);
                assert!(!seen[cy as usize][cx as usize], "two samples in one cell");
                seen[cy as usize][cx as usize] = true;
            }
            for (row, seen_row) in covered.iter_mut().zip(seen) {
                for (c, s) in row.iter_mut().zip(seen_row) {
                    *c += u32::from(s);
                }
            }
        }
        for row in covered {
            for c in row {
                let share = c as f64 / pixels as f64;
                assert!((share - 8.0 / 9.0).abs() < 0.02, "cell covered {share}");
            }
        }
    }
}
