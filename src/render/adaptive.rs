//! Adaptive anti-aliasing: a first pass of a few spread samples a pixel, then the rest
//! of the samples only where the pixel or its 4-neighbours disagree.

use glam::Vec3;

use super::bands::for_each_pixel;
use super::film::film;
use super::resolve::pixel_value;
use super::{Frame, RenderControl, RenderError, Traced};
use crate::sampling::sample_offset;
use crate::settings::{Adaptive, Region, Settings};
use crate::trace::SampleTracer;

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
) -> Result<Traced, RenderError> {
    let spp = settings.quality.spp;
    let area = settings.area();
    let first = first_pass_samples(spp, a.first, settings.seed);
    let nf = first.len();

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
    // Per pixel: the first samples' colours and their cutoff bounds.
    let mut firsts = vec![(Vec3::ZERO, 0.0f32); outer.width as usize * outer.height as usize * nf];
    let mut rays = for_each_pixel(
        settings,
        outer,
        &mut firsts,
        nf,
        nf as u64,
        control,
        |i, j, p, counts| {
            for (slot, &k) in p.iter_mut().zip(&first) {
                let (s, t) = film(settings, i, j, k);
                *slot = tracer.sample_bounded(s, t, counts);
            }
        },
    )?;

    // What the first pass shows, clamped as it will be displayed.
    let ow = outer.width as usize;
    let shown = |c: Vec3| c.clamp(Vec3::ZERO, Vec3::ONE);
    let means: Vec<Vec3> = firsts
        .chunks(nf)
        .map(|p| shown(p.iter().fold(Vec3::ZERO, |s, q| s + q.0) / nf as f32))
        .collect();
    let spread = |p: &[(Vec3, f32)]| {
        let lo = p
            .iter()
            .fold(Vec3::splat(f32::INFINITY), |m, q| m.min(shown(q.0)));
        let hi = p
            .iter()
            .fold(Vec3::splat(f32::NEG_INFINITY), |m, q| m.max(shown(q.0)));
        (hi - lo).max_element()
    };
    // Outer-grid coordinates, row 0 at the bottom: the area starts at (dx, dy).
    let dx = (area.x - x0) as usize;
    let dy = (y1 - (area.y + area.height)) as usize;
    let oh = outer.height as usize;
    let mut refine = vec![false; area.width as usize * area.height as usize];
    for (n, flag) in refine.iter_mut().enumerate() {
        let (ax, ay) = (n % area.width as usize, n / area.width as usize);
        let (ox, oy) = (ax + dx, ay + dy);
        let o = oy * ow + ox;
        let m = means[o];
        // Refine unless everything is surely below the threshold (so threshold 0, or
        // a NaN anywhere, refines).
        let reaches = |x: f32| x.partial_cmp(&a.threshold) != Some(std::cmp::Ordering::Less);
        let differs = |q: usize| reaches((means[q] - m).abs().max_element());
        *flag = reaches(spread(&firsts[o * nf..(o + 1) * nf]))
            || (ox > 0 && differs(o - 1))
            || (ox + 1 < ow && differs(o + 1))
            || (oy > 0 && differs(o - ow))
            || (oy + 1 < oh && differs(o + ow));
    }

    // Second pass: value and bound of each pixel of the area.
    let mut out: Vec<(Vec3, f32)> = refine.iter().map(|_| (Vec3::ZERO, 0.0)).collect();
    let rest = u64::from(spp) - nf as u64;
    let more = for_each_pixel(
        settings,
        area,
        &mut out,
        1,
        rest,
        control,
        |i, j, p, counts| {
            let (ax, ay) = (
                (i - area.x) as usize,
                (j - (h - area.y - area.height)) as usize,
            );
            let o = (ay + dy) * ow + ax + dx;
            let stored = &firsts[o * nf..(o + 1) * nf];
            let mut sum = Vec3::ZERO;
            let mut bound = 0.0f32;
            if refine[ay * area.width as usize + ax] {
                let mut next = 0;
                for k in 0..spp {
                    let (c, b) = if next < nf && first[next] == k {
                        next += 1;
                        stored[next - 1]
                    } else {
                        let (s, t) = film(settings, i, j, k);
                        tracer.sample_bounded(s, t, counts)
                    };
                    sum += c;
                    bound += b;
                }
                p[0] = (pixel_value(sum, spp), bound / spp as f32);
            } else {
                for &(c, b) in stored {
                    sum += c;
                    bound += b;
                }
                p[0] = (pixel_value(sum, nf as u32), bound / nf as f32);
            }
        },
    )?;
    rays.add(&more);
    let refined = refine.iter().filter(|&&r| r).count() as u64;
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
