//! What a render is asked to do: image size, sampling, depth, precision, the part of
//! the image and the threads, as one resolved [`Settings`] value.
//!
//! Settings come in layers of [`Overrides`]: the SPEC's defaults, then a scene file's
//! `[image]` table, then the command line's (or a Python call's) options. Each layer
//! may name a quality [`Preset`] and set single values; within a layer the preset comes
//! first and the single values override it, and a later layer overrides an earlier
//! one. [`Settings::with`] is the one place where a layer is applied, and
//! [`Settings::check`] the one place where the result is validated.
//!
//! This module is a leaf: it knows nothing of scenes, cameras or tracers.

use std::fmt;
use std::str::FromStr;

use crate::limits::{MAX_DEPTH, MAX_FRAMES, MAX_PIXELS, MAX_SIDE, MAX_SPP};

/// Which implementation of the model renders (SPEC §2: both compute the same function).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// The fast `f32` tracer.
    #[default]
    Fast,
    /// The `f64` reference tracer (slow; for measuring error).
    Reference,
}

/// Adaptive anti-aliasing: every pixel first gets `first` samples spread over it; only
/// pixels whose first samples, or whose 4-neighbours' means, differ by `threshold` or
/// more (largest colour component, linear values clamped to \[0, 1\]) get the rest of the
/// `spp` samples. `threshold = 0` refines every pixel, which is plain anti-aliasing
/// bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// Samples of the first pass.
    pub first: u32,
    /// Difference (linear, largest component) from which a pixel is refined.
    pub threshold: f32,
}

impl Adaptive {
    /// Samples in the first pass unless told otherwise: a 2×2 spread.
    pub const FIRST: u32 = 4;

    /// The usual first pass with the given threshold.
    pub fn with_threshold(threshold: f32) -> Self {
        Adaptive {
            first: Self::FIRST,
            threshold,
        }
    }
}

/// The knobs that trade run time for error: one point of the trade-off that
/// `whitted bench` measures, and what a [`Preset`] names.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quality {
    /// Samples per pixel (stratified and jittered beyond 1).
    pub spp: u32,
    /// `None`: every pixel gets `spp` samples.
    pub adaptive: Option<Adaptive>,
    /// Contribution cutoff ε: branches of path weight below it are not traced
    /// (0: exact). The fast tracer only; the reference traces everything.
    pub cutoff: f32,
    /// Maximum ray depth (SPEC §2: `trace` returns the sky at this depth).
    pub max_depth: u32,
    /// The tracer.
    pub precision: Precision,
}

impl Default for Quality {
    /// The SPEC's defaults: one centred sample, depth 5, everything exact.
    fn default() -> Self {
        Quality {
            spp: 1,
            adaptive: None,
            cutoff: 0.0,
            max_depth: 5,
            precision: Precision::Fast,
        }
    }
}

impl Quality {
    /// A short, unique, file-name-safe label such as `fast-spp16-aa0.03-eps0.01-d5`.
    pub fn label(&self) -> String {
        let mut s = match self.precision {
            Precision::Fast => "fast".to_string(),
            Precision::Reference => "f64".to_string(),
        };
        s += &format!("-spp{}", self.spp);
        if let Some(a) = self.adaptive {
            s += &format!("-aa{}", a.threshold);
            if a.first != Adaptive::FIRST {
                s += &format!("f{}", a.first);
            }
        }
        if self.cutoff > 0.0 {
            s += &format!("-eps{}", self.cutoff);
        }
        s += &format!("-d{}", self.max_depth);
        s
    }

    fn check(&self) -> Result<(), SettingsError> {
        if self.spp == 0 || self.spp > MAX_SPP {
            return Err(SettingsError::Spp(self.spp));
        }
        if self.max_depth > MAX_DEPTH {
            return Err(SettingsError::Depth(self.max_depth));
        }
        if !(self.cutoff.is_finite() && self.cutoff >= 0.0) {
            return Err(SettingsError::Cutoff(self.cutoff));
        }
        if let Some(a) = self.adaptive {
            if !(a.threshold.is_finite() && a.threshold >= 0.0) {
                return Err(SettingsError::AdaptiveThreshold(a.threshold));
            }
            if a.first == 0 {
                return Err(SettingsError::AdaptiveFirst);
            }
        }
        Ok(())
    }
}

