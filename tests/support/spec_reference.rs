//! The reference side of the fast-vs-reference tests, written from SPEC §2 rather than
//! taken from the renderer: the camera from its two forms, the film position of each
//! sample (`s = (i+sx)/W`, `t = (j+sy)/Hpx`, `j` from the bottom), the row order of the
//! image (top row first), the region's place (its `y` counted from the top), the mean
//! of the samples and the byte `round(clamp(c, 0, 1)·255)`, all in `f64`. Only the
//! colour of one film position comes from the library (the `f64` reference tracer's
//! `sample_f64`), and, for more than one sample a pixel, the jitter offsets: the SPEC
//! leaves their hash to the implementation (`sampling::sample_offset`, whose
//! stratification its own tests check).

use glam::DVec3;
use rayon::prelude::*;
use whitted::camera::{Camera, CameraSpec};
use whitted::scene::Scene;
use whitted::settings::{Region, Settings};
use whitted::trace::reference::ReferenceTracer;
use whitted::trace::RayCounts;

/// An 8-bit RGB image, top row first, and how many of its pixels were not finite
/// before they were made 0.
pub struct SpecImage {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
    pub non_finite: usize,
}

/// The camera of `scene` for a `width`×`height` image, by SPEC §2's formulas: the
/// scene's own, else the assignment's frame at 16:9 and its look-at form otherwise.
pub fn spec_camera(scene: &Scene, width: u32, height: u32) -> Camera {
    let spec = scene.camera.unwrap_or_else(|| {
        if u64::from(width) * 9 == u64::from(height) * 16 {
            CameraSpec::Frame {
                origin: DVec3::ZERO,
                lower_left: DVec3::new(-4.0, -2.25, -1.0),
                horizontal: DVec3::new(8.0, 0.0, 0.0),
                vertical: DVec3::new(0.0, 4.5, 0.0),
            }
        } else {
            CameraSpec::LookAt {
                look_from: DVec3::ZERO,
                look_at: DVec3::new(0.0, 0.0, -1.0),
                up: DVec3::Y,
                vfov: 2.0 * 2.25f64.atan().to_degrees(),
            }
        }
    });
    match spec {
        CameraSpec::Frame {
            origin,
            lower_left,
            horizontal,
            vertical,
        } => Camera {
            origin,
            lower_left,
            horizontal,
            vertical,
        },
        CameraSpec::LookAt {
            look_from,
            look_at,
            up,
            vfov,
        } => {
            let w = (look_from - look_at).normalize();
            let u = up.cross(w).normalize();
            let v = w.cross(u);
            let h = (vfov.to_radians() / 2.0).tan();
            let a = f64::from(width) / f64::from(height);
            Camera {
                origin: look_from,
                lower_left: look_from - a * h * u - h * v - w,
                horizontal: 2.0 * a * h * u,
                vertical: 2.0 * h * v,
            }
        }
    }
}

