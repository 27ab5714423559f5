//! The frame buffer to bytes and files, through the `image` crate. This is where the
//! bottom-up frame is flipped to the top-down order of files, once, and where linear
//! values become 8-bit bytes in the settings' [`Encoding`] (EXR stays linear). Every
//! file is written whole or not at all ([`AtomicFile`]).

mod animated;
mod atomic;
mod plain_ppm;

use std::io::{BufRead, BufWriter, Cursor, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use image::codecs::bmp::BmpEncoder;
use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::PngEncoder;
use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
use image::{DynamicImage, ExtendedColorType, ImageEncoder, Rgb32FImage, RgbImage};
use rayon::prelude::*;

use crate::render::Frame;
pub use crate::settings::Encoding;

mod srgb;
pub use srgb::{to_byte_srgb, to_byte_srgb_exact, SrgbTable};

pub mod parts;
pub use animated::{apng_delay, gif_delay_centiseconds, AnimatedFormat, AnimatedWriter};
pub use atomic::{
    check_writable, interrupt_writes, write_atomically, writes_interrupted, AtomicFile,
};

/// The file formats `whitted` writes, chosen by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// PPM, plain (P3) or binary (P6).
    Ppm {
        /// Binary P6 rather than plain P3.
        binary: bool,
    },
    /// 8-bit RGB PNG.
    Png,
    /// 8-bit RGB BMP.
    Bmp,
    /// 8-bit RGB JPEG, quality 95.
    Jpeg,
    /// OpenEXR, linear 32-bit float.
    Exr,
}

impl Format {
    /// The format for a path's extension (`binary_ppm` picks P6 over P3).
    pub fn from_path(path: &Path, binary_ppm: bool) -> Result<Format, UnknownFormat> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "ppm" => Ok(Format::Ppm { binary: binary_ppm }),
            "png" => Ok(Format::Png),
            "bmp" => Ok(Format::Bmp),
            "jpg" | "jpeg" => Ok(Format::Jpeg),
            "exr" => Ok(Format::Exr),
            _ => Err(UnknownFormat(path.to_path_buf())),
        }
    }
}

/// A file name whose extension names no format `whitted` writes.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}: unknown image format (use .ppm, .png, .bmp, .jpg or .exr)", .0.display())]
pub struct UnknownFormat(pub PathBuf);

