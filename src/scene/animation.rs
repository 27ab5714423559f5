//! Animation as data (SPEC §4, "Encoding and animation"): how many frames, at what
//! rate, and how the camera moves from frame to frame. A scene file says
//!
//! ```toml
//! [animation]
//! frames = 48           # default 1
//! fps = 24              # default 24
//! orbit = 360           # a turntable, or else keys:
//!
//! [[animation.key]]
//! frame = 0
//! look_from = [0, 0, 0] # any of look_from, look_at, up, vfov
//! ```
//!
//! Frame `k` is a still scene whose camera is [`Animation::camera_at`] the scene's
//! camera: nothing else moves, so any frame can be rendered alone, in any order or on
//! any machine, and gives the same bytes as in the whole sequence.

use glam::{DQuat, DVec3};

use crate::camera::{Camera, CameraSpec};

/// How the frames of a scene differ.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// Frame count, at least 1.
    pub frames: u32,
    /// Frames a second, for animated files (GIF, APNG) and the viewer's playback.
    pub fps: f64,
    /// How the camera moves.
    pub motion: Motion,
}

impl Animation {
    /// Frames in an animation without a `frames` key.
    pub const DEFAULT_FRAMES: u32 = 1;
    /// Frames a second without an `fps` key.
    pub const DEFAULT_FPS: f64 = 24.0;
    /// The highest `fps` accepted.
    pub const MAX_FPS: f64 = 1000.0;
}

impl Default for Animation {
    /// One still frame at 24 frames a second.
    fn default() -> Self {
        Animation {
            frames: Self::DEFAULT_FRAMES,
            fps: Self::DEFAULT_FPS,
            motion: Motion::Still,
        }
    }
}

/// The camera's path.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// The camera stands still: every frame is the same image.
    Still,
    /// A turntable: over the whole animation the camera turns this many degrees about
    /// its look-at point, around its `up` (counter-clockwise seen from above).
    Orbit {
        /// Degrees turned over all the frames.
        degrees: f64,
    },
    /// Keyframes in increasing frame order; each value is interpolated linearly
    /// between the keys that give it and held before the first and after the last.
    Keys(Vec<CameraKey>),
}

/// One keyframe: the look-at camera values it sets at its frame. A value no key gives
/// stays the scene camera's (in its look-at form).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraKey {
    /// The frame this key holds at.
    pub frame: u32,
    /// The eye.
    pub look_from: Option<DVec3>,
    /// The point looked at.
    pub look_at: Option<DVec3>,
    /// Which way is up.
    pub up: Option<DVec3>,
    /// Vertical field of view, degrees.
    pub vfov: Option<f64>,
}

impl Animation {
    /// This animation with a command line's (or a program's) options over it:
    /// `frames` sets the frame count, `orbit` makes it a turntable of that many
    /// degrees (in place of any keys).
    pub fn with(mut self, frames: Option<u32>, orbit: Option<f64>) -> Animation {
        if let Some(frames) = frames {
            self.frames = frames;
        }
        if let Some(degrees) = orbit {
            self.motion = Motion::Orbit { degrees };
        }
        self
    }

    /// The camera of frame `k`, from `still`, the camera of the scene without its
    /// animation (at the image's size: [`crate::Scene::camera_spec`]).
    ///
    /// - [`Motion::Still`]: `still` for every frame.
    /// - [`Motion::Orbit`]: frame 0 is `still` exactly; frame `k` turns it by
    ///   `degrees·k/frames` about the axis through its look-at point along its `up`.
    ///   A film-form camera turns rigidly (eye, corner and spans) about the look-at
    ///   point and `up` of its look-at form ([`Camera::to_look_at`]: the film centre,
    ///   the vertical span's direction), so it keeps its exact film at every frame.
    /// - [`Motion::Keys`]: a look-at camera whose values are interpolated between the
    ///   keys; values no key gives come from the look-at form of `still`.
    pub fn camera_at(&self, still: &CameraSpec, k: u32) -> CameraSpec {
        match &self.motion {
            Motion::Still => *still,
            Motion::Orbit { degrees } => {
                let angle = degrees * f64::from(k) / f64::from(self.frames.max(1));
                turned(still, angle)
            }
            Motion::Keys(keys) => {
                let CameraSpec::LookAt {
                    look_from,
                    look_at,
                    up,
                    vfov,
                } = look_at_form(still)
                else {
                    unreachable!("look_at_form gives the look-at form")
                };
                CameraSpec::LookAt {
                    look_from: interpolate(keys, k, |c| c.look_from).unwrap_or(look_from),
                    look_at: interpolate(keys, k, |c| c.look_at).unwrap_or(look_at),
                    up: interpolate(keys, k, |c| c.up).unwrap_or(up),
                    vfov: interpolate(keys, k, |c| c.vfov).unwrap_or(vfov),
                }
            }
        }
    }
}

