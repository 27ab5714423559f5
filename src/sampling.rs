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
    // nx × ny cells cover the pixel; sample k takes cell k.
    let nx = (spp as f32).sqrt().ceil() as u32;
    let ny = spp.div_ceil(nx);
    let (cx, cy) = (k % nx, k / nx);
    let h = hash(i, j, k, seed);
    let unit = |bits: u64| (bits & 0xff_ffff) as f32 * (1.0 / 16_777_216.0);
    let sx = (cx as f32 + unit(h)) / nx as f32;
    let sy = (cy as f32 + unit(h >> 32)) / ny as f32;
    (sx.min(BELOW_ONE), sy.min(BELOW_ONE))
}
