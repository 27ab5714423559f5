//! The viewer's camera: which camera spec applies at a window size, and how orbit,
//! zoom and moves change it. No window here, so all of it is tested directly.
//!
//! Until the user touches the camera the scene's own spec is used unchanged, so the
//! window shows exactly what `whitted render` writes. The first change converts it to
//! the look-at form ([`Camera::to_look_at`]), which the controls then edit.

use glam::{DMat3, DVec3};

use crate::camera::Camera;
use crate::camera::CameraSpec;
use crate::scene::Scene;

/// The smallest and largest vertical field of view the wheel reaches, in degrees.
pub const MIN_VFOV: f64 = 1.0;
pub const MAX_VFOV: f64 = 175.0;
/// Each wheel notch scales the field of view by this (zooming in for positive steps).
const ZOOM_PER_STEP: f64 = 0.9;
/// Each arrow press moves by this fraction of the distance to the look-at point.
const MOVE_FRACTION: f64 = 0.1;
/// The orbit never brings the view closer than this to the up axis (degrees), so
/// `up` never becomes parallel to the view direction.
const POLE_MARGIN_DEG: f64 = 1.0;

/// The camera in look-at form, as the controls edit it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub look_from: DVec3,
    pub look_at: DVec3,
    pub up: DVec3,
    /// Vertical field of view, degrees.
    pub vfov: f64,
}

impl View {
    pub fn from_spec(spec: &CameraSpec) -> Option<View> {
        match *spec {
            CameraSpec::LookAt {
                look_from,
                look_at,
                up,
                vfov,
            } => Some(View {
                look_from,
                look_at,
                up,
                vfov,
            }),
            CameraSpec::Frame { .. } => None,
        }
    }

    pub fn spec(&self) -> CameraSpec {
        CameraSpec::LookAt {
            look_from: self.look_from,
            look_at: self.look_at,
            up: self.up,
            vfov: self.vfov,
        }
    }

    /// Turns the eye around the look-at point: `yaw` about `up`, then `pitch` about the
    /// camera's right axis (radians; positive pitch raises the eye).
    pub fn orbit(&mut self, yaw: f64, pitch: f64) {
        let up = self.up.normalize();
        let offset = self.look_from - self.look_at;
        let offset = DMat3::from_axis_angle(up, yaw) * offset;
        // The angle between the offset and `up` stays inside (margin, 180° − margin).
        let angle = offset.angle_between(up);
        let margin = POLE_MARGIN_DEG.to_radians();
        let target = (angle - pitch).clamp(margin, std::f64::consts::PI - margin);
        // About this axis a positive angle turns the offset towards `up`.
        let axis = offset.cross(up);
        let offset = if axis.length_squared() > 0.0 {
            DMat3::from_axis_angle(axis.normalize(), angle - target) * offset
        } else {
            offset
        };
        self.look_from = self.look_at + offset;
    }

    /// Zooms by `steps` wheel notches (positive: narrower field of view).
    pub fn zoom(&mut self, steps: f64) {
        self.vfov = (self.vfov * ZOOM_PER_STEP.powf(steps)).clamp(MIN_VFOV, MAX_VFOV);
    }

    /// Moves eye and look-at point together: `forward` along the view direction,
    /// `right` sideways, `lift` along `up`, each in steps of a tenth of the distance
    /// to the look-at point.
    pub fn translate(&mut self, forward: f64, right: f64, lift: f64) {
        let offset = self.look_at - self.look_from;
        let step = offset.length() * MOVE_FRACTION;
        let w = offset.normalize();
        let up = self.up.normalize();
        let u = w.cross(up).normalize();
        let delta = (w * forward + u * right + up * lift) * step;
        self.look_from += delta;
        self.look_at += delta;
    }
}

/// A key or mouse action on the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Mouse drag by this many pixels (x right, y down) in a window this tall.
    Drag {
        dx: f64,
        dy: f64,
        height: u32,
    },
    Zoom(f64),
    Forward(f64),
    Right(f64),
    Lift(f64),
}

