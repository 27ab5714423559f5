//! The frame: pixels in bands on rayon, samples per pixel, progress and cancellation,
//! and the linear RGB buffer. Row 0 of every buffer here is the BOTTOM row of the
//! image (`j = 0`, as in GLUT); the file writers and the window flip it, once.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use crate::camera::Camera;
use crate::quality::{Adaptive, Quality};
use crate::sampling::sample_offset;
use crate::scene::{ImageSettings, Scene};
use crate::trace::fast::FastTracer;
use crate::trace::reference::ReferenceTracer;
use crate::trace::{RayCounts, SampleTracer};

/// Which implementation of the model renders.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Renderer {
    /// The fast `f32` tracer.
    #[default]
    Fast,
    /// The `f64` reference (slow; for measuring error).
    Reference,
}

/// A rectangle of the output image in image-tool coordinates: origin at the TOP-left.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub image: ImageSettings,
    /// Render only this rectangle of the image.
    pub region: Option<Region>,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    pub renderer: Renderer,
    /// Adaptive anti-aliasing (`None`: every pixel gets all `image.spp` samples).
    pub adaptive: Option<Adaptive>,
    /// Contribution cutoff ε of the fast tracer (0: exact).
    pub cutoff: f32,
}

impl RenderOptions {
    /// The scene's own settings, all of the image, all cores, the fast tracer.
    /// With a quality preset in the scene file, its knobs (its spp and depth are
    /// already in the scene's image settings).
    pub fn for_scene(scene: &Scene) -> Self {
        let mut opts = RenderOptions {
            image: scene.image,
            region: None,
            threads: None,
            renderer: Renderer::Fast,
            adaptive: None,
            cutoff: 0.0,
        };
        if let Some(preset) = scene.image.quality {
            let q = preset.quality();
            opts.adaptive = q.adaptive;
            opts.cutoff = q.cutoff;
            opts.renderer = q.precision;
        }
        opts
    }

    /// These options with the settings of `quality` (see [`Quality::apply`]).
    pub fn with_quality(mut self, quality: &Quality) -> Self {
        quality.apply(&mut self);
        self
    }

    /// The rectangle to render (the whole image without a region).
    pub fn area(&self) -> Region {
        self.region.unwrap_or(Region {
            x: 0,
            y: 0,
            width: self.image.width,
            height: self.image.height,
        })
    }

    /// Checks sizes and the region before anything is allocated.
    pub fn check(&self) -> Result<(), RenderError> {
        self.image.check().map_err(RenderError::Invalid)?;
        if let Some(r) = self.region {
            let fits = r.width > 0
                && r.height > 0
                && u64::from(r.x) + u64::from(r.width) <= u64::from(self.image.width)
                && u64::from(r.y) + u64::from(r.height) <= u64::from(self.image.height);
            if !fits {
                return Err(RenderError::Invalid(format!(
                    "region {},{},{},{} does not fit in the {}x{} image",
                    r.x, r.y, r.width, r.height, self.image.width, self.image.height
                )));
            }
        }
        Quality::of(self).check().map_err(RenderError::Invalid)?;
        if self.threads == Some(0) {
            return Err(RenderError::Invalid("threads must be at least 1".into()));
        }
        Ok(())
    }
}

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum RenderError {
    #[error("{0}")]
    Invalid(String),
    #[error("render cancelled")]
    Cancelled,
}

/// Shared between a render and whoever watches it: progress out, cancellation in.
#[derive(Debug, Default)]
pub struct RenderControl {
    cancel: AtomicBool,
    pub(crate) pixels_done: AtomicU64,
}

impl RenderControl {
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// Pixel-samples finished so far (a pixel counts once per sample pass).
    pub fn pixels_done(&self) -> u64 {
        self.pixels_done.load(Ordering::Relaxed)
    }
}

/// Linear RGB pixels, row 0 at the BOTTOM.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

