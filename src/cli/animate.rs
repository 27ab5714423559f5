//! `whitted render` of an animation (SPEC §5, "Animation"): the frames of a scene
//! rendered in turn with its compiled scene reused ([`Sequence`]), each frame handed
//! to a writer thread as soon as it is done, which encodes it into every output while
//! the next one renders. The render waits for the writer, so at most two frames
//! exist at a time (one rendering, one encoding): memory does not grow with the
//! frame count.
//!
//! Outputs: a pattern such as `frames/f-%04d.png` (one file per frame, named by its
//! frame number in the whole sequence), `.gif` and `.apng` (every frame in one file,
//! written atomically when the last is in), or a plain image file when one frame is
//! rendered.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, Context};
use clap::Args;
use image::RgbImage;

use super::usage;
use whitted::image_io::parts::{self, Placement};
use whitted::image_io::{self, AnimatedFormat, AnimatedWriter, Format};
use whitted::limits::MAX_FRAMES;
use whitted::render::{Frame, RenderControl, RenderError, Sequence};
use whitted::scene::Scene;
use whitted::settings::{Encoding, FrameRange, Settings};

/// The animation options of `whitted render`.
#[derive(Args, Clone, Debug, Default)]
pub(crate) struct FrameOptions {
    /// Frame count (overrides the scene's `[animation]`).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_FRAMES)))]
    frames: Option<u32>,
    /// A turntable: the camera turns DEG degrees about its look-at point over all the
    /// frames (overrides the scene's `[animation]`).
    #[arg(long, value_name = "DEG", value_parser = parse_degrees, allow_negative_numbers = true)]
    orbit: Option<f64>,
    /// Render only frame K, or frames A to B (B excluded), numbered as in the whole
    /// sequence: each frame is the same bytes either way.
    #[arg(long, value_name = "K|A..B")]
    frame: Option<FrameRange>,
}

fn parse_degrees(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err("expected a finite number of degrees".into()),
    }
}

/// A file name with `%0Nd` (or `%d`) in it: one file per frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Pattern {
    before: String,
    width: usize,
    after: String,
}

impl Pattern {
    /// The first `%d` or `%0Nd` of `text`, if any.
    fn find(text: &str) -> Option<Pattern> {
        let mut from = 0;
        while let Some(i) = text[from..].find('%').map(|i| from + i) {
            let rest = &text[i + 1..];
            let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
            if rest[digits..].starts_with('d') && (digits == 0 || rest.starts_with('0')) {
                return Some(Pattern {
                    before: text[..i].to_string(),
                    width: rest[..digits].parse().unwrap_or(0),
                    after: rest[digits + 1..].to_string(),
                });
            }
            from = i + 1;
        }
        None
    }

    /// The file of frame `k`.
    fn path(&self, k: u32) -> PathBuf {
        let width = self.width;
        PathBuf::from(format!("{}{k:0width$}{}", self.before, self.after))
    }
}

/// Where frames go.
#[derive(Debug)]
enum Output {
    /// One image: only when one frame is rendered.
    Still(PathBuf, Format),
    /// One file per frame.
    Numbered(Pattern, Format),
    /// Every frame in one file.
    Animated(PathBuf, AnimatedFormat),
}

impl Output {
    fn of(path: &Path, ppm_binary: bool) -> Result<Output, String> {
        if let Some(format) = AnimatedFormat::from_path(path) {
            if path.to_str().and_then(Pattern::find).is_some() {
                return Err(format!(
                    "{}: a GIF or APNG file holds all the frames: give it no %d pattern",
                    path.display()
                ));
            }
            return Ok(Output::Animated(path.to_path_buf(), format));
        }
        let format = Format::from_path(path, ppm_binary).map_err(|e| {
            format!("{e}; or .gif or .apng for an animation, or a %04d pattern for numbered files")
        })?;
        Ok(match path.to_str().and_then(Pattern::find) {
            Some(pattern) => Output::Numbered(pattern, format),
            None => Output::Still(path.to_path_buf(), format),
        })
    }
}

/// Vets an `-o` argument: a still image, a numbered pattern or an animated file.
pub(crate) fn parse_output(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    Output::of(&path, false)?;
    Ok(path)
}

