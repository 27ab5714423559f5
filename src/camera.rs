//! The pinhole camera of SPEC §2: origin `O`, lower-left corner `LL`, spans `H` and `V`,
//! from either form of [`CameraSpec`]. Pixel rows count from the bottom (`j = 0`), as
//! in OpenGL/GLUT.

use glam::DVec3;

/// The assignment's vertical field of view, `2·atan(2.25)` in degrees (≈ 132.075°):
/// at 16:9 it gives the spans `H = (8,0,0)`, `V = (0,4.5,0)`.
pub fn assignment_vfov_degrees() -> f64 {
    2.0 * 2.25f64.atan().to_degrees()
}

/// The two ways a scene may place the camera (SPEC §2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraSpec {
    /// From a point towards another, `up` giving the roll.
    LookAt {
        /// The eye.
        look_from: DVec3,
        /// A point the view centres on.
        look_at: DVec3,
        /// Which way is up (need not be perpendicular to the view).
        up: DVec3,
        /// Vertical field of view in degrees.
        vfov: f64,
    },
    /// The film given directly, as the assignment did.
    Frame {
        /// The eye `O`.
        origin: DVec3,
        /// Lower-left corner `LL` of the film.
        lower_left: DVec3,
        /// Horizontal span `H`.
        horizontal: DVec3,
        /// Vertical span `V`.
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

    /// Checks for the degenerate cases of SPEC §3.
    pub fn check(&self) -> Result<(), CameraError> {
        check_spec(self)
    }
}

/// A camera that cannot make an image (SPEC §3).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum CameraError {
    /// `look_from = look_at`, or points so far apart the distance overflows.
    #[error("look_from and look_at must be different points")]
    SamePoints,
    /// `up = 0`.
    #[error("up must not be the zero vector")]
    ZeroUp,
    /// `up` along the view direction: no roll can be derived.
    #[error("up is parallel to the view direction")]
    UpParallel,
    /// A field of view outside (0, 180) degrees.
    #[error("vfov must lie strictly between 0 and 180 degrees, got {0}")]
    Vfov(f64),
    /// A zero span of the film.
    #[error("horizontal and vertical spans must not be zero")]
    ZeroSpan,
    /// Spans along one line: the film has no area.
    #[error("horizontal and vertical spans are parallel")]
    ParallelSpans,
    /// Spans that overflow at this image size.
    #[error("the camera's spans are not finite")]
    NotFinite,
}

/// The pinhole camera: eye and film (SPEC §2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The eye `O`.
    pub origin: DVec3,
    /// Lower-left corner `LL` of the film.
    pub lower_left: DVec3,
    /// Horizontal span `H`.
    pub horizontal: DVec3,
    /// Vertical span `V`.
    pub vertical: DVec3,
}

fn check_spec(spec: &CameraSpec) -> Result<(), CameraError> {
    match *spec {
        CameraSpec::LookAt {
            look_from,
            look_at,
            up,
            vfov,
        } => {
            let forward = look_at - look_from;
            if forward.length_squared() == 0.0 || !forward.length_squared().is_finite() {
                return Err(CameraError::SamePoints);
            }
            if up.length_squared() == 0.0 {
                return Err(CameraError::ZeroUp);
            }
            // Parallel within rounding: the cross product is tiny next to the lengths.
            let w = forward.normalize();
            let side = up.normalize().cross(w);
            if side.length() < 1e-9 {
                return Err(CameraError::UpParallel);
            }
            if !(vfov > 0.0 && vfov < 180.0) {
                return Err(CameraError::Vfov(vfov));
            }
            Ok(())
        }
        CameraSpec::Frame {
            horizontal,
            vertical,
            ..
        } => {
            if horizontal.length_squared() == 0.0 || vertical.length_squared() == 0.0 {
                return Err(CameraError::ZeroSpan);
            }
            if horizontal.cross(vertical).length()
                <= 1e-12 * horizontal.length() * vertical.length()
            {
                return Err(CameraError::ParallelSpans);
            }
            Ok(())
        }
    }
}

impl Camera {
    /// The camera for an image of `width`×`height` pixels.
    pub fn new(spec: &CameraSpec, width: u32, height: u32) -> Result<Camera, CameraError> {
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
            return Err(CameraError::NotFinite);
        }
        Ok(camera)
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
