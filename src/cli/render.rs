//! `whitted render`: the scene's settings with the command line's options over them,
//! rendered without a window into one or more files, with a progress bar.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::anyhow;
use clap::Args;

use whitted::image_io::parts::{self, Placement};
use whitted::image_io::{self, Format};
use whitted::render::{self, RenderControl};
use whitted::settings::{Encoding, Overrides, Precision, Preset, Quality, Region, Tile};

use super::animate::{self, FrameOptions};
use super::{load_scene, whole_number};
use whitted::limits::{MAX_DEPTH, MAX_SIDE, MAX_SPP};

#[derive(Args)]
pub(crate) struct RenderArgs {
    /// A scene file (TOML); default: the built-in hw3 scene.
    scene: Option<PathBuf>,
    /// Output file, format by extension: .ppm .png .bmp .jpg .exr (repeatable).
    /// Default: output.ppm and output.png. Animations: a pattern such as
    /// f-%04d.png (a file per frame), or .gif or .apng (all frames in one file).
    #[arg(short, long = "output", value_name = "FILE", value_parser = animate::parse_output)]
    output: Vec<PathBuf>,
    /// Write binary PPM (P6) instead of plain (P3).
    #[arg(long)]
    ppm_binary: bool,
    /// Image width in pixels (overrides the scene's).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_number(1, MAX_SIDE))]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene's).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_number(1, MAX_SIDE))]
    height: Option<u32>,
    /// Samples per pixel.
    #[arg(long, allow_negative_numbers = true, value_parser = whole_number(1, MAX_SPP))]
    spp: Option<u32>,
    /// Maximum ray depth: 1 traces the rays from the eye only, 5 (the default) four
    /// bounces of reflection and refraction. 0 traces no ray at all: every pixel is the
    /// sky seen in its direction (SPEC §2: `trace` returns the sky at `max_depth`).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_number(0, MAX_DEPTH))]
    depth: Option<u32>,
    /// Sampling seed.
    #[arg(long, allow_negative_numbers = true)]
    seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long, allow_negative_numbers = true, value_parser = whole_number(1, 1024))]
    threads: Option<u32>,
    /// Render only this rectangle: X,Y,W,H in output pixels, origin top-left.
    #[arg(long, value_name = "X,Y,W,H")]
    region: Option<Region>,
    /// Render only tile I (from 0) of a grid of N tiles the program picks (near-square
    /// rectangles, row by row). PNG and EXR parts record their place for
    /// `whitted stitch`.
    #[arg(long, value_name = "I/N", conflicts_with = "region")]
    tile: Option<Tile>,
    /// Use the slow f64 reference renderer.
    #[arg(long)]
    reference: bool,
    /// Quality preset: draft, default, high or reference (docs/quality.md); the
    /// other options override its settings.
    #[arg(long, value_name = "PRESET")]
    quality: Option<Preset>,
    /// How values become 8-bit bytes: linear (the default) or srgb (the sRGB curve);
    /// overrides the scene's. EXR files stay linear.
    #[arg(long, value_name = "ENCODING")]
    encoding: Option<Encoding>,
    /// No progress bar and no closing line.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    animation: FrameOptions,
}

impl RenderArgs {
    /// The options that override the scene's settings.
    fn overrides(&self) -> Overrides {
        Overrides {
            quality: self.quality,
            width: self.width,
            height: self.height,
            spp: self.spp,
            max_depth: self.depth,
            seed: self.seed,
            precision: self.reference.then_some(Precision::Reference),
            region: self.region,
            tile: self.tile,
            threads: self.threads.map(|t| t as usize),
            encoding: self.encoding,
        }
    }
}