/// The named presets (`--quality`, `quality = "…"` in a scene file).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Preset {
    /// Interactive previews: one centred sample, depth 5, everything exact (the
    /// SPEC's defaults, what a render without options does).
    Draft,
    /// The knee of the measured time/error front on 3 of the 4 study scenes (and next
    /// to it on the fourth): RMSE about one 8-bit level.
    Default,
    /// The cheapest setting within 10% of the best error the fast tracer reached in
    /// the study (at a third of the time of 64 plain samples).
    High,
    /// The converged reference of the study: f64, 256 stratified spp, depth 16.
    Reference,
}

impl Preset {
    /// Every preset, cheapest first.
    pub const ALL: [Preset; 4] = [
        Preset::Draft,
        Preset::Default,
        Preset::High,
        Preset::Reference,
    ];

    /// The name in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Draft => "draft",
            Preset::Default => "default",
            Preset::High => "high",
            Preset::Reference => "reference",
        }
    }

    /// The settings of the preset. The values come from the study in docs/quality.md
    /// (`whitted bench`); re-run it before changing them.
    pub fn quality(self) -> Quality {
        match self {
            Preset::Draft => Quality::default(),
            Preset::Default => Quality {
                spp: 16,
                adaptive: Some(Adaptive::with_threshold(0.1)),
                cutoff: 0.0,
                max_depth: 16,
                precision: Precision::Fast,
            },
            Preset::High => Quality {
                spp: 64,
                adaptive: Some(Adaptive::with_threshold(0.03)),
                cutoff: 0.0,
                max_depth: 16,
                precision: Precision::Fast,
            },
            Preset::Reference => Quality {
                spp: 256,
                adaptive: None,
                cutoff: 0.0,
                max_depth: 16,
                precision: Precision::Reference,
            },
        }
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not one of the [`Preset`]s.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown quality \"{0}\": expected draft, default, high or reference")]
pub struct UnknownPreset(pub String);

impl FromStr for Preset {
    type Err = UnknownPreset;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Preset::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| UnknownPreset(s.to_string()))
    }
}

/// How linear values become 8-bit bytes (SPEC §4 `encoding`): in files other than EXR,
/// and in the window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// `round(clamp(c, 0, 1)·255)`: the assignment's bytes.
    #[default]
    Linear,
    /// The sRGB transfer curve, then the same rounding.
    Srgb,
}

impl Encoding {
    /// Both encodings.
    pub const ALL: [Encoding; 2] = [Encoding::Linear, Encoding::Srgb];

    /// The name in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Linear => "linear",
            Encoding::Srgb => "srgb",
        }
    }
}

impl fmt::Display for Encoding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not one of the [`Encoding`]s.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown encoding \"{0}\": expected linear or srgb")]
pub struct UnknownEncoding(pub String);

impl FromStr for Encoding {
    type Err = UnknownEncoding;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Encoding::ALL
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| UnknownEncoding(s.to_string()))
    }
}

/// A rectangle of the output image in image-tool coordinates: origin at the TOP-left.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Region {
    /// Left column.
    pub x: u32,
    /// Top row, counted from the top.
    pub y: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

impl Region {
    /// Whether the region has pixels and lies inside a `width`×`height` image.
    pub fn fits_in(&self, width: u32, height: u32) -> bool {
        self.width > 0
            && self.height > 0
            && u64::from(self.x) + u64::from(self.width) <= u64::from(width)
            && u64::from(self.y) + u64::from(self.height) <= u64::from(height)
    }
}

/// Text that is not a [`Region`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("expected X,Y,W,H: four whole numbers, W and H at least 1")]
pub struct BadRegion;

impl FromStr for Region {
    type Err = BadRegion;

    /// `X,Y,W,H` (the command line's `--region`), spaces allowed around the numbers.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let numbers: Result<Vec<u32>, _> = text.split(',').map(|p| p.trim().parse()).collect();
        match numbers.as_deref() {
            Ok(&[x, y, width, height]) if width > 0 && height > 0 => Ok(Region {
                x,
                y,
                width,
                height,
            }),
            _ => Err(BadRegion),
        }
    }
}

impl fmt::Display for Region {
    /// `X,Y,W,H`, as [`Region::from_str`] reads it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x, self.y, self.width, self.height)
    }
}

/// Tile `index` (from 0) of a grid of `count` tiles over the image: a part of the image
/// for one machine of many (SPEC §5). The grid is the program's choice
/// ([`Tile::grid`]); a tile is a rectangle, and the tiles cover the image once.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Tile {
    /// Which tile, from 0, row by row from the top-left.
    pub index: u32,
    /// How many tiles.
    pub count: u32,
}