/// The camera the viewer renders with: the scene's, or the user's edit of it.
#[derive(Clone, Debug)]
pub struct CameraControl {
    scene_spec: Option<CameraSpec>,
    scene_size: (u32, u32),
    edited: Option<View>,
}

impl CameraControl {
    pub fn new(scene: &Scene) -> Self {
        CameraControl {
            scene_spec: scene.camera,
            scene_size: (scene.settings().width, scene.settings().height),
            edited: None,
        }
    }

    /// Whether the user has changed the camera since the start or the last reset.
    pub fn is_edited(&self) -> bool {
        self.edited.is_some()
    }

    pub fn reset(&mut self) {
        self.edited = None;
    }

    /// The spec to render `width`×`height` with. Unedited, it is what `whitted render`
    /// uses at that size, except for a scene that gives the spans directly: those are
    /// made for the scene's own size, so at another size its look-at form keeps the
    /// vertical field of view instead of stretching the picture.
    pub fn spec(&self, scene: &Scene, width: u32, height: u32) -> CameraSpec {
        if let Some(view) = self.edited {
            return view.spec();
        }
        match self.scene_spec {
            Some(frame @ CameraSpec::Frame { .. }) if (width, height) != self.scene_size => {
                let (w, h) = self.scene_size;
                Camera::new(&frame, w, h)
                    .map(|c| c.to_look_at())
                    .unwrap_or(frame)
            }
            _ => scene.camera_spec(width, height),
        }
    }

