//! `whitted`: a Whitted-style CPU ray tracer for scenes of spheres.
//!
//! The data flows through the modules in this order:
//! scene file → [`scene`] → [`settings`] and [`camera`] → [`trace`] (using the shared
//! formulas of [`model`] and the ray–sphere roots of [`intersect`]) → [`render`](mod@render) (the
//! frame buffer) → [`image_io`] (files), the window or a Python array.
//!
//! A scene carries the settings its file gives ([`Scene::image`]); options from a
//! command line or a program go over them as one more layer of [`Overrides`], and
//! [`render()`] takes the resolved [`Settings`]:
//!
//! ```
//! use whitted::image_io::{self, Format};
//! use whitted::scene::{hw3_scene, HW3_DEFAULT_SEED};
//! use whitted::{render, Overrides, RenderControl};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let scene = hw3_scene(HW3_DEFAULT_SEED); // or Scene::load(path)?
//! let settings = scene.settings().with(&Overrides {
//!     width: Some(160),
//!     height: Some(90),
//!     ..Overrides::default()
//! });
//! let (frame, stats) = render(&scene, &settings, &RenderControl::default())?;
//! assert_eq!((frame.width, frame.height), (160, 90));
//! assert!(stats.rays.total() > 0);
//! # let dir = tempfile::tempdir()?;
//! # let path = dir.path().join("hw3.png");
//! image_io::save(&frame, &path, Format::Png, settings.encoding)?; // row 0 at the top
//! # Ok(())
//! # }
//! ```
//!
//! `../shared/SPEC.md` §2 defines the function every renderer here computes; the fast
//! `f32` tracer ([`trace::fast`]) and the `f64` reference ([`trace::reference`]) both
//! implement it, and the tests measure the one against the other.
//!
//! With `default-features = false` the library depends on none of the command line's
//! or the window's crates; the features `cli` and `viewer` (on by default) add them.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub(crate) mod accel;
// The shells' support (`whitted bench`, `whitted time`, the window): behind features,
// not part of the library's API.
#[cfg(feature = "cli")]
#[doc(hidden)]
pub mod bench;
pub mod camera;
pub mod image_io;
pub mod intersect;
pub mod limits;
pub mod model;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod settings;
#[cfg(all(feature = "cli", feature = "viewer"))]
#[doc(hidden)]
pub mod speed;
pub mod trace;
#[cfg(feature = "viewer")]
#[doc(hidden)]
pub mod viewer;

// README's examples run as doc tests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

pub use camera::{Camera, CameraSpec};
pub use render::{render, Frame, RenderControl, RenderError, RenderStats};
pub use scene::{Scene, SceneError};
pub use settings::{Overrides, Precision, Preset, Quality, Settings};