impl Frame {
    pub fn new(width: u32, height: u32) -> Self {
        Frame {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    /// Pixel `(i, j)`, `j` counted from the bottom.
    pub fn get(&self, i: u32, j: u32) -> Vec3 {
        self.pixels[j as usize * self.width as usize + i as usize]
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    pub rays: RayCounts,
    /// Wall time of the whole render, preparation included.
    pub seconds: f64,
    /// Of which: compiling the scene for the tracer (acceleration structures).
    pub build_seconds: f64,
}

impl RenderStats {
    pub fn mrays_per_second(&self) -> f64 {
        self.rays.total() as f64 / self.seconds.max(1e-9) / 1e6
    }
}

/// Builds the tracer that `opts` asks for.
pub fn make_tracer<'a>(
    scene: &'a Scene,
    opts: &RenderOptions,
) -> Result<Box<dyn SampleTracer + 'a>, RenderError> {
    Ok(match Tracer::new(scene, opts)? {
        Tracer::Fast(t) => Box::new(t),
        Tracer::Reference(t) => Box::new(t),
    })
}

/// The tracer of a render, by type: the pixel loops are compiled for each, so that the
/// per-sample call is direct and inlined (a virtual call per sample costs a tenth of a
/// 1-sample frame).
enum Tracer<'a> {
    Fast(FastTracer),
    Reference(ReferenceTracer<'a>),
}

impl<'a> Tracer<'a> {
    fn new(scene: &'a Scene, opts: &RenderOptions) -> Result<Self, RenderError> {
        let camera = Camera::for_scene(scene, opts.image.width, opts.image.height)
            .map_err(|m| RenderError::Invalid(format!("camera: {m}")))?;
        let depth = opts.image.max_depth;
        Ok(match opts.renderer {
            Renderer::Fast => {
                Tracer::Fast(FastTracer::new(scene, &camera, depth).with_cutoff(opts.cutoff))
            }
            Renderer::Reference => Tracer::Reference(ReferenceTracer::new(scene, camera, depth)),
        })
    }
}

/// Rows per unit of parallel work.
const BAND_ROWS: usize = 8;

/// Runs `pixel(i, j, state, counts)` for every pixel of `area` (image pixels, `j` from
/// the bottom) on the thread pool of `opts`. `states` holds `per_pixel` items for each
/// pixel of the area, row 0 at the bottom of the area. Progress counts `samples` per
/// pixel.
fn for_each_pixel<T, F>(
    opts: &RenderOptions,
    area: Region,
    states: &mut [T],
    per_pixel: usize,
    samples: u64,
    control: &RenderControl,
    pixel: F,
) -> Result<RayCounts, RenderError>
where
    T: Send,
    F: Fn(u32, u32, &mut [T], &mut RayCounts) + Sync,
{
    for_each_row(
        opts,
        area,
        states,
        per_pixel,
        samples,
        control,
        |j, row, counts| {
            for (a, state) in row.chunks_mut(per_pixel).enumerate() {
                pixel(area.x + a as u32, j, state, counts);
            }
        },
    )
}

/// Runs `row(j, states, counts)` for every row of `area` (`j` from the bottom of the
/// image) with the states of its pixels; see [`for_each_pixel`].
pub(crate) fn for_each_row<T, F>(
    opts: &RenderOptions,
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
    let j0 = opts.image.height - (area.y + area.height);
    let progress = aw as u64 * samples;
    for_each_band(
        opts,
        states,
        aw * per_pixel,
        progress,
        control,
        |r, states, counts| row(j0 + r as u32, states, counts),
    )
}

/// Runs `row(r, items, counts)` for each row `r` of `items` (rows of `row_len` items)
/// on the threads of `opts`, in bands of [`BAND_ROWS`] rows, until `control` is
/// cancelled; each row done adds `progress` to the progress count.
pub(crate) fn for_each_band<T, F>(
    opts: &RenderOptions,
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
    in_pool(opts, || {
        items
            .par_chunks_mut(row_len * BAND_ROWS)
            .enumerate()
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

/// Runs `work` on the threads `opts` asks for.
pub(crate) fn in_pool<R: Send>(
    opts: &RenderOptions,
    work: impl FnOnce() -> R + Send,
) -> Result<R, RenderError> {
    Ok(match opts.threads {
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
        .map_err(|e| RenderError::Invalid(format!("cannot start {n} threads: {e}")))?;
    let pool = Arc::new(pool);
    pools.push((n, Arc::clone(&pool)));
    Ok(pool)
}

/// The film abscissae of the centres of the area's columns: `film`'s `s` for one
/// sample a pixel (the same values), worked out once.
fn pixel_centres(opts: &RenderOptions, area: Region) -> Vec<f32> {
    let columns: Vec<u32> = (area.x..area.x + area.width).collect();
    centres_of(opts, &columns)
}

/// [`pixel_centres`] of some columns.
pub(crate) fn centres_of(opts: &RenderOptions, columns: &[u32]) -> Vec<f32> {
    columns
        .iter()
        .map(|&i| (i as f32 + 0.5) / opts.image.width as f32)
        .collect()
}

/// Sample 0 of the pixels `columns` (film abscissae `centres`, from [`centres_of`]) of
/// row `j` into `out`, as [`accumulate`] of sample 0 sums it: the pixel centres a row
/// at a time for one sample a pixel, else the first jittered sample of each.
pub(crate) fn first_samples<T: SampleTracer + ?Sized>(
    tracer: &T,
    opts: &RenderOptions,
    columns: &[u32],
    centres: &[f32],
    j: u32,
    out: &mut [Vec3],
    counts: &mut RayCounts,
) {
    if opts.image.spp == 1 {
        tracer.sample_row(centres, centre_height(opts, j), out, counts);
        return;
    }
    for (&i, sum) in columns.iter().zip(out) {
        let (s, t) = film(opts, i, j, 0);
        *sum = Vec3::ZERO;
        *sum += tracer.sample(s, t, counts);
    }
}

/// `film`'s `t` for one sample a pixel in row `j`.
fn centre_height(opts: &RenderOptions, j: u32) -> f32 {
    (j as f32 + 0.5) / opts.image.height as f32
}

/// The film position of sample `k` of pixel `(i, j)`.
#[inline]
fn film(opts: &RenderOptions, i: u32, j: u32, k: u32) -> (f32, f32) {
    let (sx, sy) = sample_offset(i, j, k, opts.image.spp, opts.image.seed);
    (
        (i as f32 + sx) / opts.image.width as f32,
        (j as f32 + sy) / opts.image.height as f32,
    )
}

/// Sums samples `samples` of every pixel of the area into `sums` (area-sized, row 0 at
/// the bottom of the area): added to what it holds, or, for a range from sample 0,
/// from scratch (so a reused buffer needs no clearing). In sample order, so that any
/// split into passes sums the same numbers in the same order.
pub fn accumulate<T: SampleTracer + ?Sized>(
    tracer: &T,
    opts: &RenderOptions,
    samples: Range<u32>,
    sums: &mut [Vec3],
    control: &RenderControl,
) -> Result<RayCounts, RenderError> {
    let area = opts.area();
    if samples == (0..1) {
        return accumulate_first(tracer, opts, sums, control, &|_, _| {});
    }
    let n = samples.len() as u64;
    let afresh = samples.start == 0;
    for_each_pixel(opts, area, sums, 1, n, control, |i, j, sum, counts| {
        if afresh {
            sum[0] = Vec3::ZERO;
        }
        for k in samples.clone() {
            let (s, t) = film(opts, i, j, k);
            sum[0] += tracer.sample(s, t, counts);
        }
    })
}

/// [`accumulate`] of sample 0 alone, calling `after_row(j, row)` with each row once it
/// is traced (on the thread that traced it): whole rows at once, written in place
/// (`first_samples`, which the viewer's preview shares).
pub fn accumulate_first<T: SampleTracer + ?Sized>(
    tracer: &T,
    opts: &RenderOptions,
    sums: &mut [Vec3],
    control: &RenderControl,
    after_row: &(dyn Fn(u32, &mut [Vec3]) + Sync),
) -> Result<RayCounts, RenderError> {
    let area = opts.area();
    let columns: Vec<u32> = (area.x..area.x + area.width).collect();
    let centres = centres_of(opts, &columns);
    for_each_row(opts, area, sums, 1, 1, control, |j, row, counts| {
        first_samples(tracer, opts, &columns, &centres, j, row, counts);
        after_row(j, row);
    })
}

/// Divides sums of `samples` samples into pixel values; anything non-finite becomes 0
/// so that no NaN or infinity can reach a file or the window.
pub fn resolve(sums: &[Vec3], samples: u32, width: u32, height: u32) -> Frame {
    // In parallel, in runs through `pixel_values` (for one sample a copy).
    let mut pixels = vec![Vec3::ZERO; sums.len()];
    pixels
        .par_chunks_mut(4096)
        .zip(sums.par_chunks(4096))
        .for_each(|(out, sums)| pixel_values(sums, samples, out));
    Frame {
        width,
        height,
        pixels,
    }
}

/// [`pixel_value`] of each of `sums` into `out`: for one sample a copy, mended where
/// not finite (looked for without a branch a pixel, as `render` does).
pub fn pixel_values(sums: &[Vec3], samples: u32, out: &mut [Vec3]) {
    if samples > 1 {
        for (p, &sum) in out.iter_mut().zip(sums) {
            *p = pixel_value(sum, samples);
        }
        return;
    }
    out.copy_from_slice(sums);
    mend_non_finite(out);
}

/// The values of one-sample pixels in place: anything non-finite becomes 0. Looked
/// for without a branch a pixel (it never happens in a sound scene): p − p is 0 for a
/// finite p and NaN otherwise, and a NaN stays in the sum.
pub fn mend_non_finite(values: &mut [Vec3]) {
    #[allow(clippy::eq_op)] // p − p is the point
    let poison = values.iter().fold(Vec3::ZERO, |sum, &p| sum + (p - p));
    if poison != Vec3::ZERO {
        for p in values.iter_mut().filter(|p| !p.is_finite()) {
            *p = Vec3::ZERO;
        }
    }
}

/// A sum of `samples` samples as a finite pixel value.
#[inline]
pub fn pixel_value(sum: Vec3, samples: u32) -> Vec3 {
    let c = sum / samples.max(1) as f32;
    if c.is_finite() {
        c
    } else {
        Vec3::ZERO
    }
}

/// A render with what its quality settings cost in accuracy and saved in work.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendered {
    pub frame: Frame,
    /// For each pixel (same layout as the frame), a bound of the error the contribution
    /// cutoff caused: `|exact − value| ≤ bound` in every colour component, before
    /// clamping and rounding. All zero without a cutoff.
    pub cutoff_bound: Vec<f32>,
    /// Pixels that got more than the first pass of adaptive anti-aliasing (all of them
    /// without it).
    pub refined: u64,
    pub stats: RenderStats,
}

/// Renders the area of `opts` with all its samples.
pub fn render(
    scene: &Scene,
    opts: &RenderOptions,
    control: &RenderControl,
) -> Result<(Frame, RenderStats), RenderError> {
    let r = render_bounded(scene, opts, control)?;
    Ok((r.frame, r.stats))
}

/// Renders the area of `opts` and reports the cutoff's error bound per pixel and how
/// many pixels adaptive anti-aliasing refined.
pub fn render_bounded(
    scene: &Scene,
    opts: &RenderOptions,
    control: &RenderControl,
) -> Result<Rendered, RenderError> {
    opts.check()?;
    let start = Instant::now();
    // The build runs on the render's threads too: `--threads 1` means one thread.
    let tracer = in_pool(opts, || Tracer::new(scene, opts))??;
    let build_seconds = start.elapsed().as_secs_f64();
    let (frame, cutoff_bound, refined, rays) = match &tracer {
        Tracer::Fast(t) => render_with(t, opts, control)?,
        Tracer::Reference(t) => render_with(t, opts, control)?,
    };
    Ok(Rendered {
        frame,
        cutoff_bound,
        refined,
        stats: RenderStats {
            rays,
            seconds: start.elapsed().as_secs_f64(),
            build_seconds,
        },
    })
}

/// The frame, the cutoff's error bounds, the pixels refined and the rays, with `tracer`.
#[allow(clippy::type_complexity)]
fn render_with<T: SampleTracer>(
    tracer: &T,
    opts: &RenderOptions,
    control: &RenderControl,
) -> Result<(Frame, Vec<f32>, u64, RayCounts), RenderError> {
    let area = opts.area();
    let spp = opts.image.spp;
    let n = area.width as usize * area.height as usize;
    let frame = |pixels| Frame {
        width: area.width,
        height: area.height,
        pixels,
    };
    match opts.adaptive {
        Some(a) if a.first < spp => adaptive(tracer, opts, a, control),
        _ if opts.cutoff == 0.0 || opts.renderer == Renderer::Reference => {
            // Nothing is skipped, so every bound is 0: the pixels are written in place
            // (zeroed in parallel: on two cores a serial fill of a 1280×720 frame costs
            // a tenth of the render).
            let mut pixels: Vec<Vec3> = in_pool(opts, || {
                (0..n).into_par_iter().map(|_| Vec3::ZERO).collect()
            })?;
            let centres = pixel_centres(opts, area);
            let rays = for_each_row(
                opts,
                area,
                &mut pixels,
                1,
                u64::from(spp),
                control,
                |j, row, counts| {
                    if spp == 1 {
                        // The pixel centres: `film` for one sample, with the columns'
                        // positions worked out once (same values, no division), and
                        // the row at once, which lets the tracer share work.
                        tracer.sample_row(&centres, centre_height(opts, j), row, counts);
                        mend_non_finite(row);
                        return;
                    }
                    for (a, p) in row.iter_mut().enumerate() {
                        let i = area.x + a as u32;
                        let mut sum = Vec3::ZERO;
                        for k in 0..spp {
                            let (s, t) = film(opts, i, j, k);
                            sum += tracer.sample(s, t, counts);
                        }
                        *p = pixel_value(sum, spp);
                    }
                },
            )?;
            Ok((frame(pixels), vec![0.0; n], n as u64, rays))
        }
        _ => {
            let mut acc: Vec<(Vec3, f32)> = in_pool(opts, || {
                (0..n).into_par_iter().map(|_| (Vec3::ZERO, 0.0)).collect()
            })?;
            let rays = for_each_pixel(
                opts,
                area,
                &mut acc,
                1,
                u64::from(spp),
                control,
                |i, j, p, counts| {
                    let (sum, bound) = &mut p[0];
                    for k in 0..spp {
                        let (s, t) = film(opts, i, j, k);
                        let (c, b) = tracer.sample_bounded(s, t, counts);
                        *sum += c;
                        *bound += b;
                    }
                },
            )?;
            let (pixels, bounds) = in_pool(opts, || {
                acc.par_iter()
                    .map(|p| (pixel_value(p.0, spp), p.1 / spp as f32))
                    .unzip()
            })?;
            Ok((frame(pixels), bounds, n as u64, rays))
        }
    }
}

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
#[allow(clippy::type_complexity)]
fn adaptive<T: SampleTracer>(
    tracer: &T,
    opts: &RenderOptions,
    a: Adaptive,
    control: &RenderControl,
) -> Result<(Frame, Vec<f32>, u64, RayCounts), RenderError> {
    let spp = opts.image.spp;
    let area = opts.area();
    let first = first_pass_samples(spp, a.first, opts.image.seed);
    let nf = first.len();

    // The first pass covers the area and a one-pixel margin inside the image, so a
    // region's edge pixels see the same neighbours as in the whole image.
    let (w, h) = (opts.image.width, opts.image.height);
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
        opts,
        outer,
        &mut firsts,
        nf,
        nf as u64,
        control,
        |i, j, p, counts| {
            for (slot, &k) in p.iter_mut().zip(&first) {
                let (s, t) = film(opts, i, j, k);
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
    let more = for_each_pixel(opts, area, &mut out, 1, rest, control, |i, j, p, counts| {
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
                    let (s, t) = film(opts, i, j, k);
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
    })?;
    rays.add(&more);
    let refined = refine.iter().filter(|&&r| r).count() as u64;
    let frame = Frame {
        width: area.width,
        height: area.height,
        pixels: out.iter().map(|p| p.0).collect(),
    };
    Ok((frame, out.iter().map(|p| p.1).collect(), refined, rays))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tracer whose samples are NaN or infinite in some places.
    struct Poisoned;

    impl SampleTracer for Poisoned {
        fn sample(&self, s: f32, t: f32, _: &mut RayCounts) -> Vec3 {
            match ((s * 10.0) as u32 + (t * 10.0) as u32) % 4 {
                0 => Vec3::new(f32::NAN, 0.5, 0.5),
                1 => Vec3::new(0.25, f32::INFINITY, 0.5),
                2 => Vec3::new(0.25, 0.5, f32::NEG_INFINITY),
                _ => Vec3::new(s, t, 0.5),
            }
        }
    }

    #[test]
    fn pixel_values_of_a_row_are_each_pixel_value() {
        let sums = [
            Vec3::new(0.5, 1.5, 3.0),
            Vec3::new(f32::NAN, 0.25, 0.0),
            Vec3::new(1.0, f32::INFINITY, 2.0),
            Vec3::new(-0.0, 7.0, 1e-30),
        ];
        for samples in [0, 1, 3] {
            let mut out = [Vec3::splat(9.0); 4];
            pixel_values(&sums, samples, &mut out);
            for (k, (&o, &s)) in out.iter().zip(&sums).enumerate() {
                let want = pixel_value(s, samples);
                assert_eq!(
                    o.to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits)
                );
                assert!(o.is_finite(), "samples {samples}, pixel {k}");
            }
        }
        // With one sample, a finite sum is its own value; a poisoned one is black.
        let mut out = [Vec3::ZERO; 4];
        pixel_values(&sums, 1, &mut out);
        assert_eq!(
            [out[0], out[1], out[2], out[3]],
            [sums[0], Vec3::ZERO, Vec3::ZERO, sums[3]]
        );
    }

    #[test]
    fn no_nan_or_infinity_reaches_a_frame() {
        for spp in [1, 2] {
            let mut opts = RenderOptions::for_scene(&crate::scene::hw3_scene(0));
            (opts.image.width, opts.image.height, opts.image.spp) = (20, 10, spp);
            let (frame, ..) = render_with(&Poisoned, &opts, &RenderControl::default()).unwrap();
            let finite = frame.pixels.iter().filter(|p| p.is_finite()).count();
            assert_eq!(finite, 200, "spp {spp}");
            let black = frame.pixels.iter().filter(|&&p| p == Vec3::ZERO).count();
            let sane = frame.pixels.iter().filter(|p| p.z == 0.5).count();
            assert!(
                black > 50 && sane > 20 && black + sane == 200,
                "spp {spp}: {black} {sane}"
            );
        }
    }
}
