//! The fast `f32` tracer against the `f64` reference, whose image is made by the
//! SPEC's formulas in `support::spec_reference` (camera, film positions, row order,
//! region, mean, bytes), not by the renderer's: at most 0.01% of the pixels may differ
//! by more than one 8-bit level, and none by more than 8 except a handful on
//! silhouettes. The built-in scene with one light, and with two and three coloured
//! lights (one behind the balls), at one sample a pixel and more, whole and in a region,
//! and inside a diffuse dome.

mod support;

use glam::DVec3;
use support::spec_reference::{check_close, spec_reference};
use whitted::image_io::{to_rgb8, Encoding};
use whitted::render::{self, RenderControl};
use whitted::scene::{hw3_scene, Light, Scene, HW3_DEFAULT_SEED};
use whitted::settings::{Region, Settings};

/// The fast render of `settings` (its region, if any), as 8-bit linear bytes.
fn fast(scene: &Scene, settings: &Settings) -> Vec<u8> {
    let (frame, _) = render::render(scene, settings, &RenderControl::default()).expect("render");
    to_rgb8(&frame, Encoding::Linear).into_raw()
}

/// Fast vs reference on `scene` at `width`×`height`, `spp` samples, `region`.
fn compare(label: &str, scene: &Scene, size: (u32, u32), spp: u32, region: Option<Region>) {
    let mut opts = scene.settings();
    (opts.width, opts.height) = size;
    opts.quality.spp = spp;
    opts.seed = 11;
    opts.region = region;
    let reference = spec_reference(scene, &opts);
    if let Err(e) = check_close(label, &fast(scene, &opts), &reference) {
        panic!("{e}");
    }
}

/// hw3 lit by `lights` (position, RGB intensity) instead of its one white light.
fn hw3_lit(lights: &[([f64; 3], [f64; 3])]) -> Scene {
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    scene.lights = lights
        .iter()
        .map(|&(p, i)| Light {
            position: DVec3::from_array(p),
            intensity: DVec3::from_array(i),
        })
        .collect();
    scene
}

/// A warm light at the default place and a cool one to the right.
const TWO_LIGHTS: [([f64; 3], [f64; 3]); 2] = [
    ([-10.0, 10.0, 0.0], [0.9, 0.55, 0.3]),
    ([6.0, 4.0, 3.0], [0.3, 0.5, 0.9]),
];

/// The two lights and a green one behind the balls (beyond the farthest, at z = −3.5),
/// low, so that the balls cast shadows towards the camera.
fn three_lights() -> [([f64; 3], [f64; 3]); 3] {
    [
        TWO_LIGHTS[0],
        TWO_LIGHTS[1],
        ([0.5, 1.0, -8.0], [0.3, 0.8, 0.35]),
    ]
}

#[test]
fn fast_matches_reference_on_hw3_640x360() {
    let scene = hw3_scene(HW3_DEFAULT_SEED);
    compare("hw3 640x360, 1 spp", &scene, (640, 360), 1, None);
}

#[test]
fn fast_matches_reference_with_two_and_three_coloured_lights() {
    compare(
        "hw3, two lights, 320x180, 1 spp",
        &hw3_lit(&TWO_LIGHTS),
        (320, 180),
        1,
        None,
    );
    compare(
        "hw3, three lights (one behind), 320x180, 1 spp",
        &hw3_lit(&three_lights()),
        (320, 180),
        1,
        None,
    );
}

/// Materials that mix: the small balls made partly diffuse and partly mirror, glass, or
/// both (weights between 0 and 1, two indices of refraction), so that every weight of
/// SPEC §2's mix (`(1 − w_t)(1 − w_r)` local, `w_r` reflected, `w_t` transmitted) is
/// neither 0 nor 1 somewhere.
#[test]
fn fast_matches_reference_with_mixed_materials() {
    let mut scene = hw3_lit(&TWO_LIGHTS);
    for (i, ball) in scene.spheres.iter_mut().skip(4).enumerate() {
        (ball.reflect, ball.transmit, ball.ior) = match i % 4 {
            0 => (0.35, 0.0, 1.5),
            1 => (0.0, 0.45, 1.5),
            2 => (0.25, 0.3, 1.33),
            _ => (0.6, 0.2, 2.0),
        };
    }
    compare(
        "hw3, mixed materials, 320x180, 1 spp",
        &scene,
        (320, 180),
        1,
        None,
    );
}

/// A light a hair above the orange ball's top, 1.5·10⁻⁶ of its radius away: outside
/// the band of spheres the light's grid tests for every segment (10⁻⁶), inside the one
/// where the quick test's widened sphere reaches over the light (its slack, 2⁻¹⁸ of
/// the squared distances). The ball shades the whole ground, each point by how steeply
/// its segment enters the ball just below the light; a quick test that loses the ball
/// lights the ground.
#[test]
fn fast_matches_reference_with_a_light_a_hair_above_a_ball() {
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    let ball = &scene.spheres[3];
    let top = ball.center + DVec3::Y * ball.radius * (1.0 + 1.5e-6);
    scene.lights = vec![Light {
        position: top,
        intensity: DVec3::ONE,
    }];
    compare(
        "hw3, a light 1.5e-6 r above the orange ball, 320x180, 1 spp",
        &scene,
        (320, 180),
        1,
        None,
    );
}

/// Inside a diffuse dome: hw3 under a white ball of radius 30 around the camera, which
/// the ground cuts. Every ray that misses the balls and the ground meets the dome from
/// inside, where the normal that faces the ray is the inward one (`nf = −n`) and the
/// light, inside too, lights it.
#[test]
fn fast_matches_reference_inside_a_diffuse_dome() {
    let mut scene = hw3_scene(HW3_DEFAULT_SEED);
    scene.spheres.push(whitted::scene::Sphere::new(
        DVec3::new(0.0, 0.0, -2.0),
        30.0,
    ));
    compare(
        "hw3 inside a diffuse dome, 320x180, 1 spp",
        &scene,
        (320, 180),
        1,
        None,
    );
}

/// Anti-aliased: the samples' film positions matter (`t` divides by the height). Also
/// at 2:1, where the scene's camera is the look-at form, and with 3 samples (a 2×2
/// grid with one cell left out).
#[test]
fn fast_matches_reference_with_several_samples_a_pixel() {
    let scene = hw3_lit(&three_lights());
    compare(
        "hw3, three lights, 192x108, 4 spp",
        &scene,
        (192, 108),
        4,
        None,
    );
    compare(
        "hw3, two lights, 200x100, 3 spp",
        &hw3_lit(&TWO_LIGHTS),
        (200, 100),
        3,
        None,
    );
}

/// A region is the same crop of the image the SPEC defines (`y` from the top), not a
/// shifted one.
#[test]
fn fast_matches_reference_in_a_region() {
    let scene = hw3_lit(&TWO_LIGHTS);
    // Across the balls and the ground, where a shift in x or y changes pixels.
    let region = Region {
        x: 97,
        y: 71,
        width: 120,
        height: 60,
    };
    compare(
        "hw3 region 97,71,120,60 of 320x180, 1 spp",
        &scene,
        (320, 180),
        1,
        Some(region),
    );
    compare(
        "hw3 region 97,71,120,60 of 320x180, 2 spp",
        &scene,
        (320, 180),
        2,
        Some(region),
    );
}
