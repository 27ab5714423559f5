//! Progressive refinement: the passes one view is rendered in. First a coarse preview
//! at a fraction of the resolution (fast, so that dragging the mouse stays fluid), then
//! the full resolution at one sample per pixel (the preview's pixels taken as they
//! are), then more samples in growing batches up to the target. Sample batches cover
//! `0..spp` in order without gaps, so the sums (and so the pixels) equal a single
//! render of all samples.

use std::ops::Range;

/// The preview has 1/factor of the width and of the height: this at first, then
/// whatever [`preview_factor`] picks from the speed measured so far.
pub const START_PREVIEW_FACTOR: u32 = 4;
const MIN_PREVIEW_FACTOR: u32 = 2;
const MAX_PREVIEW_FACTOR: u32 = 16;
/// The time a preview should take, so that a drag shows about 30 views a second.
const PREVIEW_SECONDS: f64 = 1.0 / 30.0;
/// No preview for images with fewer pixels than this: the full frame is fast anyway.
const PREVIEW_MIN_PIXELS: u64 = 32 * 32 * 16;
/// The largest batch of samples between two displayed frames.
const MAX_BATCH: u32 = 8;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Pass {
    /// The whole image at `width`×`height` (1/`factor` of the size): the first sample
    /// of one pixel of every `factor`×`factor` block (see `viewer::lattice`), shown
    /// scaled up, and taken by the first full pass.
    Preview {
        width: u32,
        height: u32,
        factor: u32,
    },
    /// These samples of every pixel at full resolution.
    Samples(Range<u32>),
}

/// The preview factor for a `width`×`height` view that renders a preview within
/// `PREVIEW_SECONDS` at `pixels_per_second` (measured on earlier one-sample passes);
/// 1 (no preview) when the full view itself renders within that time: a preview would
/// then only put a coarse picture in front of every frame of a drag.
pub fn preview_factor(width: u32, height: u32, pixels_per_second: f64) -> u32 {
    if !(pixels_per_second.is_finite() && pixels_per_second > 0.0) {
        return START_PREVIEW_FACTOR;
    }
    let budget = (pixels_per_second * PREVIEW_SECONDS).max(1.0);
    let pixels = f64::from(width) * f64::from(height);
    if pixels <= budget {
        return 1;
    }
    let factor = (pixels / budget).sqrt().ceil();
    (factor as u32).clamp(MIN_PREVIEW_FACTOR, MAX_PREVIEW_FACTOR)
}

/// The pixels per second that size the next preview, from a pass of `pass_pixels`
/// pixel-samples at `samples` samples so far that took `seconds`: one-sample passes
/// only (previews and first full passes; later ones take their samples at jittered
/// positions, a different speed). `None` leaves the last measurement.
pub fn measured_speed(samples: u32, pass_pixels: u64, seconds: f64) -> Option<f64> {
    (samples <= 1 && seconds > 0.0).then(|| pass_pixels as f64 / seconds)
}