impl Tile {
    /// Columns and rows of `count` tiles over a `width`×`height` image: of the
    /// factorizations `columns × rows = count` that fit (no tile narrower or lower than
    /// a pixel), the one whose tiles are closest to square, and of those the one with
    /// fewer columns (rows of tiles are whole rows of the image's memory).
    pub fn grid(count: u32, width: u32, height: u32) -> Option<(u32, u32)> {
        let squareness = |(c, r): (u32, u32)| {
            let aspect = (f64::from(width) / f64::from(c)) / (f64::from(height) / f64::from(r));
            aspect.ln().abs()
        };
        (1..=count)
            .filter(|&c| count.is_multiple_of(c))
            .map(|c| (c, count / c))
            .filter(|&(c, r)| c <= width && r <= height)
            .min_by(|&a, &b| squareness(a).total_cmp(&squareness(b)))
    }

    /// The tile's rectangle in a `width`×`height` image (`None` when the image has
    /// fewer pixels than tiles in a direction, or the index is out of range). Edges
    /// fall at `⌊k·width/columns⌋` and `⌊k·height/rows⌋`.
    pub fn region(&self, width: u32, height: u32) -> Option<Region> {
        if self.index >= self.count {
            return None;
        }
        let (columns, rows) = Tile::grid(self.count, width, height)?;
        let edge =
            |k: u32, n: u32, size: u32| (u64::from(k) * u64::from(size) / u64::from(n)) as u32;
        let (c, r) = (self.index % columns, self.index / columns);
        let (x0, x1) = (edge(c, columns, width), edge(c + 1, columns, width));
        let (y0, y1) = (edge(r, rows, height), edge(r + 1, rows, height));
        Some(Region {
            x: x0,
            y: y0,
            width: x1 - x0,
            height: y1 - y0,
        })
    }
}

/// Text that is not a [`Tile`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("expected I/N: tile I of N tiles, 0 <= I < N")]
pub struct BadTile;

impl FromStr for Tile {
    type Err = BadTile;

    /// `I/N` (the command line's `--tile`), spaces allowed around the numbers.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let (index, count) = text.split_once('/').ok_or(BadTile)?;
        match (index.trim().parse(), count.trim().parse()) {
            (Ok(index), Ok(count)) if index < count => Ok(Tile { index, count }),
            _ => Err(BadTile),
        }
    }
}

impl fmt::Display for Tile {
    /// `I/N`, as [`Tile::from_str`] reads it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Frames `start..end` (end excluded, `start < end <= MAX_FRAMES`) of an animation,
/// numbered as in the whole sequence.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FrameRange {
    /// The first frame.
    pub start: u32,
    /// The frame after the last.
    pub end: u32,
}

impl FrameRange {
    /// All `frames` frames of a sequence.
    pub fn all(frames: u32) -> FrameRange {
        FrameRange {
            start: 0,
            end: frames,
        }
    }

    /// Frames in the range.
    pub fn len(&self) -> u32 {
        self.end.saturating_sub(self.start)
    }

    /// Whether the range holds no frame (never, for a parsed range).
    pub fn is_empty(&self) -> bool {
        self.end <= self.start
    }
}

/// Text that is not a [`FrameRange`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("expected a frame number K or a range A..B with A < B (frames from 0 to {MAX_FRAMES})")]
pub struct BadFrameRange;

impl FromStr for FrameRange {
    type Err = BadFrameRange;

    /// `K` (frame K alone) or `A..B` (the command line's `--frame`), spaces allowed
    /// around the numbers. B may be [`MAX_FRAMES`]: the range of a sequence's last
    /// frames.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let number = |s: &str| s.trim().parse::<u32>().ok().filter(|&k| k <= MAX_FRAMES);
        let (start, end) = match text.split_once("..") {
            None => number(text).map(|k| (k, k.saturating_add(1))),
            Some((a, b)) => number(a).zip(number(b)),
        }
        .ok_or(BadFrameRange)?;
        if start < end && end <= MAX_FRAMES {
            Ok(FrameRange { start, end })
        } else {
            Err(BadFrameRange)
        }
    }
}

impl fmt::Display for FrameRange {
    /// `K` for one frame, else `A..B`, as [`FrameRange::from_str`] reads it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.len() == 1 {
            write!(f, "{}", self.start)
        } else {
            write!(f, "{}..{}", self.start, self.end)
        }
    }
}

