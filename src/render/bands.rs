//! Rows over threads: every band of [`BAND_ROWS`] rows is a rayon task of its own, on
//! the pool of the settings' thread count, with progress counted and cancellation
//! checked a row at a time.

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use super::{RenderControl, RenderError};
use crate::settings::{Region, Settings};
use crate::trace::RayCounts;

/// Rows per unit of parallel work.
pub(super) const BAND_ROWS: usize = 8;

/// Runs `row(j, states, counts)` for every row of `area` (`j` from the bottom of the
/// image) with the states of its pixels (`per_pixel` items each, row 0 at the bottom of
/// the area) on the thread pool of `settings`. Progress counts `samples` per pixel.
pub(crate) fn for_each_row<T, F>(
    settings: &Settings,
    area: Region,
    states: &mut [T],
    per_pixel: usize,
    samples: u64,
    control: &RenderControl,
    row: F,
) -> Result<RayCounts, RenderError>
where
    T: Send,
    F: Fn(u32, &mut [T], &mut RayCounts) + Sync,
{
    let aw = area.width as usize;
    assert_eq!(
        states.len(),
        aw * area.height as usize * per_pixel,
        "states must cover the area"
    );
    // The area's bottom row, counted from the image's bottom.
    let j0 = settings.height - (area.y + area.height);
    let progress = aw as u64 * samples;
    for_each_band(
        settings,
        states,
        aw * per_pixel,
        progress,
        control,
        |r, states, counts| row(j0 + r as u32, states, counts),
    )
}

/// Runs `row(j, bytes, counts)` for every row of `area` (`j` from the bottom of the
/// image) with its 3 bytes a pixel; `bytes` holds the area's rows TOP row first, the
/// order of files and screens. Progress counts one sample a pixel.
pub(super) fn for_each_row_of_bytes<F>(
    settings: &Settings,
    area: Region,
    bytes: &mut [u8],
    control: &RenderControl,
    row: F,
) -> Result<RayCounts, RenderError>
where
    F: Fn(u32, &mut [u8], &mut RayCounts) + Sync,
{
    let aw = area.width as usize;
    assert_eq!(
        bytes.len(),
        3 * aw * area.height as usize,
        "bytes must cover the area"
    );
    // The area's top row, counted from the image's bottom (saturating: an empty area
    // at the bottom has none).
    let j_top = settings.height.saturating_sub(area.y + 1);
    for_each_band(
        settings,
        bytes,
        3 * aw,
        aw as u64,
        control,
        |r, bytes, counts| row(j_top - r as u32, bytes, counts),
    )
}

/// Runs `row(r, items, counts)` for each row `r` of `items` (rows of `row_len` items)
/// on the threads of `settings`, in bands of [`BAND_ROWS`] rows, until `control` is
/// cancelled; each row done adds `progress` to the progress count.
pub(crate) fn for_each_band<T, F>(
    settings: &Settings,
    items: &mut [T],
    row_len: usize,
    progress: u64,
    control: &RenderControl,
    row: F,
) -> Result<RayCounts, RenderError>
where
    T: Send,
    F: Fn(usize, &mut [T], &mut RayCounts) + Sync,
{
    let row_len = row_len.max(1);
    // The bands in an order that spreads over the image at every moment (bit-reversed
    // indices: 0, ½, ¼, ¾, …): the work done so far is a fair sample of the image, so a
    // progress bar's rate and ETA hold although rows of sky cost less than rows of balls.
    let mut bands: Vec<(usize, &mut [T])> =
        items.chunks_mut(row_len * BAND_ROWS).enumerate().collect();
    bands.sort_unstable_by_key(|&(band, _)| (band as u64).reverse_bits());
    in_pool(settings, || {
        bands
            .into_par_iter()
            // Every band a task of its own. Left to itself, rayon cuts the range into a
            // few pieces and splits a piece further only when it is stolen: on two
            // threads, the half of an image whose rows cost more (balls below a sky)
            // went to one thread in pieces too large to share, and the other idled
            // (many_10000: two threads 1.40x as fast as one; 1.88x so).
            .with_max_len(1)
            .map(|(band, rows)| {
                let mut counts = RayCounts::default();
                for (r, items) in rows.chunks_mut(row_len).enumerate() {
                    if control.is_cancelled() {
                        return Err(RenderError::Cancelled);
                    }
                    row(band * BAND_ROWS + r, items, &mut counts);
                    control.pixels_done.fetch_add(progress, Ordering::Relaxed);
                }
                Ok(counts)
            })
            .try_reduce(RayCounts::default, |mut a, b| {
                a.add(&b);
                Ok(a)
            })
    })?
}

/// Runs `work` on the threads `settings` asks for.
pub(crate) fn in_pool<R: Send>(
    settings: &Settings,
    work: impl FnOnce() -> R + Send,
) -> Result<R, RenderError> {
    Ok(match settings.threads {
        None => work(),
        Some(n) => thread_pool(n)?.install(work),
    })
}

/// A pool of `n` worker threads, started once per process and reused: starting threads
/// for every render (every frame of the viewer) would cost more than small renders.
fn thread_pool(n: usize) -> Result<Arc<rayon::ThreadPool>, RenderError> {
    static POOLS: Mutex<Vec<(usize, Arc<rayon::ThreadPool>)>> = Mutex::new(Vec::new());
    let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, pool)) = pools.iter().find(|(size, _)| *size == n) {
        return Ok(Arc::clone(pool));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|source| RenderError::Threads { threads: n, source })?;
    let pool = Arc::new(pool);
    pools.push((n, Arc::clone(&pool)));
    Ok(pool)
}
