//! Adaptive anti-aliasing: a first pass of a few spread samples a pixel, then the rest
//! of the samples only where the pixel or its 4-neighbours disagree.

use glam::Vec3;

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::OnceLock;

use super::bands::for_each_row;
use super::film::{each_sample, Film};
use super::resolve::pixel_value;
use super::{Frame, RenderControl, RenderError, Traced};
use crate::sampling::sample_offset;
use crate::settings::{Adaptive, Region, Settings};
use crate::trace::{RayCounts, SampleTracer};

/// The sample indices of the first adaptive pass: `first` of the `spp` stratified
/// samples, chosen to spread over the pixel (a plain prefix 0..first would all sit in
/// the bottom row of strata). Sorted, so that sums keep sample order.
pub fn first_pass_samples(spp: u32, first: u32, seed: u64) -> Vec<u32> {
    if first >= spp {
        return (0..spp).collect();
    }
    // Targets on a g×g grid; for each, the nearest unused stratum (the strata are the
    // same in every pixel, only the jitter differs, so pixel (0, 0) stands for all).
    let g = (first as f32).sqrt().ceil() as u32;
    let offsets: Vec<(f32, f32)> = (0..spp)
        .map(|k| sample_offset(0, 0, k, spp, seed))
        .collect();
    let mut chosen: Vec<u32> = Vec::with_capacity(first as usize);
    for m in 0..first {
        let tx = ((m % g) as f32 + 0.5) / g as f32;
        let ty = ((m / g) as f32 + 0.5) / g as f32;
        let best = (0..spp)
            .filter(|k| !chosen.contains(k))
            .min_by(|&a, &b| {
                let d = |k: u32| {
                    let (x, y) = offsets[k as usize];
                    (x - tx).powi(2) + (y - ty).powi(2)
                };
                d(a).total_cmp(&d(b))
            })
            .expect("fewer chosen than spp");
        chosen.push(best);
    }
    chosen.sort_unstable();
    chosen
}