/// The passes for a `width`×`height` view with `spp` samples per pixel, starting
/// with a preview at 1/`factor` of the size (none for a factor of 1).
pub fn plan(width: u32, height: u32, spp: u32, factor: u32) -> Vec<Pass> {
    let mut passes = Vec::new();
    if factor > 1 && u64::from(width) * u64::from(height) >= PREVIEW_MIN_PIXELS {
        let factor = factor.max(MIN_PREVIEW_FACTOR);
        passes.push(Pass::Preview {
            width: width.div_ceil(factor),
            height: height.div_ceil(factor),
            factor,
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

/// When to start rendering a changed camera. A drag moves the camera more often than
/// a preview renders; starting a view at every move would cancel each one before it
/// shows anything. So a change waits while the current view has nothing on screen
/// yet, and the latest camera starts as soon as it has (latest wins, one in flight).
#[derive(Debug, Default)]
pub struct Throttle {
    /// The current view has shown a frame (or failed).
    shown: bool,
    /// A camera change waits.
    pending: bool,
}

impl Throttle {
    /// A view was submitted.
    pub fn started(&mut self) {
        self.shown = false;
        self.pending = false;
    }

    /// The camera changed: true if it should be rendered now, else it waits.
    pub fn changed(&mut self) -> bool {
        if self.shown {
            true
        } else {
            self.pending = true;
            false
        }
    }

    /// The current view showed a frame or failed: true if a waiting change should be
    /// rendered now.
    pub fn shown(&mut self) -> bool {
        self.shown = true;
        std::mem::take(&mut self.pending)
    }
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
        let passes = plan(1280, 720, 1, 4);
        assert_eq!(
            passes,
            vec![
                Pass::Preview {
                    width: 320,
                    height: 180,
                    factor: 4
                },
                Pass::Samples(0..1)
            ]
        );
        // Odd sizes round up so that every full pixel has a preview pixel.
        assert_eq!(
            plan(321, 181, 1, 4)[0],
            Pass::Preview {
                width: 81,
                height: 46,
                factor: 4
            }
        );
    }

    #[test]
    fn tiny_images_skip_the_preview() {
        assert_eq!(plan(64, 64, 1, 4), vec![Pass::Samples(0..1)]);
    }

    #[test]
    fn no_preview_when_the_full_view_fits_the_time_budget() {
        // 921 600 pixels in 1/30 s need 27.6 Mpixel/s; just above, no preview.
        let fits = 1280.0 * 720.0 / PREVIEW_SECONDS;
        assert_eq!(preview_factor(1280, 720, fits * 1.01), 1);
        assert_eq!(preview_factor(1280, 720, fits * 0.99), MIN_PREVIEW_FACTOR);
        assert_eq!(
            plan(1280, 720, 4, 1),
            vec![
                Pass::Samples(0..1),
                Pass::Samples(1..2),
                Pass::Samples(2..4)
            ]
        );
    }

    #[test]
    fn batches_cover_all_samples_in_order() {
        for spp in [1, 2, 3, 5, 16, 17, 100, 1000] {
            let ranges = samples(&plan(320, 180, spp, 4));
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
            samples(&plan(320, 180, 16, 4)),
            vec![0..1, 1..2, 2..4, 4..8, 8..16]
        );
    }

    #[test]
    fn the_preview_factor_fits_the_time_budget() {
        // 1.2 Mpixel/s and 1/30 s: 40 000 pixels, so 1280×720 needs 1/5 per side.
        assert_eq!(preview_factor(1280, 720, 1.2e6), 5);
        let (w, h) = (1280 / 5, 720 / 5);
        assert!(f64::from(w * h) <= 1.2e6 / 30.0);
        // Clamped at both ends, and a sane start without a measurement.
        assert_eq!(preview_factor(1280, 720, 2.0e7), MIN_PREVIEW_FACTOR);
        assert_eq!(preview_factor(1280, 720, 1.0), MAX_PREVIEW_FACTOR);
        assert_eq!(preview_factor(1280, 720, f64::NAN), START_PREVIEW_FACTOR);
        assert_eq!(preview_factor(1280, 720, 0.0), START_PREVIEW_FACTOR);
    }

    #[test]
    fn camera_changes_wait_for_the_current_view_to_show() {
        let mut t = Throttle::default();
        t.started();
        // Moves while nothing is on screen wait, and collapse into one.
        assert!(!t.changed());
        assert!(!t.changed());
        assert!(t.shown(), "the waiting change starts once a frame shows");
        t.started();
        assert!(!t.shown(), "nothing waits any more");
        // Once the view shows, changes start at once (cancelling its refinement).
        assert!(t.changed());
        t.started();
        assert!(!t.changed());
        t.started(); // e.g. a resize started a view anyway: the wait is over
        assert!(!t.shown());
    }
}
