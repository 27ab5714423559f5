//! Scene files (SPEC §4): the committed built-in scene stays what the generator prints
//! and what the binary renders; the loader's defaults, integer literals, both camera
//! forms and an empty light list.

mod common;
use common::whitted;

use std::path::Path;

use glam::DVec3;
use whitted::camera::{assignment_vfov_degrees, CameraSpec};
use whitted::scene::{hw3_scene, to_toml, Light, Sky, Sphere, HW3_DEFAULT_SEED};
use whitted::settings::Overrides;
use whitted::Scene;

const ASSET: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/hw3.toml");

fn parse(text: &str) -> Scene {
    Scene::from_toml_str(text, "test.toml").unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_committed_hw3_scene_is_what_the_generator_prints() {
    let committed = std::fs::read_to_string(ASSET).expect("assets/scenes/hw3.toml");
    let printed = String::from_utf8(whitted(&["scene", "hw3"])).unwrap();
    assert!(
        committed == printed,
        "assets/scenes/hw3.toml is stale: regenerate it with \
         `whitted scene hw3 > assets/scenes/hw3.toml`"
    );
    let seeded = String::from_utf8(whitted(&["scene", "hw3", "--seed", "2020"])).unwrap();
    assert_eq!(seeded, printed, "2020 is the default seed");
}

#[test]
fn loading_the_committed_scene_gives_the_built_in_scene() {
    let loaded = Scene::load(Path::new(ASSET)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(loaded, hw3_scene(HW3_DEFAULT_SEED));
    assert_eq!(loaded.name, "hw3");

    // The recipe of SPEC §4, read back from the file: the four big balls, then 48 small
    // ones on the ground with the palette's colours and one kind each.
    let s = &loaded.spheres;
    assert_eq!(s.len(), 52);
    assert_eq!(
        (s[0].center, s[0].radius),
        (DVec3::new(0.0, -100.5, -2.0), 100.0)
    );
    assert_eq!((s[1].transmit, s[2].reflect), (0.9, 0.9));
    assert_eq!(s[3].color, DVec3::new(1.0, 0.7, 0.3));
    let palette = [
        [0.8, 0.3, 0.3],
        [0.3, 0.8, 0.3],
        [0.3, 0.3, 0.8],
        [0.8, 0.8, 0.3],
        [0.3, 0.8, 0.8],
        [0.8, 0.3, 0.8],
        [0.8, 0.8, 0.8],
        [0.3, 0.3, 0.3],
    ];
    let mut kinds = [0; 3];
    for b in &s[4..] {
        assert_eq!((b.center.y, b.radius), (-0.4, 0.1));
        assert!((-1.5..=1.5).contains(&b.center.x));
        assert!((-3.5..=-0.5).contains(&b.center.z));
        assert!(palette.contains(&b.color.to_array()));
        assert!(b.reflect == 0.0 || b.transmit == 0.0);
        let kind = if b.reflect > 0.0 {
            1 // mirror-ish
        } else if b.transmit > 0.0 {
            2 // glassy
        } else {
            0 // plain
        };
        kinds[kind] += 1;
    }
    assert_eq!(kinds.iter().sum::<i32>(), 48);
    assert!(
        kinds.iter().all(|&k| k > 5),
        "all three kinds occur: {kinds:?}"
    );
}

#[test]
fn the_binary_renders_the_committed_scene_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let built_in = dir.path().join("built-in.ppm");
    let from_file = dir.path().join("from-file.ppm");
    let size = ["--quiet", "--width", "64", "--height", "36", "--ppm-binary"];
    let mut a = vec!["render", "-o", built_in.to_str().unwrap()];
    a.extend(size);
    whitted(&a);
    let mut b = vec!["render", ASSET, "-o", from_file.to_str().unwrap()];
    b.extend(size);
    whitted(&b);
    assert_eq!(
        std::fs::read(&built_in).unwrap(),
        std::fs::read(&from_file).unwrap()
    );
}

#[test]
fn another_seed_moves_only_the_small_balls() {
    let text = String::from_utf8(whitted(&["scene", "hw3", "--seed", "7"])).unwrap();
    let other = parse(&text);
    let default = hw3_scene(HW3_DEFAULT_SEED);
    assert_eq!(other.spheres.len(), 52);
    assert_eq!(other.spheres[..4], default.spheres[..4]);
    assert_ne!(other.spheres[4..], default.spheres[4..]);
    assert_eq!(other.spheres, hw3_scene(7).spheres);
}

#[test]
fn writing_and_loading_round_trips() {
    let mut scene = parse(
        "[camera]\nlook_from = [1, 2, 3]\nlook_at = [0, 0.5, -1]\nup = [0, 1, 0]\nvfov = 40.5\n\
         [image]\nwidth = 320\nheight = 200\nmax_depth = 3\nspp = 9\nseed = 11\nquality = \"high\"\n\
         [sky]\ndown = [0.1, 0.2, 0.3]\nup = [0.4, 0.5, 0.6]\n\
         [[light]]\nposition = [1, 1, 1]\nintensity = [0.5, 0.25, 2]\n\
         [[sphere]]\ncenter = [0.1, 0.2, 0.3]\nradius = 0.7\ncolor = [0.3, 0.6, 0.9]\n\
         reflect = 0.2\ntransmit = 0.7\nior = 1.33\n",
    );
    scene.name = "scene".into();
    // The file's own spp and depth win over the preset's.
    let s = scene.settings();
    assert_eq!((s.quality.spp, s.quality.max_depth), (9, 3));
    assert!(scene.image.quality.is_some());
    assert_eq!(parse(&to_toml(&scene)), scene);
    let framed = Scene {
        camera: Some(CameraSpec::assignment_frame()),
        ..scene
    };
    assert_eq!(parse(&to_toml(&framed)), framed);
}

#[test]
fn missing_tables_and_keys_take_the_defaults() {
    let scene = parse("[[sphere]]\ncenter = [0.0, 0.0, -1.0]\nradius = 0.5\n");
    assert_eq!(scene.camera, None, "no camera: the assignment's");
    assert_eq!(scene.image, Overrides::default(), "no [image]: nothing set");
    let s = scene.settings();
    assert_eq!(
        (
            s.width,
            s.height,
            s.quality.max_depth,
            s.quality.spp,
            s.seed
        ),
        (1280, 720, 5, 1, 0)
    );
    assert_eq!(
        scene.sky,
        Sky {
            down: DVec3::ONE,
            up: DVec3::new(0.5, 0.7, 1.0)
        }
    );
    assert_eq!(
        scene.lights,
        [Light {
            position: DVec3::new(-10.0, 10.0, 0.0),
            intensity: DVec3::ONE
        }]
    );
    assert_eq!(
        scene.spheres,
        [Sphere {
            center: DVec3::new(0.0, 0.0, -1.0),
            radius: 0.5,
            color: DVec3::ONE,
            reflect: 0.0,
            transmit: 0.0,
            ior: 2.0
        }]
    );
    // Partial tables keep the defaults of the keys they leave out.
    let scene = parse("[image]\nspp = 4\n[sky]\nup = [0, 0, 1]\n[[light]]\nposition = [1, 2, 3]\n");
    let s = scene.settings();
    assert_eq!((s.quality.spp, s.width, s.quality.max_depth), (4, 1280, 5));
    assert_eq!((scene.sky.down, scene.sky.up), (DVec3::ONE, DVec3::Z));
    assert_eq!(scene.lights[0].intensity, DVec3::ONE);
    // An empty file is an empty scene under the default light.
    let empty = parse("");
    assert!(empty.spheres.is_empty());
    assert_eq!(empty.lights, [Light::default()]);
}

#[test]
fn integers_are_accepted_wherever_numbers_are_expected() {
    let ints = parse(
        "[camera]\nlook_from = [0, 1, 2]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 90\n\
         [sky]\ndown = [1, 1, 1]\nup = [0, 0, 1]\n\
         [[light]]\nposition = [-10, 10, 0]\nintensity = [2, 1, 0]\n\
         [[sphere]]\ncenter = [0, -100, -2]\nradius = 100\ncolor = [1, 0, 1]\n\
         reflect = 1\ntransmit = 0\nior = 3\n",
    );
    let floats = parse(
        "[camera]\nlook_from = [0.0, 1.0, 2.0]\nlook_at = [0.0, 0.0, -1.0]\n\
         up = [0.0, 1.0, 0.0]\nvfov = 90.0\n\
         [sky]\ndown = [1.0, 1.0, 1.0]\nup = [0.0, 0.0, 1.0]\n\
         [[light]]\nposition = [-10.0, 10.0, 0.0]\nintensity = [2.0, 1.0, 0.0]\n\
         [[sphere]]\ncenter = [0.0, -100.0, -2.0]\nradius = 100.0\ncolor = [1.0, 0.0, 1.0]\n\
         reflect = 1.0\ntransmit = 0.0\nior = 3.0\n",
    );
    assert_eq!(ints, floats);
    assert_eq!(ints.spheres[0].radius, 100.0);
    // Mixed within one array too.
    assert_eq!(
        parse("[[sphere]]\ncenter = [0, 0.5, -2]\nradius = 1\n").spheres[0].center,
        DVec3::new(0.0, 0.5, -2.0)
    );
}

#[track_caller]
fn assert_close(a: DVec3, b: DVec3) {
    assert!((a - b).abs().max_element() < 1e-12, "{a} vs {b}");
}

#[test]
fn both_camera_forms() {
    // The frame form is taken as given.
    let scene = parse(
        "[camera]\norigin = [0, 1, 0]\nlower_left = [-2, 0, -1]\n\
         horizontal = [4, 0, 0]\nvertical = [0, 2, 0]\n",
    );
    let spec = CameraSpec::Frame {
        origin: DVec3::Y,
        lower_left: DVec3::new(-2.0, 0.0, -1.0),
        horizontal: DVec3::new(4.0, 0.0, 0.0),
        vertical: DVec3::new(0.0, 2.0, 0.0),
    };
    assert_eq!(scene.camera, Some(spec));
    let cam = scene.camera(100, 100).unwrap();
    assert_eq!(
        (cam.origin, cam.lower_left, cam.horizontal, cam.vertical),
        (
            DVec3::Y,
            DVec3::new(-2.0, 0.0, -1.0),
            DVec3::X * 4.0,
            DVec3::Y * 2.0
        )
    );

    // The look-at form, by SPEC §2 by hand: from (0,0,0) at (0,0,-1), up y, vfov 90 at
    // 2:1. w = (0,0,1), u = (1,0,0), v = (0,1,0), h = tan 45° = 1, a = 2:
    // LL = O − a·h·u − h·v − w = (−2, −1, −1), H = 2·a·h·u = (4,0,0), V = 2·h·v = (0,2,0).
    let scene =
        parse("[camera]\nlook_from = [0, 0, 0]\nlook_at = [0, 0, -1]\nup = [0, 1, 0]\nvfov = 90\n");
    assert_eq!(
        scene.camera,
        Some(CameraSpec::LookAt {
            look_from: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
            vfov: 90.0
        })
    );
    let cam = scene.camera(200, 100).unwrap();
    assert_close(cam.origin, DVec3::ZERO);
    assert_close(cam.lower_left, DVec3::new(-2.0, -1.0, -1.0));
    assert_close(cam.horizontal, DVec3::new(4.0, 0.0, 0.0));
    assert_close(cam.vertical, DVec3::new(0.0, 2.0, 0.0));

    // Looking along +x from (1,2,3), vfov 90, square: w = (−1,0,0), u = up × w =
    // (0,0,1) (the image's right is +z), v = w × u = (0,1,0), h = a = 1:
    // LL = (1,2,3) − (0,0,1) − (0,1,0) + (1,0,0) = (2,1,2), H = (0,0,2), V = (0,2,0).
    let scene =
        parse("[camera]\nlook_from = [1, 2, 3]\nlook_at = [5, 2, 3]\nup = [0, 1, 0]\nvfov = 90\n");
    let cam = scene.camera(100, 100).unwrap();
    assert_close(cam.origin, DVec3::new(1.0, 2.0, 3.0));
    assert_close(cam.horizontal, DVec3::new(0.0, 0.0, 2.0));
    assert_close(cam.vertical, DVec3::new(0.0, 2.0, 0.0));
    assert_close(cam.lower_left, DVec3::new(2.0, 1.0, 2.0));

    // Keys of the look-at form left out take the assignment's values.
    let partial = parse("[camera]\nvfov = 60\n");
    assert_eq!(
        partial.camera,
        Some(CameraSpec::LookAt {
            look_from: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
            vfov: 60.0
        })
    );

    // Mixing the forms is an error.
    let err = Scene::from_toml_str("[camera]\norigin = [0, 0, 0]\nvfov = 90\n", "mixed.toml")
        .unwrap_err();
    assert!(err.to_string().starts_with("mixed.toml:"), "{err}");
}

#[test]
fn no_camera_means_the_assignments_view_at_any_aspect() {
    let scene = parse("");
    // 16:9: the assignment's exact frame.
    let cam = scene.camera(1280, 720).unwrap();
    assert_eq!(cam.lower_left, DVec3::new(-4.0, -2.25, -1.0));
    assert_eq!(
        (cam.horizontal, cam.vertical),
        (DVec3::X * 8.0, DVec3::Y * 4.5)
    );
    // 4:3: the same vertical view (vfov = 2·atan 2.25), the horizontal span follows.
    assert!((assignment_vfov_degrees() - 132.07502205).abs() < 1e-8);
    let cam = scene.camera(800, 600).unwrap();
    assert_close(cam.vertical, DVec3::new(0.0, 4.5, 0.0));
    assert_close(cam.horizontal, DVec3::new(6.0, 0.0, 0.0));
    assert_close(cam.lower_left, DVec3::new(-3.0, -2.25, -1.0));
}

#[test]
fn zero_lights() {
    let scene = parse("light = []\n[[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\n");
    assert!(scene.lights.is_empty());
    assert_eq!(scene.spheres.len(), 1);
    // And it writes back as an empty list, not as "the default light".
    assert!(parse(&to_toml(&scene)).lights.is_empty());
}