/// Why a frame could not be encoded.
#[derive(Debug, thiserror::Error)]
pub enum EncodeError {
    /// The encoder of the `image` crate failed.
    #[error(transparent)]
    Image(#[from] image::ImageError),
    /// The OpenEXR encoder failed.
    #[error(transparent)]
    Exr(#[from] exr::error::Error),
    /// EXR holds linear values: it is encoded from a frame, not from 8-bit bytes.
    #[error("EXR is written from linear values, not bytes")]
    ExrFromBytes,
}

/// A linear value to 8 bits: `round(clamp(c, 0, 1)·255)`, no gamma (SPEC §2).
#[inline(always)]
pub fn to_byte(c: f32) -> u8 {
    // Without a branch or a libm call, as the window converts every pixel of every
    // frame with it (`f32::round` is a libm call on baseline x86-64). `max` drops a
    // NaN, so NaN gives 0.
    #[allow(clippy::manual_clamp)] // not `clamp`, which would keep a NaN
    let x = c.max(0.0).min(1.0) * 255.0;
    // x + 2²³ lies in [2²³, 2²³ + 255], where the f32 spacing is 1: the addition
    // rounds x to the nearest integer r, ties to even, and r sits in the low bits.
    let y = x + ROUNDER;
    let r = y - ROUNDER;
    // Round half away from zero instead: a tie rounded down to even is x = r + ½
    // (x − r is exact: Sterbenz, or x itself when r = 0).
    let tie_down = u32::from(x - r == 0.5);
    (y.to_bits() - ROUNDER.to_bits() + tie_down) as u8
}

/// 2²³: the smallest f32 whose spacing is 1.
const ROUNDER: f32 = 8_388_608.0;

/// Linear values to bytes in one [`Encoding`]: [`to_byte`] or [`to_byte_srgb`], with
/// the sRGB table looked up once rather than at every value.
#[derive(Clone, Copy, Debug)]
pub enum ByteEncoder {
    /// [`to_byte`].
    Linear,
    /// [`SrgbTable::byte`].
    Srgb(&'static SrgbTable),
}

impl ByteEncoder {
    /// The encoder of `encoding` (the first sRGB one builds the table: well under a
    /// millisecond).
    pub fn new(encoding: Encoding) -> Self {
        match encoding {
            Encoding::Linear => ByteEncoder::Linear,
            Encoding::Srgb => ByteEncoder::Srgb(SrgbTable::get()),
        }
    }

    /// The byte of linear value `c`.
    #[inline(always)]
    pub fn byte(self, c: f32) -> u8 {
        match self {
            ByteEncoder::Linear => to_byte(c),
            ByteEncoder::Srgb(table) => table.byte(c),
        }
    }
}

/// The frame as 8-bit RGB in `encoding`, row 0 at the TOP (the order of files and
/// screens).
pub fn to_rgb8(frame: &Frame, encoding: Encoding) -> RgbImage {
    let (w, h) = (frame.width, frame.height);
    // One loop per encoding, each with its conversion inlined.
    let bytes = match ByteEncoder::new(encoding) {
        ByteEncoder::Linear => frame.bytes_top_first(to_byte),
        ByteEncoder::Srgb(table) => frame.bytes_top_first(|c| table.byte(c)),
    };
    RgbImage::from_raw(w, h, bytes).expect("the buffer has w*h*3 bytes")
}

/// Rows converted by one task of [`to_rgb32f`] at least.
const ROWS_PER_TASK: usize = 32;

/// The frame as linear 32-bit float RGB, row 0 at the top.
pub fn to_rgb32f(frame: &Frame) -> Rgb32FImage {
    let (w, h) = (frame.width, frame.height);
    let row_len = w.max(1) as usize;
    let mut values = vec![0f32; frame.pixels.len() * 3];
    values
        .par_chunks_mut(row_len * 3)
        .zip(frame.pixels.par_chunks_exact(row_len).rev())
        .with_min_len(ROWS_PER_TASK)
        .for_each(|(out, row)| {
            for (o, p) in out.chunks_exact_mut(3).zip(row) {
                o.copy_from_slice(&p.to_array());
            }
        });
    Rgb32FImage::from_raw(w, h, values).expect("the buffer has w*h*3 values")
}

#[derive(Debug, thiserror::Error)]
/// Why an image file could not be written (nothing was left behind).
#[error("{path}: {message}")]
pub struct SaveError {
    /// The file asked for.
    pub path: String,
    /// What went wrong.
    pub message: String,
}

/// Decodes an image file read from `reader` (what `whitted compare` reads): its format
/// from its first bytes, else `format`, within `limits` on size and memory
/// (`image::Limits::default()` for files, smaller ones to fuzz faster).
pub fn decode_image<R: BufRead + Seek>(
    mut reader: R,
    format: Option<image::ImageFormat>,
    limits: image::Limits,
) -> image::ImageResult<DynamicImage> {
    check_header_fits(&mut reader, format)?;
    let mut reader = image::ImageReader::new(reader);
    if let Some(format) = format {
        reader.set_format(format);
    }
    reader.limits(limits);
    reader.with_guessed_format()?.decode()
}

/// Refuses a PNG file whose header states more pixels than its bytes can hold (see
/// [`check_holds`]), before the decoder allocates them (up to the 512 MiB of
/// `image::Limits::default()`); leaves `reader` where it was. (`image`'s EXR decoder
/// reads the table of every chunk its header calls for before it allocates pixels.)
fn check_header_fits<R: BufRead + Seek>(
    reader: &mut R,
    format: Option<image::ImageFormat>,
) -> image::ImageResult<()> {
    use image::error::{DecodingError, ImageFormatHint};
    use image::ImageFormat;
    let start = reader.stream_position()?;
    let file_bytes = bytes_left(reader)?;
    let mut probe = image::ImageReader::new(&mut *reader);
    if let Some(format) = format {
        probe.set_format(format);
    }
    let probe = probe.with_guessed_format()?;
    if probe.format() == Some(ImageFormat::Png) {
        // A header the probe cannot read is the decoder's to report.
        if let Ok((width, height)) = probe.into_dimensions() {
            // The fewest bits a pixel takes before compression: 1-bit grey or palette.
            check_holds(width, height, 1, file_bytes).map_err(|message| {
                let hint = ImageFormatHint::Exact(ImageFormat::Png);
                image::ImageError::Decoding(DecodingError::new(hint, message))
            })?;
        }
    }
    reader.seek(SeekFrom::Start(start))?;
    Ok(())
}

/// Fails unless a file of `file_bytes` bytes can hold `width`×`height` pixels of at
/// least `bits_per_pixel` bits each before compression (at most
/// [`limits::MAX_EXPANSION`](crate::limits::MAX_EXPANSION) bytes a byte): a header
/// of a few bytes stating a huge image is refused before the image is allocated.
pub(crate) fn check_holds(
    width: u32,
    height: u32,
    bits_per_pixel: u64,
    file_bytes: u64,
) -> Result<(), String> {
    let bytes = u64::from(width) * u64::from(height) * bits_per_pixel / 8;
    if bytes > file_bytes.saturating_mul(crate::limits::MAX_EXPANSION) {
        return Err(format!(
            "its header states {width}x{height} pixels, more than its {file_bytes} bytes can hold"
        ));
    }
    Ok(())
}

/// The bytes from `reader`'s position to its end; leaves it where it was.
pub(crate) fn bytes_left<R: Seek>(reader: &mut R) -> std::io::Result<u64> {
    let here = reader.stream_position()?;
    let end = reader.seek(SeekFrom::End(0))?;
    reader.seek(SeekFrom::Start(here))?;
    Ok(end.saturating_sub(here))
}

/// Encodes 8-bit RGB (top row first) in `format`.
pub fn encode_rgb8(
    image: &RgbImage,
    format: Format,
    out: &mut dyn Write,
) -> Result<(), EncodeError> {
    let (w, h) = image.dimensions();
    let raw = image.as_raw();
    let rgb = ExtendedColorType::Rgb8;
    let result = match format {
        Format::Ppm { binary: true } => PnmEncoder::new(out)
            .with_subtype(PnmSubtype::Pixmap(SampleEncoding::Binary))
            .write_image(raw, w, h, rgb),
        Format::Ppm { binary: false } => {
            plain_ppm::write(raw, w, h, out).map_err(image::ImageError::IoError)
        }
        Format::Png => PngEncoder::new(out).write_image(raw, w, h, rgb),
        Format::Bmp => BmpEncoder::new(&mut &mut *out).write_image(raw, w, h, rgb),
        Format::Jpeg => JpegEncoder::new_with_quality(out, 95).write_image(raw, w, h, rgb),
        Format::Exr => return Err(EncodeError::ExrFromBytes),
    };
    Ok(result?)
}

/// The frame encoded in `format`, its bytes in `encoding` (EXR: linear values).
pub fn encode(frame: &Frame, format: Format, encoding: Encoding) -> Result<Vec<u8>, EncodeError> {
    let mut out = Vec::new();
    match format {
        Format::Exr => out = exr_bytes(frame, None)?,
        _ => encode_rgb8(&to_rgb8(frame, encoding), format, &mut out)?,
    }
    Ok(out)
}

/// Saves 8-bit RGB (top row first) to `path` in `format` (not EXR), atomically. The
/// encoder writes into the file as it goes, so the encoded image is never held whole
/// in memory (a plain PPM's text is about four times the pixels' bytes).
pub fn save_rgb8(image: &RgbImage, path: &Path, format: Format) -> Result<(), SaveError> {
    let mut file = AtomicFile::create(path)?;
    let mut out = FlushAtEnd(BufWriter::with_capacity(WRITE_BUFFER, &mut file));
    encode_rgb8(image, format, &mut out).map_err(|e| encode_failure(path, e))?;
    out.finish().map_err(|e| io_failure(path, e))?;
    file.commit()
}

/// Bytes an encoder's output is gathered in before each write to the file.
const WRITE_BUFFER: usize = 1 << 16;

/// A buffered writer whose `flush` waits for the end: the PNM encoder flushes after
/// every line of its text, which would make a system call of every 70 bytes.
struct FlushAtEnd<W: Write>(BufWriter<W>);

impl<W: Write> FlushAtEnd<W> {
    /// Writes out what the buffer holds.
    fn finish(self) -> std::io::Result<()> {
        self.0.into_inner().map(drop).map_err(|e| e.into_error())
    }
}

impl<W: Write> Write for FlushAtEnd<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Saves the frame to `path` in `format`, its bytes in `encoding`, atomically. EXR is
/// encoded into the temporary file as it goes too, unless the target is written in
/// place (a device or a FIFO cannot seek back to the table of chunk offsets).
pub fn save(
    frame: &Frame,
    path: &Path,
    format: Format,
    encoding: Encoding,
) -> Result<(), SaveError> {
    if format != Format::Exr {
        return save_rgb8(&to_rgb8(frame, encoding), path, format);
    }
    let mut file = AtomicFile::create(path)?;
    if let Some(temp) = file.temporary_file() {
        let mut out = BufWriter::with_capacity(WRITE_BUFFER, temp);
        write_exr(frame, None, &mut out).map_err(|e| encode_failure(path, e))?;
        out.flush().map_err(|e| io_failure(path, e))?;
    } else {
        let bytes = exr_bytes(frame, None).map_err(|e| encode_failure(path, e))?;
        file.write_all(&bytes).map_err(|e| io_failure(path, e))?;
    }
    file.commit()
}

/// Why `path` was not written: the file's own errors (a full disk) in the system's
/// words, the encoder's as such.
fn encode_failure(path: &Path, e: EncodeError) -> SaveError {
    match e {
        EncodeError::Image(image::ImageError::IoError(e))
        | EncodeError::Exr(exr::error::Error::Io(e)) => io_failure(path, e),
        e => SaveError {
            path: path.display().to_string(),
            message: format!("cannot encode: {e}"),
        },
    }
}

fn io_failure(path: &Path, e: std::io::Error) -> SaveError {
    SaveError {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// The frame's linear RGB as OpenEXR (top row first), in memory (see [`write_exr`]).
pub(crate) fn exr_bytes(
    frame: &Frame,
    part: Option<&parts::Placement>,
) -> Result<Vec<u8>, EncodeError> {
    let mut out = Cursor::new(Vec::new());
    write_exr(frame, part, &mut out)?;
    Ok(out.into_inner())
}

/// The frame's linear RGB as OpenEXR (top row first) into `out`, through the `exr`
/// crate, which reads the pixels from the frame as it encodes them: the whole image,
/// or with `part`, a part whose data window sits at its place in the whole image's
/// display window and whose header records the placement (see [`parts`]). Written on
/// one thread, so the chunks come in order and the same pixels give the same bytes.
pub(crate) fn write_exr(
    frame: &Frame,
    part: Option<&parts::Placement>,
    out: impl Write + Seek,
) -> Result<(), EncodeError> {
    use exr::meta::attribute::{AttributeValue, IntegerBounds, Text};
    use exr::prelude::{
        Encoding, Image, Layer, LayerAttributes, SpecificChannels, Vec2, WritableImage,
    };
    let (width, height) = (frame.width as usize, frame.height as usize);
    let mut attributes = LayerAttributes::default();
    if let Some(p) = part {
        attributes.layer_position = Vec2(p.region.x as i32, p.region.y as i32);
        attributes.other.insert(
            Text::from(parts::KEY),
            AttributeValue::Text(Text::from(p.to_string().as_str())),
        );
    }
    // The frame's rows run from the bottom; the file's from the top.
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let px = frame.get(p.x() as u32, frame.height - 1 - p.y() as u32);
        (px.x, px.y, px.z)
    });
    let mut exr_image = Image::from_layer(Layer::new(
        (width, height),
        attributes,
        Encoding::default(),
        channels,
    ));
    if let Some(p) = part {
        exr_image.attributes.display_window =
            IntegerBounds::new((0, 0), (p.width as usize, p.height as usize));
    }
    exr_image.write().non_parallel().to_buffered(out)?;
    Ok(())
}