/// Whether this render goes through the frames (else it is the plain still render).
pub(crate) fn wanted(options: &FrameOptions, scene: &Scene, outputs: &[PathBuf]) -> bool {
    let frame_outputs = outputs
        .iter()
        .any(|p| !matches!(Output::of(p, false), Ok(Output::Still(..))));
    scene.animation.is_some()
        || options.frames.is_some()
        || options.orbit.is_some()
        || options.frame.is_some()
        || frame_outputs
}

/// What the writer thread gets of each frame.
struct Finished {
    k: u32,
    rgb: RgbImage,
    /// The linear values, when an EXR output or a part needs them.
    linear: Option<Frame>,
    /// Where the frame belongs in the whole image, when it is a region or tile of it
    /// (PNG and EXR files record it, for `whitted stitch`).
    part: Option<(Placement, Encoding)>,
}

/// Renders the frames `options` select of `scene` (with its animation overridden by
/// `options`) at `settings`, into `outputs`.
pub(crate) fn render_frames(
    mut scene: Scene,
    settings: &Settings,
    options: &FrameOptions,
    outputs: &[PathBuf],
    ppm_binary: bool,
    quiet: bool,
) -> anyhow::Result<()> {
    if options.frames.is_some() || options.orbit.is_some() {
        let animation = scene.animation.take().unwrap_or_default();
        scene.animation = Some(animation.with(options.frames, options.orbit));
    }
    let frames = scene.frames();
    let fps = scene.fps();
    let range = options.frame.unwrap_or(FrameRange::all(frames));
    if range.end > frames {
        return Err(usage(format!(
            "--frame {range}: the scene has {frames} frame{} (0 to {})",
            if frames == 1 { "" } else { "s" },
            frames - 1
        )));
    }
    let count = range.len();
    let defaults = [PathBuf::from("output.ppm"), PathBuf::from("output.png")];
    let outputs = if outputs.is_empty() && count == 1 {
        &defaults[..]
    } else {
        outputs
    };
    if outputs.is_empty() {
        return Err(usage(format!(
            "{count} frames to render: name the files with -o (a pattern such as \
             frames/f-%04d.png, or a .gif or .apng file)"
        )));
    }
    settings.check()?;
    let area = settings.area();

    let mut targets = Vec::new();
    for path in outputs {
        let output = Output::of(path, ppm_binary).map_err(|e| anyhow!(e))?;
        match &output {
            Output::Still(path, _) if count > 1 => {
                return Err(usage(format!(
                    "{}: one image cannot hold {count} frames: use a pattern such as \
                     f-%04d.png for numbered files, or a .gif or .apng file",
                    path.display()
                )))
            }
            Output::Still(path, _) | Output::Animated(path, _) => image_io::check_writable(path)?,
            Output::Numbered(pattern, _) => image_io::check_writable(&pattern.path(range.start))?,
        }
        targets.push(output);
    }
    // Before the animated files are opened: a FIFO waits for its reader there.
    let control = Arc::new(RenderControl::default());
    super::stop_on_signals(super::cancel(&control))?;
    let mut animated = Vec::new();
    for output in &targets {
        if let Output::Animated(path, format) = output {
            let writer =
                AnimatedWriter::create(path, *format, (area.width, area.height), count, fps)?;
            animated.push(writer);
        }
    }
    let is_part = settings.region.is_some() || settings.tile.is_some();
    let linear = is_part
        || targets.iter().any(|o| {
            matches!(
                o,
                Output::Still(_, Format::Exr) | Output::Numbered(_, Format::Exr)
            )
        });

    let done = Arc::new(AtomicU64::new(0));
    let show_progress = !quiet && std::io::stderr().is_terminal();
    let progress = show_progress.then(|| {
        let done = Arc::clone(&done);
        super::Progress::start(
            "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} frames ETA {eta}",
            move || (done.load(Ordering::Relaxed), u64::from(count)),
        )
    });

    // A rendezvous: the render hands a frame over only once the writer has finished
    // the one before.
    let (frames_out, frames_in) = sync_channel::<Finished>(0);
    let writer = {
        let done = Arc::clone(&done);
        std::thread::Builder::new()
            .name("whitted-frames".into())
            .spawn(move || write_frames(frames_in, targets, animated, count, &done))
            .context("cannot start the writer thread")?
    };

    let start = Instant::now();
    let mut sequence = Sequence::new(&scene);
    let mut rays = 0u64;
    let mut samples = 0u64;
    let mut stopped: Option<anyhow::Error> = None;
    for k in range.start..range.end {
        let camera = scene.frame_camera_spec(k, settings.width, settings.height);
        let (frame, stats) = match sequence.render(&camera, settings, &control) {
            Ok(rendered) => rendered,
            Err(RenderError::Cancelled) => {
                stopped = Some(anyhow!("interrupted"));
                break;
            }
            Err(e) => {
                stopped = Some(anyhow!(e).context(format!("frame {k}")));
                break;
            }
        };
        rays += stats.rays.total();
        samples += stats.rays.primary;
        let part = is_part.then(|| {
            let still = scene.frame(k, settings.width, settings.height);
            (Placement::of(&still, settings), settings.encoding)
        });
        let finished = Finished {
            k,
            rgb: image_io::to_rgb8(&frame, settings.encoding),
            linear: linear.then_some(frame),
            part,
        };
        if frames_out.send(finished).is_err() {
            break; // the writer failed: it says why
        }
    }
    drop(frames_out);
    let written = writer
        .join()
        .map_err(|_| anyhow!("the writer thread panicked"))?;
    let seconds = start.elapsed().as_secs_f64();
    if let Some(progress) = progress {
        progress.finish();
    }
    let written = written?;
    if let Some(e) = stopped {
        let animated_left = outputs
            .iter()
            .any(|p| AnimatedFormat::from_path(p).is_some());
        return Err(e.context(format!(
            "stopped after {written} of {count} frames{}",
            if animated_left {
                " (no GIF or APNG file was written)"
            } else {
                ""
            }
        )));
    }
    if !quiet {
        for path in outputs {
            match Output::of(path, ppm_binary) {
                Ok(Output::Numbered(pattern, _)) if count > 1 => eprintln!(
                    "wrote {} to {} ({count} files)",
                    pattern.path(range.start).display(),
                    pattern.path(range.end - 1).display()
                ),
                Ok(Output::Numbered(pattern, _)) => {
                    eprintln!("wrote {}", pattern.path(range.start).display())
                }
                _ => eprintln!("wrote {}", path.display()),
            }
        }
        let frames = if count == 1 {
            format!("frame {}", range.start)
        } else {
            format!("frames {}..{}", range.start, range.end)
        };
        eprintln!(
            "rendered {} {frames} at {}x{} ({}) in {:.3} s: \
             {rays} rays, {:.1} Mrays/s",
            scene.name,
            area.width,
            area.height,
            super::render::sampling(&settings.quality, samples / u64::from(count), area),
            seconds,
            rays as f64 / seconds.max(1e-9) / 1e6
        );
    }
    Ok(())
}

