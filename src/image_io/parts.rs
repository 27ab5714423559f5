//! Parts of a big image (SPEC §5): a render of a region or tile records in its file
//! where it belongs in the whole image, and [`stitch`] puts parts back together into
//! exactly the whole image, or refuses (gaps, overlaps, parts of different images).
//!
//! The record lives in the file itself: a PNG `tEXt` chunk `whitted-part`, and in EXR
//! the standard data window (the part's pixels) inside the display window (the whole
//! image), with the same text as a header attribute. Other formats cannot carry it.

use std::fmt;
use std::io::{BufRead, Seek};
use std::path::Path;
use std::str::FromStr;

use glam::Vec3;
use image::{Rgb32FImage, RgbImage};

use super::{bytes_left, check_holds, exr_bytes, to_rgb8, write_atomically, Format, SaveError};
use crate::limits;
use crate::render::Frame;
use crate::scene::{to_toml, Scene};
use crate::settings::{Encoding, Region, Settings};

/// The PNG text keyword and EXR attribute name of the record.
pub(super) const KEY: &str = "whitted-part";

/// Where a part belongs: its rectangle in the whole image (origin top-left), the whole
/// image's size, and a fingerprint of what was rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// The part's rectangle in the whole image.
    pub region: Region,
    /// The whole image's width.
    pub width: u32,
    /// The whole image's height.
    pub height: u32,
    /// [`image_id`] of the scene and settings: parts of one image share it.
    pub image: u64,
    /// How the image's 8-bit bytes are made (for EXR parts stitched into 8-bit files).
    pub encoding: Encoding,
}

impl Placement {
    /// The placement of what `settings` renders of `scene`.
    pub fn of(scene: &Scene, settings: &Settings) -> Placement {
        Placement {
            region: settings.area(),
            width: settings.width,
            height: settings.height,
            image: image_id(scene, settings),
            encoding: settings.encoding,
        }
    }
}

impl fmt::Display for Placement {
    /// The record's text: `region=X,Y,W,H image=WxH id=HEX encoding=NAME`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "region={} image={}x{} id={:016x} encoding={}",
            self.region,
            self.width,
            self.height,
            self.image,
            self.encoding.name()
        )
    }
}

/// A record that is not a [`Placement`], or places a part outside the image, or
/// describes an image larger than a render can be.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("not a part's record")]
pub struct BadPlacement;

impl FromStr for Placement {
    type Err = BadPlacement;

    /// The record's text as [`Placement`]'s `Display` writes it; fields in any order,
    /// unknown fields ignored, `encoding` linear when missing.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let placement = record(text).ok_or(BadPlacement)?;
        let (width, height) = (placement.width, placement.height);
        // The whole image is one `whitted render` could make: `stitch` allocates it.
        let whole_fits = (1..=limits::MAX_SIDE).contains(&width)
            && (1..=limits::MAX_SIDE).contains(&height)
            && u64::from(width) * u64::from(height) <= limits::MAX_PIXELS;
        if whole_fits && placement.region.fits_in(width, height) {
            Ok(placement)
        } else {
            Err(BadPlacement)
        }
    }
}

/// The fields of a record, not yet checked against each other.
fn record(text: &str) -> Option<Placement> {
    let mut region = None;
    let mut size = None;
    let mut id = None;
    let mut encoding = Encoding::Linear;
    for field in text.split_whitespace() {
        let (key, value) = field.split_once('=')?;
        match key {
            "region" => region = Some(value.parse::<Region>().ok()?),
            "image" => {
                let (w, h) = value.split_once('x')?;
                size = Some((w.parse().ok()?, h.parse().ok()?));
            }
            "id" => id = Some(u64::from_str_radix(value, 16).ok()?),
            "encoding" => encoding = value.parse().ok()?,
            _ => {}
        }
    }
    let (width, height) = size?;
    Some(Placement {
        region: region?,
        width,
        height,
        image: id?,
        encoding,
    })
}

