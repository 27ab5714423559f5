//! Views of one scene rendered in turn (the frames of an animation): the scene is
//! compiled for the fast tracer once, and each view rebuilds only the camera's part
//! (`FastTracer::with_camera`). A view rendered here is bit for bit what [`render`]
//! gives for the scene with that camera: the compiled scene does not depend on the
//! camera, and the camera's part is built the same way.
//!
//! [`render`]: super::render

use std::time::Instant;

use super::bands::in_pool;
use super::{RenderError, RenderStats, Traced, Tracer};
use crate::camera::{Camera, CameraSpec};
use crate::render::{Frame, RenderControl};
use crate::scene::Scene;
use crate::settings::Settings;
use crate::trace::fast::FastTracer;

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
        let previous = self.fast.take();
        let tracer = in_pool(settings, || {
            Tracer::new(self.scene, camera, settings, previous)
        })?;
        let build_seconds = start.elapsed().as_secs_f64();
        let traced = tracer.render(settings, control);
        if let Tracer::Fast(fast) = tracer {
            self.fast = Some(fast);
        }
        let Traced { frame, rays, .. } = traced?;
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
