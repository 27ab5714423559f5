//! The pinhole camera of SPEC §2: origin `O`, lower-left corner `LL`, spans `H` and `V`,
//! from either form of [`CameraSpec`]. Pixel rows count from the bottom (`j = 0`), as
//! in OpenGL/GLUT.

use glam::DVec3;

use crate::scene::{CameraSpec, Scene};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub origin: DVec3,
    pub lower_left: DVec3,
    pub horizontal: DVec3,
    pub vertical: DVec3,
}

/// Checks a camera spec for the degenerate cases of SPEC §3.
pub fn check_spec(spec: &CameraSpec) -> Result<(), String> {
    match *spec {
        CameraSpec::LookAt {
            look_from,
            look_at,
            up,
            vfov,
        } => {
            let forward = look_at - look_from;
            if forward.length_squared() == 0.0 || !forward.length_squared().is_finite() {
                return Err("look_from and look_at must be different points".into());
            }
            if up.length_squared() == 0.0 {
                return Err("up must not be the zero vector".into());
            }
            // Parallel within rounding: the cross product is tiny next to the lengths.
            let w = forward.normalize();
            let side = up.normalize().cross(w);
            if side.length() < 1e-9 {
                return Err("up is parallel to the view direction".into());
            }
            if !(vfov > 0.0 && vfov < 180.0) {
                return Err(format!(
                    "vfov must lie strictly between 0 and 180 degrees, got {vfov}"
                ));
            }
            Ok(())
        }
        CameraSpec::Frame {
            horizontal,
            vertical,
            ..
        } => {
            if horizontal.length_squared() == 0.0 || vertical.length_squared() == 0.0 {
                return Err("horizontal and vertical spans must not be zero".into());
            }
            if horizontal.cross(vertical).length()
                <= 1e-12 * horizontal.length() * vertical.length()
            {
                return Err("horizontal and vertical spans are parallel".into());
            }
            Ok(())
        }
    }
}

impl Camera {
    /// The camera for an image of `width`×`height` pixels.
    pub fn new(spec: &CameraSpec, width: u32, height: u32) -> Result<Camera, String> {
        check_spec(spec)?;
        let camera = match *spec {
            CameraSpec::LookAt {
                look_from,
                look_at,
                up,
                vfov,
            } => {
                let w = (look_from - look_at).normalize();
                let u = up.cross(w).normalize();
                let v = w.cross(u);
                let h = (vfov.to_radians() / 2.0).tan();
                let a = f64::from(width) / f64::from(height);
                Camera {
                    origin: look_from,
                    lower_left: look_from - u * (a * h) - v * h - w,
                    horizontal: u * (2.0 * a * h),
                    vertical: v * (2.0 * h),
                }
            }
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
            },
        };
        let finite = [
            camera.origin,
            camera.lower_left,
            camera.horizontal,
            camera.vertical,
        ]
        .iter()
        .all(|v| v.is_finite());
        if !finite {
            return Err("the camera's spans are not finite".into());
        }
        Ok(camera)
    }

    /// The camera of `scene` at `width`×`height`.
    pub fn for_scene(scene: &Scene, width: u32, height: u32) -> Result<Camera, String> {
        Camera::new(&scene.camera_spec(width, height), width, height)
    }

    /// The same camera in look-at form (for the viewer's orbit and zoom): looking at the
    /// image centre, one unit of view distance per `|LL + H/2 + V/2 − O|`.
    pub fn to_look_at(&self) -> CameraSpec {
        let centre = self.lower_left + self.horizontal * 0.5 + self.vertical * 0.5;
        let forward = centre - self.origin;
        let vfov = 2.0 * (self.vertical.length() * 0.5).atan2(forward.length());
        CameraSpec::LookAt {
            look_from: self.origin,
            look_at: centre,
            up: self.vertical.normalize(),
            vfov: vfov.to_degrees(),
        }
    }
}
