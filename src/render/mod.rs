//! The frame: pixels in bands on rayon, samples per pixel, progress and cancellation,
//! and the linear RGB buffer. Row 0 of every buffer here is the BOTTOM row of the
//! image (`j = 0`, as in GLUT); the file writers and the window flip it, once.
//!
//! [`render()`] takes a scene and resolved [`Settings`]; the submodules are its steps:
//! `bands` (rows over threads), `film` (where samples land), `adaptive`
//! (anti-aliasing where it matters), [`resolve()`] (sums to finite pixel values) and
//! `progressive` (sums kept between the passes of a progressive render).

mod adaptive;
pub(crate) mod bands;
pub(crate) mod film;
mod frame;
pub(crate) mod progressive;
mod resolve;
mod sequence;

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use crate::camera::{Camera, CameraError};
use crate::scene::Scene;
use crate::settings::{Adaptive, Precision, Region, Settings, SettingsError};
use crate::trace::fast::FastTracer;
use crate::trace::reference::ReferenceTracer;
use crate::trace::{RayCounts, SampleTracer};
use adaptive::adaptive;
use bands::{for_each_row, for_each_row_of_bytes, in_pool, BAND_ROWS};
use film::{centre_height, centres_of, each_sample_of_row, pixel_centres, Film};

pub use adaptive::first_pass_samples;
use frame::bytes_of_row;
pub use frame::Frame;
pub use progressive::{accumulate, accumulate_first};
pub use resolve::{mend_non_finite, pixel_value, pixel_values, resolve};
pub use sequence::Sequence;

/// Why a render did not finish.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// Settings that [`Settings::check`] refuses.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The scene's camera cannot make an image of this size.
    #[error("camera: {0}")]
    Camera(#[from] CameraError),
    /// The thread pool could not be started.
    #[error("cannot start {threads} threads: {source}")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// What the pool builder said.
        source: rayon::ThreadPoolBuildError,
    },
    /// [`RenderControl::cancel`] was called.
    #[error("render cancelled")]
    Cancelled,
}

/// Shared between a render and whoever watches it: progress out, cancellation in.
#[derive(Debug, Default)]
pub struct RenderControl {
    cancel: AtomicBool,
    pub(crate) pixels_done: AtomicU64,
    samples_total: AtomicU64,
}

impl RenderControl {
    /// Asks the render to stop; it returns [`RenderError::Cancelled`] within a row.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Whether [`RenderControl::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// Samples traced so far: the work done, in the unit of
    /// [`RenderControl::samples_total`].
    pub fn pixels_done(&self) -> u64 {
        self.pixels_done.load(Ordering::Relaxed)
    }

    /// The samples the render will trace when it is done (0 before it starts). A
    /// render with adaptive anti-aliasing estimates its second pass from the pixels
    /// its first pass has flagged so far, and knows it exactly once the first pass
    /// is over; the count never includes samples that are not traced.
    pub fn samples_total(&self) -> u64 {
        self.samples_total.load(Ordering::Relaxed)
    }

    pub(crate) fn set_samples_total(&self, total: u64) {
        self.samples_total.store(total, Ordering::Relaxed);
    }
}

/// What a render cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Rays cast, by kind.
    pub rays: RayCounts,
    /// Wall time of the whole render, preparation included.
    pub seconds: f64,
    /// Of which: compiling the scene for the tracer (acceleration structures).
    pub build_seconds: f64,
}

impl RenderStats {
    /// Rays cast a second of wall time, in millions.
    pub fn mrays_per_second(&self) -> f64 {
        self.rays.total() as f64 / self.seconds.max(1e-9) / 1e6
    }
}