/// A fingerprint of the image that `settings` make of `scene`, whatever part of it is
/// rendered and on how many threads: FNV-1a of the scene's text and the settings.
pub fn image_id(scene: &Scene, settings: &Settings) -> u64 {
    let whole = Settings {
        region: None,
        tile: None,
        threads: None,
        ..settings.clone()
    };
    let text = format!("{}\n{whole:?}", to_toml(scene));
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Saves a part with its placement: PNG (bytes in `encoding`) and EXR (linear) only,
/// the formats that carry it.
pub fn save_part(
    frame: &Frame,
    placement: &Placement,
    path: &Path,
    format: Format,
    encoding: Encoding,
) -> Result<(), SaveError> {
    let bytes = encode_part(frame, placement, format, encoding).map_err(|message| SaveError {
        path: path.display().to_string(),
        message,
    })?;
    write_atomically(path, &bytes)
}

/// The bytes of the file [`save_part`] writes.
pub fn encode_part(
    frame: &Frame,
    placement: &Placement,
    format: Format,
    encoding: Encoding,
) -> Result<Vec<u8>, String> {
    match format {
        Format::Png => png_part(&to_rgb8(frame, encoding), placement),
        Format::Exr => exr_bytes(frame, Some(placement)).map_err(|e| e.to_string()),
        _ => return Err("a part records its place in the image only in PNG and EXR files".into()),
    }
    .map_err(|e| format!("cannot encode: {e}"))
}

fn png_part(image: &RgbImage, placement: &Placement) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, image.width(), image.height());
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .add_text_chunk(KEY.into(), placement.to_string())
        .map_err(|e| e.to_string())?;
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer
        .write_image_data(image.as_raw())
        .map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(out)
}

/// A part read back: where it belongs and its pixels (top row first).
#[derive(Clone, Debug)]
pub struct Part {
    /// Where the part belongs.
    pub placement: Placement,
    /// Its pixels.
    pub pixels: PartPixels,
}

/// The pixels of a part, as its file holds them.
#[derive(Clone, Debug)]
pub enum PartPixels {
    /// 8-bit RGB (from PNG).
    Bytes(RgbImage),
    /// Linear values (from EXR).
    Linear(Rgb32FImage),
}