/// The SPEC's byte of a linear value: `round(clamp(c, 0, 1)·255)`.
pub fn spec_byte(c: f64) -> u8 {
    (c.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The image `settings` ask for (its size, samples, seed, depth and region; no tile,
/// no adaptive sampling, no cutoff), computed by the SPEC from the `f64` tracer's
/// colours.
pub fn spec_reference(scene: &Scene, settings: &Settings) -> SpecImage {
    let (w, h, spp) = (settings.width, settings.height, settings.quality.spp);
    assert!(settings.tile.is_none() && settings.quality.adaptive.is_none());
    let region = settings.region.unwrap_or(Region {
        x: 0,
        y: 0,
        width: w,
        height: h,
    });
    let camera = spec_camera(scene, w, h);
    let tracer = ReferenceTracer::new(scene, camera, settings.quality.max_depth);
    let row_bytes = region.width as usize * 3;
    let mut rgb = vec![0u8; row_bytes * region.height as usize];
    let non_finite: usize = rgb
        .par_chunks_mut(row_bytes)
        .enumerate()
        .map(|(y, out)| {
            // Output row `y` of the region is image row `region.y + y` from the top.
            let j = h - 1 - (region.y + y as u32);
            let mut bad = 0;
            for (x, px) in out.chunks_exact_mut(3).enumerate() {
                let i = region.x + x as u32;
                let mut sum = DVec3::ZERO;
                for k in 0..spp {
                    let (sx, sy) = if spp == 1 {
                        (0.5, 0.5)
                    } else {
                        let (sx, sy) =
                            whitted::sampling::sample_offset(i, j, k, spp, settings.seed);
                        assert!((0.0..1.0).contains(&sx) && (0.0..1.0).contains(&sy));
                        (f64::from(sx), f64::from(sy))
                    };
                    let s = (f64::from(i) + sx) / f64::from(w);
                    let t = (f64::from(j) + sy) / f64::from(h);
                    sum += tracer.sample_f64(s, t, &mut RayCounts::default());
                }
                let mut c = sum / f64::from(spp);
                if !c.is_finite() {
                    bad += 1;
                    c = DVec3::ZERO;
                }
                px.copy_from_slice(&[spec_byte(c.x), spec_byte(c.y), spec_byte(c.z)]);
            }
            bad
        })
        .sum();
    SpecImage {
        width: region.width,
        height: region.height,
        rgb,
        non_finite,
    }
}

/// Pixels that may differ by more than 8 levels, if each sits on a silhouette.
pub const HANDFUL: usize = 5;

/// Checks an 8-bit image (top row first) against the reference: at most 0.01% of the
/// pixels differ by more than one level, and at most [`HANDFUL`] by more than 8, each
/// on a silhouette (where the reference itself jumps by more than 8 levels to a
/// neighbour, so that an `f32` ray may pass on the other side of an edge). Prints the
/// figures under `label`; returns what failed.
pub fn check_close(label: &str, fast: &[u8], reference: &SpecImage) -> Result<(), String> {
    let (w, h) = (reference.width, reference.height);
    assert_eq!(fast.len(), reference.rgb.len(), "{label}: sizes differ");
    let px = |img: &[u8], x: u32, y: u32| -> [u8; 3] {
        let k = 3 * (y as usize * w as usize + x as usize);
        [img[k], img[k + 1], img[k + 2]]
    };
    let diff = |a: [u8; 3], b: [u8; 3]| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap();
    let on_silhouette = |x: u32, y: u32| -> bool {
        let p = px(&reference.rgb, x, y);
        (-1i64..=1)
            .flat_map(|dy| (-1i64..=1).map(move |dx| (dx, dy)))
            .filter_map(|(dx, dy)| {
                let (nx, ny) = (i64::from(x) + dx, i64::from(y) + dy);
                (nx >= 0 && ny >= 0 && nx < i64::from(w) && ny < i64::from(h))
                    .then(|| px(&reference.rgb, nx as u32, ny as u32))
            })
            .any(|q| diff(p, q) > 8)
    };
    let total = (w * h) as usize;
    let (mut over1, mut max, mut big) = (0usize, 0u8, Vec::new());
    for y in 0..h {
        for x in 0..w {
            let d = diff(px(fast, x, y), px(&reference.rgb, x, y));
            max = max.max(d);
            over1 += usize::from(d > 1);
            if d > 8 {
                big.push((x, y, d, on_silhouette(x, y)));
            }
        }
    }
    println!(
        "{label} ({total} pixels): {over1} differ by >1 level ({:.4}%), {} by >8; largest \
         difference {max} levels; {} non-finite reference pixels",
        100.0 * over1 as f64 / total as f64,
        big.len(),
        reference.non_finite
    );
    let mut failures = Vec::new();
    if over1 * 10_000 > total {
        failures.push(format!("{over1} pixels differ by more than one level"));
    }
    if big.len() > HANDFUL {
        failures.push(format!("{} pixels differ by more than 8 levels", big.len()));
    }
    let inner: Vec<_> = big.iter().filter(|b| !b.3).take(10).collect();
    if !inner.is_empty() {
        failures.push(format!(
            "pixels (x, y from the top-left, levels) away from any silhouette differ by \
             more than 8 levels: {inner:?}"
        ));
    }
    if reference.non_finite > 0 {
        failures.push(format!(
            "{} non-finite reference pixels",
            reference.non_finite
        ));
    }
    if failures.is_empty() {
        Ok(())
    } else {
        Err(format!("{label}: {}", failures.join("; ")))
    }
}
