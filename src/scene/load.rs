//! Scene files (TOML, SPEC §4): parsing with `serde` + `toml`, then validation of every
//! value with the line and column of the offending key. Nothing here panics on input.
//!
//! Memory: `toml` builds a tree of the whole document before `serde` sees it, about 35
//! to 65 times the size of the text (measured: 483 MB for the 13.5 MB many_100000
//! scene, 2.3 GB for a million minimal spheres). So the common layout of big scenes,
//! the settings first and then a run of `[[sphere]]` tables to the end of the file, is
//! parsed in batches of tables, in parallel ([`SphereRun`]; many_100000: 24 MB peak,
//! 0.46 s instead of 0.9 s), and every other layout only up to
//! [`limits::MAX_WHOLE_PARSE_BYTES`]. The sphere count is known from a scan of the
//! lines before anything is parsed, so a file with too many spheres is refused first.

use std::ops::Range;
use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;
use serde::Deserialize;
use toml::Spanned;

use super::{Light, Scene, SceneError, Sky, Sphere};
use crate::camera::CameraSpec;
use crate::limits;
use crate::settings::{Overrides, Preset, Settings, UnknownPreset};

type V3 = Spanned<[f64; 3]>;
type Num = Spanned<f64>;
type Int = Spanned<i64>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileScene {
    camera: Option<Spanned<FileCamera>>,
    image: Option<Spanned<FileImage>>,
    sky: Option<FileSky>,
    light: Option<Bounded<FileLight, LightLimit>>,
    sphere: Option<Bounded<FileSphere, SphereLimit>>,
}

/// A batch of `[[sphere]]` tables of a run (see [`SphereRun`]) parsed on its own.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSphereTable {
    sphere: Vec<FileSphere>,
}

/// A cap on the length of an array in the file.
trait Limit {
    const MAX: usize;
    const WHAT: &'static str;
}

struct SphereLimit;
impl Limit for SphereLimit {
    const MAX: usize = limits::MAX_SPHERES;
    const WHAT: &'static str = "spheres";
}

struct LightLimit;
impl Limit for LightLimit {
    const MAX: usize = limits::MAX_LIGHTS;
    const WHAT: &'static str = "lights";
}

/// An array that refuses its element number `L::MAX + 1` as soon as it is seen, rather
/// than after all of them have been collected.
struct Bounded<T, L>(Vec<T>, std::marker::PhantomData<L>);