/// Why parts could not be read or put together.
#[derive(Debug, thiserror::Error)]
pub enum StitchError {
    /// A file that cannot be read as a part.
    #[error("{path}: {message}")]
    Unreadable {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// Parts that belong to different images (size, scene or settings).
    #[error("{path} is a part of another image ({theirs}) than {first} ({ours})")]
    OtherImage {
        /// The part that differs.
        path: String,
        /// The first part.
        first: String,
        /// The first part's image.
        ours: String,
        /// This part's image.
        theirs: String,
    },
    /// PNG parts mixed with EXR parts.
    #[error("{path}: parts must all be PNG or all be EXR")]
    MixedKinds {
        /// The part that differs.
        path: String,
    },
    /// Two parts cover one pixel.
    #[error("{a} and {b} overlap (at pixel {x},{y})")]
    Overlap {
        /// One part.
        a: String,
        /// The other.
        b: String,
        /// A pixel both cover (origin top-left).
        x: u32,
        /// Its row.
        y: u32,
    },
    /// Pixels no part covers.
    #[error("the parts leave {missing} pixels of the {width}x{height} image uncovered (the first at {x},{y})")]
    Gap {
        /// Uncovered pixels.
        missing: u64,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
        /// The first uncovered pixel.
        x: u32,
        /// Its row.
        y: u32,
    },
    /// No parts at all.
    #[error("no parts given")]
    NoParts,
}

/// Reads a part written by [`save_part`], its kind by the file's extension.
pub fn read_part(path: &Path) -> Result<Part, StitchError> {
    let shown = path.display().to_string();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let format = match ext.as_str() {
        "png" => Format::Png,
        "exr" => Format::Exr,
        _ => return Err(unreadable(&shown, not_a_part())),
    };
    let file = std::fs::File::open(path).map_err(|e| unreadable(&shown, e.to_string()))?;
    decode_part(std::io::BufReader::new(file), format, &shown)
}

/// Reads a part from `reader`: a PNG or EXR file (`format`) written by [`save_part`];
/// `name` names it in errors.
pub fn decode_part<R: BufRead + Seek>(
    reader: R,
    format: Format,
    name: &str,
) -> Result<Part, StitchError> {
    match format {
        Format::Png => decode_png_part(reader),
        Format::Exr => decode_exr_part(reader),
        _ => Err(not_a_part()),
    }
    .map_err(|message| unreadable(name, message))
}

fn unreadable(name: &str, message: String) -> StitchError {
    StitchError::Unreadable {
        path: name.to_string(),
        message,
    }
}

fn not_a_part() -> String {
    "not a part: parts are PNG or EXR files written with --tile or --region".into()
}

fn no_record() -> String {
    "records no place in an image: not written with --tile or --region".into()
}

/// The fewest bits a part's pixel takes before compression: 8-bit RGB in a PNG (an
/// EXR part's three channels take at least 48).
const LEAST_PART_BITS: u64 = 24;

fn decode_png_part<R: BufRead + Seek>(mut reader: R) -> Result<Part, String> {
    let file_bytes = bytes_left(&mut reader).map_err(|e| e.to_string())?;
    let decoder = png::Decoder::new(reader);
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    let placement = reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .find(|t| t.keyword == KEY)
        .and_then(|t| t.text.parse().ok())
        .ok_or_else(no_record)?;
    let info = reader.info();
    if (info.color_type, info.bit_depth) != (png::ColorType::Rgb, png::BitDepth::Eight) {
        return Err("not an 8-bit RGB PNG".into());
    }
    check_size(&placement, info.width, info.height)?;
    check_holds(info.width, info.height, LEAST_PART_BITS, file_bytes)?;
    let mut buf = vec![0; reader.output_buffer_size().ok_or("an image too large")?];
    let frame = reader.next_frame(&mut buf).map_err(|e| e.to_string())?;
    buf.truncate(frame.buffer_size());
    let image = RgbImage::from_raw(frame.width, frame.height, buf).ok_or("a short image")?;
    check_size(&placement, image.width(), image.height())?;
    Ok(Part {
        placement,
        pixels: PartPixels::Bytes(image),
    })
}

fn decode_exr_part<R: BufRead + Seek>(mut reader: R) -> Result<Part, String> {
    use exr::meta::attribute::AttributeValue;
    use exr::meta::MetaData;
    use exr::prelude::traits::{ReadChannels, ReadLayers};
    // The headers first: their sizes decide what the pixels take, and a part's are
    // known from its record before anything that large is allocated.
    let file_bytes = bytes_left(&mut reader).map_err(|e| e.to_string())?;
    let meta = MetaData::read_from_buffered(&mut reader, false).map_err(|e| e.to_string())?;
    let header = meta.headers.first().ok_or("an EXR file with no layer")?;
    let placement = match header
        .own_attributes
        .other
        .get(&exr::meta::attribute::Text::from(KEY))
    {
        Some(AttributeValue::Text(t)) => t.to_string().parse().ok(),
        _ => None,
    }
    .ok_or_else(no_record)?;
    if meta.headers.len() != 1 {
        return Err("a part holds one layer".into());
    }
    let side = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    let size = header.layer_size;
    let (width, height) = (side(size.width()), side(size.height()));
    check_size(&placement, width, height)?;
    check_holds(width, height, LEAST_PART_BITS, file_bytes)?;
    reader.rewind().map_err(|e| e.to_string())?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |resolution, _| Rgb32FImage::new(resolution.width() as u32, resolution.height() as u32),
            |pixels: &mut Rgb32FImage, p, (r, g, b, _a): (f32, f32, f32, f32)| {
                pixels.put_pixel(p.x() as u32, p.y() as u32, image::Rgb([r, g, b]))
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(reader)
        .map_err(|e| e.to_string())?;
    let attributes = &image.layer_data.attributes;
    let pixels = image.layer_data.channel_data.pixels;
    let origin = attributes.layer_position;
    let r = placement.region;
    if (i64::from(origin.x()), i64::from(origin.y())) != (i64::from(r.x), i64::from(r.y)) {
        return Err("its data window disagrees with its record".into());
    }
    check_size(&placement, pixels.width(), pixels.height())?;
    Ok(Part {
        placement,
        pixels: PartPixels::Linear(pixels),
    })
}

fn check_size(placement: &Placement, width: u32, height: u32) -> Result<(), String> {
    let r = placement.region;
    if (width, height) != (r.width, r.height) {
        return Err(format!(
            "holds {width}x{height} pixels for a {}x{} part",
            r.width, r.height
        ));
    }
    Ok(())
}

/// The whole image put together from `parts` (with the paths they came from, for
/// messages): 8-bit from PNG parts, a linear frame from EXR parts. Every pixel must be
/// covered exactly once by parts of one image.
pub fn stitch(parts: &[(String, Part)]) -> Result<PartPixels, StitchError> {
    let (first_path, first) = parts.first().ok_or(StitchError::NoParts)?;
    let p0 = first.placement;
    let describe = |p: &Placement| format!("{}x{}, id {:016x}", p.width, p.height, p.image);
    let (w, h) = (p0.width, p0.height);
    let mut owner: Vec<u32> = vec![u32::MAX; w as usize * h as usize];
    for (k, (path, part)) in parts.iter().enumerate() {
        let p = part.placement;
        if (p.width, p.height, p.image) != (p0.width, p0.height, p0.image) {
            return Err(StitchError::OtherImage {
                path: path.clone(),
                first: first_path.clone(),
                ours: describe(&p0),
                theirs: describe(&p),
            });
        }
        if std::mem::discriminant(&part.pixels) != std::mem::discriminant(&first.pixels) {
            return Err(StitchError::MixedKinds { path: path.clone() });
        }
        let r = p.region;
        for y in r.y..r.y + r.height {
            for x in r.x..r.x + r.width {
                let slot = &mut owner[y as usize * w as usize + x as usize];
                if *slot != u32::MAX {
                    return Err(StitchError::Overlap {
                        a: parts[*slot as usize].0.clone(),
                        b: path.clone(),
                        x,
                        y,
                    });
                }
                *slot = k as u32;
            }
        }
    }
    let missing = owner.iter().filter(|&&o| o == u32::MAX).count() as u64;
    if let Some(at) = owner.iter().position(|&o| o == u32::MAX) {
        return Err(StitchError::Gap {
            missing,
            width: w,
            height: h,
            x: at as u32 % w,
            y: at as u32 / w,
        });
    }
    Ok(match &first.pixels {
        PartPixels::Bytes(_) => PartPixels::Bytes(paste(parts, w, h, |p| match p {
            PartPixels::Bytes(image) => Some(image),
            PartPixels::Linear(_) => None,
        })),
        PartPixels::Linear(_) => PartPixels::Linear(paste(parts, w, h, |p| match p {
            PartPixels::Linear(image) => Some(image),
            PartPixels::Bytes(_) => None,
        })),
    })
}

/// The `w`×`h` image with each part's pixels (of the kind `pixels` picks) in its place.
fn paste<P: image::Pixel>(
    parts: &[(String, Part)],
    w: u32,
    h: u32,
    pixels: impl Fn(&PartPixels) -> Option<&image::ImageBuffer<P, Vec<P::Subpixel>>>,
) -> image::ImageBuffer<P, Vec<P::Subpixel>> {
    let mut whole = image::ImageBuffer::new(w, h);
    for (_, part) in parts {
        if let Some(img) = pixels(&part.pixels) {
            let r = part.placement.region;
            image::imageops::replace(&mut whole, img, i64::from(r.x), i64::from(r.y));
        }
    }
    whole
}

/// A frame (rows from the bottom) from linear pixels stored top row first.
pub fn frame_of(image: &Rgb32FImage) -> Frame {
    let (w, h) = image.dimensions();
    let mut frame = Frame::new(w, h);
    for (x, y, p) in image.enumerate_pixels() {
        frame.pixels[(h - 1 - y) as usize * w as usize + x as usize] = Vec3::from_array(p.0);
    }
    frame
}
