//! Scenes back to TOML text in the format of SPEC §4 (through `toml`'s serializer).

use serde::Serialize;

use super::{Animation, Motion, Scene};
use crate::camera::CameraSpec;

#[derive(Serialize)]
struct OutScene {
    #[serde(skip_serializing_if = "Option::is_none")]
    camera: Option<OutCamera>,
    image: OutImage,
    sky: OutSky,
    #[serde(skip_serializing_if = "Option::is_none")]
    animation: Option<OutAnimation>,
    light: Vec<OutLight>,
    sphere: Vec<OutSphere>,
}

#[derive(Serialize)]
#[serde(untagged)]
enum OutCamera {
    LookAt {
        look_from: [f64; 3],
        look_at: [f64; 3],
        up: [f64; 3],
        vfov: f64,
    },
    Frame {
        origin: [f64; 3],
        lower_left: [f64; 3],
        horizontal: [f64; 3],
        vertical: [f64; 3],
    },
}

#[derive(Serialize)]
struct OutImage {
    #[serde(skip_serializing_if = "Option::is_none")]
    width: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    height: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_depth: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    spp: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    seed: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    quality: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    encoding: Option<&'static str>,
}

#[derive(Serialize)]
struct OutAnimation {
    frames: u32,
    fps: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    orbit: Option<f64>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    key: Vec<OutKey>,
}

#[derive(Serialize)]
struct OutKey {
    frame: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    look_from: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    look_at: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    up: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    vfov: Option<f64>,
}

fn out_animation(a: &Animation) -> OutAnimation {
    let (orbit, key) = match &a.motion {
        Motion::Still => (None, Vec::new()),
        Motion::Orbit { degrees } => (Some(*degrees), Vec::new()),
        Motion::Keys(keys) => (
            None,
            keys.iter()
                .map(|k| OutKey {
                    frame: k.frame,
                    look_from: k.look_from.map(|v| v.to_array()),
                    look_at: k.look_at.map(|v| v.to_array()),
                    up: k.up.map(|v| v.to_array()),
                    vfov: k.vfov,
                })
                .collect(),
        ),
    };
    OutAnimation {
        frames: a.frames,
        fps: a.fps,
        orbit,
        key,
    }
}

#[derive(Serialize)]
struct OutSky {
    down: [f64; 3],
    up: [f64; 3],
}

#[derive(Serialize)]
struct OutLight {
    position: [f64; 3],
    intensity: [f64; 3],
}

#[derive(Serialize)]
struct OutSphere {
    center: [f64; 3],
    radius: f64,
    color: [f64; 3],
    reflect: f64,
    transmit: f64,
    ior: f64,
}

fn out_camera(spec: CameraSpec) -> OutCamera {
    match spec {
        CameraSpec::LookAt {
            look_from,
            look_at,
            up,
            vfov,
        } => OutCamera::LookAt {
            look_from: look_from.to_array(),
            look_at: look_at.to_array(),
            up: up.to_array(),
            vfov,
        },
        CameraSpec::Frame {
            origin,
            lower_left,
            horizontal,
            vertical,
        } => OutCamera::Frame {
            origin: origin.to_array(),
            lower_left: lower_left.to_array(),
            horizontal: horizontal.to_array(),
            vertical: vertical.to_array(),
        },
    }
}

/// The camera as a TOML inline table, `{ look_from = [..], .. }`: one line that
/// `camera = ` makes the `[camera]` table of a scene file (the viewer prints it when it
/// saves, so that `whitted render` can render the same view).
pub fn camera_to_toml(spec: &CameraSpec) -> String {
    toml::Value::try_from(out_camera(*spec))
        .expect("a camera of finite numbers always serialises")
        .to_string()
}

/// The scene as TOML; loading the text gives the same scene back.
pub fn to_toml(scene: &Scene) -> String {
    let out = OutScene {
        camera: scene.camera.map(out_camera),
        image: OutImage {
            width: scene.image.width,
            height: scene.image.height,
            max_depth: scene.image.max_depth,
            spp: scene.image.spp,
            seed: scene.image.seed,
            quality: scene.image.quality.map(|q| q.name()),
            encoding: scene.image.encoding.map(|e| e.name()),
        },
        sky: OutSky {
            down: scene.sky.down.to_array(),
            up: scene.sky.up.to_array(),
        },
        animation: scene.animation.as_ref().map(out_animation),
        light: scene
            .lights
            .iter()
            .map(|l| OutLight {
                position: l.position.to_array(),
                intensity: l.intensity.to_array(),
            })
            .collect(),
        sphere: scene
            .spheres
            .iter()
            .map(|s| OutSphere {
                center: s.center.to_array(),
                radius: s.radius,
                color: s.color.to_array(),
                reflect: s.reflect,
                transmit: s.transmit,
                ior: s.ior,
            })
            .collect(),
    };
    toml::to_string(&out).expect("a scene of finite numbers always serialises")
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A scene whose text is `camera = ` and the printed camera, then `[image]`.
    fn camera_of(inline: &str) -> Option<CameraSpec> {
        let text = format!("camera = {inline}\n[image]\nwidth = 4\nheight = 3\n");
        Scene::from_toml_str(&text, "camera.toml").unwrap().camera
    }

    #[test]
    fn a_printed_camera_is_one_line_that_loads_back_bit_for_bit() {
        let look_at = CameraSpec::LookAt {
            look_from: DVec3::new(0.1, 1.0 / 3.0, -2.5e-7),
            look_at: DVec3::new(123_456.789e3, -0.0, 7.000000000000001),
            up: DVec3::Y,
            vfov: 45.000000000000014,
        };
        let frame = CameraSpec::assignment_frame();
        for spec in [look_at, frame] {
            let line = camera_to_toml(&spec);
            assert!(!line.contains('\n') && line.starts_with('{'), "{line}");
            assert_eq!(camera_of(&line), Some(spec), "{line}");
        }
    }
}
