//! The study's renders: one render of a setting reduced to the figures the study
//! keeps, and the converged reference of a scene, cached on disk.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::Path;

use anyhow::Context;
use glam::Vec3;

use super::BenchOptions;
use crate::render::{render_bounded, Frame, RenderControl};
use crate::scene::Scene;
use crate::settings::{Preset, Quality, Settings};

/// One render of a setting, with what the study records of it.
pub(crate) struct Measured {
    pub frame: Frame,
    /// The largest per-pixel error bound the contribution cutoff reports, in 8-bit
    /// levels.
    pub cutoff_bound: f64,
    /// Share of pixels that adaptive anti-aliasing gave all samples.
    pub refined: f64,
    pub rays: u64,
    /// Wall time of the render, seconds.
    pub seconds: f64,
}

/// Renders `scene` with `quality` at the size and threads of `opts`.
pub(crate) fn render_once(
    scene: &Scene,
    quality: &Quality,
    opts: &BenchOptions,
) -> anyhow::Result<Measured> {
    let ro = Settings {
        width: opts.width,
        height: opts.height,
        quality: *quality,
        threads: opts.threads,
        ..scene.settings()
    };
    let r = render_bounded(scene, &ro, &RenderControl::default())
        .with_context(|| format!("{}: {}", scene.name, quality.label()))?;
    let bound = r.cutoff_bound.iter().fold(0.0f32, |m, &b| m.max(b));
    let pixels = r.frame.pixels.len().max(1) as f64;
    Ok(Measured {
        frame: r.frame,
        cutoff_bound: f64::from(bound) * 255.0,
        refined: r.refined as f64 / pixels,
        rays: r.stats.rays.total(),
        seconds: r.stats.seconds,
    })
}

/// The converged reference of a scene, with the cost of the render that made it.
pub(crate) struct Reference {
    pub frame: Frame,
    /// Wall time of the render, seconds.
    pub seconds: f64,
    pub rays: u64,
}

/// The converged reference of a scene, from the cache in `dir` when a previous run
/// made it for the same scene, size and settings.
///
/// The cache holds two files per reference, named by a hash of the scene, size,
/// settings and a probe render: `.f32` (the pixels, little-endian RGB `f32`s, row by
/// row) and `.time` (seconds and rays of the render that made it).
pub(crate) fn reference(
    scene: &Scene,
    opts: &BenchOptions,
    dir: &Path,
) -> anyhow::Result<Reference> {
    let q = Preset::Reference.quality();
    let mut h = DefaultHasher::new();
    (
        crate::scene::to_toml(scene),
        q.label(),
        opts.width,
        opts.height,
    )
        .hash(&mut h);
    // A tiny render of the same scene stands for the reference code: if that code
    // changes what it computes, the probe (almost surely) changes and the cache misses.
    let probe = BenchOptions {
        width: 8,
        height: 8,
        ..opts.clone()
    };
    let probe_q = Quality { spp: 4, ..q };
    for p in render_once(scene, &probe_q, &probe)?.frame.pixels {
        p.to_array().map(f32::to_bits).hash(&mut h);
    }
    let path = dir.join(format!(
        "{}-{}x{}-{:016x}.f32",
        scene.name,
        opts.width,
        opts.height,
        h.finish()
    ));
    let timing = path.with_extension("time");
    if let Some(cached) = read_cached(&path, &timing, opts) {
        return Ok(cached);
    }
    let Measured {
        frame,
        rays,
        seconds,
        ..
    } = render_once(scene, &q, opts)?;
    let bytes: Vec<u8> = frame
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    std::fs::write(&path, bytes).with_context(|| format!("cannot write {}", path.display()))?;
    std::fs::write(&timing, format!("{seconds} {rays}\n"))
        .with_context(|| format!("cannot write {}", timing.display()))?;
    Ok(Reference {
        frame,
        seconds,
        rays,
    })
}

/// The cached reference at `path` (pixels) and `timing` (its cost); `None` when either
/// is missing or does not fit the size of `opts`.
fn read_cached(path: &Path, timing: &Path, opts: &BenchOptions) -> Option<Reference> {
    let bytes = std::fs::read(path).ok()?;
    let t = std::fs::read_to_string(timing).ok()?;
    let (seconds, rays) = t.split_once(' ')?;
    let (seconds, rays) = (
        seconds.parse::<f64>().ok()?,
        rays.trim().parse::<u64>().ok()?,
    );
    let n = opts.width as usize * opts.height as usize;
    if bytes.len() != n * 12 {
        return None;
    }
    let floats: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let pixels = floats
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    Some(Reference {
        frame: Frame {
            width: opts.width,
            height: opts.height,
            pixels,
        },
        seconds,
        rays,
    })
}