impl<'de, T: Deserialize<'de>, L: Limit> Deserialize<'de> for Bounded<T, L> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit<T, L>(std::marker::PhantomData<(T, L)>);
        impl<'de, T: Deserialize<'de>, L: Limit> serde::de::Visitor<'de> for Visit<T, L> {
            type Value = Bounded<T, L>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "an array of at most {} {}", L::MAX, L::WHAT)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Self::Value, A::Error> {
                let mut items = Vec::new();
                while let Some(item) = seq.next_element()? {
                    if items.len() == L::MAX {
                        return Err(serde::de::Error::custom(format!(
                            "more than {} {}: the limit is {}",
                            L::MAX,
                            L::WHAT,
                            L::MAX
                        )));
                    }
                    items.push(item);
                }
                Ok(Bounded(items, std::marker::PhantomData))
            }
        }
        d.deserialize_seq(Visit(std::marker::PhantomData))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileCamera {
    look_from: Option<V3>,
    look_at: Option<V3>,
    up: Option<V3>,
    vfov: Option<Num>,
    origin: Option<V3>,
    lower_left: Option<V3>,
    horizontal: Option<V3>,
    vertical: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileImage {
    width: Option<Int>,
    height: Option<Int>,
    max_depth: Option<Int>,
    spp: Option<Int>,
    seed: Option<Int>,
    quality: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSky {
    down: Option<V3>,
    up: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileLight {
    position: Option<V3>,
    intensity: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSphere {
    center: V3,
    radius: Num,
    color: Option<V3>,
    reflect: Option<Num>,
    transmit: Option<Num>,
    ior: Option<Num>,
}

pub(super) fn load(path: &Path) -> Result<Scene, SceneError> {
    let shown = path.display().to_string();
    let io_error = |e: std::io::Error| SceneError {
        location: shown.clone(),
        message: format!("cannot read scene file: {e}"),
    };
    let size = std::fs::metadata(path).map_err(io_error)?.len();
    if size > limits::MAX_FILE_BYTES {
        return Err(SceneError {
            location: shown,
            message: format!(
                "scene file is {size} bytes, more than the limit of {}",
                limits::MAX_FILE_BYTES
            ),
        });
    }
    let bytes = std::fs::read(path).map_err(io_error)?;
    let text = String::from_utf8(bytes).map_err(|e| SceneError {
        location: shown.clone(),
        message: format!(
            "scene file is not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ),
    })?;
    let mut scene = parse(&text, &shown)?;
    scene.name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    Ok(scene)
}

/// Turns byte offsets into `path:line:column` messages.
struct Locator<'a> {
    text: &'a str,
    path: &'a str,
    /// Where the text that was parsed (and that spans count in) starts in `text`.
    offset: usize,
}

impl Locator<'_> {
    fn at(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        let offset = span.start.saturating_add(self.offset).min(self.text.len());
        let before = &self.text[..self.text.floor_char_boundary_compat(offset)];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        SceneError {
            location: format!("{}:{line}:{column}", self.path),
            message: message.into(),
        }
    }

    fn whole(&self, message: impl Into<String>) -> SceneError {
        SceneError {
            location: self.path.to_string(),
            message: message.into(),
        }
    }
}

trait FloorCharBoundary {
    fn floor_char_boundary_compat(&self, i: usize) -> usize;
}

impl FloorCharBoundary for str {
    fn floor_char_boundary_compat(&self, mut i: usize) -> usize {
        while !self.is_char_boundary(i) {
            i -= 1;
        }
        i
    }
}

/// Parses and validates scene text, streaming a trailing run of `[[sphere]]` tables.
pub(super) fn parse(text: &str, path: &str) -> Result<Scene, SceneError> {
    let at = Locator {
        text,
        path,
        offset: 0,
    };
    if text.len() as u64 > limits::MAX_FILE_BYTES {
        return Err(at.whole(format!(
            "scene text is {} bytes, more than the limit of {}",
            text.len(),
            limits::MAX_FILE_BYTES
        )));
    }
    match SphereRun::find(text).map_err(|(offset, m)| at.at(offset..offset, m))? {
        Some(run) => parse_with_run(text, path, &run),
        None => parse_whole(text, path),
    }
}

/// Parses and validates scene text as one TOML document (no streaming).
pub(super) fn parse_whole(text: &str, path: &str) -> Result<Scene, SceneError> {
    let at = Locator {
        text,
        path,
        offset: 0,
    };
    if text.len() as u64 > limits::MAX_WHOLE_PARSE_BYTES {
        return Err(at.whole(format!(
            "scene text is {} bytes: files over {} bytes must put their spheres last, as \
             [[sphere]] tables with no other table after them",
            text.len(),
            limits::MAX_WHOLE_PARSE_BYTES
        )));
    }
    let file: FileScene = from_toml(text, &at)?;
    let mut scene = settings(&at, &file)?;
    let list = file.sphere.map(|b| b.0).unwrap_or_default();
    scene.spheres.reserve_exact(list.len());
    for (k, s) in list.iter().enumerate() {
        scene.spheres.push(sphere(&at, s, k)?);
    }
    Ok(scene)
}

fn from_toml<T: serde::de::DeserializeOwned>(text: &str, at: &Locator) -> Result<T, SceneError> {
    toml::from_str(text).map_err(|e| {
        let message = e.message().trim().replace('\n', " ");
        match (e.span(), plain_type_error(&message)) {
            // A value of the wrong type or length: named by its field, as the
            // validation messages name theirs.
            (Some(span), Some(plain)) => {
                let message = match field_at(at.text, span.start.saturating_add(at.offset)) {
                    Some(field) => format!("{field}: {plain}"),
                    None => plain,
                };
                at.at(span, message)
            }
            (Some(span), None) => at.at(span, message),
            (None, plain) => at.whole(plain.unwrap_or(message)),
        }
    })
}

/// serde's wording of a wrong type or length in the words of a scene file: "invalid
/// type: string \"big\", expected f64" becomes "expected a number, got the string
/// \"big\"". `None` for other messages.
fn plain_type_error(message: &str) -> Option<String> {
    let (got, expected) = if let Some(rest) = message.strip_prefix("invalid type: ") {
        // The last ", expected ": a string value may hold those words itself.
        let (got, expected) = rest.rsplit_once(", expected ")?;
        let got = if let Some(text) = got.strip_prefix("string ") {
            format!("the string {text}")
        } else if let Some((_, value)) = got.split_once(" `") {
            value.trim_end_matches('`').to_string() // integer `3`, boolean `true`
        } else {
            match got {
                "sequence" => "an array".into(),
                "map" => "a table".into(),
                other => other.into(),
            }
        };
        (got, expected)
    } else if let Some(rest) = message.strip_prefix("invalid length ") {
        let (n, expected) = rest.rsplit_once(", expected ")?;
        (format!("{n} values"), expected)
    } else {
        return None;
    };
    let expected = match expected {
        "f64" | "f32" => "a number",
        "i64" | "u64" | "i32" | "u32" => "a whole number",
        "an array of length 3" => "an array of 3 numbers",
        // The loader's own types ("struct FileImage") are tables in the file.
        other if other.starts_with("struct ") => "a table",
        other => other,
    };
    Some(format!("expected {expected}, got {got}"))
}

/// The field whose value starts at byte `offset` of the scene text, named as the
/// validation messages name fields ("sphere 2: radius", "image.width"): the key of the
/// line (when the value follows its `=`) under the table header above it. `None`
/// where that is not plain (an inline table, say): better no name than a wrong one.
fn field_at(text: &str, offset: usize) -> Option<String> {
    let offset = text.floor_char_boundary_compat(offset.min(text.len()));
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let (key, value) = text[line_start..offset].split_once('=')?;
    let key = key.trim();
    let bare = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    if key.is_empty() || !key.chars().all(bare) || !value.trim().is_empty() {
        return None;
    }
    let before = &text[..line_start];
    // A header's table name: `[image]` → ("image", false), `[[sphere]]` → ("sphere", true).
    let header = |line: &str| -> Option<(String, bool)> {
        let line = line.trim();
        let array = line.starts_with("[[");
        let name = line.trim_start_matches('[').split(']').next()?.trim();
        line.starts_with('[').then(|| (name.to_string(), array))
    };
    Some(match before.lines().rev().find_map(header) {
        None => key.to_string(),
        Some((table, true)) => {
            let index = before
                .lines()
                .filter_map(header)
                .filter(|(name, array)| *array && *name == table)
                .count();
            format!("{table} {index}: {key}")
        }
        Some((table, false)) => format!("{table}.{key}"),
    })
}

/// Where a file's trailing run of `[[sphere]]` tables starts, and how many there are.
struct SphereRun {
    /// Byte offsets of the `[[sphere]]` header lines.
    first: usize,
    count: usize,
}

impl SphereRun {
    /// Scans the lines (no allocation). `Err` when there are more `[[sphere]]` headers
    /// than [`limits::MAX_SPHERES`]; `None` when the spheres are not one trailing run of
    /// plain `[[sphere]]` tables, or when multi-line strings could hide header lines:
    /// then the file is parsed whole.
    fn find(text: &str) -> Result<Option<SphereRun>, (usize, String)> {
        let mut first = None;
        let mut count = 0usize;
        let mut other_table_after = false;
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            let start = offset;
            offset += line.len();
            let trimmed = line.trim_start();
            if !trimmed.starts_with('[') {
                continue;
            }
            if is_sphere_header(trimmed) {
                count += 1;
                if count > limits::MAX_SPHERES {
                    return Err((
                        start,
                        format!(
                            "more than {} [[sphere]] tables: the limit is {}",
                            limits::MAX_SPHERES,
                            limits::MAX_SPHERES
                        ),
                    ));
                }
                first.get_or_insert(start);
            } else if first.is_some() {
                other_table_after = true;
            }
        }
        let multi_line_strings = text.contains("\"\"\"") || text.contains("'''");
        Ok(match first {
            Some(first) if !other_table_after && !multi_line_strings => {
                Some(SphereRun { first, count })
            }
            _ => None,
        })
    }

    /// The byte ranges of the tables of the run, in order.
    fn tables<'t>(&self, text: &'t str) -> impl Iterator<Item = Range<usize>> + 't {
        let mut starts = text[self.first..]
            .split_inclusive('\n')
            .scan(self.first, |offset, line| {
                let start = *offset;
                *offset += line.len();
                Some((start, line))
            })
            .filter(|(_, line)| is_sphere_header(line.trim_start()))
            .map(|(start, _)| start)
            .peekable();
        std::iter::from_fn(move || {
            let start = starts.next()?;
            let end = starts.peek().copied().unwrap_or(text.len());
            Some(start..end)
        })
    }
}

