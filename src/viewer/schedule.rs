//! Progressive refinement: the passes one view is rendered in. First a coarse preview
//! at a fraction of the resolution (fast, so that dragging the mouse stays fluid), then
//! the full resolution at one sample per pixel, then more samples in growing batches
//! up to the target. Sample batches cover `0..spp` in order without gaps, so the sums
//! (and so the pixels) equal a single render of all samples.

use std::ops::Range;

/// The preview has 1/`PREVIEW_FACTOR` of the width and of the height.
pub const PREVIEW_FACTOR: u32 = 4;
/// No preview for images with fewer pixels than this: the full frame is fast anyway.
const PREVIEW_MIN_PIXELS: u64 = 32 * 32 * 16;
/// The largest batch of samples between two displayed frames.
const MAX_BATCH: u32 = 8;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Pass {
    /// The whole image at `width`×`height` (the reduced size), one sample per pixel,
    /// shown scaled up.
    Preview { width: u32, height: u32 },
    /// These samples of every pixel at full resolution.
    Samples(Range<u32>),
}

/// The passes for a `width`×`height` view with `spp` samples per pixel.
pub fn plan(width: u32, height: u32, spp: u32) -> Vec<Pass> {
    let mut passes = Vec::new();
    if u64::from(width) * u64::from(height) >= PREVIEW_MIN_PIXELS {
        passes.push(Pass::Preview {
            width: width.div_ceil(PREVIEW_FACTOR),
            height: height.div_ceil(PREVIEW_FACTOR),
        });
    }
    let spp = spp.max(1);
    let mut done = 0;
    while done < spp {
        // 1, 1, 2, 4, 8, 8, ...: the first refinements come quickly.
        let batch = done.clamp(1, MAX_BATCH).min(spp - done);
        passes.push(Pass::Samples(done..done + batch));
        done += batch;
    }
    passes
}

/// The preview pixel that full-resolution pixel `(i, j)` shows (either row order, as
/// long as both images use the same one).
pub fn preview_source(i: u32, j: u32, factor: u32) -> (u32, u32) {
    (i / factor, j / factor)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn samples(passes: &[Pass]) -> Vec<Range<u32>> {
        passes
            .iter()
            .filter_map(|p| match p {
                Pass::Samples(r) => Some(r.clone()),
                Pass::Preview { .. } => None,
            })
            .collect()
    }

    #[test]
    fn large_images_start_with_a_quarter_size_preview() {
        let passes = plan(1280, 720, 1);
        assert_eq!(
            passes,
            vec![
                Pass::Preview {
                    width: 320,
                    height: 180
                },
                Pass::Samples(0..1)
            ]
        );
        // Odd sizes round up so that every full pixel has a preview pixel.
        assert_eq!(
            plan(321, 181, 1)[0],
            Pass::Preview {
                width: 81,
                height: 46
            }
        );
    }

    #[test]
    fn tiny_images_skip_the_preview() {
        assert_eq!(plan(64, 64, 1), vec![Pass::Samples(0..1)]);
    }

    #[test]
    fn batches_cover_all_samples_in_order() {
        for spp in [1, 2, 3, 5, 16, 17, 100, 1000] {
            let ranges = samples(&plan(320, 180, spp));
            assert_eq!(ranges[0], 0..1, "spp {spp}: one sample first");
            let mut next = 0;
            for r in &ranges {
                assert_eq!(r.start, next, "spp {spp}: contiguous");
                assert!(!r.is_empty() && r.len() as u32 <= MAX_BATCH);
                next = r.end;
            }
            assert_eq!(next, spp);
        }
        assert_eq!(
            samples(&plan(320, 180, 16)),
            vec![0..1, 1..2, 2..4, 4..8, 8..16]
        );
    }

    #[test]
    fn preview_pixels_cover_blocks() {
        assert_eq!(preview_source(0, 0, 4), (0, 0));
        assert_eq!(preview_source(3, 7, 4), (0, 1));
        assert_eq!(preview_source(320, 4, 4), (80, 1));
    }
}
