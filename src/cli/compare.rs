//! `whitted compare A B`: the difference of two image files in one line
//! (`rmse=… psnr=… max=… over1=…% flip=…`, 8-bit levels), a heat map on request, and
//! exit status 1 past a threshold, for scripts and CI.

use std::io::BufReader;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::Args;

use whitted::bench::{measure, Errors, Levels};
use whitted::image_io::{self, Format};

#[derive(Args)]
pub(crate) struct CompareArgs {
    /// The image to test (PNG, PPM, BMP, JPEG or EXR; EXR as linear values × 255).
    a: PathBuf,
    /// The image to compare it with, of the same size.
    b: PathBuf,
    /// Write FLIP's per-pixel difference here as a colour-mapped image (magma: black
    /// is no difference, light yellow the largest); format by extension.
    #[arg(long, value_name = "FILE", value_parser = parse_heat_map)]
    heatmap: Option<HeatMap>,
    /// Exit with status 1 when the RMSE (8-bit levels) is above this.
    #[arg(long, value_name = "X", value_parser = parse_limit)]
    max_rmse: Option<f64>,
    /// Exit with status 1 when more than this percentage of pixels is off by more
    /// than one level.
    #[arg(long, value_name = "PCT", value_parser = parse_limit)]
    max_over1: Option<f64>,
}

fn parse_limit(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err("expected a number ≥ 0".into()),
    }
}

/// Where the heat map goes, in an 8-bit format.
#[derive(Clone, Debug)]
struct HeatMap {
    path: PathBuf,
    format: Format,
}

fn parse_heat_map(text: &str) -> Result<HeatMap, String> {
    let path = PathBuf::from(text);
    match Format::from_path(&path, true).map_err(|e| e.to_string())? {
        Format::Exr => Err("a heat map is an 8-bit image: use .png, .ppm, .bmp or .jpg".into()),
        format => Ok(HeatMap { path, format }),
    }
}

fn load(path: &Path) -> anyhow::Result<Levels> {
    let image = std::fs::File::open(path)
        .map_err(anyhow::Error::from)
        .and_then(|file| {
            let hint = image::ImageFormat::from_path(path).ok();
            Ok(image_io::decode_image(
                BufReader::new(file),
                hint,
                image::Limits::default(),
            )?)
        })
        .with_context(|| format!("{}: cannot read the image", path.display()))?;
    Ok(Levels::from_image(image))
}

/// The one line `whitted compare` prints.
pub(crate) fn line(e: &Errors) -> String {
    format!(
        "rmse={:.4} psnr={:.2} max={} over1={:.4}% flip={:.5}",
        e.rmse,
        e.psnr,
        e.max,
        e.off_by_more_than_1 * 100.0,
        e.flip
    )
}

pub(crate) fn compare_command(args: CompareArgs) -> anyhow::Result<()> {
    if let Some(heat) = &args.heatmap {
        image_io::check_writable(&heat.path)?;
    }
    let (a, b) = (load(&args.a)?, load(&args.b)?);
    let Some(comparison) = measure(&a, &b) else {
        bail!(
            "{} is {}x{} but {} is {}x{}: only images of the same size can be compared",
            args.a.display(),
            a.width,
            a.height,
            args.b.display(),
            b.width,
            b.height
        );
    };
    let errors = comparison.errors;
    println!("{}", line(&errors));
    if let Some(heat) = &args.heatmap {
        image_io::save_rgb8(&comparison.heat_map(), &heat.path, heat.format)?;
    }
    let over1 = errors.off_by_more_than_1 * 100.0;
    if let Some(limit) = args.max_rmse.filter(|&l| errors.rmse > l) {
        bail!("rmse {:.4} is above --max-rmse {limit}", errors.rmse);
    }
    if let Some(limit) = args.max_over1.filter(|&l| over1 > l) {
        bail!("over1 {over1:.4}% is above --max-over1 {limit}%");
    }
    Ok(())
}