/// Builds the tracer that `settings` asks for.
pub fn make_tracer<'a>(
    scene: &'a Scene,
    settings: &Settings,
) -> Result<Box<dyn SampleTracer + 'a>, RenderError> {
    let camera = scene.camera(settings.width, settings.height)?;
    Ok(match Tracer::new(scene, camera, settings, None) {
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
    /// The tracer `settings` ask for, seeing `scene` through `camera`. A fast tracer of
    /// the same scene from an earlier view (`previous`) lends its compiled scene, so
    /// only the camera's part is built.
    fn new(
        scene: &'a Scene,
        camera: Camera,
        settings: &Settings,
        previous: Option<FastTracer>,
    ) -> Self {
        let depth = settings.quality.max_depth;
        match settings.quality.precision {
            Precision::Fast => Tracer::Fast(
                match previous {
                    Some(p) => p.with_camera(&camera, depth),
                    None => FastTracer::new(scene, &camera, depth),
                }
                .with_cutoff(settings.quality.cutoff),
            ),
            Precision::Reference => Tracer::Reference(ReferenceTracer::new(scene, camera, depth)),
        }
    }

    /// The area of `settings`, traced.
    fn render(&self, settings: &Settings, control: &RenderControl) -> Result<Traced, RenderError> {
        match self {
            Tracer::Fast(t) => render_with(t, settings, control),
            Tracer::Reference(t) => render_with(t, settings, control),
        }
    }
}

/// A render with what its quality settings cost in accuracy and saved in work.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendered {
    /// The pixels of the area rendered.
    pub frame: Frame,
    /// For each pixel (same layout as the frame), a bound of the error the contribution
    /// cutoff caused: `|exact − value| ≤ bound` in every colour component, before
    /// clamping and rounding. All zero without a cutoff.
    pub cutoff_bound: Vec<f32>,
    /// Pixels that got more than the first pass of adaptive anti-aliasing (all of them
    /// without it).
    pub refined: u64,
    /// What the render cost.
    pub stats: RenderStats,
}

/// Renders the area of `settings` with all its samples.
pub fn render(
    scene: &Scene,
    settings: &Settings,
    control: &RenderControl,
) -> Result<(Frame, RenderStats), RenderError> {
    let r = render_bounded(scene, settings, control)?;
    Ok((r.frame, r.stats))
}

/// Renders the area of `settings` with all its samples into 8-bit RGB, top row first,
/// `byte` turning each linear value into its byte (an encoding's conversion): to the
/// byte what [`render`] and then [`Frame::bytes_top_first`] give. A render of one
/// sample a pixel that skips nothing converts each row as it traces it and keeps no
/// linear frame (11 MB at 1280×720, whose fresh pages cost a tenth of a cold render
/// of hw3); any other renders the frame, then converts it.
pub fn render_bytes(
    scene: &Scene,
    settings: &Settings,
    control: &RenderControl,
    byte: impl Fn(f32) -> u8 + Sync,
) -> Result<(Vec<u8>, RenderStats), RenderError> {
    let quality = &settings.quality;
    let adaptive = matches!(quality.adaptive, Some(a) if a.first < quality.spp);
    let skips = quality.cutoff != 0.0 && quality.precision != Precision::Reference;
    if quality.spp != 1 || adaptive || skips {
        let (frame, stats) = render(scene, settings, control)?;
        return Ok((frame.bytes_top_first(byte), stats));
    }
    settings.check()?;
    let start = Instant::now();
    let camera = scene.camera(settings.width, settings.height)?;
    let tracer = in_pool(settings, || Tracer::new(scene, camera, settings, None))?;
    let build_seconds = start.elapsed().as_secs_f64();
    let (bytes, rays) = match &tracer {
        Tracer::Fast(t) => one_sample_rgb8(t, settings, control, &byte)?,
        Tracer::Reference(t) => one_sample_rgb8(t, settings, control, &byte)?,
    };
    let stats = RenderStats {
        rays,
        seconds: start.elapsed().as_secs_f64(),
        build_seconds,
    };
    Ok((bytes, stats))
}

/// The one-sample pass of [`render_with`], each row converted to bytes by `byte` as
/// soon as it is traced, top row first.
fn one_sample_rgb8<T: SampleTracer>(
    tracer: &T,
    settings: &Settings,
    control: &RenderControl,
    byte: &(impl Fn(f32) -> u8 + Sync),
) -> Result<(Vec<u8>, RayCounts), RenderError> {
    let area = settings.area();
    let n = area.width as usize * area.height as usize;
    control.set_samples_total(n as u64);
    let mut bytes = vec![0u8; 3 * n];
    let centres = pixel_centres(settings, area);
    let rays = for_each_row_of_bytes(settings, area, &mut bytes, control, |j, out, counts| {
        let mut row = vec![Vec3::ZERO; centres.len()];
        tracer.sample_row(&centres, centre_height(settings, j), &mut row, counts);
        mend_non_finite(&mut row);
        bytes_of_row(&row, out, byte);
    })?;
    Ok((bytes, rays))
}

