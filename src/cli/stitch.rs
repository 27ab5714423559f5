//! `whitted stitch`: parts written with `--tile` or `--region` put back together into
//! the whole image, byte for byte what rendering it whole writes.

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;

use whitted::image_io::parts::{self, PartPixels};
use whitted::image_io::{self, Format};

#[derive(Args)]
pub(crate) struct StitchArgs {
    /// The whole image, format by extension: .ppm .png .bmp .jpg from PNG parts; any,
    /// .exr included, from EXR parts.
    #[arg(short, long = "output", value_name = "FILE", value_parser = parse_image_path)]
    output: PathBuf,
    /// Write binary PPM (P6) instead of plain (P3).
    #[arg(long)]
    ppm_binary: bool,
    /// The parts (PNG or EXR files written with --tile or --region).
    #[arg(required = true, value_name = "PART")]
    parts: Vec<PathBuf>,
}

/// A path whose extension names a still format (else a usage error).
fn parse_image_path(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    Format::from_path(&path, false).map_err(|e| e.to_string())?;
    Ok(path)
}

pub(crate) fn stitch_command(args: StitchArgs) -> anyhow::Result<()> {
    let format = Format::from_path(&args.output, args.ppm_binary)?;
    image_io::check_writable(&args.output)?;
    super::stop_on_signals(|| {})?;
    let mut read: Vec<(String, parts::Part)> = Vec::new();
    for path in &args.parts {
        if image_io::writes_interrupted() {
            bail!("interrupted: {} was not written", args.output.display());
        }
        read.push((path.display().to_string(), parts::read_part(path)?));
    }
    match parts::stitch(&read)? {
        PartPixels::Linear(image) => {
            let encoding = read[0].1.placement.encoding;
            image_io::save(&parts::frame_of(&image), &args.output, format, encoding)?;
        }
        PartPixels::Bytes(image) => {
            if format == Format::Exr {
                bail!(
                    "{}: 8-bit PNG parts cannot make an EXR file (render the parts as .exr)",
                    args.output.display()
                );
            }
            image_io::save_rgb8(&image, &args.output, format)?;
        }
    }
    Ok(())
}
