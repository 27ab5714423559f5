//! The user's world: spheres, lights, sky, camera and image settings, in `f64` exactly
//! as the scene file gave them. Loading (`load`) validates everything, so the
//! renderers downstream may assume a scene is sane. This module never renders.

mod animation;
mod hw3;
mod load;
mod many;
mod write;

use glam::DVec3;

use crate::camera::{Camera, CameraError, CameraSpec};
use crate::settings::{Overrides, Settings};

pub use animation::{look_at_form, Animation, CameraKey, Motion};
pub use hw3::{hw3_scene, hw3_toml, HW3_DEFAULT_SEED};
pub use many::many_scene;
pub use write::{camera_to_toml, to_toml};

/// A ball of the scene (SPEC §2, "Scene contents").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre `c`.
    pub center: DVec3,
    /// Radius `r > 0`.
    pub radius: f64,
    /// Diffuse colour `kd`.
    pub color: DVec3,
    /// Reflect weight `w_r`.
    pub reflect: f64,
    /// Transmit weight `w_t`.
    pub transmit: f64,
    /// Index of refraction, at least 1.
    pub ior: f64,
}

impl Sphere {
    /// The assignment's index of refraction.
    pub const DEFAULT_IOR: f64 = 2.0;

    /// A white diffuse sphere.
    pub fn new(center: DVec3, radius: f64) -> Self {
        Sphere {
            center,
            radius,
            color: DVec3::ONE,
            reflect: 0.0,
            transmit: 0.0,
            ior: Self::DEFAULT_IOR,
        }
    }
}

/// A point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Position `P`.
    pub position: DVec3,
    /// Intensity `I` (RGB, each at least 0).
    pub intensity: DVec3,
}

impl Default for Light {
    fn default() -> Self {
        Light {
            position: DVec3::new(-10.0, 10.0, 0.0),
            intensity: DVec3::ONE,
        }
    }
}

/// The background: a vertical blend from `down` (d.y = −1) to `up` (d.y = 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    /// The colour straight down (`d.y = −1`).
    pub down: DVec3,
    /// The colour straight up (`d.y = 1`).
    pub up: DVec3,
}

impl Default for Sky {
    fn default() -> Self {
        Sky {
            down: DVec3::ONE,
            up: DVec3::new(0.5, 0.7, 1.0),
        }
    }
}

/// A validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// A short name for titles and file names ("hw3", or the file stem).
    pub name: String,
    /// `None`: the assignment's camera (SPEC §2, "The default is the assignment's").
    pub camera: Option<CameraSpec>,
    /// What the file's `[image]` table sets; [`Scene::settings`] resolves it.
    pub image: Overrides,
    /// The background.
    pub sky: Sky,
    /// Point lights (may be none).
    pub lights: Vec<Light>,
    /// The balls.
    pub spheres: Vec<Sphere>,
    /// `None`: one still frame (the file has no `[animation]` table).
    pub animation: Option<Animation>,
}

impl Scene {
    /// The camera spec that applies at `width`×`height`: the scene's own, or the
    /// assignment's exact frame at 16:9 and its look-at form at any other aspect.
    pub fn camera_spec(&self, width: u32, height: u32) -> CameraSpec {
        match self.camera {
            Some(spec) => spec,
            None if u64::from(width) * 9 == u64::from(height) * 16 => {
                CameraSpec::assignment_frame()
            }
            None => CameraSpec::assignment_look_at(),
        }
    }

    /// Frames of the scene's animation (1 for a still scene).
    pub fn frames(&self) -> u32 {
        self.animation.as_ref().map_or(1, |a| a.frames)
    }

    /// Frames a second of the scene's animation ([`Animation::DEFAULT_FPS`] for a
    /// still scene).
    pub fn fps(&self) -> f64 {
        self.animation
            .as_ref()
            .map_or(Animation::DEFAULT_FPS, |a| a.fps)
    }

    /// The camera spec of frame `k` at `width`×`height`: [`Scene::camera_spec`] moved
    /// by the animation ([`Animation::camera_at`]). Every renderer of a frame (the
    /// command line, the viewer, Python) takes its camera from here.
    pub fn frame_camera_spec(&self, k: u32, width: u32, height: u32) -> CameraSpec {
        let still = self.camera_spec(width, height);
        match &self.animation {
            None => still,
            Some(animation) => animation.camera_at(&still, k),
        }
    }

    /// Frame `k` at `width`×`height` as a still scene: this scene with the camera of
    /// that frame and no animation. Rendered like any scene, it gives the frame's
    /// pixels.
    pub fn frame(&self, k: u32, width: u32, height: u32) -> Scene {
        Scene {
            camera: Some(self.frame_camera_spec(k, width, height)),
            animation: None,
            ..self.clone()
        }
    }

    /// The camera at `width`×`height` ([`Scene::camera_spec`] made concrete).
    pub fn camera(&self, width: u32, height: u32) -> Result<Camera, CameraError> {
        Camera::new(&self.camera_spec(width, height), width, height)
    }

    /// The scene's settings: the SPEC's defaults with the file's `[image]` table over
    /// them. Command-line or Python options go over these with [`Settings::with`].
    pub fn settings(&self) -> Settings {
        Settings::default().with(&self.image)
    }

    /// Parses and validates a scene from TOML text; `path` names it in errors.
    pub fn from_toml_str(text: &str, path: &str) -> Result<Scene, SceneError> {
        load::parse(text, path)
    }

    /// As [`Scene::from_toml_str`], but always parsing the text as one TOML document
    /// (no streaming of `[[sphere]]` tables): for tests that compare the two paths.
    #[doc(hidden)]
    pub fn from_toml_str_whole(text: &str, path: &str) -> Result<Scene, SceneError> {
        load::parse_whole(text, path)
    }

    /// Reads, parses and validates a scene file.
    pub fn load(path: &std::path::Path) -> Result<Scene, SceneError> {
        load::load(path)
    }
}

/// Why a scene could not be loaded: where (file, and line:column when known) and what.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}: {message}", self.location())]
pub struct SceneError {
    /// The file, or the name the text was given.
    pub path: String,
    /// Line of the offending value, from 1 (`None`: the file as a whole).
    pub line: Option<usize>,
    /// Column of the offending value, in characters from 1.
    pub column: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl SceneError {
    /// An error about the file as a whole.
    pub fn whole(path: impl Into<String>, message: impl Into<String>) -> Self {
        SceneError {
            path: path.into(),
            line: None,
            column: None,
            message: message.into(),
        }
    }

    /// `file`, or `file:line:column`.
    pub fn location(&self) -> String {
        match (self.line, self.column) {
            (Some(line), Some(column)) => format!("{}:{line}:{column}", self.path),
            _ => self.path.clone(),
        }
    }
}