/// Adaptive anti-aliasing: a first pass of a few spread samples per pixel, then the
/// remaining samples only where the pixel or its 4-neighbours disagree. A refined pixel
/// sums all its `spp` samples in sample order (the stored first ones in their places),
/// exactly as a full render does, so threshold 0 is identical to full anti-aliasing.
pub(super) fn adaptive<T: SampleTracer>(
    tracer: &T,
    settings: &Settings,
    a: Adaptive,
    control: &RenderControl,
    set_total: &(dyn Fn(u64) + Sync),
) -> Result<Traced, RenderError> {
    let spp = settings.quality.spp;
    let area = settings.area();
    let first = first_pass_samples(spp, a.first, settings.seed);
    let nf = first.len();
    let film = Film::new(settings);

    // The first pass covers the area and a one-pixel margin inside the image, so a
    // region's edge pixels see the same neighbours as in the whole image.
    let (w, h) = (settings.width, settings.height);
    let x0 = area.x.saturating_sub(1);
    let y0 = area.y.saturating_sub(1);
    let x1 = (area.x + area.width + 1).min(w);
    let y1 = (area.y + area.height + 1).min(h);
    let outer = Region {
        x: x0,
        y: y0,
        width: x1 - x0,
        height: y1 - y0,
    };
    // What the first pass shows, clamped as it will be displayed.
    let shown = |c: Vec3| c.clamp(Vec3::ZERO, Vec3::ONE);
    let mean = |p: &[(Vec3, f32)]| shown(p.iter().fold(Vec3::ZERO, |s, q| s + q.0) / nf as f32);
    let spread = |p: &[(Vec3, f32)]| {
        let lo = p
            .iter()
            .fold(Vec3::splat(f32::INFINITY), |m, q| m.min(shown(q.0)));
        let hi = p
            .iter()
            .fold(Vec3::splat(f32::NEG_INFINITY), |m, q| m.max(shown(q.0)));
        (hi - lo).max_element()
    };
    // Refine unless everything is surely below the threshold (so threshold 0, or a NaN
    // anywhere, refines).
    let reaches = |x: f32| x.partial_cmp(&a.threshold) != Some(std::cmp::Ordering::Less);
    // Whether pixel `o` of an outer row is refined: its own samples or its neighbours
    // in the row flag it (`local`), or its mean differs from the pixel below or above.
    type Row = (Vec<Vec3>, Vec<bool>);
    let flagged = |(means, local): &Row, below: Option<&Row>, above: Option<&Row>, o: usize| {
        let differs = |other: Option<&Row>| {
            other.is_some_and(|(m, _)| reaches((m[o] - means[o]).abs().max_element()))
        };
        local[o] || differs(below) || differs(above)
    };

    // Progress counts the samples traced. The second pass traces `rest` samples in
    // each pixel the first pass flags. Until the first pass is over, that share is
    // estimated from the rows whose flags are known (the row and the rows above and
    // below it done), so the total, the percentage and the ETA settle early.
    let rest = u64::from(spp) - nf as u64;
    let first_samples = u64::from(outer.width) * u64::from(outer.height) * nf as u64;
    let area_pixels = u64::from(area.width) * u64::from(area.height);
    set_total(first_samples);
    let ow = outer.width as usize;
    let oh = outer.height as usize;
    let j_outer = h - (outer.y + outer.height);
    // Per outer row (from the bottom): the pixels' means and whether their own samples
    // or their neighbours in the row flag them; and whether the row was counted.
    let rows: Vec<OnceLock<Row>> = (0..oh).map(|_| OnceLock::new()).collect();
    let counted: Vec<AtomicBool> = (0..oh).map(|_| AtomicBool::new(false)).collect();
    let (rows_seen, rows_flagged) = (AtomicU64::new(0), AtomicU64::new(0));
    let count_row = |r: usize| {
        let get = |q: usize| rows.get(q).and_then(OnceLock::get);
        let Some(row) = get(r) else { return };
        let below = if r > 0 {
            get(r - 1).map(Some)
        } else {
            Some(None)
        };
        let (Some(below), Some(above)) = (
            below,
            get(r + 1).map(Some).or((r + 1 == oh).then_some(None)),
        ) else {
            return;
        };
        if counted[r].swap(true, Ordering::Relaxed) {
            return;
        }
        let flagged = (0..ow).filter(|&o| flagged(row, below, above, o)).count() as u64;
        let seen = rows_seen.fetch_add(ow as u64, Ordering::Relaxed) + ow as u64;
        let flagged = rows_flagged.fetch_add(flagged, Ordering::Relaxed) + flagged;
        let refined = (area_pixels as f64 * flagged as f64 / seen as f64).round() as u64;
        set_total(first_samples + refined * rest);
    };

    // Per pixel: the first samples' colours and their cutoff bounds.
    let mut firsts = vec![(Vec3::ZERO, 0.0f32); ow * oh * nf];
    let mut rays = for_each_row(
        settings,
        outer,
        &mut firsts,
        nf,
        nf as u64,
        control,
        |j, row, counts| {
            for (o, p) in row.chunks_mut(nf).enumerate() {
                let i = outer.x + o as u32;
                let mut slots = p.iter_mut();
                each_sample(
                    tracer,
                    &film,
                    (i, j),
                    first.iter().copied(),
                    counts,
                    |_, v| {
                        *slots.next().expect("a slot a first sample") = v;
                    },
                );
            }
            let means: Vec<Vec3> = row.chunks(nf).map(mean).collect();
            let differs = |o: usize, q: usize| reaches((means[q] - means[o]).abs().max_element());
            let local = row
                .chunks(nf)
                .enumerate()
                .map(|(o, p)| {
                    reaches(spread(p))
                        || (o > 0 && differs(o, o - 1))
                        || (o + 1 < ow && differs(o, o + 1))
                })
                .collect();
            let r = (j - j_outer) as usize;
            let _ = rows[r].set((means, local));
            for q in r.saturating_sub(1)..=r + 1 {
                count_row(q);
            }
        },
    )?;
    let rows: Vec<Row> = rows
        .into_iter()
        .map(|r| r.into_inner().expect("the first pass did every row"))
        .collect();

    // Outer-grid coordinates, row 0 at the bottom: the area starts at (dx, dy).
    let dx = (area.x - x0) as usize;
    let dy = (y1 - (area.y + area.height)) as usize;
    let mut refine = vec![false; area.width as usize * area.height as usize];
    for (n, flag) in refine.iter_mut().enumerate() {
        let (ax, ay) = (n % area.width as usize, n / area.width as usize);
        let (ox, oy) = (ax + dx, ay + dy);
        let below = oy.checked_sub(1).map(|q| &rows[q]);
        *flag = flagged(&rows[oy], below, rows.get(oy + 1), ox);
    }

    // Second pass: value and bound of each pixel of the area; progress counts the
    // samples of the refined pixels only.
    let refined = refine.iter().filter(|&&r| r).count() as u64;
    set_total(first_samples + refined * rest);
    let pixel = |i: u32, j: u32, p: &mut (Vec3, f32), counts: &mut RayCounts| {
        let (ax, ay) = (
            (i - area.x) as usize,
            (j - (h - area.y - area.height)) as usize,
        );
        let o = (ay + dy) * ow + ax + dx;
        let stored = &firsts[o * nf..(o + 1) * nf];
        let mut sum = Vec3::ZERO;
        let mut bound = 0.0f32;
        if refine[ay * area.width as usize + ax] {
            // The samples not stored, traced two at a time; the sums take every sample
            // in index order, the stored ones in their places between them.
            let mut add = |(c, b): (Vec3, f32)| {
                sum += c;
                bound += b;
            };
            let rest = (0..spp).filter(|k| first.binary_search(k).is_err());
            let mut next = 0;
            each_sample(tracer, &film, (i, j), rest, counts, |k, v| {
                while next < nf && first[next] < k {
                    add(stored[next]);
                    next += 1;
                }
                add(v);
            });
            for &v in &stored[next..] {
                add(v);
            }
            *p = (pixel_value(sum, spp), bound / spp as f32);
        } else {
            for &(c, b) in stored {
                sum += c;
                bound += b;
            }
            *p = (pixel_value(sum, nf as u32), bound / nf as f32);
        }
    };
    let mut out: Vec<(Vec3, f32)> = refine.iter().map(|_| (Vec3::ZERO, 0.0)).collect();
    let more = for_each_row(settings, area, &mut out, 1, 0, control, |j, row, counts| {
        let ay = (j - (h - area.y - area.height)) as usize;
        let aw = area.width as usize;
        for (ax, p) in row.iter_mut().enumerate() {
            pixel(area.x + ax as u32, j, p, counts);
        }
        let traced = refine[ay * aw..(ay + 1) * aw]
            .iter()
            .filter(|&&r| r)
            .count() as u64;
        control
            .pixels_done
            .fetch_add(traced * rest, Ordering::Relaxed);
    })?;
    rays.add(&more);
    let frame = Frame {
        width: area.width,
        height: area.height,
        pixels: out.iter().map(|p| p.0).collect(),
    };
    Ok(Traced {
        frame,
        cutoff_bound: out.iter().map(|p| p.1).collect(),
        refined,
        rays,
    })
}