/// Everything a render needs besides the scene, resolved from the layers of
/// [`Overrides`] and checked by [`Settings::check`].
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Seed of the sample jitter.
    pub seed: u64,
    /// Samples, anti-aliasing, cutoff, depth and precision.
    pub quality: Quality,
    /// Render only this rectangle of the image (`None`: all of it).
    pub region: Option<Region>,
    /// Render only this tile of the image (not with a region).
    pub tile: Option<Tile>,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// How values become 8-bit bytes.
    pub encoding: Encoding,
}

impl Default for Settings {
    /// The SPEC's defaults: 1280×720, seed 0, [`Quality::default`], the whole image on
    /// all cores.
    fn default() -> Self {
        Settings {
            width: 1280,
            height: 720,
            seed: 0,
            quality: Quality::default(),
            region: None,
            tile: None,
            threads: None,
            encoding: Encoding::Linear,
        }
    }
}

/// One layer of settings: what a scene file's `[image]` table, a command line or a
/// Python call says. Every field is optional; a preset applies first, then the single
/// values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    /// A quality preset, applied before the values below.
    pub quality: Option<Preset>,
    /// Image width in pixels.
    pub width: Option<u32>,
    /// Image height in pixels.
    pub height: Option<u32>,
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Maximum ray depth.
    pub max_depth: Option<u32>,
    /// Seed of the sample jitter.
    pub seed: Option<u64>,
    /// The tracer.
    pub precision: Option<Precision>,
    /// Render only this rectangle (a layer's region or tile replaces an earlier one).
    pub region: Option<Region>,
    /// Render only this tile.
    pub tile: Option<Tile>,
    /// Worker threads.
    pub threads: Option<usize>,
    /// How values become 8-bit bytes.
    pub encoding: Option<Encoding>,
}

impl Overrides {
    /// `later` laid over this layer, as one layer: for every `s`,
    /// `s.with(&a.then(&b)) == s.with(&a).with(&b)`. A preset in `later` replaces what
    /// this layer set of the preset's knobs (samples, depth, precision).
    pub fn then(&self, later: &Overrides) -> Overrides {
        let base = if later.quality.is_some() {
            Overrides {
                quality: later.quality,
                spp: None,
                max_depth: None,
                precision: None,
                ..*self
            }
        } else {
            *self
        };
        Overrides {
            quality: base.quality,
            width: later.width.or(base.width),
            height: later.height.or(base.height),
            spp: later.spp.or(base.spp),
            max_depth: later.max_depth.or(base.max_depth),
            seed: later.seed.or(base.seed),
            precision: later.precision.or(base.precision),
            region: part(later, &base).0,
            tile: part(later, &base).1,
            threads: later.threads.or(base.threads),
            encoding: later.encoding.or(base.encoding),
        }
    }
}

/// The part of the image of `later` over `base`: a region or tile in `later` replaces
/// both of `base`'s.
fn part(later: &Overrides, base: &Overrides) -> (Option<Region>, Option<Tile>) {
    if later.region.is_some() || later.tile.is_some() {
        (later.region, later.tile)
    } else {
        (base.region, base.tile)
    }
}

impl Settings {
    /// These settings with the layer `o` over them: its preset first, then its values.
    pub fn with(mut self, o: &Overrides) -> Settings {
        if let Some(preset) = o.quality {
            self.quality = preset.quality();
        }
        let q = &mut self.quality;
        q.spp = o.spp.unwrap_or(q.spp);
        q.max_depth = o.max_depth.unwrap_or(q.max_depth);
        q.precision = o.precision.unwrap_or(q.precision);
        self.width = o.width.unwrap_or(self.width);
        self.height = o.height.unwrap_or(self.height);
        self.seed = o.seed.unwrap_or(self.seed);
        if o.region.is_some() || o.tile.is_some() {
            (self.region, self.tile) = (o.region, o.tile);
        }
        self.threads = o.threads.or(self.threads);
        self.encoding = o.encoding.unwrap_or(self.encoding);
        self
    }

    /// The rectangle to render: the region, the tile's rectangle, or the whole image.
    /// (A tile that does not fit counts as the whole image; [`Settings::check`]
    /// refuses it.)
    pub fn area(&self) -> Region {
        let whole = Region {
            x: 0,
            y: 0,
            width: self.width,
            height: self.height,
        };
        match (self.region, self.tile) {
            (Some(r), _) => r,
            (None, Some(t)) => t.region(self.width, self.height).unwrap_or(whole),
            (None, None) => whole,
        }
    }