/// Renders the area of `settings` and reports the cutoff's error bound per pixel and how
/// many pixels adaptive anti-aliasing refined.
pub fn render_bounded(
    scene: &Scene,
    settings: &Settings,
    control: &RenderControl,
) -> Result<Rendered, RenderError> {
    settings.check()?;
    let start = Instant::now();
    let camera = scene.camera(settings.width, settings.height)?;
    // The build runs on the render's threads too: `--threads 1` means one thread.
    let tracer = in_pool(settings, || Tracer::new(scene, camera, settings, None))?;
    let build_seconds = start.elapsed().as_secs_f64();
    let Traced {
        frame,
        cutoff_bound,
        refined,
        rays,
    } = tracer.render(settings, control)?;
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

/// What the pixel loops of a render give back.
struct Traced {
    frame: Frame,
    /// See [`Rendered::cutoff_bound`].
    cutoff_bound: Vec<f32>,
    /// See [`Rendered::refined`].
    refined: u64,
    rays: RayCounts,
}

/// Pixels of one strip of an adaptive render at most. The first pass keeps every first
/// sample of what it covers (64 bytes a pixel at 4 first samples: 530 MB for a whole
/// 3840×2160 image), so a larger image goes through it a strip at a time. Up to this
/// size an image is one strip, and its progress total is estimated from the image's
/// own first pass; beyond it, the strips to come are estimated from the strips done.
const ADAPTIVE_STRIP_PIXELS: usize = 1 << 21;

/// Adaptive anti-aliasing of the area of `settings`, in strips of whole rows of at most
/// `strip_pixels` pixels (at least one band of rows). A strip is rendered as a region,
/// which gives exactly that crop of the whole area (its first pass looks one pixel
/// beyond it, as the whole area's does).
fn adaptive_in_strips<T: SampleTracer>(
    tracer: &T,
    settings: &Settings,
    a: Adaptive,
    control: &RenderControl,
    strip_pixels: usize,
) -> Result<Traced, RenderError> {
    let area = settings.area();
    let rows = (strip_pixels / area.width.max(1) as usize).max(BAND_ROWS) as u32;
    if rows >= area.height {
        return adaptive(tracer, settings, a, control, &|t| {
            control.set_samples_total(t)
        });
    }
    let n = area.width as usize * area.height as usize;
    let mut whole = Traced {
        frame: Frame {
            width: area.width,
            height: area.height,
            pixels: vec![Vec3::ZERO; n],
        },
        cutoff_bound: vec![0.0; n],
        refined: 0,
        rays: RayCounts::default(),
    };
    let bottom = area.y + area.height;
    // Strips from the middle out, in bit-reversed order, so the strips done at any
    // moment spread over the image and the progress estimate of those to come is a
    // fair one.
    let mut strips: Vec<u32> = (area.y..bottom).step_by(rows as usize).collect();
    let n = strips.len() as u64;
    strips.sort_unstable_by_key(|&y| {
        let k = u64::from((y - area.y) / rows);
        ((k + n / 2) % n).reverse_bits()
    });
    let start = control.pixels_done();
    let mut rows_done = 0u64;
    for y in strips {
        let height = rows.min(bottom - y);
        // Progress: the samples of the strips done, this strip's estimate, and the
        // rows still to come at the rate of the rows so far.
        let done = control.pixels_done() - start;
        let rows_after = u64::from(area.height) - rows_done - u64::from(height);
        let set_total = |strip_total: u64| {
            let rate = (done + strip_total) as f64 / (rows_done + u64::from(height)) as f64;
            let rest = (rate * rows_after as f64).round() as u64;
            control.set_samples_total(start + done + strip_total + rest);
        };
        let strip = Settings {
            region: Some(Region {
                x: area.x,
                y,
                width: area.width,
                height,
            }),
            tile: None,
            ..settings.clone()
        };
        let part = adaptive(tracer, &strip, a, control, &set_total)?;
        rows_done += u64::from(height);
        // Both frames count rows from the bottom: the strip's bottom row is the
        // area's row `bottom - (y + height)`.
        let start = (bottom - (y + height)) as usize * area.width as usize;
        let end = start + part.frame.pixels.len();
        whole.frame.pixels[start..end].copy_from_slice(&part.frame.pixels);
        whole.cutoff_bound[start..end].copy_from_slice(&part.cutoff_bound);
        whole.refined += part.refined;
        whole.rays.add(&part.rays);
    }
    Ok(whole)
}

/// The area of `settings` rendered with `tracer`.
fn render_with<T: SampleTracer>(
    tracer: &T,
    settings: &Settings,
    control: &RenderControl,
) -> Result<Traced, RenderError> {
    let area = settings.area();
    let spp = settings.quality.spp;
    let film = Film::new(settings);
    let n = area.width as usize * area.height as usize;
    control.set_samples_total(n as u64 * u64::from(spp));
    let frame = |pixels| Frame {
        width: area.width,
        height: area.height,
        pixels,
    };
    match settings.quality.adaptive {
        Some(a) if a.first < spp => {
            adaptive_in_strips(tracer, settings, a, control, ADAPTIVE_STRIP_PIXELS)
        }
        _ if settings.quality.cutoff == 0.0
            || settings.quality.precision == Precision::Reference =>
        {
            // Nothing is skipped, so every bound is 0: the pixels are written in place
            // (zeroed in parallel: on two cores a serial fill of a 1280×720 frame costs
            // a tenth of the render).
            let mut pixels: Vec<Vec3> = in_pool(settings, || {
                (0..n).into_par_iter().map(|_| Vec3::ZERO).collect()
            })?;
            let columns: Vec<u32> = (area.x..area.x + area.width).collect();
            let centres = centres_of(settings, &columns);
            let rays = for_each_row(
                settings,
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
                        tracer.sample_row(&centres, centre_height(settings, j), row, counts);
                        mend_non_finite(row);
                        return;
                    }
                    // The sums in the pixels' places, then their values.
                    row.fill(Vec3::ZERO);
                    each_sample_of_row(tracer, &film, &columns, j, 0..spp, counts, {
                        |a, _, (c, _)| row[a] += c
                    });
                    for p in row.iter_mut() {
                        *p = pixel_value(*p, spp);
                    }
                },
            )?;
            Ok(Traced {
                frame: frame(pixels),
                cutoff_bound: vec![0.0; n],
                refined: n as u64,
                rays,
            })
        }
        _ => {
            let mut acc: Vec<(Vec3, f32)> = in_pool(settings, || {
                (0..n).into_par_iter().map(|_| (Vec3::ZERO, 0.0)).collect()
            })?;
            let columns: Vec<u32> = (area.x..area.x + area.width).collect();
            let centres = centres_of(settings, &columns);
            let rays = for_each_row(
                settings,
                area,
                &mut acc,
                1,
                u64::from(spp),
                control,
                |j, row, counts| {
                    if spp == 1 {
                        // The pixel centres a row at a time, as without a cutoff.
                        let t = centre_height(settings, j);
                        return tracer.sample_row_bounded(&centres, t, row, counts);
                    }
                    each_sample_of_row(tracer, &film, &columns, j, 0..spp, counts, {
                        |a, _, (c, b)| {
                            row[a].0 += c;
                            row[a].1 += b;
                        }
                    });
                },
            )?;
            let (pixels, bounds) = in_pool(settings, || {
                acc.par_iter()
                    .map(|p| (pixel_value(p.0, spp), p.1 / spp as f32))
                    .unzip()
            })?;
            Ok(Traced {
                frame: frame(pixels),
                cutoff_bound: bounds,
                refined: n as u64,
                rays,
            })
        }
    }
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
    fn adaptive_strips_give_the_pixels_of_one_pass() {
        let scene = crate::scene::hw3_scene(2020);
        let tracer = FastTracer::new(&scene, &scene.camera(96, 54).unwrap(), 5).with_cutoff(0.0);
        let a = Adaptive::with_threshold(0.05);
        for region in [
            None,
            Some(Region {
                x: 7,
                y: 5,
                width: 61,
                height: 43,
            }),
        ] {
            let mut settings = scene.settings();
            (settings.width, settings.height, settings.quality.spp) = (96, 54, 16);
            settings.region = region;
            let control = RenderControl::default();
            let whole = adaptive(&tracer, &settings, a, &control, &|_| {}).unwrap();
            // Strips of one band (8 rows), of 17 rows, and one strip.
            for strip_pixels in [1, 17 * 96, usize::MAX] {
                let control = RenderControl::default();
                let strips =
                    adaptive_in_strips(&tracer, &settings, a, &control, strip_pixels).unwrap();
                // The progress total ends at the samples traced, strips or not.
                assert_eq!(control.samples_total(), control.pixels_done());
                assert_eq!(control.pixels_done(), strips.rays.primary);
                assert_eq!(strips.frame, whole.frame, "{region:?} {strip_pixels}");
                assert_eq!(strips.cutoff_bound, whole.cutoff_bound);
                assert_eq!(strips.refined, whole.refined);
            }
            // Some pixels are refined and some not: the test can tell strips apart.
            let n = whole.frame.pixels.len() as u64;
            assert!(whole.refined > 0 && whole.refined < n, "{}", whole.refined);
        }
    }

    #[test]
    fn no_nan_or_infinity_reaches_a_frame() {
        for spp in [1, 2] {
            let mut settings = crate::scene::hw3_scene(0).settings();
            (settings.width, settings.height, settings.quality.spp) = (20, 10, spp);
            let frame = render_with(&Poisoned, &settings, &RenderControl::default())
                .unwrap()
                .frame;
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

    /// Bytes straight from the rows are the frame path's bytes (the frame, then
    /// `to_rgb8`): one sample a pixel (rows converted as they are traced) in both
    /// encodings, a region away from every edge, the reference tracer, and the renders
    /// that make a frame first (4 samples, a cutoff).
    #[test]
    fn bytes_straight_from_the_rows_are_the_frame_s_bytes() {
        use crate::image_io::{to_rgb8, ByteEncoder, Encoding};
        let scene = crate::scene::hw3_scene(0);
        let mut base = scene.settings();
        (base.width, base.height) = (64, 36);
        let with = |change: &dyn Fn(&mut Settings)| {
            let mut s = base.clone();
            change(&mut s);
            s
        };
        let cases = [
            ("one sample", with(&|_| {}), Encoding::Linear),
            ("one sample, sRGB", with(&|_| {}), Encoding::Srgb),
            (
                "a region",
                with(&|s| {
                    s.region = Some(Region {
                        x: 5,
                        y: 3,
                        width: 40,
                        height: 20,
                    })
                }),
                Encoding::Linear,
            ),
            (
                "reference",
                with(&|s| s.quality.precision = Precision::Reference),
                Encoding::Srgb,
            ),
            ("4 samples", with(&|s| s.quality.spp = 4), Encoding::Linear),
            (
                "a cutoff",
                with(&|s| s.quality.cutoff = 0.05),
                Encoding::Linear,
            ),
        ];
        for (name, settings, encoding) in cases {
            let (frame, _) = render(&scene, &settings, &RenderControl::default()).unwrap();
            let want = to_rgb8(&frame, encoding);
            let encoder = ByteEncoder::new(encoding);
            let (got, stats) = render_bytes(&scene, &settings, &RenderControl::default(), |c| {
                encoder.byte(c)
            })
            .unwrap();
            assert!(got == *want.as_raw(), "{name}: the bytes differ");
            // Not a blank picture: the top row (sky) and the bottom row (ground) differ.
            let rows: Vec<&[u8]> = got.chunks(3 * want.width() as usize).collect();
            assert_ne!(rows[0], rows[rows.len() - 1], "{name}");
            assert!(stats.rays.primary > 0, "{name}");
        }
    }
}