    /// Applies an action; returns whether the camera changed.
    pub fn apply(&mut self, scene: &Scene, width: u32, height: u32, action: Action) -> bool {
        let mut view = match self.edited {
            Some(v) => v,
            None => {
                let spec = self.spec(scene, width, height);
                match View::from_spec(&spec) {
                    Some(v) => v,
                    None => match Camera::new(&spec, width, height) {
                        Ok(c) => View::from_spec(&c.to_look_at()).expect("look-at form"),
                        Err(_) => return false,
                    },
                }
            }
        };
        let before = view;
        match action {
            Action::Drag { dx, dy, height } => {
                // Dragging across the whole window height turns the view by 180°.
                let per_pixel = std::f64::consts::PI / f64::from(height.max(1));
                view.orbit(-dx * per_pixel, dy * per_pixel);
            }
            Action::Zoom(steps) => view.zoom(steps),
            Action::Forward(n) => view.translate(n, 0.0, 0.0),
            Action::Right(n) => view.translate(0.0, n, 0.0),
            Action::Lift(n) => view.translate(0.0, 0.0, n),
        }
        let valid = view.spec().check().is_ok()
            && [view.look_from, view.look_at].iter().all(|p| p.is_finite());
        if !valid || view == before {
            return false;
        }
        self.edited = Some(view);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::hw3_scene;

    fn approx(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-9
    }

    fn view() -> View {
        View {
            look_from: DVec3::new(0.0, 0.0, 0.0),
            look_at: DVec3::new(0.0, 0.0, -2.0),
            up: DVec3::Y,
            vfov: 90.0,
        }
    }

    #[test]
    fn orbit_keeps_the_distance_and_the_look_at_point() {
        let mut v = view();
        v.orbit(0.7, 0.3);
        assert!(approx(v.look_at, DVec3::new(0.0, 0.0, -2.0)));
        assert!(((v.look_from - v.look_at).length() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_quarter_yaw_moves_the_eye_to_the_side() {
        // Eye at +z of the look-at point; a +90° turn about +y takes +z to +x.
        let mut v = view();
        v.orbit(std::f64::consts::FRAC_PI_2, 0.0);
        assert!(approx(v.look_from, DVec3::new(2.0, 0.0, -2.0)));
    }

    #[test]
    fn pitch_raises_the_eye_and_stops_short_of_the_pole() {
        let mut v = view();
        v.orbit(0.0, 0.5);
        // Raised by 0.5 rad on a circle of radius 2.
        assert!(approx(
            v.look_from,
            DVec3::new(0.0, 2.0 * 0.5f64.sin(), -2.0 + 2.0 * 0.5f64.cos())
        ));
        v.orbit(0.0, 10.0);
        let angle = (v.look_from - v.look_at)
            .angle_between(DVec3::Y)
            .to_degrees();
        assert!((angle - POLE_MARGIN_DEG).abs() < 1e-9, "angle {angle}");
        assert!(v.spec().check().is_ok());
    }

    #[test]
    fn zoom_scales_and_clamps_the_field_of_view() {
        let mut v = view();
        v.zoom(1.0);
        assert!((v.vfov - 81.0).abs() < 1e-12);
        v.zoom(-2.0);
        assert!((v.vfov - 100.0).abs() < 1e-9);
        v.zoom(-100.0);
        assert_eq!(v.vfov, MAX_VFOV);
        v.zoom(1000.0);
        assert_eq!(v.vfov, MIN_VFOV);
    }

    #[test]
    fn moves_are_a_tenth_of_the_distance() {
        let mut v = view();
        v.translate(1.0, 0.0, 0.0);
        assert!(approx(v.look_from, DVec3::new(0.0, 0.0, -0.2)));
        assert!(approx(v.look_at, DVec3::new(0.0, 0.0, -2.2)));
        let mut v = view();
        v.translate(0.0, 1.0, -1.0);
        // Looking down −z with +y up, right is +x.
        assert!(approx(v.look_from, DVec3::new(0.2, -0.2, 0.0)));
    }

    #[test]
    fn unedited_is_the_scene_camera_and_reset_returns_to_it() {
        let scene = hw3_scene(crate::scene::HW3_DEFAULT_SEED);
        let mut c = CameraControl::new(&scene);
        assert_eq!(c.spec(&scene, 1280, 720), scene.camera_spec(1280, 720));
        assert_eq!(c.spec(&scene, 400, 300), scene.camera_spec(400, 300));
        assert!(c.apply(&scene, 1280, 720, Action::Zoom(1.0)));
        match c.spec(&scene, 1280, 720) {
            CameraSpec::LookAt { vfov, .. } => {
                let expected = crate::camera::assignment_vfov_degrees() * 0.9;
                assert!((vfov - expected).abs() < 1e-9, "vfov {vfov}");
            }
            other => panic!("expected look-at form, got {other:?}"),
        }
        c.reset();
        assert!(!c.is_edited());
        assert_eq!(c.spec(&scene, 1280, 720), scene.camera_spec(1280, 720));
    }

    #[test]
    fn a_frame_camera_keeps_its_vertical_fov_at_another_size() {
        let mut scene = hw3_scene(crate::scene::HW3_DEFAULT_SEED);
        scene.camera = Some(CameraSpec::assignment_frame());
        let c = CameraControl::new(&scene);
        assert_eq!(c.spec(&scene, 1280, 720), CameraSpec::assignment_frame());
        match c.spec(&scene, 640, 640) {
            CameraSpec::LookAt { vfov, .. } => {
                let expected = crate::camera::assignment_vfov_degrees();
                assert!((vfov - expected).abs() < 1e-9);
            }
            other => panic!("expected look-at form, got {other:?}"),
        }
    }

    #[test]
    fn drag_across_the_window_turns_half_way_round() {
        let scene = hw3_scene(crate::scene::HW3_DEFAULT_SEED);
        let mut c = CameraControl::new(&scene);
        let drag = Action::Drag {
            dx: 360.0,
            dy: 0.0,
            height: 720,
        };
        assert!(c.apply(&scene, 1280, 720, drag));
        match c.spec(&scene, 1280, 720) {
            CameraSpec::LookAt {
                look_from, look_at, ..
            } => {
                // A quarter turn about the look-at point (0,0,-1): the eye, 1 unit
                // towards +z of it, goes to 1 unit towards −x.
                assert!(approx(look_at, DVec3::new(0.0, 0.0, -1.0)));
                assert!(
                    approx(look_from, DVec3::new(-1.0, 0.0, -1.0)),
                    "{look_from}"
                );
            }
            other => panic!("expected look-at form, got {other:?}"),
        }
    }
}