pub(crate) fn render_command(args: RenderArgs) -> anyhow::Result<()> {
    super::keep_freed_blocks();
    let scene = load_scene(args.scene.as_deref())?;
    if animate::wanted(&args.animation, &scene, &args.output) {
        let opts = scene.settings().with(&args.overrides());
        return animate::render_frames(
            scene,
            &opts,
            &args.animation,
            &args.output,
            args.ppm_binary,
            args.quiet,
        );
    }
    let outputs: Vec<PathBuf> = if args.output.is_empty() {
        vec!["output.ppm".into(), "output.png".into()]
    } else {
        args.output.clone()
    };
    let mut targets = Vec::new();
    for path in outputs {
        // clap's parser has vetted every extension.
        let format = Format::from_path(&path, args.ppm_binary)?;
        // A folder we cannot write into fails now, not after a long render.
        image_io::check_writable(&path)?;
        targets.push((path, format));
    }

    let opts = scene.settings().with(&args.overrides());
    opts.check()?;

    let control = Arc::new(RenderControl::default());
    super::stop_on_signals(super::cancel(&control))?;
    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let area = opts.area();
    let progress = show_progress.then(|| {
        let control = Arc::clone(&control);
        super::Progress::start(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}",
            move || (control.pixels_done(), control.samples_total()),
        )
    });

    // Files of bytes only (not parts, which record their place): rendered straight
    // into bytes, with no linear frame.
    let is_part = opts.region.is_some() || opts.tile.is_some();
    let bytes_only = !is_part && targets.iter().all(|(_, f)| *f != Format::Exr);
    let result = if bytes_only {
        let encoder = image_io::ByteEncoder::new(opts.encoding);
        render::render_bytes(&scene, &opts, &control, |c| encoder.byte(c)).map(|(bytes, stats)| {
            let image = image::RgbImage::from_raw(area.width, area.height, bytes)
                .expect("the buffer has w*h*3 bytes");
            (Rendered::Bytes(image), stats)
        })
    } else {
        render::render(&scene, &opts, &control)
            .map(|(frame, stats)| (Rendered::Frame(frame), stats))
    };
    if let Some(progress) = progress {
        progress.finish();
    }
    let (rendered, stats) = result.map_err(|e| match e {
        render::RenderError::Cancelled => anyhow!("interrupted: no file was written"),
        other => anyhow!(other),
    })?;

    for (path, format) in &targets {
        if control.is_cancelled() {
            return Err(anyhow!(
                "interrupted: stopped before writing {}",
                path.display()
            ));
        }
        match &rendered {
            Rendered::Bytes(image) => image_io::save_rgb8(image, path, *format)?,
            Rendered::Frame(frame) if is_part && matches!(format, Format::Png | Format::Exr) => {
                let placement = Placement::of(&scene, &opts);
                parts::save_part(frame, &placement, path, *format, opts.encoding)?;
            }
            Rendered::Frame(frame) => image_io::save(frame, path, *format, opts.encoding)?,
        }
        if !args.quiet {
            eprintln!("wrote {}", path.display());
        }
    }
    if !args.quiet {
        eprintln!(
            "rendered {} {}x{} ({}) in {:.4} s (build {:.4} s): {} rays, {:.1} Mrays/s",
            scene.name,
            area.width,
            area.height,
            sampling(&opts.quality, stats.rays.primary, area),
            stats.seconds,
            stats.build_seconds,
            stats.rays.total(),
            stats.mrays_per_second()
        );
    }
    Ok(())
}

/// A render as the files to write need it.
enum Rendered {
    /// Linear values (EXR, parts).
    Frame(render::Frame),
    /// 8-bit RGB, top row first, in the settings' encoding.
    Bytes(image::RgbImage),
}

/// What the closing line says of the samples and the depth: "16 spp, depth 5", or
/// for adaptive anti-aliasing "adaptive, up to 64 spp, mean 5.8, depth 16" (`samples`:
/// the samples traced, one primary ray each, over the `area`'s pixels).
pub(crate) fn sampling(quality: &Quality, samples: u64, area: Region) -> String {
    let depth = match quality.max_depth {
        0 => "depth 0: no ray traced, every pixel is the sky".to_string(),
        d => format!("depth {d}"),
    };
    match quality.adaptive {
        Some(a) if a.first < quality.spp && quality.max_depth > 0 => {
            let pixels = (u64::from(area.width) * u64::from(area.height)).max(1);
            let mean = samples as f64 / pixels as f64;
            format!(
                "adaptive, up to {} spp, mean {mean:.1}, {depth}",
                quality.spp
            )
        }
        _ => format!("{} spp, {depth}", quality.spp),
    }
}
