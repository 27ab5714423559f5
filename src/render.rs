//! The frame: pixels in bands on rayon, samples per pixel, progress and cancellation,
//! and the linear RGB buffer. Row 0 of every buffer here is the BOTTOM row of the
//! image (`j = 0`, as in GLUT); the file writers and the window flip it, once.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use crate::camera::Camera;
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
}

impl RenderOptions {
    /// The scene's own settings, all of the image, all cores, the fast tracer.
    pub fn for_scene(scene: &Scene) -> Self {
        RenderOptions {
            image: scene.image,
            region: None,
            threads: None,
            renderer: Renderer::Fast,
        }
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
    pixels_done: AtomicU64,
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
    let camera = Camera::for_scene(scene, opts.image.width, opts.image.height)
        .map_err(|m| RenderError::Invalid(format!("camera: {m}")))?;
    let depth = opts.image.max_depth;
    Ok(match opts.renderer {
        Renderer::Fast => Box::new(FastTracer::new(scene, &camera, depth)),
        Renderer::Reference => Box::new(ReferenceTracer::new(scene, camera, depth)),
    })
}

/// Rows per unit of parallel work.
const BAND_ROWS: usize = 8;

/// Adds samples `samples` of every pixel of the area into `sums` (area-sized, row 0 at
/// the bottom of the area), in sample order, so that any split into passes sums the
/// same numbers in the same order.
pub fn accumulate(
    tracer: &dyn SampleTracer,
    opts: &RenderOptions,
    samples: Range<u32>,
    sums: &mut [Vec3],
    control: &RenderControl,
) -> Result<RayCounts, RenderError> {
    let area = opts.area();
    let (w, h) = (opts.image.width, opts.image.height);
    let aw = area.width as usize;
    assert_eq!(
        sums.len(),
        aw * area.height as usize,
        "sums must cover the area"
    );
    // The area's bottom row, counted from the image's bottom.
    let j0 = h - (area.y + area.height);
    let (wf, hf) = (w as f32, h as f32);
    let spp = opts.image.spp;
    let seed = opts.image.seed;

    let mut work = || {
        sums.par_chunks_mut(aw * BAND_ROWS)
            .enumerate()
            .map(|(band, rows)| {
                let mut counts = RayCounts::default();
                for (r, row) in rows.chunks_mut(aw).enumerate() {
                    if control.is_cancelled() {
                        return Err(RenderError::Cancelled);
                    }
                    let j = j0 + (band * BAND_ROWS + r) as u32;
                    for (a, sum) in row.iter_mut().enumerate() {
                        let i = area.x + a as u32;
                        for k in samples.clone() {
                            let (sx, sy) = sample_offset(i, j, k, spp, seed);
                            let s = (i as f32 + sx) / wf;
                            let t = (j as f32 + sy) / hf;
                            *sum += tracer.sample(s, t, &mut counts);
                        }
                    }
                    control
                        .pixels_done
                        .fetch_add(aw as u64 * samples.len() as u64, Ordering::Relaxed);
                }
                Ok(counts)
            })
            .try_reduce(RayCounts::default, |mut a, b| {
                a.add(&b);
                Ok(a)
            })
    };
    match opts.threads {
        None => work(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| RenderError::Invalid(format!("cannot start {n} threads: {e}")))?
            .install(work),
    }
}

/// Divides sums of `samples` samples into pixel values; anything non-finite becomes 0
/// so that no NaN or infinity can reach a file or the window.
pub fn resolve(sums: &[Vec3], samples: u32, width: u32, height: u32) -> Frame {
    let n = samples.max(1) as f32;
    let pixels = sums
        .iter()
        .map(|&s| {
            let c = s / n;
            if c.is_finite() {
                c
            } else {
                Vec3::ZERO
            }
        })
        .collect();
    Frame {
        width,
        height,
        pixels,
    }
}

/// Renders the area of `opts` with all its samples.
pub fn render(
    scene: &Scene,
    opts: &RenderOptions,
    control: &RenderControl,
) -> Result<(Frame, RenderStats), RenderError> {
    opts.check()?;
    let start = Instant::now();
    let tracer = make_tracer(scene, opts)?;
    let build_seconds = start.elapsed().as_secs_f64();
    let area = opts.area();
    let mut sums = vec![Vec3::ZERO; area.width as usize * area.height as usize];
    let rays = accumulate(tracer.as_ref(), opts, 0..opts.image.spp, &mut sums, control)?;
    let frame = resolve(&sums, opts.image.spp, area.width, area.height);
    let stats = RenderStats {
        rays,
        seconds: start.elapsed().as_secs_f64(),
        build_seconds,
    };
    Ok((frame, stats))
}