/// `[[sphere]]`, spaces allowed inside the brackets, then nothing or a comment.
fn is_sphere_header(line: &str) -> bool {
    let Some(rest) = line.strip_prefix("[[") else {
        return false;
    };
    let Some(rest) = rest.trim_start_matches([' ', '\t']).strip_prefix("sphere") else {
        return false;
    };
    let Some(rest) = rest.trim_start_matches([' ', '\t']).strip_prefix("]]") else {
        return false;
    };
    let rest = rest.trim();
    rest.is_empty() || rest.starts_with('#')
}

/// The settings before the run as one document, then each sphere table on its own.
fn parse_with_run(text: &str, path: &str, run: &SphereRun) -> Result<Scene, SceneError> {
    let at = Locator {
        text,
        path,
        offset: 0,
    };
    let head = &text[..run.first];
    let file: FileScene = from_toml(head, &at)?;
    if file.sphere.is_some() {
        return Err(at.at(
            run.first..run.first,
            "[[sphere]] tables cannot follow a `sphere` array defined above",
        ));
    }
    let mut scene = settings(&at, &file)?;
    // Batches of consecutive tables, parsed in parallel: each batch's `toml` tree is
    // small, and the batches come back in order, so the first error is the first in
    // the file.
    let mut batches: Vec<(usize, Range<usize>)> = Vec::new();
    for (k, range) in run.tables(text).enumerate() {
        match batches.last_mut() {
            Some((first, batch)) if k - *first < TABLES_PER_BATCH => batch.end = range.end,
            _ => batches.push((k, range)),
        }
    }
    let parsed: Vec<Result<Vec<Sphere>, SceneError>> = batches
        .par_iter()
        .map(|(first, range)| {
            let batch_at = Locator {
                text,
                path,
                offset: range.start,
            };
            let tables: FileSphereTable = from_toml(&text[range.clone()], &batch_at)?;
            tables
                .sphere
                .iter()
                .enumerate()
                .map(|(i, s)| sphere(&batch_at, s, first + i))
                .collect()
        })
        .collect();
    scene.spheres.reserve_exact(run.count);
    for batch in parsed {
        scene.spheres.extend(batch?);
    }
    if scene.spheres.len() != run.count {
        // Cannot happen: each batch holds exactly its header lines' tables.
        return Err(at.whole(format!(
            "found {} spheres for {} [[sphere]] headers",
            scene.spheres.len(),
            run.count
        )));
    }
    Ok(scene)
}

