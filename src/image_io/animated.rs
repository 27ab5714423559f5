//! Animated files, one frame at a time: GIF through the `image` crate's encoder
//! (NeuQuant palette per frame), APNG through the `png` crate. Each frame goes to
//! the file as soon as it is added, so an animation of any length holds one frame in
//! memory; the file appears (an [`AtomicFile`] put in place) only when the last frame
//! is in.

use std::io::{BufWriter, Write};
use std::path::Path;
use std::sync::{Arc, Mutex, PoisonError};

use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, RgbImage, RgbaImage};

use super::{AtomicFile, SaveError};

/// The animated formats, chosen by extension (`.gif`, `.apng`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimatedFormat {
    /// GIF: 256 colours a frame, delays in hundredths of a second.
    Gif,
    /// Animated PNG: lossless 8-bit RGB.
    Apng,
}

impl AnimatedFormat {
    /// The format for a path's extension, if it names an animated one.
    pub fn from_path(path: &Path) -> Option<AnimatedFormat> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        match ext.as_str() {
            "gif" => Some(AnimatedFormat::Gif),
            "apng" => Some(AnimatedFormat::Apng),
            _ => None,
        }
    }
}

/// NeuQuant's sampling factor: 10 is the `gif` crate's advice (1 is best and about
/// ten times slower; the palette error of 10 is bounded in the tests).
const GIF_SPEED: i32 = 10;

/// A GIF frame's delay for `fps`, in hundredths of a second (the format's unit):
/// rounded, and at least 2, since browsers slow down shorter delays to 1/10 s.
pub fn gif_delay_centiseconds(fps: f64) -> u16 {
    (100.0 / fps).round().clamp(2.0, f64::from(u16::MAX)) as u16
}

/// An APNG frame's delay for `fps` as seconds `numerator / denominator`: exactly
/// `1/fps` for a whole `fps`, else to a ten-thousandth of a second.
pub fn apng_delay(fps: f64) -> (u16, u16) {
    if fps.fract() == 0.0 && (1.0..=f64::from(u16::MAX)).contains(&fps) {
        (1, fps as u16)
    } else {
        let numerator = (10_000.0 / fps).round().clamp(1.0, f64::from(u16::MAX));
        (numerator as u16, 10_000)
    }
}

/// The sink shared with an encoder that owns its writer and never gives it back.
#[derive(Clone)]
struct Shared(Arc<Mutex<BufWriter<AtomicFile>>>);

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .flush()
    }
}

enum Encoder {
    Gif(GifEncoder<Shared>),
    Apng(png::Writer<Shared>),
}

/// An animated file being written: [`AnimatedWriter::add`] each frame (8-bit RGB,
/// top row first, as [`super::to_rgb8`] makes it), then [`AnimatedWriter::finish`].
/// Dropped unfinished, it leaves nothing behind.
pub struct AnimatedWriter {
    path: std::path::PathBuf,
    sink: Shared,
    encoder: Encoder,
    size: (u32, u32),
    delay_ms: u32,
}

impl AnimatedWriter {
    /// Starts `path` for `frames` frames of `width`×`height` at `fps` (an APNG
    /// states its frame count up front; a GIF does not).
    pub fn create(
        path: &Path,
        format: AnimatedFormat,
        (width, height): (u32, u32),
        frames: u32,
        fps: f64,
    ) -> Result<AnimatedWriter, SaveError> {
        let err = |message: String| SaveError {
            path: path.display().to_string(),
            message,
        };
        let sink = AtomicFile::create(path)?;
        let sink = Shared(Arc::new(Mutex::new(BufWriter::new(sink))));
        let encoder = match format {
            AnimatedFormat::Gif => {
                if width > u32::from(u16::MAX) || height > u32::from(u16::MAX) {
                    return Err(err(format!(
                        "a GIF is at most {0}x{0} pixels, not {width}x{height}",
                        u16::MAX
                    )));
                }
                let mut gif = GifEncoder::new_with_speed(sink.clone(), GIF_SPEED);
                gif.set_repeat(Repeat::Infinite)
                    .map_err(|e| err(format!("cannot encode: {e}")))?;
                Encoder::Gif(gif)
            }
            AnimatedFormat::Apng => {
                let png_err = |e: png::EncodingError| err(format!("cannot encode: {e}"));
                let mut png = png::Encoder::new(sink.clone(), width, height);
                png.set_color(png::ColorType::Rgb);
                png.set_depth(png::BitDepth::Eight);
                png.set_animated(frames, 0).map_err(png_err)?;
                let (numerator, denominator) = apng_delay(fps);
                png.set_frame_delay(numerator, denominator)
                    .map_err(png_err)?;
                Encoder::Apng(png.write_header().map_err(png_err)?)
            }
        };
        Ok(AnimatedWriter {
            path: path.to_path_buf(),
            sink,
            encoder,
            size: (width, height),
            delay_ms: u32::from(gif_delay_centiseconds(fps)) * 10,
        })
    }

    fn err(&self, message: String) -> SaveError {
        SaveError {
            path: self.path.display().to_string(),
            message,
        }
    }

    /// Encodes and writes the next frame.
    pub fn add(&mut self, frame: &RgbImage) -> Result<(), SaveError> {
        self.sink
            .0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get_ref()
            .check_still_there()?;
        if frame.dimensions() != self.size {
            let (w, h) = frame.dimensions();
            return Err(self.err(format!(
                "a frame of {w}x{h} in an animation of {}x{}",
                self.size.0, self.size.1
            )));
        }
        let result = match &mut self.encoder {
            Encoder::Gif(gif) => {
                let rgba = RgbaImage::from_fn(self.size.0, self.size.1, |x, y| {
                    let [r, g, b] = frame.get_pixel(x, y).0;
                    image::Rgba([r, g, b, 255])
                });
                let delay = Delay::from_numer_denom_ms(self.delay_ms, 1);
                gif.encode_frame(image::Frame::from_parts(rgba, 0, 0, delay))
                    .map_err(|e| e.to_string())
            }
            Encoder::Apng(png) => png
                .write_image_data(frame.as_raw())
                .map_err(|e| e.to_string()),
        };
        result.map_err(|e| self.err(format!("cannot encode: {e}")))
    }

    /// Ends the file and puts it in place (synced, then renamed over the target).
    pub fn finish(self) -> Result<(), SaveError> {
        let AnimatedWriter {
            path,
            sink,
            encoder,
            ..
        } = self;
        let err = |message: String| SaveError {
            path: path.display().to_string(),
            message,
        };
        match encoder {
            // The GIF trailer is written when the encoder is dropped.
            Encoder::Gif(gif) => drop(gif),
            Encoder::Apng(png) => png
                .finish()
                .map_err(|e| err(format!("cannot encode: {e}")))?,
        }
        let buffered = Arc::try_unwrap(sink.0)
            .map_err(|_| err("the encoder still holds the file".into()))?
            .into_inner()
            .unwrap_or_else(PoisonError::into_inner);
        let file = buffered
            .into_inner()
            .map_err(|e| err(e.error().to_string()))?;
        file.commit()
    }
}
