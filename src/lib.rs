//! `whitted`: a Whitted-style CPU ray tracer for scenes of spheres.
//!
//! The data flows through the modules in this order:
//! scene file → [`scene`] → [`camera`] → [`trace`] (using the shared formulas of
//! [`model`]) → [`render`] (the frame buffer) → [`image_io`] (files) or `viewer` (window).
//!
//! `../shared/SPEC.md` §2 defines the function every renderer here computes; the fast
//! `f32` tracer ([`trace::fast`]) and the `f64` reference ([`trace::reference`]) both
//! implement it, and the tests measure the one against the other.
#![forbid(unsafe_code)]

pub(crate) mod accel;
pub mod bench;
pub mod camera;
pub mod image_io;
pub mod model;
pub mod quality;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod speed;
pub mod trace;
pub mod viewer;

pub use camera::Camera;
pub use render::{render, Frame, RenderOptions, RenderStats};
pub use scene::{Scene, SceneError};
