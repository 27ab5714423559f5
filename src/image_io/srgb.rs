//! Linear values to sRGB bytes: `round(clamp(srgb(c), 0, 1)·255)` with the sRGB
//! transfer curve `srgb(c) = 12.92·c` for `c ≤ 0.0031308`, else
//! `1.055·c^(1/2.4) − 0.055` (IEC 61966-2-1).
//!
//! The window converts every pixel of every frame, so the curve is not evaluated per
//! value: a table holds, for each bucket of f32 values (an exponent and the top 7
//! mantissa bits: a relative width of at most 2⁻⁷), the byte at the bucket's start and
//! where in the bucket the byte goes up by one. The bytes' spacing in linear values is
//! at least 1/113 relative (at 1; wider below), so a bucket holds at most one step, and
//! a byte is one load and one comparison. The table is built from the formula in
//! `f64` ([`to_byte_srgb_exact`]), so both give the same byte for every `f32`.

use std::sync::LazyLock;

/// The lowest bucket starts at 2⁻¹³ (every value below gives byte 0: the first step
/// is at 1.5·10⁻⁴); the last holds 1.0 alone.
const FIRST: u32 = (127 - 13) << 23;
const BUCKETS: usize = ((1.0f32.to_bits() - FIRST) >> 16) as usize + 1;
/// A threshold no value within a bucket reaches: the byte does not step there.
const NO_STEP: u32 = 1 << 16;

/// The bucket table: for each bucket, `byte << 24 | step`, where values whose low 16
/// bits are `step` or more get `byte + 1`.
pub struct SrgbTable([u32; BUCKETS]);

impl std::fmt::Debug for SrgbTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SrgbTable({BUCKETS} buckets)")
    }
}

static TABLE: LazyLock<Box<SrgbTable>> = LazyLock::new(SrgbTable::build);

impl SrgbTable {
    /// The table, built on first use.
    pub fn get() -> &'static SrgbTable {
        &TABLE
    }

    fn build() -> Box<SrgbTable> {
        let mut table = Box::new(SrgbTable([0; BUCKETS]));
        for (b, entry) in table.0.iter_mut().enumerate() {
            let first = FIRST + ((b as u32) << 16);
            let last = (first | 0xffff).min(1.0f32.to_bits());
            let byte = |low: u32| to_byte_srgb_exact(f32::from_bits(first | low));
            let (lo, hi) = (byte(0), byte(last & 0xffff));
            let step = if lo == hi {
                NO_STEP
            } else {
                assert_eq!(hi, lo + 1, "two steps in the bucket at {first:#x}");
                // The first low half-word that gives `hi`.
                let (mut below, mut at) = (0u32, last & 0xffff);
                while at - below > 1 {
                    let mid = (below + at) / 2;
                    if byte(mid) == hi {
                        at = mid;
                    } else {
                        below = mid;
                    }
                }
                at
            };
            *entry = u32::from(lo) << 24 | step;
        }
        table
    }

    /// The sRGB byte of linear value `c` (NaN gives 0), without a branch.
    #[inline(always)]
    pub fn byte(&self, c: f32) -> u8 {
        // `max` drops a NaN, so NaN gives 0.
        #[allow(clippy::manual_clamp)] // not `clamp`, which would keep a NaN
        let bits = c.max(0.0).min(1.0).to_bits();
        // Values below the first bucket share its entry, which has no step.
        let bucket = ((bits >> 16).saturating_sub(FIRST >> 16)) as usize;
        let entry = self.0[bucket.min(BUCKETS - 1)];
        let up = u32::from(bits & 0xffff >= entry & 0x1_ffff);
        ((entry >> 24) + up) as u8
    }
}

/// The sRGB byte of linear value `c` (NaN gives 0), by the table.
#[inline]
pub fn to_byte_srgb(c: f32) -> u8 {
    SrgbTable::get().byte(c)
}

/// The sRGB byte of linear value `c` (NaN gives 0), by the formula in `f64`: what
/// [`to_byte_srgb`] computes, slowly.
pub fn to_byte_srgb_exact(c: f32) -> u8 {
    if c.is_nan() {
        return 0;
    }
    let c = f64::from(c.clamp(0.0, 1.0));
    let s = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each encoder gives the SPEC's bytes, worked by hand: linear
    /// `round(clamp(c)·255)` with halves away from zero, and sRGB through
    /// `12.92c` or `1.055·c^(1/2.4) − 0.055` (c = 0.5: 187.516 → 188; 0.2: 123.555 →
    /// 124; 0.05: 63.189 → 63; 0.001: 3.295 → 3); out of range and NaN clamp.
    #[test]
    fn byte_encoders_give_the_spec_s_bytes_by_hand() {
        use crate::image_io::ByteEncoder;
        use crate::settings::Encoding;
        let linear = ByteEncoder::new(Encoding::Linear);
        for (c, byte) in [
            (0.0, 0),
            (1.0, 255),
            (0.5, 128),
            (0.2, 51),
            (0.75, 191),
            (-0.5, 0),
            (7.0, 255),
            (f32::NAN, 0),
        ] {
            assert_eq!(linear.byte(c), byte, "linear {c}");
        }
        let srgb = ByteEncoder::new(Encoding::Srgb);
        for (c, byte) in [
            (0.0, 0),
            (1.0, 255),
            (0.5, 188),
            (0.2, 124),
            (0.05, 63),
            (0.001, 3),
            (-0.5, 0),
            (7.0, 255),
            (f32::NAN, 0),
        ] {
            assert_eq!(srgb.byte(c), byte, "sRGB {c}");
        }
    }

    #[test]
    fn buckets_cover_two_to_the_minus_13_up_to_one() {
        assert_eq!(f32::from_bits(FIRST), 2f32.powi(-13));
        assert_eq!(BUCKETS, 13 * 128 + 1);
        // The first step (byte 1) lies beyond the first bucket.
        assert_eq!(SrgbTable::get().0[0], NO_STEP);
        assert_eq!(SrgbTable::get().0[BUCKETS - 1], 255 << 24 | NO_STEP);
    }
}
