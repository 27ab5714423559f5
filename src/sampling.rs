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
    Strata::new(spp).of_pixel(i, j, seed).offset(k)
}

/// The cells that stratify a pixel's samples ([`sample_offset`]), worked out once for
/// all the pixels of a render.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Strata {
    spp: u32,
    nx: u32,
    ny: u32,
}

impl Strata {
    pub(crate) fn new(spp: u32) -> Strata {
        // nx × ny cells cover the pixel (one for a sample at its centre).
        let nx = (spp.max(1) as f32).sqrt().ceil() as u32;
        Strata {
            spp,
            nx,
            ny: spp.max(1).div_ceil(nx),
        }
    }

    /// What the samples of pixel `(i, j)` share: where their cells start.
    #[inline]
    pub(crate) fn of_pixel(&self, i: u32, j: u32, seed: u64) -> PixelStrata {
        // When spp < nx·ny some cells stay empty; so that no part of the pixel is
        // favoured, the spp cells taken run on from a start drawn per pixel: every
        // cell is then equally likely to be sampled (no bias).
        let cells = self.nx * self.ny;
        let start = if self.spp <= 1 {
            0
        } else {
            (hash(i, j, u32::MAX, seed) % u64::from(cells)) as u32
        };
        PixelStrata {
            strata: *self,
            pixel: (i, j),
            seed,
            start,
        }
    }
}

/// The strata of one pixel's samples ([`Strata::of_pixel`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PixelStrata {
    strata: Strata,
    pixel: (u32, u32),
    seed: u64,
    start: u32,
}

impl PixelStrata {
    /// [`sample_offset`] of sample `k` of the pixel.
    #[inline]
    pub(crate) fn offset(&self, k: u32) -> (f32, f32) {
        let Strata { spp, nx, ny } = self.strata;
        if spp <= 1 {
            return (0.5, 0.5);
        }
        let cell = (k + self.start) % (nx * ny);
        let (cx, cy) = (cell % nx, cell / nx);
        let ((i, j), seed) = (self.pixel, self.seed);
        let h = hash(i, j, k, seed);
        let unit = |bits: u64| (bits & 0xff_ffff) as f32 * (1.0 / 16_777_216.0);
        let sx = (cx as f32 + unit(h)) / nx as f32;
        let sy = (cy as f32 + unit(h >> 32)) / ny as f32;
        (sx.min(BELOW_ONE), sy.min(BELOW_ONE))
    }
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

    /// The first outputs of splitmix64 seeded with 0 (its state steps by the golden
    /// gamma `0x9e3779b97f4a7c15`), as printed by Vigna's reference `splitmix64.c`.
    #[test]
    fn mix_is_splitmix64_s_finaliser() {
        let gamma = 0x9e37_79b9_7f4a_7c15u64;
        let published = [
            0xe220_a839_7b1d_cdaf,
            0x6e78_9e6a_a1b9_65f4,
            0x06c4_5d18_8009_454f,
            0xf88b_b8a8_724c_81ec,
        ];
        for (n, want) in (1u64..).zip(published) {
            assert_eq!(mix(gamma.wrapping_mul(n)), want, "output {n}");
        }
    }

    /// A counter-based hash of (pixel, sample, seed): flipping any one bit of any input
    /// changes the hash, about half of its 64 bits on average (avalanche).
    #[test]
    fn hash_depends_on_every_bit_of_every_input() {
        let (i, j, k, seed) = (1234u32, 567u32, 9u32, 0x5eed_u64);
        let base = hash(i, j, k, seed);
        let mut flipped = Vec::new();
        for b in 0..32 {
            flipped.push(hash(i ^ 1 << b, j, k, seed));
            flipped.push(hash(i, j ^ 1 << b, k, seed));
            flipped.push(hash(i, j, k ^ 1 << b, seed));
        }
        for b in 0..64 {
            flipped.push(hash(i, j, k, seed ^ 1 << b));
        }
        let changed: Vec<u32> = flipped.iter().map(|h| (h ^ base).count_ones()).collect();
        assert!(changed.iter().all(|&c| c > 0), "{changed:?}");
        let mean = changed.iter().sum::<u32>() as f64 / changed.len() as f64;
        // 160 flips of Binomial(64, ½) bits: mean 32, standard error 0.32.
        assert!((mean - 32.0).abs() < 2.0, "mean {mean} bits changed");
    }

    /// Where each sample sits inside its cell is uniform on [0, 1)² (10 bins a side
    /// hold a tenth each), and no two samples of the 64×64 pixels share a position.
    #[test]
    fn jitter_is_uniform_inside_the_cells_and_never_repeats() {
        let spp = 16;
        let mut bins = [[0u32; 10]; 2];
        let mut positions = std::collections::HashSet::new();
        let mut sums = [0.0f64; 2];
        for j in 0..64 {
            for i in 0..64 {
                for k in 0..spp {
                    let (sx, sy) = sample_offset(i, j, k, spp, 3);
                    let new = positions.insert((sx.to_bits(), sy.to_bits()));
                    assert!(new, "pixel ({i}, {j}) sample {k} repeats a position");
                    for (axis, s) in [sx, sy].into_iter().enumerate() {
                        let within = (f64::from(s) * 4.0).fract();
                        sums[axis] += within;
                        bins[axis][(within * 10.0) as usize] += 1;
                    }
                }
            }
        }
        let n = 64.0 * 64.0 * f64::from(spp);
        for axis in 0..2 {
            // Mean ½ within 0.005 (the standard error is 0.0011).
            assert!(
                (sums[axis] / n - 0.5).abs() < 0.005,
                "axis {axis}: {}",
                sums[axis] / n
            );
            for b in bins[axis] {
                // 6,554 expected a bin, standard deviation 77.
                assert!(
                    (f64::from(b) / n - 0.1).abs() < 0.005,
                    "axis {axis}: {:?}",
                    bins[axis]
                );
            }
        }
    }

    /// Offsets stay below 1 (SPEC §2: in [0,1)²) even where `(cy + jitter)/ny` rounds
    /// up to 1 in `f32`: sample 3 of 4 of pixel (2544, 731), seed 7 (found by a search
    /// over the hash) falls in the top row of cells with all 24 jitter bits set.
    #[test]
    fn the_topmost_jitter_stays_inside_the_pixel() {
        let (i, j, k, spp, seed) = (2544, 731, 3, 4, 7);
        assert_eq!(hash(i, j, k, seed) >> 32 & 0xff_ffff, 0xff_ffff);
        let (_, sy) = sample_offset(i, j, k, spp, seed);
        assert!(sy < 1.0, "{sy}");
        // At most a rounding step or two of f32 below 1 (6e-8 each).
        assert!(sy > 1.0 - 1e-7, "{sy}");
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