/// `[[sphere]]` tables parsed as one `toml` document when streaming (about 2 MB of tree).
const TABLES_PER_BATCH: usize = 512;

/// Everything but the spheres, validated.
fn settings(at: &Locator, file: &FileScene) -> Result<Scene, SceneError> {
    let camera = match &file.camera {
        None => None,
        Some(c) => Some(camera(at, c)?),
    };

    let mut image = Overrides::default();
    if let Some(spanned) = &file.image {
        let img = spanned.get_ref();
        if let Some(q) = &img.quality {
            let preset: Preset = q
                .get_ref()
                .parse()
                .map_err(|e: UnknownPreset| at.at(q.span(), format!("image.quality: {e}")))?;
            image.quality = Some(preset);
        }
        let dims = [
            (
                &img.width,
                &mut image.width,
                "width",
                1,
                i64::from(limits::MAX_SIDE),
            ),
            (
                &img.height,
                &mut image.height,
                "height",
                1,
                i64::from(limits::MAX_SIDE),
            ),
            (
                &img.max_depth,
                &mut image.max_depth,
                "max_depth",
                0,
                i64::from(limits::MAX_DEPTH),
            ),
            (
                &img.spp,
                &mut image.spp,
                "spp",
                1,
                i64::from(limits::MAX_SPP),
            ),
        ];
        for (value, slot, key, lo, hi) in dims {
            if let Some(v) = value {
                let n = *v.get_ref();
                if n < lo || n > hi {
                    return Err(at.at(
                        v.span(),
                        format!("image.{key} = {n} is out of range: expected {lo} to {hi}"),
                    ));
                }
                *slot = Some(n as u32);
            }
        }
        if let Some(seed) = &img.seed {
            let n = *seed.get_ref();
            if n < 0 {
                return Err(at.at(
                    seed.span(),
                    format!("image.seed = {n} must not be negative"),
                ));
            }
            image.seed = Some(n as u64);
        }
        Settings::default()
            .with(&image)
            .check()
            .map_err(|e| at.at(spanned.span(), e.to_string()))?;
    }

    let mut sky = Sky::default();
    if let Some(s) = &file.sky {
        if let Some(v) = &s.down {
            sky.down = colour(at, v, &"sky.down")?;
        }
        if let Some(v) = &s.up {
            sky.up = colour(at, v, &"sky.up")?;
        }
    }

    let lights = match &file.light {
        None => vec![Light::default()],
        Some(list) => {
            let list = &list.0;
            let mut out = Vec::with_capacity(list.len());
            for (k, l) in list.iter().enumerate() {
                let mut light = Light::default();
                if let Some(v) = &l.position {
                    light.position = finite(
                        at,
                        v,
                        &Field {
                            table: "light",
                            index: k,
                            key: "position",
                        },
                    )?;
                }
                if let Some(v) = &l.intensity {
                    light.intensity = finite(
                        at,
                        v,
                        &Field {
                            table: "light",
                            index: k,
                            key: "intensity",
                        },
                    )?;
                    if light.intensity.min_element() < 0.0 {
                        return Err(
                            at.at(v.span(), format!("light {}: intensity must be >= 0", k + 1))
                        );
                    }
                }
                out.push(light);
            }
            out
        }
    };

    Ok(Scene {
        name: "scene".into(),
        camera,
        image,
        sky,
        lights,
        spheres: Vec::new(),
    })
}

