//! Every value of a parsed scene file checked against SPEC §3 and [`crate::limits`],
//! with the position of the offending key: what passes here renders.

use glam::DVec3;
use toml::Spanned;

use super::messages::Locator;
use super::schema::{FileAnimation, FileCamera, FileScene, FileSphere, Num, V3};
use crate::camera::CameraSpec;
use crate::limits;
use crate::scene::{Animation, CameraKey, Light, Motion, Scene, SceneError, Sky, Sphere};
use crate::settings::{
    Encoding, Overrides, Preset, Settings, SettingsError, UnknownEncoding, UnknownPreset,
};

/// Everything but the spheres, validated.
pub(super) fn settings(at: &Locator, file: &FileScene) -> Result<Scene, SceneError> {
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
        if let Some(name) = &img.encoding {
            let encoding: Encoding = name
                .get_ref()
                .parse()
                .map_err(|e: UnknownEncoding| at.at(name.span(), format!("image.encoding: {e}")))?;
            image.encoding = Some(encoding);
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
        Settings::default().with(&image).check().map_err(|e| {
            let message = match e {
                // A scene file describes a whole image, which must fit in one render.
                SettingsError::TooManyPixels { width, height } => format!(
                    "image size {width}x{height} is too large: at most {} pixels",
                    limits::MAX_PIXELS
                ),
                e => e.to_string(),
            };
            at.at(spanned.span(), message)
        })?;
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

    let animation = match &file.animation {
        None => None,
        Some(a) => Some(animation(at, a, camera)?),
    };

    Ok(Scene {
        name: "scene".into(),
        camera,
        image,
        sky,
        lights,
        spheres: Vec::new(),
        animation,
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
pub(super) fn sphere(at: &Locator, s: &FileSphere, k: usize) -> Result<Sphere, SceneError> {
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

/// The `[animation]` table, with every frame's camera checked (`camera`: the scene's).
fn animation(
    at: &Locator,
    a: &Spanned<FileAnimation>,
    camera: Option<CameraSpec>,
) -> Result<Animation, SceneError> {
    let file = a.get_ref();
    let mut animation = Animation::default();
    if let Some(v) = &file.frames {
        let n = *v.get_ref();
        let max = i64::from(limits::MAX_FRAMES);
        if !(1..=max).contains(&n) {
            return Err(at.at(
                v.span(),
                format!("animation.frames = {n} is out of range: expected 1 to {max}"),
            ));
        }
        animation.frames = n as u32;
    }
    if let Some(v) = &file.fps {
        let fps = number(at, v, &"animation.fps")?;
        if !(fps > 0.0 && fps <= Animation::MAX_FPS) {
            return Err(at.at(
                v.span(),
                format!(
                    "animation.fps = {fps} is out of range: expected more than 0, at most {}",
                    Animation::MAX_FPS
                ),
            ));
        }
        animation.fps = fps;
    }
    match (&file.orbit, &file.key) {
        (Some(orbit), Some(_)) => {
            return Err(at.at(
                orbit.span(),
                "animation: give either orbit or [[animation.key]] tables, not both",
            ));
        }
        (Some(orbit), None) => {
            animation.motion = Motion::Orbit {
                degrees: number(at, orbit, &"animation.orbit")?,
            };
        }
        (None, Some(keys)) => {
            let mut list: Vec<CameraKey> = Vec::with_capacity(keys.len());
            for (k, spanned) in keys.iter().enumerate() {
                let key = spanned.get_ref();
                let what = |name: &str| format!("animation key {}: {name}", k + 1);
                let frame = *key.frame.get_ref();
                let max = i64::from(limits::MAX_FRAMES);
                if !(0..max).contains(&frame) {
                    return Err(at.at(
                        key.frame.span(),
                        format!(
                            "{} = {frame} is out of range: expected 0 to {}",
                            what("frame"),
                            max - 1
                        ),
                    ));
                }
                let frame = frame as u32;
                if let Some(previous) = list.last().filter(|p| p.frame >= frame) {
                    return Err(at.at(
                        key.frame.span(),
                        format!(
                            "{} = {frame} is not after the previous key's frame {}: keys go in increasing frame order",
                            what("frame"),
                            previous.frame
                        ),
                    ));
                }
                let v3 = |v: &Option<V3>, name: &str| match v {
                    None => Ok(None),
                    Some(v) => finite(at, v, &what(name)).map(Some),
                };
                list.push(CameraKey {
                    frame,
                    look_from: v3(&key.look_from, "look_from")?,
                    look_at: v3(&key.look_at, "look_at")?,
                    up: v3(&key.up, "up")?,
                    vfov: match &key.vfov {
                        None => None,
                        Some(v) => Some(number(at, v, &what("vfov"))?),
                    },
                });
            }
            // No keys (`key = []`) is no motion.
            if !list.is_empty() {
                animation.motion = Motion::Keys(list);
            }
        }
        (None, None) => {}
    }
    // Every frame's camera up to the last key (after it the camera holds): keys may
    // meet in a degenerate camera (the eye on the look-at point) between two good
    // ones. A turntable turns a good camera rigidly, which keeps it good.
    let still = camera.unwrap_or_else(CameraSpec::assignment_look_at);
    let last = match &animation.motion {
        Motion::Keys(keys) => keys.last().map_or(0, |key| key.frame),
        _ => 0,
    };
    for k in 0..=last {
        animation
            .camera_at(&still, k)
            .check()
            .map_err(|e| at.at(a.span(), format!("animation: frame {k}: camera: {e}")))?;
    }
    Ok(animation)
}