#[cfg(test)]
mod tests {
    use std::sync::Mutex;

    use super::*;
    use crate::render::make_tracer;
    use crate::scene::{hw3_scene, HW3_DEFAULT_SEED};
    use crate::settings::Preset;

    /// A tracer that notes the progress (samples done, samples expected) at every
    /// sample it traces.
    struct Watched<'a> {
        inner: Box<dyn SampleTracer + 'a>,
        control: &'a RenderControl,
        seen: Mutex<Vec<(u64, u64)>>,
    }

    impl SampleTracer for Watched<'_> {
        fn sample(&self, s: f32, t: f32, counts: &mut RayCounts) -> Vec3 {
            self.sample_bounded(s, t, counts).0
        }

        fn sample_bounded(&self, s: f32, t: f32, counts: &mut RayCounts) -> (Vec3, f32) {
            let progress = (self.control.pixels_done(), self.control.samples_total());
            self.seen.lock().unwrap().push(progress);
            self.inner.sample_bounded(s, t, counts)
        }
    }

    /// Renders hw3 at 320×180 with the `high` preset on one thread (the bands in their
    /// order, whatever else runs on the machine) through `render`, checks that every
    /// sample traced is counted once and the total ends exact, and returns the render
    /// and the largest gap between the share the bar shows and the true share once a
    /// tenth of the work is done.
    fn watch_progress(
        render: impl FnOnce(&Watched, &Settings, Adaptive, &RenderControl) -> Traced,
    ) -> (Traced, f64) {
        let scene = hw3_scene(HW3_DEFAULT_SEED);
        let mut settings = scene.settings().with(&crate::settings::Overrides {
            quality: Some(Preset::High),
            width: Some(320),
            height: Some(180),
            threads: Some(1),
            ..Default::default()
        });
        settings.seed = 1;
        let control = RenderControl::default();
        let watched = Watched {
            inner: make_tracer(&scene, &settings).unwrap(),
            control: &control,
            seen: Mutex::new(Vec::new()),
        };
        let Some(a) = settings.quality.adaptive else {
            panic!("high is adaptive")
        };
        let traced = render(&watched, &settings, a, &control);
        let seen = watched.seen.into_inner().unwrap();
        let samples = seen.len() as u64;
        assert_eq!(control.pixels_done(), samples);
        assert_eq!(control.samples_total(), samples);
        assert_eq!(traced.rays.primary, samples);
        let worst = seen
            .iter()
            .filter(|&&(done, _)| done as f64 / samples as f64 > 0.1)
            .map(|&(done, total)| {
                (done as f64 / total.max(1) as f64 - done as f64 / samples as f64).abs()
            })
            .fold(0.0, f64::max);
        (traced, worst)
    }

    #[test]
    fn progress_counts_the_samples_traced_and_its_total_settles_early() {
        let (traced, worst) = watch_progress(|tracer, settings, a, control| {
            adaptive(tracer, settings, a, control, &|t| {
                control.set_samples_total(t)
            })
            .unwrap()
        });
        // Only some pixels get the rest of the samples.
        assert!(traced.refined > 0 && traced.refined < 320 * 180 / 2);
        // No long stall, no jump.
        assert!(
            worst < 0.05,
            "the bar is off by {worst:.3} past a tenth of the work"
        );
    }

    #[test]
    fn the_estimate_is_exact_once_every_row_is_flagged() {
        // When the first pass has flagged every row of the whole image, the estimate
        // counts every pixel it refines: the last total it sets is the final one. Every
        // estimate lies between no pixel refined and every pixel refined.
        let totals = Mutex::new(Vec::new());
        let mut bounds = (0, 0);
        watch_progress(|tracer, settings, a, control| {
            let pixels = u64::from(settings.width) * u64::from(settings.height);
            let first = pixels * u64::from(a.first);
            bounds = (
                first,
                first + pixels * u64::from(settings.quality.spp - a.first),
            );
            adaptive(tracer, settings, a, control, &|t| {
                totals.lock().unwrap().push(t);
                control.set_samples_total(t)
            })
            .unwrap()
        });
        let totals = totals.into_inner().unwrap();
        let n = totals.len();
        assert!(n > 100, "{n} totals set");
        assert_eq!(totals[n - 2], totals[n - 1]);
        let (least, most) = bounds;
        for (k, &t) in totals.iter().enumerate() {
            assert!(
                (least..=most).contains(&t),
                "total {k} of {n} is {t}, outside {least}..={most}"
            );
        }
    }

    #[test]
    fn progress_in_strips_settles_early_too() {
        // Strips of 23 rows: 8 of them. Strips differ in cost (sky above, balls below),
        // and those to come are estimated from those done: looser than one strip's
        // estimate (measured: 0.25).
        let (_, worst) = watch_progress(|tracer, settings, a, control| {
            super::super::adaptive_in_strips(tracer, settings, a, control, 23 * 320).unwrap()
        });
        assert!(
            worst < 0.3,
            "the bar is off by {worst:.3} past a tenth of the work"
        );
    }
}