/// The camera in look-at form: a film-form camera through [`Camera::to_look_at`]
/// (which needs no image size: the film is given).
pub fn look_at_form(spec: &CameraSpec) -> CameraSpec {
    match *spec {
        look @ CameraSpec::LookAt { .. } => look,
        CameraSpec::Frame {
            origin,
            lower_left,
            horizontal,
            vertical,
        } => Camera {
            origin,
            lower_left,
            horizontal,
            vertical,
        }
        .to_look_at(),
    }
}

/// `spec` turned by `degrees` about the vertical axis (its `up`) through its look-at
/// point. Zero degrees gives `spec` itself, bit for bit.
fn turned(spec: &CameraSpec, degrees: f64) -> CameraSpec {
    if degrees == 0.0 {
        return *spec;
    }
    let CameraSpec::LookAt {
        look_at: pivot,
        up: axis,
        ..
    } = look_at_form(spec)
    else {
        unreachable!("look_at_form gives the look-at form")
    };
    let turn = DQuat::from_axis_angle(axis.normalize(), degrees.to_radians());
    let point = |p: DVec3| pivot + turn * (p - pivot);
    match *spec {
        CameraSpec::LookAt {
            look_from,
            look_at,
            up,
            vfov,
        } => CameraSpec::LookAt {
            look_from: point(look_from),
            look_at,
            up,
            vfov,
        },
        CameraSpec::Frame {
            origin,
            lower_left,
            horizontal,
            vertical,
        } => CameraSpec::Frame {
            origin: point(origin),
            lower_left: point(lower_left),
            horizontal: turn * horizontal,
            vertical: turn * vertical,
        },
    }
}

/// The value at frame `k` of the keys that give one (`get`): linear between the two
/// keys around `k`, the first's before it, the last's after it; `None` when no key
/// gives the value.
fn interpolate<T>(keys: &[CameraKey], k: u32, get: impl Fn(&CameraKey) -> Option<T>) -> Option<T>
where
    T: Copy
        + std::ops::Add<Output = T>
        + std::ops::Sub<Output = T>
        + std::ops::Mul<f64, Output = T>,
{
    let mut before: Option<(u32, T)> = None;
    for key in keys {
        let Some(value) = get(key) else { continue };
        if key.frame >= k {
            return Some(match before {
                Some((frame, previous)) if key.frame > k => {
                    let t = f64::from(k - frame) / f64::from(key.frame - frame);
                    previous + (value - previous) * t
                }
                _ => value,
            });
        }
        before = Some((key.frame, value));
    }
    before.map(|(_, value)| value)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(frame: u32, vfov: f64) -> CameraKey {
        CameraKey {
            frame,
            vfov: Some(vfov),
            ..CameraKey::default()
        }
    }

    #[test]
    fn values_are_linear_between_keys_and_held_outside() {
        let keys = [key(2, 10.0), CameraKey::default(), key(6, 30.0)];
        let at = |k| interpolate(&keys, k, |c| c.vfov);
        assert_eq!(
            (0..9).map(at).collect::<Vec<_>>(),
            [10.0, 10.0, 10.0, 15.0, 20.0, 25.0, 30.0, 30.0, 30.0].map(Some)
        );
        assert_eq!(interpolate(&keys, 3, |c| c.look_from), None);
    }

    #[test]
    fn a_quarter_turn_takes_the_eye_from_plus_z_to_plus_x() {
        let still = CameraSpec::LookAt {
            look_from: DVec3::new(0.0, 1.0, 2.0),
            look_at: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::new(0.0, 2.0, 0.0),
            vfov: 40.0,
        };
        let CameraSpec::LookAt { look_from, .. } = turned(&still, 90.0) else {
            panic!("look-at in, look-at out")
        };
        assert!((look_from - DVec3::new(2.0, 1.0, 0.0)).length() < 1e-12);
        assert_eq!(turned(&still, 0.0), still);
    }
}