    /// Checks sizes, samples, depth, the region and the threads against [`crate::limits`]
    /// before anything is allocated. What a render allocates is its area (the region,
    /// the tile or the whole image): the area is held to [`MAX_PIXELS`], the whole
    /// image's sides to [`MAX_SIDE`].
    pub fn check(&self) -> Result<(), SettingsError> {
        let (width, height) = (self.width, self.height);
        if width == 0 || height == 0 {
            return Err(SettingsError::EmptyImage { width, height });
        }
        if width > MAX_SIDE || height > MAX_SIDE {
            return Err(SettingsError::SideTooLong { width, height });
        }
        self.quality.check()?;
        if let Some(r) = self.region {
            if !r.fits_in(width, height) {
                return Err(SettingsError::RegionOutside {
                    region: r,
                    width,
                    height,
                });
            }
        }
        if let Some(t) = self.tile {
            if self.region.is_some() {
                return Err(SettingsError::RegionAndTile);
            }
            if t.region(width, height).is_none() {
                return Err(SettingsError::TileOutside {
                    tile: t,
                    width,
                    height,
                });
            }
        }
        let area = self.area();
        if u64::from(area.width) * u64::from(area.height) > MAX_PIXELS {
            return Err(match (self.region, self.tile) {
                (None, None) => SettingsError::TooManyPixels { width, height },
                (_, tile) => SettingsError::AreaTooLarge { area, tile },
            });
        }
        if self.threads == Some(0) {
            return Err(SettingsError::NoThreads);
        }
        Ok(())
    }
}

/// What fits where a region does not: the largest region at its origin, or where its
/// origin may be.
fn what_fits(region: &Region, width: u32, height: u32) -> String {
    if region.x >= width || region.y >= height {
        format!("its corner must be inside, at X below {width} and Y below {height}")
    } else {
        format!(
            "the largest region at {},{} is {}x{}",
            region.x,
            region.y,
            width - region.x,
            height - region.y
        )
    }
}

/// The tallest image of `width` columns within [`MAX_PIXELS`].
fn tallest(width: u32) -> u64 {
    (MAX_PIXELS / u64::from(width.max(1))).min(u64::from(MAX_SIDE))
}

