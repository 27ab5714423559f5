//! `whitted render`: the scene's settings with the command line's options over them,
//! rendered without a window into one or more files, with a progress bar.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{anyhow, Context};
use clap::Args;

use whitted::image_io::parts::{self, Placement};
use whitted::image_io::{self, Format};
use whitted::render::{self, RenderControl};
use whitted::settings::{Encoding, Overrides, Precision, Preset, Region, Tile};

use super::animate::{self, FrameOptions};
use super::load_scene;

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
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene's).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    height: Option<u32>,
    /// Samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    spp: Option<u32>,
    /// Maximum ray depth.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    depth: Option<u32>,
    /// Sampling seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// Render only this rectangle: X,Y,W,H in output pixels, origin top-left.
    #[arg(long, value_name = "X,Y,W,H", value_parser = parse_region)]
    region: Option<Region>,
    /// Render only tile I (from 0) of a grid of N tiles the program picks (near-square
    /// rectangles, row by row). PNG and EXR parts record their place for
    /// `whitted stitch`.
    #[arg(long, value_name = "I/N", value_parser = parse_tile, conflicts_with = "region")]
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

fn parse_tile(text: &str) -> Result<Tile, String> {
    let parsed = text
        .split_once('/')
        .and_then(|(i, n)| Some((i.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((index, count)) if index < count => Ok(Tile { index, count }),
        _ => Err("expected I/N: tile I of N tiles, 0 <= I < N".into()),
    }
}

fn parse_region(text: &str) -> Result<Region, String> {
    let parts: Vec<&str> = text.split(',').collect();
    let numbers: Result<Vec<u32>, _> = parts.iter().map(|p| p.trim().parse::<u32>()).collect();
    match numbers.as_deref() {
        Ok(&[x, y, width, height]) if width > 0 && height > 0 => Ok(Region {
            x,
            y,
            width,
            height,
        }),
        _ => Err("expected X,Y,W,H: four whole numbers, W and H at least 1".into()),
    }
}

pub(crate) fn render_command(args: RenderArgs) -> anyhow::Result<()> {
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
    {
        let control = Arc::clone(&control);
        ctrlc::set_handler(move || control.cancel())
            .context("cannot install the interrupt handler")?;
    }
    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let area = opts.area();
    let total = u64::from(area.width) * u64::from(area.height) * u64::from(opts.quality.spp);
    let progress = show_progress.then(|| spawn_progress(Arc::clone(&control), total));

    let result = render::render(&scene, &opts, &control);
    if let Some((done, handle)) = progress {
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        let _ = handle.join();
    }
    let (frame, stats) = result.map_err(|e| match e {
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
        let is_part = opts.region.is_some() || opts.tile.is_some();
        if is_part && matches!(format, Format::Png | Format::Exr) {
            let placement = Placement::of(&scene, &opts);
            parts::save_part(&frame, &placement, path, *format, opts.encoding)?;
        } else {
            image_io::save(&frame, path, *format, opts.encoding)?;
        }
        if !args.quiet {
            eprintln!("wrote {}", path.display());
        }
    }
    if !args.quiet {
        eprintln!(
            "rendered {} {}x{} ({} spp, depth {}) in {:.3} s: {} rays, {:.1} Mrays/s",
            scene.name,
            area.width,
            area.height,
            opts.quality.spp,
            opts.quality.max_depth,
            stats.seconds,
            stats.rays.total(),
            stats.mrays_per_second()
        );
    }
    Ok(())
}

/// A progress bar on stderr that appears only once a render has run for a second.
fn spawn_progress(
    control: Arc<RenderControl>,
    total: u64,
) -> (
    Arc<std::sync::atomic::AtomicBool>,
    std::thread::JoinHandle<()>,
) {
    use std::sync::atomic::{AtomicBool, Ordering};
    let done = Arc::new(AtomicBool::new(false));
    let finished = Arc::clone(&done);
    let handle = std::thread::spawn(move || {
        let start = Instant::now();
        let mut bar: Option<indicatif::ProgressBar> = None;
        while !finished.load(Ordering::Relaxed) {
            std::thread::sleep(Duration::from_millis(50));
            if bar.is_none() && start.elapsed() > Duration::from_secs(1) {
                let b = indicatif::ProgressBar::new(total);
                b.set_style(
                    indicatif::ProgressStyle::with_template(
                        "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}",
                    )
                    .expect("a valid template"),
                );
                bar = Some(b);
            }
            if let Some(b) = &bar {
                b.set_position(control.pixels_done());
            }
        }
        if let Some(b) = bar {
            b.finish_and_clear();
        }
    });
    (done, handle)
}
