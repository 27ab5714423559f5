//! Views of one scene rendered in turn (the frames of an animation): the scene is
//! compiled for the fast tracer once, and each view rebuilds only the camera's part
//! (`FastTracer::with_camera`). A view rendered here is bit for bit what [`render`]
//! gives for the scene with that camera: the compiled scene does not depend on the
//! camera, and the camera's part is built the same way.
//!
//! [`render`]: super::render

use std::time::Instant;

use super::bands::in_pool;
use super::{render_with, RenderError, RenderStats, Traced};
use crate::camera::{Camera, CameraSpec};
use crate::render::{Frame, RenderControl};
use crate::scene::Scene;
use crate::settings::{Precision, Settings};
use crate::trace::fast::FastTracer;
use crate::trace::reference::ReferenceTracer;

/// Renders `scene` from one camera after another, compiling it once.
pub struct Sequence<'a> {
    scene: &'a Scene,
    /// The last view's fast tracer: its compiled scene serves the next view.
    fast: Option<FastTracer>,
}

impl<'a> Sequence<'a> {
    /// Nothing is compiled until the first view.
    pub fn new(scene: &'a Scene) -> Self {
        Sequence { scene, fast: None }
    }

    /// The area of `settings` seen by `camera` (the scene's own camera is not used).
    pub fn render(
        &mut self,
        camera: &CameraSpec,
        settings: &Settings,
        control: &RenderControl,
    ) -> Result<(Frame, RenderStats), RenderError> {
        settings.check()?;
        let start = Instant::now();
        let camera = Camera::new(camera, settings.width, settings.height)?;
        let depth = settings.quality.max_depth;
        let traced = match settings.quality.precision {
            Precision::Fast => {
                let previous = self.fast.take();
                let scene = self.scene;
                let tracer = in_pool(settings, || match previous {
                    Some(p) => p.with_camera(&camera, depth),
                    None => FastTracer::new(scene, &camera, depth),
                })?
                .with_cutoff(settings.quality.cutoff);
                let build_seconds = start.elapsed().as_secs_f64();
                let traced = render_with(&tracer, settings, control);
                self.fast = Some(tracer);
                (traced?, build_seconds)
            }
            Precision::Reference => {
                let tracer = ReferenceTracer::new(self.scene, camera, depth);
                (render_with(&tracer, settings, control)?, 0.0)
            }
        };
        let (Traced { frame, rays, .. }, build_seconds) = traced;
        Ok((
            frame,
            RenderStats {
                rays,
                seconds: start.elapsed().as_secs_f64(),
                build_seconds,
            },
        ))
    }
}
