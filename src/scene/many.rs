//! The peers' scaling scenes ("many_N", `../shared/peers/make_hw3.py --many N`): N
//! random balls resting on a large ground sphere, with a big glass, mirror and diffuse
//! ball, drawn with the same generator, so `many_scene(N)` is the peers' scene.

use glam::DVec3;

use super::hw3::{random_material, PyRandom};
use super::{Light, Scene, Sky, Sphere};
use crate::camera::CameraSpec;
use crate::settings::Overrides;

/// `round(x, 6)` as Python prints it: correctly rounded to six decimals.
fn round6(x: f64) -> f64 {
    format!("{x:.6}")
        .parse()
        .expect("a formatted number parses")
}

/// The scene `many_N` with `n` small balls (seeded with `n`, as the peers do).
pub fn many_scene(n: usize) -> Scene {
    const R: f64 = 1000.0;
    let ground = DVec3::new(0.0, -R, 0.0);
    let (width, height) = (1280u32, 720u32);
    // The peers' look-at camera, rounded to six decimals as their files store it.
    let look = CameraSpec::LookAt {
        look_from: DVec3::new(0.0, 18.0, 60.0),
        look_at: DVec3::new(0.0, 0.0, -8.0),
        up: DVec3::Y,
        vfov: 45.0,
    };
    let cam = crate::camera::Camera::new(&look, width, height).expect("a valid camera");
    let r6 = |v: DVec3| DVec3::new(round6(v.x), round6(v.y), round6(v.z));
    let camera = CameraSpec::Frame {
        origin: cam.origin,
        lower_left: r6(cam.lower_left),
        horizontal: r6(cam.horizontal),
        vertical: r6(cam.vertical),
    };
    let mut spheres = vec![
        Sphere::new(ground, R),
        Sphere {
            transmit: 0.9,
            ..Sphere::new(DVec3::new(0.0, 3.0, 0.0), 3.0)
        },
        Sphere {
            reflect: 0.9,
            ..Sphere::new(DVec3::new(9.0, 3.0, -6.0), 3.0)
        },
        Sphere {
            color: DVec3::new(1.0, 0.7, 0.3),
            ..Sphere::new(DVec3::new(-9.0, 3.0, -6.0), 3.0)
        },
    ];
    let mut rng = PyRandom::new(n as u64);
    for _ in 0..n {
        let x = rng.random() * 100.0 - 50.0;
        let z = rng.random() * 100.0 - 50.0;
        let r = 0.1 + 0.2 * rng.random();
        let (color, reflect, transmit) = random_material(&mut rng);
        // Resting on the ground.
        let y = ground.y + ((R + r) * (R + r) - x * x - z * z).sqrt();
        spheres.push(Sphere {
            color,
            reflect: round6(reflect),
            transmit: round6(transmit),
            ..Sphere::new(r6(DVec3::new(x, y, z)), round6(r))
        });
    }
    Scene {
        name: format!("many_{n}"),
        camera: Some(camera),
        image: Overrides {
            width: Some(width),
            height: Some(height),
            ..Overrides::default()
        },
        sky: Sky::default(),
        lights: vec![Light {
            position: DVec3::new(-30.0, 60.0, 40.0),
            intensity: DVec3::ONE,
        }],
        spheres,
        animation: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values copied from the file `make_hw3.py --many 1000 --toml` writes (Python's
    /// generator): the same draws give the same scene.
    #[test]
    fn many_1000_is_the_peers_scene() {
        let s = many_scene(1000);
        assert_eq!(s.spheres.len(), 1004);
        let fifth = s.spheres[4];
        assert_eq!(fifth.center, DVec3::new(27.735664, -0.409086, 16.982556));
        assert_eq!(fifth.radius, 0.119828);
        assert_eq!(fifth.color, DVec3::new(0.8, 0.3, 0.8));
        assert_eq!((fifth.reflect, fifth.transmit), (0.0, 0.165759));
        let last = s.spheres[1003];
        assert_eq!(last.center, DVec3::new(37.826361, -1.137561, 36.114477));
        assert_eq!((last.radius, last.transmit), (0.230604, 0.074451));
        let Some(CameraSpec::Frame {
            lower_left,
            horizontal,
            vertical,
            ..
        }) = s.camera
        else {
            panic!("the peers store a frame camera")
        };
        assert_eq!(lower_left, DVec3::new(-0.73638, 17.343685, 59.139289));
        assert_eq!(horizontal, DVec3::new(1.472759, 0.0, 0.0));
        assert_eq!(vertical, DVec3::new(0.0, 0.800845, -0.211988));
    }
}