/// The writer thread: every frame into every output; the animated files are put in
/// place only when all `count` frames are in. Returns the frames written.
fn write_frames(
    frames: Receiver<Finished>,
    targets: Vec<Output>,
    mut animated: Vec<AnimatedWriter>,
    count: u32,
    done: &AtomicU64,
) -> anyhow::Result<u32> {
    let mut written = 0;
    for Finished {
        k,
        rgb,
        linear,
        part,
    } in frames
    {
        for target in &targets {
            let (path, format) = match target {
                Output::Still(path, format) => (path.clone(), *format),
                Output::Numbered(pattern, format) => (pattern.path(k), *format),
                Output::Animated(..) => continue,
            };
            match (&linear, format, part) {
                (Some(frame), Format::Png | Format::Exr, Some((placement, encoding))) => {
                    parts::save_part(frame, &placement, &path, format, encoding)?
                }
                (Some(frame), Format::Exr, _) => {
                    image_io::save(frame, &path, format, Encoding::Linear)?
                }
                _ => image_io::save_rgb8(&rgb, &path, format)?,
            }
        }
        for writer in &mut animated {
            writer.add(&rgb)?;
        }
        written += 1;
        done.store(u64::from(written), Ordering::Relaxed);
    }
    if written < count {
        return Ok(written); // interrupted: the animated files are dropped unwritten
    }
    for writer in animated {
        writer.finish()?;
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_number_files_by_frame() {
        let p = Pattern::find("frames/f-%04d.png").unwrap();
        assert_eq!(p.path(7), PathBuf::from("frames/f-0007.png"));
        assert_eq!(p.path(12345), PathBuf::from("frames/f-12345.png"));
        let p = Pattern::find("100%-%d.ppm").unwrap();
        assert_eq!(p.path(3), PathBuf::from("100%-3.ppm"));
        assert_eq!(Pattern::find("plain.png"), None);
        assert_eq!(Pattern::find("f-%4d.png"), None, "no zero: not a pattern");
    }
}