/// Names a value in messages ("sphere 3: radius"), formatted only when an error needs it.
struct Field<'a> {
    table: &'a str,
    /// Number of the table in its array, from 0.
    index: usize,
    key: &'a str,
}

impl std::fmt::Display for Field<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}: {}", self.table, self.index + 1, self.key)
    }
}

/// Sphere number `k` (from 0), validated.
fn sphere(at: &Locator, s: &FileSphere, k: usize) -> Result<Sphere, SceneError> {
    let field = |key| Field {
        table: "sphere",
        index: k,
        key,
    };
    let center = finite(at, &s.center, &field("center"))?;
    let radius = number(at, &s.radius, &field("radius"))?;
    if radius <= 0.0 {
        return Err(at.at(
            s.radius.span(),
            format!("sphere {}: radius must be > 0, got {radius}", k + 1),
        ));
    }
    let mut sphere = Sphere::new(center, radius);
    if let Some(v) = &s.color {
        sphere.color = colour(at, v, &field("color"))?;
    }
    if let Some(v) = &s.reflect {
        sphere.reflect = weight(at, v, &field("reflect"))?;
    }
    if let Some(v) = &s.transmit {
        sphere.transmit = weight(at, v, &field("transmit"))?;
    }
    if let Some(v) = &s.ior {
        sphere.ior = number(at, v, &field("ior"))?;
        if sphere.ior < 1.0 {
            return Err(at.at(
                v.span(),
                format!("sphere {}: ior must be >= 1, got {}", k + 1, sphere.ior),
            ));
        }
    }
    Ok(sphere)
}

fn number(at: &Locator, v: &Num, what: &dyn std::fmt::Display) -> Result<f64, SceneError> {
    let x = *v.get_ref();
    if x.is_finite() {
        Ok(x)
    } else {
        Err(at.at(v.span(), format!("{what} must be a finite number, got {x}")))
    }
}

fn finite(at: &Locator, v: &V3, what: &dyn std::fmt::Display) -> Result<DVec3, SceneError> {
    let a = *v.get_ref();
    if a.iter().all(|x| x.is_finite()) {
        Ok(DVec3::from_array(a))
    } else {
        Err(at.at(
            v.span(),
            format!("{what} must be finite numbers, got {a:?}"),
        ))
    }
}

fn colour(at: &Locator, v: &V3, what: &dyn std::fmt::Display) -> Result<DVec3, SceneError> {
    let c = finite(at, v, what)?;
    if c.min_element() < 0.0 || c.max_element() > 1.0 {
        return Err(at.at(
            v.span(),
            format!("{what} must lie in [0, 1], got {:?}", c.to_array()),
        ));
    }
    Ok(c)
}

fn weight(at: &Locator, v: &Num, what: &dyn std::fmt::Display) -> Result<f64, SceneError> {
    let w = number(at, v, what)?;
    if !(0.0..=1.0).contains(&w) {
        return Err(at.at(v.span(), format!("{what} must lie in [0, 1], got {w}")));
    }
    Ok(w)
}

