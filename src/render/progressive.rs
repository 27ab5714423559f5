//! Sums of samples kept from pass to pass, for renders that refine progressively (the
//! viewer): any split of the samples into passes sums the same numbers in the same
//! order as one whole render.

use std::ops::Range;

use glam::Vec3;

use super::bands::for_each_row;
use super::film::{centre_height, centres_of, each_sample_of_row, Film};
use super::{RenderControl, RenderError};
use crate::settings::Settings;
use crate::trace::{RayCounts, SampleTracer};

/// Sample 0 of the pixels `columns` (film abscissae `centres`, from [`centres_of`]) of
/// row `j` into `out`, as [`accumulate`] of sample 0 sums it: the pixel centres a row
/// at a time for one sample a pixel, else the first jittered sample of each.
pub(crate) fn first_samples<T: SampleTracer + ?Sized>(
    tracer: &T,
    settings: &Settings,
    columns: &[u32],
    centres: &[f32],
    j: u32,
    out: &mut [Vec3],
    counts: &mut RayCounts,
) {
    if settings.quality.spp == 1 {
        tracer.sample_row(centres, centre_height(settings, j), out, counts);
        return;
    }
    // Each sum from zero as `accumulate` starts it.
    let film = Film::new(settings);
    each_sample_of_row(tracer, &film, columns, j, 0..1, counts, |a, _, (c, _)| {
        out[a] = Vec3::ZERO + c;
    });
}

/// Sums samples `samples` of every pixel of the area into `sums` (area-sized, row 0 at
/// the bottom of the area): added to what it holds, or, for a range from sample 0,
/// from scratch (so a reused buffer needs no clearing). In sample order, so that any
/// split into passes sums the same numbers in the same order.
pub fn accumulate<T: SampleTracer + ?Sized>(
    tracer: &T,
    settings: &Settings,
    samples: Range<u32>,
    sums: &mut [Vec3],
    control: &RenderControl,
) -> Result<RayCounts, RenderError> {
    let area = settings.area();
    if samples == (0..1) {
        return accumulate_first(tracer, settings, sums, control, &|_, _| {});
    }
    let n = samples.len() as u64;
    let afresh = samples.start == 0;
    let film = Film::new(settings);
    let columns: Vec<u32> = (area.x..area.x + area.width).collect();
    for_each_row(settings, area, sums, 1, n, control, |j, row, counts| {
        if afresh {
            row.fill(Vec3::ZERO);
        }
        let ks = samples.clone();
        each_sample_of_row(tracer, &film, &columns, j, ks, counts, {
            |a, _, (c, _)| row[a] += c
        });
    })
}

/// [`accumulate`] of sample 0 alone, calling `after_row(j, row)` with each row once it
/// is traced (on the thread that traced it): whole rows at once, written in place
/// (`first_samples`, which the viewer's preview shares).
pub fn accumulate_first<T: SampleTracer + ?Sized>(
    tracer: &T,
    settings: &Settings,
    sums: &mut [Vec3],
    control: &RenderControl,
    after_row: &(dyn Fn(u32, &mut [Vec3]) + Sync),
) -> Result<RayCounts, RenderError> {
    let area = settings.area();
    let columns: Vec<u32> = (area.x..area.x + area.width).collect();
    let centres = centres_of(settings, &columns);
    for_each_row(settings, area, sums, 1, 1, control, |j, row, counts| {
        first_samples(tracer, settings, &columns, &centres, j, row, counts);
        after_row(j, row);
    })
}
