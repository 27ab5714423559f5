//! Scene files (TOML, SPEC §4): parsing with `serde` + `toml`, then validation of every
//! value with the line and column of the offending key. Nothing here panics on input.

use std::ops::Range;
use std::path::Path;

use glam::DVec3;
use serde::Deserialize;
use toml::Spanned;

use super::{limits, CameraSpec, ImageSettings, Light, Scene, SceneError, Sky, Sphere};

type V3 = Spanned<[f64; 3]>;
type Num = Spanned<f64>;
type Int = Spanned<i64>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileScene {
    camera: Option<Spanned<FileCamera>>,
    image: Option<FileImage>,
    sky: Option<FileSky>,
    light: Option<Vec<FileLight>>,
    sphere: Option<Vec<FileSphere>>,
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
}

impl Locator<'_> {
    fn at(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        let offset = span.start.min(self.text.len());
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

pub(super) fn parse(text: &str, path: &str) -> Result<Scene, SceneError> {
    let at = Locator { text, path };
    let file: FileScene = toml::from_str(text).map_err(|e| {
        let message = e.message().trim().replace('\n', " ");
        match e.span() {
            Some(span) => at.at(span, message),
            None => at.whole(message),
        }
    })?;

    let camera = match &file.camera {
        None => None,
        Some(c) => Some(camera(&at, c)?),
    };

    let mut image = ImageSettings::default();
    if let Some(img) = &file.image {
        // A quality preset first: the file's own spp and max_depth override its values.
        if let Some(q) = &img.quality {
            let preset: crate::quality::Preset = q
                .get_ref()
                .parse()
                .map_err(|m: String| at.at(q.span(), format!("image.quality: {m}")))?;
            image.spp = preset.quality().spp;
            image.max_depth = preset.quality().max_depth;
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
                *slot = n as u32;
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
            image.seed = n as u64;
        }
        image.check().map_err(|m| at.whole(m))?;
    }

    let mut sky = Sky::default();
    if let Some(s) = &file.sky {
        if let Some(v) = &s.down {
            sky.down = colour(&at, v, "sky.down")?;
        }
        if let Some(v) = &s.up {
            sky.up = colour(&at, v, "sky.up")?;
        }
    }

    let lights = match &file.light {
        None => vec![Light::default()],
        Some(list) => {
            if list.len() > limits::MAX_LIGHTS {
                return Err(at.whole(format!(
                    "{} lights, more than the limit of {}",
                    list.len(),
                    limits::MAX_LIGHTS
                )));
            }
            let mut out = Vec::with_capacity(list.len());
            for (k, l) in list.iter().enumerate() {
                let mut light = Light::default();
                if let Some(v) = &l.position {
                    light.position = finite(&at, v, &format!("light {}: position", k + 1))?;
                }
                if let Some(v) = &l.intensity {
                    light.intensity = finite(&at, v, &format!("light {}: intensity", k + 1))?;
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

    let file_spheres = file.sphere.unwrap_or_default();
    if file_spheres.len() > limits::MAX_SPHERES {
        return Err(at.whole(format!(
            "{} spheres, more than the limit of {}",
            file_spheres.len(),
            limits::MAX_SPHERES
        )));
    }
    let mut spheres = Vec::with_capacity(file_spheres.len());
    for (k, s) in file_spheres.iter().enumerate() {
        let who = format!("sphere {}", k + 1);
        let center = finite(&at, &s.center, &format!("{who}: center"))?;
        let radius = number(&at, &s.radius, &format!("{who}: radius"))?;
        if radius <= 0.0 {
            return Err(at.at(
                s.radius.span(),
                format!("{who}: radius must be > 0, got {radius}"),
            ));
        }
        let mut sphere = Sphere::new(center, radius);
        if let Some(v) = &s.color {
            sphere.color = colour(&at, v, &format!("{who}: color"))?;
        }
        if let Some(v) = &s.reflect {
            sphere.reflect = weight(&at, v, &format!("{who}: reflect"))?;
        }
        if let Some(v) = &s.transmit {
            sphere.transmit = weight(&at, v, &format!("{who}: transmit"))?;
        }
        if let Some(v) = &s.ior {
            sphere.ior = number(&at, v, &format!("{who}: ior"))?;
            if sphere.ior < 1.0 {
                return Err(at.at(
                    v.span(),
                    format!("{who}: ior must be >= 1, got {}", sphere.ior),
                ));
            }
        }
        spheres.push(sphere);
    }

    Ok(Scene {
        name: "scene".into(),
        camera,
        image,
        sky,
        lights,
        spheres,
    })
}

fn number(at: &Locator, v: &Num, what: &str) -> Result<f64, SceneError> {
    let x = *v.get_ref();
    if x.is_finite() {
        Ok(x)
    } else {
        Err(at.at(v.span(), format!("{what} must be a finite number, got {x}")))
    }
}

fn finite(at: &Locator, v: &V3, what: &str) -> Result<DVec3, SceneError> {
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

fn colour(at: &Locator, v: &V3, what: &str) -> Result<DVec3, SceneError> {
    let c = finite(at, v, what)?;
    if c.min_element() < 0.0 || c.max_element() > 1.0 {
        return Err(at.at(
            v.span(),
            format!("{what} must lie in [0, 1], got {:?}", c.to_array()),
        ));
    }
    Ok(c)
}

fn weight(at: &Locator, v: &Num, what: &str) -> Result<f64, SceneError> {
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
                Some(v) => number(at, v, "camera.vfov")?,
            },
        }
    };
    crate::camera::check_spec(&spec).map_err(|m| at.at(c.span(), format!("camera: {m}")))?;
    Ok(spec)
}