/// Settings that [`Settings::check`] refuses.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// A side of zero pixels.
    #[error("image size {width}x{height} is empty: width and height must be at least 1")]
    EmptyImage {
        /// Width asked for.
        width: u32,
        /// Height asked for.
        height: u32,
    },
    /// A side beyond [`MAX_SIDE`].
    #[error("image size {width}x{height} is too large: each side must be at most {MAX_SIDE}")]
    SideTooLong {
        /// Width asked for.
        width: u32,
        /// Height asked for.
        height: u32,
    },
    /// A whole image of more than [`MAX_PIXELS`] pixels.
    #[error(
        "image size {width}x{height} is too large: at most {MAX_PIXELS} pixels in one render \
         ({width}x{} at this width); render it in parts, a region or a tile at a time",
        tallest(*width)
    )]
    TooManyPixels {
        /// Width asked for.
        width: u32,
        /// Height asked for.
        height: u32,
    },
    /// A region or tile of more than [`MAX_PIXELS`] pixels.
    #[error(
        "{} is {}x{}, too large: at most {MAX_PIXELS} pixels in one render ({}x{} at this width)",
        tile.map_or(format!("region {},{},{},{}", area.x, area.y, area.width, area.height),
            |t| format!("tile {}/{}", t.index, t.count)),
        area.width, area.height, area.width, tallest(area.width)
    )]
    AreaTooLarge {
        /// The rectangle asked for.
        area: Region,
        /// The tile it is, if it is one.
        tile: Option<Tile>,
    },
    /// Samples per pixel of 0 or beyond [`MAX_SPP`].
    #[error("spp {0} is out of range: expected 1 to {MAX_SPP}")]
    Spp(u32),
    /// Depth beyond [`MAX_DEPTH`].
    #[error("max_depth {0} is out of range: expected 0 to {MAX_DEPTH}")]
    Depth(u32),
    /// A negative or non-finite cutoff.
    #[error("cutoff {0} is out of range: expected a number ≥ 0")]
    Cutoff(f32),
    /// A negative or non-finite adaptive threshold.
    #[error("adaptive threshold {0} is out of range: expected a number ≥ 0")]
    AdaptiveThreshold(f32),
    /// An adaptive first pass of no samples.
    #[error("adaptive first pass needs at least 1 sample")]
    AdaptiveFirst,
    /// A region that is empty or reaches outside the image.
    #[error(
        "region {},{},{},{} does not fit in the {width}x{height} image: {}",
        region.x, region.y, region.width, region.height, what_fits(region, *width, *height)
    )]
    RegionOutside {
        /// The region asked for.
        region: Region,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// Both a region and a tile.
    #[error("give a region or a tile, not both")]
    RegionAndTile,
    /// A tile index beyond the count, or more tiles than the image has pixels.
    #[error(
        "tile {}/{} does not exist in a {width}x{height} image: expected an index from 0 to {} and at most as many tiles as pixels",
        tile.index, tile.count, tile.count.saturating_sub(1)
    )]
    TileOutside {
        /// The tile asked for.
        tile: Tile,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// Zero worker threads.
    #[error("threads must be at least 1")]
    NoThreads,
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn layer() -> impl Strategy<Value = Overrides> {
        let preset = prop::option::of(prop::sample::select(Preset::ALL.to_vec()));
        let small = || prop::option::of(0u32..100);
        let precision = prop::option::of(prop::sample::select(vec![
            Precision::Fast,
            Precision::Reference,
        ]));
        (
            preset,
            (small(), small(), small(), small()),
            prop::option::of(0u64..9),
            precision,
            prop::option::of((0u32..9, 0u32..9, 1u32..9, 1u32..9)),
            prop::option::of((0u32..9, 1u32..9)),
            prop::option::of(1usize..9),
            prop::option::of(prop::sample::select(Encoding::ALL.to_vec())),
        )
            .prop_map(
                |(
                    quality,
                    (width, height, spp, max_depth),
                    seed,
                    precision,
                    r,
                    t,
                    threads,
                    encoding,
                )| {
                    Overrides {
                        quality,
                        width,
                        height,
                        spp,
                        max_depth,
                        seed,
                        precision,
                        region: r.map(|(x, y, width, height)| Region {
                            x,
                            y,
                            width,
                            height,
                        }),
                        tile: t.map(|(index, count)| Tile { index, count }),
                        threads,
                        encoding,
                    }
                },
            )
    }

    #[test]
    fn regions_read_four_numbers_and_print_back() {
        let r: Region = " 3, 4,5 ,6".parse().unwrap();
        assert_eq!(
            r,
            Region {
                x: 3,
                y: 4,
                width: 5,
                height: 6
            }
        );
        assert_eq!(r.to_string(), "3,4,5,6");
        for bad in ["1,2,0,4", "1,2,3", "1,2,3,4,5", "-1,2,3,4", "a,b,c,d", ""] {
            assert_eq!(bad.parse::<Region>(), Err(BadRegion), "{bad}");
        }
        assert_eq!(
            BadRegion.to_string(),
            "expected X,Y,W,H: four whole numbers, W and H at least 1"
        );
    }

    #[test]
    fn tiles_need_an_index_below_the_count() {
        assert_eq!("2 / 7".parse(), Ok(Tile { index: 2, count: 7 }));
        assert_eq!(Tile { index: 2, count: 7 }.to_string(), "2/7");
        for bad in ["4/4", "0/0", "a/b", "3", "1/2/3", "-1/2"] {
            assert_eq!(bad.parse::<Tile>(), Err(BadTile), "{bad}");
        }
        assert_eq!(
            BadTile.to_string(),
            "expected I/N: tile I of N tiles, 0 <= I < N"
        );
    }

    #[test]
    fn frame_ranges_exclude_their_end() {
        assert_eq!("5".parse(), Ok(FrameRange { start: 5, end: 6 }));
        assert_eq!("2..9".parse(), Ok(FrameRange { start: 2, end: 9 }));
        assert_eq!(FrameRange { start: 5, end: 6 }.to_string(), "5");
        assert_eq!(FrameRange { start: 2, end: 9 }.to_string(), "2..9");
        // The last frame of the longest sequence, alone or ending a range.
        let last = MAX_FRAMES - 1;
        assert_eq!(
            last.to_string().parse(),
            Ok(FrameRange {
                start: last,
                end: MAX_FRAMES
            })
        );
        assert_eq!(
            format!("0..{MAX_FRAMES}").parse(),
            Ok(FrameRange::all(MAX_FRAMES))
        );
        let beyond = [
            MAX_FRAMES.to_string(),
            format!("0..{}", MAX_FRAMES + 1),
            u32::MAX.to_string(),
        ];
        for bad in ["9..2", "3..3", "-1", "a", "1..", "..4", "1..2..3"]
            .into_iter()
            .chain(beyond.iter().map(String::as_str))
        {
            assert_eq!(bad.parse::<FrameRange>(), Err(BadFrameRange), "{bad}");
        }
        assert_eq!(
            BadFrameRange.to_string(),
            "expected a frame number K or a range A..B with A < B (frames from 0 to 1048576)"
        );
    }

    proptest! {
        #[test]
        fn two_layers_joined_apply_as_the_two_in_turn(a in layer(), b in layer()) {
            let base = Settings::default();
            prop_assert_eq!(
                base.clone().with(&a.then(&b)),
                base.with(&a).with(&b)
            );
        }
    }

    #[test]
    fn a_preset_comes_before_the_values_of_its_layer_and_after_earlier_layers() {
        let file = Overrides {
            quality: Some(Preset::High),
            spp: Some(3),
            width: Some(64),
            ..Overrides::default()
        };
        let s = Settings::default().with(&file);
        assert_eq!((s.quality.spp, s.quality.max_depth, s.width), (3, 16, 64));
        assert_eq!(s.quality.adaptive, Some(Adaptive::with_threshold(0.03)));

        // A preset on the command line replaces the file's samples, keeps its size.
        let cli = Overrides {
            quality: Some(Preset::Reference),
            ..Overrides::default()
        };
        let s = s.with(&cli);
        assert_eq!((s.quality.spp, s.width), (256, 64));
        assert_eq!(s.quality.precision, Precision::Reference);
        assert_eq!(s.quality.adaptive, None);
    }

    #[test]
    fn check_refuses_each_value_out_of_range() {
        let ok = Settings::default();
        assert_eq!(ok.check(), Ok(()));
        let bad = |f: &dyn Fn(&mut Settings)| {
            let mut s = Settings::default();
            f(&mut s);
            s.check().unwrap_err().to_string()
        };
        assert_eq!(
            bad(&|s| s.width = 0),
            "image size 0x720 is empty: width and height must be at least 1"
        );
        assert_eq!(
            bad(&|s| s.height = MAX_SIDE + 1),
            "image size 1280x65537 is too large: each side must be at most 65536"
        );
        assert_eq!(
            bad(&|s| (s.width, s.height) = (MAX_SIDE, MAX_SIDE)),
            "image size 65536x65536 is too large: at most 268435456 pixels in one render \
             (65536x4096 at this width); render it in parts, a region or a tile at a time"
        );
        assert_eq!(
            bad(&|s| s.quality.spp = 0),
            "spp 0 is out of range: expected 1 to 65536"
        );
        assert_eq!(
            bad(&|s| s.quality.max_depth = MAX_DEPTH + 1),
            "max_depth 65 is out of range: expected 0 to 64"
        );
        assert_eq!(
            bad(&|s| s.quality.cutoff = f32::NAN),
            "cutoff NaN is out of range: expected a number ≥ 0"
        );
        assert_eq!(
            bad(&|s| s.quality.adaptive = Some(Adaptive::with_threshold(-1.0))),
            "adaptive threshold -1 is out of range: expected a number ≥ 0"
        );
        assert_eq!(
            bad(&|s| s.region = Some(Region {
                x: 1200,
                y: 700,
                width: 81,
                height: 20
            })),
            "region 1200,700,81,20 does not fit in the 1280x720 image: the largest region \
             at 1200,700 is 80x20"
        );
        assert_eq!(
            bad(&|s| s.region = Some(Region {
                x: 1280,
                y: 0,
                width: 1,
                height: 1
            })),
            "region 1280,0,1,1 does not fit in the 1280x720 image: its corner must be \
             inside, at X below 1280 and Y below 720"
        );
        assert_eq!(bad(&|s| s.threads = Some(0)), "threads must be at least 1");
    }

    #[test]
    fn the_pixel_limit_holds_for_what_is_rendered_and_the_sides_for_the_image() {
        let huge = |region, tile| Settings {
            width: MAX_SIDE,
            height: MAX_SIDE,
            region,
            tile,
            ..Settings::default()
        };
        let small = Region {
            x: 0,
            y: 0,
            width: 64,
            height: 64,
        };
        assert_eq!(huge(Some(small), None).check(), Ok(()));
        // 65536 tiles of 256x256.
        assert_eq!(
            huge(
                None,
                Some(Tile {
                    index: 7,
                    count: 1 << 16
                })
            )
            .check(),
            Ok(())
        );
        let half = Region {
            x: 0,
            y: 0,
            width: MAX_SIDE,
            height: MAX_SIDE / 2,
        };
        assert_eq!(
            huge(Some(half), None).check().unwrap_err().to_string(),
            "region 0,0,65536,32768 is 65536x32768, too large: at most 268435456 pixels \
             in one render (65536x4096 at this width)"
        );
        assert_eq!(
            huge(None, Some(Tile { index: 0, count: 4 }))
                .check()
                .unwrap_err()
                .to_string(),
            "tile 0/4 is 32768x32768, too large: at most 268435456 pixels in one render \
             (32768x8192 at this width)"
        );
        // The sides of the whole image stay bounded, region or not.
        let mut long = huge(Some(small), None);
        long.width = MAX_SIDE + 1;
        assert_eq!(
            long.check(),
            Err(SettingsError::SideTooLong {
                width: MAX_SIDE + 1,
                height: MAX_SIDE
            })
        );
    }

    #[test]
    fn tiles_cover_the_image_once_in_near_square_rectangles() {
        for (width, height) in [(1280, 720), (7, 3), (1, 1), (3840, 2160), (100, 1)] {
            for count in 1..=40 {
                let Some((columns, rows)) = Tile::grid(count, width, height) else {
                    assert!(count > width * height || (count > width && count > height));
                    continue;
                };
                assert_eq!(columns * rows, count);
                let mut covered = vec![0u8; (width * height) as usize];
                for index in 0..count {
                    let r = Tile { index, count }.region(width, height).unwrap();
                    assert!(r.width > 0 && r.height > 0, "{count} tiles: {r:?}");
                    for y in r.y..r.y + r.height {
                        for x in r.x..r.x + r.width {
                            covered[(y * width + x) as usize] += 1;
                        }
                    }
                }
                assert!(covered.iter().all(|&c| c == 1), "{width}x{height} {count}");
            }
        }
        // 16 tiles of a 16:9 image: 4×4 tiles of 320×180 (16:9 again, the squarest
        // choice of 1×16, 2×8, 4×4, 8×2, 16×1).
        assert_eq!(Tile::grid(16, 1280, 720), Some((4, 4)));
        assert_eq!(
            Tile {
                index: 5,
                count: 16
            }
            .region(1280, 720),
            Some(Region {
                x: 320,
                y: 180,
                width: 320,
                height: 180
            })
        );
        // A prime count: bands across the longer side.
        assert_eq!(Tile::grid(7, 1280, 720), Some((7, 1)));
        assert_eq!(Tile { index: 7, count: 7 }.region(1280, 720), None);
    }

    #[test]
    fn a_tile_and_a_region_exclude_each_other() {
        let tile = Tile { index: 1, count: 4 };
        let s = Settings::default().with(&Overrides {
            tile: Some(tile),
            ..Overrides::default()
        });
        assert_eq!(s.area(), tile.region(1280, 720).unwrap());
        let r = Region {
            x: 1,
            y: 2,
            width: 3,
            height: 4,
        };
        let s2 = s.clone().with(&Overrides {
            region: Some(r),
            ..Overrides::default()
        });
        assert_eq!((s2.region, s2.tile, s2.area()), (Some(r), None, r));
        let both = Settings::default().with(&Overrides {
            region: Some(r),
            tile: Some(tile),
            ..Overrides::default()
        });
        assert_eq!(both.check(), Err(SettingsError::RegionAndTile));
        let outside = Settings::default().with(&Overrides {
            tile: Some(Tile { index: 4, count: 4 }),
            ..Overrides::default()
        });
        assert_eq!(
            outside.check().unwrap_err().to_string(),
            "tile 4/4 does not exist in a 1280x720 image: expected an index from 0 to 3 and \
             at most as many tiles as pixels"
        );
    }

    #[test]
    fn encodings_parse_from_their_names_only() {
        for e in Encoding::ALL {
            assert_eq!(e.name().parse::<Encoding>(), Ok(e));
        }
        assert_eq!(Settings::default().encoding, Encoding::Linear);
        assert_eq!(
            "sRGB".parse::<Encoding>().unwrap_err().to_string(),
            "unknown encoding \"sRGB\": expected linear or srgb"
        );
    }

    #[test]
    fn presets_parse_from_their_names_only() {
        for p in Preset::ALL {
            assert_eq!(p.name().parse::<Preset>(), Ok(p));
        }
        assert_eq!(
            "best".parse::<Preset>().unwrap_err().to_string(),
            "unknown quality \"best\": expected draft, default, high or reference"
        );
    }
}
