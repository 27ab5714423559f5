//! The user's world: spheres, lights, sky, camera and image settings, in `f64` exactly
//! as the scene file gave them. Loading ([`load`]) validates everything, so the
//! renderers downstream may assume a scene is sane. This module never renders.

mod hw3;
mod load;
mod many;
mod write;

use glam::DVec3;

pub use hw3::{hw3_scene, hw3_toml, HW3_DEFAULT_SEED};
pub use many::many_scene;
pub use write::to_toml;

/// The assignment's vertical field of view, `2·atan(2.25)` in degrees (≈ 132.075°):
/// at 16:9 it gives the spans `H = (8,0,0)`, `V = (0,4.5,0)`.
pub fn assignment_vfov_degrees() -> f64 {
    2.0 * 2.25f64.atan().to_degrees()
}

/// Upper bounds checked before anything is allocated for a render.
pub mod limits {
    /// Pixels in one image (2^28: a 16384×16384 image).
    pub const MAX_PIXELS: u64 = 1 << 28;
    /// Width or height alone.
    pub const MAX_SIDE: u32 = 1 << 16;
    pub const MAX_SPP: u32 = 1 << 16;
    pub const MAX_DEPTH: u32 = 64;
    /// Spheres in a scene (about 100 MB of them); counted in the file before parsing.
    pub const MAX_SPHERES: usize = 1 << 20;
    pub const MAX_LIGHTS: usize = 1 << 10;
    /// Scene files larger than this are refused before they are read.
    pub const MAX_FILE_BYTES: u64 = 1 << 26;
    /// Scene text parsed as one TOML document at most (the `toml` tree takes 35-65
    /// times the text); larger files must end in a run of `[[sphere]]` tables, which is
    /// parsed a batch of tables at a time.
    pub const MAX_WHOLE_PARSE_BYTES: u64 = 1 << 24;
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: DVec3,
    pub radius: f64,
    /// Diffuse colour `kd`.
    pub color: DVec3,
    /// Reflect weight `w_r`.
    pub reflect: f64,
    /// Transmit weight `w_t`.
    pub transmit: f64,
    pub ior: f64,
}

impl Sphere {
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

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub position: DVec3,
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
    pub down: DVec3,
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

/// The two ways a scene may place the camera (SPEC §2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraSpec {
    LookAt {
        look_from: DVec3,
        look_at: DVec3,
        up: DVec3,
        /// Vertical field of view in degrees.
        vfov: f64,
    },
    Frame {
        origin: DVec3,
        lower_left: DVec3,
        horizontal: DVec3,
        vertical: DVec3,
    },
}

impl CameraSpec {
    /// The assignment's look-at form: from the origin towards −z, `vfov = 2·atan(2.25)`.
    pub fn assignment_look_at() -> Self {
        CameraSpec::LookAt {
            look_from: DVec3::ZERO,
            look_at: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            vfov: assignment_vfov_degrees(),
        }
    }

    /// The assignment's exact frame (meant for 16:9 images).
    pub fn assignment_frame() -> Self {
        CameraSpec::Frame {
            origin: DVec3::ZERO,
            lower_left: DVec3::new(-4.0, -2.25, -1.0),
            horizontal: DVec3::new(8.0, 0.0, 0.0),
            vertical: DVec3::new(0.0, 4.5, 0.0),
        }
    }
}

/// Image settings; each can be overridden on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageSettings {
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
    pub spp: u32,
    pub seed: u64,
    /// The quality preset the file names (`quality = "draft"`). Its `spp` and
    /// `max_depth` are already in the fields above (unless the file gave those too);
    /// its other knobs apply through `RenderOptions::for_scene`.
    pub quality: Option<crate::quality::Preset>,
}

impl Default for ImageSettings {
    fn default() -> Self {
        ImageSettings {
            width: 1280,
            height: 720,
            max_depth: 5,
            spp: 1,
            seed: 0,
            quality: None,
        }
    }
}

impl ImageSettings {
    /// Checks the limits of [`limits`]; `what` names where the values came from.
    pub fn check(&self) -> Result<(), String> {
        use limits::*;
        if self.width == 0 || self.height == 0 {
            return Err(format!(
                "image size {}x{} is empty: width and height must be at least 1",
                self.width, self.height
            ));
        }
        if self.width > MAX_SIDE || self.height > MAX_SIDE {
            return Err(format!(
                "image size {}x{} is too large: each side must be at most {MAX_SIDE}",
                self.width, self.height
            ));
        }
        if u64::from(self.width) * u64::from(self.height) > MAX_PIXELS {
            return Err(format!(
                "image size {}x{} is too large: at most {MAX_PIXELS} pixels",
                self.width, self.height
            ));
        }
        if self.spp == 0 || self.spp > MAX_SPP {
            return Err(format!(
                "spp {} is out of range: expected 1 to {MAX_SPP}",
                self.spp
            ));
        }
        if self.max_depth > MAX_DEPTH {
            return Err(format!(
                "max_depth {} is out of range: expected 0 to {MAX_DEPTH}",
                self.max_depth
            ));
        }
        Ok(())
    }
}

/// A validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// A short name for titles and file names ("hw3", or the file stem).
    pub name: String,
    /// `None`: the assignment's camera (SPEC §2, "The default is the assignment's").
    pub camera: Option<CameraSpec>,
    pub image: ImageSettings,
    pub sky: Sky,
    pub lights: Vec<Light>,
    pub spheres: Vec<Sphere>,
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
#[error("{location}: {message}")]
pub struct SceneError {
    /// `file`, or `file:line:column`.
    pub location: String,
    pub message: String,
}