fn camera(at: &Locator, c: &Spanned<FileCamera>) -> Result<CameraSpec, SceneError> {
    let cam = c.get_ref();
    let look = [&cam.look_from, &cam.look_at, &cam.up];
    let frame = [&cam.origin, &cam.lower_left, &cam.horizontal, &cam.vertical];
    let any_look = look.iter().any(|v| v.is_some()) || cam.vfov.is_some();
    let any_frame = frame.iter().any(|v| v.is_some());
    let v3 = |v: &Option<V3>, default: DVec3, key: &str| match v {
        None => Ok(default),
        Some(v) => finite(at, v, &format!("camera.{key}")),
    };
    let spec = if any_frame {
        if any_look {
            return Err(at.at(
                c.span(),
                "camera: give either look_from/look_at/up/vfov or origin/lower_left/horizontal/vertical, not both",
            ));
        }
        let CameraSpec::Frame {
            origin,
            lower_left,
            horizontal,
            vertical,
        } = CameraSpec::assignment_frame()
        else {
            unreachable!("the assignment frame is a frame")
        };
        CameraSpec::Frame {
            origin: v3(&cam.origin, origin, "origin")?,
            lower_left: v3(&cam.lower_left, lower_left, "lower_left")?,
            horizontal: v3(&cam.horizontal, horizontal, "horizontal")?,
            vertical: v3(&cam.vertical, vertical, "vertical")?,
        }
    } else {
        let CameraSpec::LookAt {
            look_from,
            look_at,
            up,
            vfov,
        } = CameraSpec::assignment_look_at()
        else {
            unreachable!("the assignment look-at is a look-at")
        };
        CameraSpec::LookAt {
            look_from: v3(&cam.look_from, look_from, "look_from")?,
            look_at: v3(&cam.look_at, look_at, "look_at")?,
            up: v3(&cam.up, up, "up")?,
            vfov: match &cam.vfov {
                None => vfov,
                Some(v) => number(at, v, &"camera.vfov")?,
            },
        }
    };
    spec.check()
        .map_err(|e| at.at(c.span(), format!("camera: {e}")))?;
    Ok(spec)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_errors_read_in_the_words_of_a_scene_file() {
        for (serde, plain) in [
            (
                "invalid type: string \"big\", expected f64",
                "expected a number, got the string \"big\"",
            ),
            (
                "invalid type: floating point `1.5`, expected i64",
                "expected a whole number, got 1.5",
            ),
            (
                "invalid type: boolean `true`, expected f64",
                "expected a number, got true",
            ),
            (
                "invalid type: sequence, expected f64",
                "expected a number, got an array",
            ),
            (
                "invalid length 2, expected an array of length 3",
                "expected an array of 3 numbers, got 2 values",
            ),
            (
                // A string that holds the words of the message itself.
                "invalid type: string \"a, expected b\", expected f64",
                "expected a number, got the string \"a, expected b\"",
            ),
            (
                "invalid type: integer `3`, expected struct FileImage",
                "expected a table, got 3",
            ),
        ] {
            assert_eq!(plain_type_error(serde).as_deref(), Some(plain));
        }
        assert_eq!(plain_type_error("unknown field `shine`"), None);
    }

    #[test]
    fn fields_are_named_by_their_table_and_key() {
        let text =
            "seed = 1\n[image]\nwidth = x\n[[sphere]]\nradius = 1\n\n[[sphere]]\n  radius = y\n";
        let at = |needle: &str| field_at(text, text.find(needle).unwrap());
        assert_eq!(at("1\n[image]").as_deref(), Some("seed"));
        assert_eq!(at("x").as_deref(), Some("image.width"));
        assert_eq!(at("1\n\n").as_deref(), Some("sphere 1: radius"));
        assert_eq!(at("y").as_deref(), Some("sphere 2: radius"));
        // On a header or a key itself there is no value to name.
        assert_eq!(at("[image]"), None);
        assert_eq!(at("width"), None);
        // An inline table is not named rather than misnamed; another array of
        // tables whose name contains this one's is not counted.
        let inline = "sphere = [{ center = [0, 0, -1], radius = \"big\" }]\n";
        assert_eq!(field_at(inline, inline.find("\"big").unwrap()), None);
        let text = "[[spotlight]]\nx = 1\n[[light]]\nintensity = z\n";
        assert_eq!(
            field_at(text, text.find('z').unwrap()).as_deref(),
            Some("light 1: intensity")
        );
        // Offsets past the end or inside a character do not panic.
        assert_eq!(field_at("é = ", 1), None);
        assert_eq!(field_at("a = ", 99).as_deref(), Some("a"));
    }
}
