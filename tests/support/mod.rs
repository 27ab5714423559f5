//! Shared by the integration tests: the stress scenes, built in code from the hw3 scene
//! so that the files in `assets/scenes/stress/` can be checked against what they claim
//! to be; a helper that renders a scene with either tracer and counts non-finite
//! samples before they are zeroed; and proptest's seeded runner and strategies.
#![allow(dead_code)]

pub mod spec_reference;

use std::path::PathBuf;

use glam::{DVec3, Vec3};
use proptest::strategy::Strategy;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use whitted::camera::CameraSpec;
use whitted::render::{self, RenderControl};
use whitted::scene::{self, Light, Scene, Sphere};
use whitted::settings::Precision;

/// The folder of the stress scenes.
pub fn stress_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/stress")
}

/// One stress scene: its file stem, what it stresses (the file's leading comment) and
/// the scene itself.
pub struct Stress {
    pub name: &'static str,
    pub comment: &'static str,
    pub scene: Scene,
}

/// The built-in hw3 scene with its camera made explicit (the assignment's exact frame),
/// so that transforms can move the camera with the world.
pub fn hw3() -> Scene {
    let mut s = scene::hw3_scene(scene::HW3_DEFAULT_SEED);
    s.camera = Some(CameraSpec::assignment_frame());
    s
}

/// `scene` with every position mapped by `p ↦ p·scale + shift`, radii and camera spans
/// scaled. The shading model has no distance fall-off, so the image is the same.
pub fn transformed(scene: &Scene, scale: f64, shift: DVec3) -> Scene {
    let p = |v: DVec3| v * scale + shift;
    let mut s = scene.clone();
    s.camera = Some(match scene.camera_spec(16, 9) {
        CameraSpec::Frame {
            origin,
            lower_left,
            horizontal,
            vertical,
        } => CameraSpec::Frame {
            origin: p(origin),
            lower_left: p(lower_left),
            horizontal: horizontal * scale,
            vertical: vertical * scale,
        },
        CameraSpec::LookAt {
            look_from,
            look_at,
            up,
            vfov,
        } => CameraSpec::LookAt {
            look_from: p(look_from),
            look_at: p(look_at),
            up,
            vfov,
        },
    });
    for l in &mut s.lights {
        l.position = p(l.position);
    }
    for b in &mut s.spheres {
        b.center = p(b.center);
        b.radius *= scale;
    }
    s
}

fn named(mut scene: Scene, name: &str) -> Scene {
    scene.name = name.to_string();
    scene
}

fn ball(center: [f64; 3], radius: f64, color: [f64; 3], reflect: f64, transmit: f64) -> Sphere {
    Sphere {
        color: DVec3::from_array(color),
        reflect,
        transmit,
        ..Sphere::new(DVec3::from_array(center), radius)
    }
}

/// A deterministic sequence in [0, 1) for placing balls (splitmix64).
struct Seq(u64);

impl Seq {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// hw3 with the ground replaced by a sphere of radius `r` whose top stays at y = −0.5.
fn big_ground(r: f64) -> Scene {
    let mut s = hw3();
    s.spheres[0].radius = r;
    s.spheres[0].center = DVec3::new(0.0, -0.5 - r, -2.0);
    s
}

/// Tiny balls (r = 1e-3) `dist` away from a camera at the origin looking down −z,
/// spread over the view; every third one glassy, every third one a mirror; a diffuse
/// backdrop ball behind them so that refraction has something to bend.
fn tiny(dist: f64, seed: u64) -> Scene {
    let r = 1e-3;
    // A view about 36 radii high, so each ball is about 10 pixels tall at 180 rows.
    let half_height = 18.0 * r;
    let vfov = 2.0 * (half_height / dist).atan().to_degrees();
    let mut seq = Seq(seed);
    let mut spheres = Vec::new();
    for k in 0..30 {
        let x = (seq.next() * 2.0 - 1.0) * half_height * 1.6;
        let y = (seq.next() * 2.0 - 1.0) * half_height * 0.9;
        let z = -dist - seq.next() * 10.0 * r;
        let (reflect, transmit) = match k % 3 {
            0 => (0.0, 0.9),
            1 => (0.8, 0.0),
            _ => (0.0, 0.0),
        };
        let color = [0.3 + 0.5 * seq.next(), 0.3 + 0.5 * seq.next(), 0.8];
        spheres.push(ball([x, y, z], r, color, reflect, transmit));
    }
    // Backdrop: a diffuse ball whose near side is 20 radii behind the tiny ones.
    let back_r = 10.0 * r;
    spheres.push(ball(
        [0.0, 0.0, -dist - 20.0 * r - back_r],
        back_r,
        [1.0, 0.7, 0.3],
        0.0,
        0.0,
    ));
    Scene {
        name: String::new(),
        camera: Some(CameraSpec::LookAt {
            look_from: DVec3::ZERO,
            look_at: DVec3::new(0.0, 0.0, -dist),
            up: DVec3::Y,
            vfov,
        }),
        image: hw3().image,
        sky: Default::default(),
        // Up and to the left of the balls, far enough to shine on all of them alike.
        lights: vec![Light {
            position: DVec3::new(-10.0 * dist, 10.0 * dist, 0.0),
            intensity: DVec3::ONE,
        }],
        spheres,
        animation: None,
    }
}

/// Every stress scene, in the order of the table `stress_scenes.rs` prints.
pub fn stress_scenes() -> Vec<Stress> {
    let mut out = Vec::new();
    let mut push = |name: &'static str, comment: &'static str, scene: Scene| {
        out.push(Stress {
            name,
            comment,
            scene: named(scene, name),
        })
    };
    push(
        "ground-1e5",
        "A ground sphere of radius 1e5 under the hw3 balls: rays meet it at grazing angles \
         near the horizon, where f32 intersection maths loses t.",
        big_ground(1e5),
    );
    push(
        "ground-1e6",
        "A ground sphere of radius 1e6 under the hw3 balls: as ground-1e5, ten times larger.",
        big_ground(1e6),
    );
    push(
        "hw3-translated-1e4",
        "The hw3 scene (camera and light too) translated by (1e4, 1e4, 1e4): every \
         coordinate is large, so f32 positions keep only about 1e-3 of absolute precision.",
        transformed(&hw3(), 1.0, DVec3::splat(1e4)),
    );
    push(
        "hw3-scaled-1e-3",
        "The hw3 scene (camera and light too) scaled by 1e-3: small balls of radius 1e-4 \
         and a ground of radius 0.1.",
        transformed(&hw3(), 1e-3, DVec3::ZERO),
    );
    push(
        "hw3-scaled-1e3",
        "The hw3 scene (camera and light too) scaled by 1e3: a ground of radius 1e5 and \
         spawn points with coordinates in the thousands.",
        transformed(&hw3(), 1e3, DVec3::ZERO),
    );
    push(
        "tiny-near",
        "Thirty balls of radius 1e-3 only 0.05 from the camera, a third of them glassy and \
         a third mirrors: spawn offsets must scale down with the ball.",
        tiny(0.05, 1),
    );
    push(
        "tiny-far",
        "Thirty balls of radius 1e-3 at distance 1e3 from the camera (a very narrow field \
         of view), a third of them glassy: hit/miss and spawn points at f32 resolution.",
        tiny(1e3, 2),
    );
    push(
        "camera-in-glass",
        "The camera sits inside a glass ball (ior 1.5) in the hw3 scene: every primary ray \
         starts inside and leaves through the far root; many undergo total internal \
         reflection.",
        {
            let mut s = hw3();
            s.spheres
                .push(ball([0.0, 0.0, 0.0], 0.3, [1.0, 1.0, 1.0], 0.0, 1.0));
            let last = s.spheres.len() - 1;
            s.spheres[last].ior = 1.5;
            s
        },
    );
    push(
        "facing-mirrors",
        "Two huge facing mirror spheres (radius 1e4, reflect 0.95) with balls between \
         them, max_depth 64: rays bounce to the depth limit.",
        {
            let r = 1e4;
            let mut s = hw3();
            s.spheres.truncate(4);
            s.spheres
                .push(ball([-r - 2.5, 0.0, -2.0], r, [1.0, 1.0, 1.0], 0.95, 0.0));
            s.spheres
                .push(ball([r + 2.5, 0.0, -2.0], r, [1.0, 1.0, 1.0], 0.95, 0.0));
            s.camera = Some(CameraSpec::LookAt {
                look_from: DVec3::new(-1.5, 0.5, 2.0),
                look_at: DVec3::new(0.5, 0.0, -2.0),
                up: DVec3::Y,
                vfov: 70.0,
            });
            s.image.max_depth = Some(64);
            // Between the mirrors (the default light would sit inside the left one).
            s.lights = vec![Light {
                position: DVec3::new(0.0, 5.0, 0.0),
                intensity: DVec3::ONE,
            }];
            s
        },
    );
    push(
        "resting-grazing",
        "Balls resting exactly on the ground (touching), balls interpenetrating each other \
         and the ground, lit by a light 4 degrees above the horizon: long shadows, shadow \
         rays that graze the ground and start next to other surfaces.",
        {
            let mut s = hw3();
            s.spheres.truncate(1);
            s.spheres[0].radius = 1e3;
            s.spheres[0].center = DVec3::new(0.0, -0.5 - 1e3, -2.0);
            let top = -0.5;
            // Resting: touching the ground at one point.
            for (k, (x, r)) in [(-1.2, 0.3), (-0.4, 0.2), (0.3, 0.25), (1.1, 0.35)]
                .iter()
                .enumerate()
            {
                let z = -2.0 - 0.4 * k as f64;
                s.spheres.push(ball(
                    [*x, top + r, z],
                    *r,
                    [0.8, 0.3 + 0.15 * k as f64, 0.3],
                    if k == 2 { 0.6 } else { 0.0 },
                    if k == 3 { 0.8 } else { 0.0 },
                ));
            }
            // Interpenetrating the ground.
            s.spheres.push(ball(
                [-0.8, top + 0.1, -1.4],
                0.2,
                [0.3, 0.8, 0.3],
                0.0,
                0.0,
            ));
            s.spheres
                .push(ball([0.7, top, -1.3], 0.15, [0.3, 0.3, 0.8], 0.0, 0.7));
            // Interpenetrating each other (and resting): a pair and a stack.
            s.spheres
                .push(ball([0.0, top + 0.2, -1.5], 0.2, [0.8, 0.8, 0.3], 0.0, 0.0));
            s.spheres.push(ball(
                [0.25, top + 0.2, -1.5],
                0.2,
                [0.3, 0.8, 0.8],
                0.5,
                0.0,
            ));
            s.spheres.push(ball(
                [-0.4, top + 0.6, -2.4],
                0.2,
                [0.8, 0.3, 0.8],
                0.0,
                0.0,
            ));
            s.lights = vec![Light {
                position: DVec3::new(-20.0, 1.0, -2.0),
                // Bright, so that the ground it grazes is not black.
                intensity: DVec3::splat(6.0),
            }];
            s
        },
    );
    push(
        "crowded-light",
        "The camera and the light inside a small hollow walled by 600 overlapping balls \
         of radius 1, a third mirrors and a third glass, with 40 small balls in the \
         hollow: each big ball fills a ninth to a fifth of the sky seen from the light, \
         too many cells for the light's directional grid at its resolution, so it gets \
         one at half of it.",
        {
            let mut s = hw3();
            let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
            let on_sphere = |k: usize, of: usize| {
                let z = 1.0 - 2.0 * (k as f64 + 0.5) / of as f64;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * k as f64;
                DVec3::new(r * phi.cos(), r * phi.sin(), z)
            };
            s.spheres = (0..600)
                .map(|k| {
                    let c = on_sphere(k, 600) * (1.3 + 0.03 * (k * 7 % 11) as f64);
                    let color = [0.3 + 0.5 * (k % 2) as f64, 0.5, 0.8 - 0.4 * (k % 3) as f64];
                    let (reflect, transmit) = [(0.0, 0.0), (0.7, 0.0), (0.0, 0.8)][k % 3];
                    ball(c.to_array(), 1.0, color, reflect, transmit)
                })
                .chain((0..40).map(|k| {
                    let c = on_sphere(k, 40) * 0.2;
                    ball(c.to_array(), 0.03, [0.9, 0.9, 0.2], 0.0, 0.0)
                }))
                .collect();
            s.camera = Some(CameraSpec::LookAt {
                look_from: DVec3::ZERO,
                look_at: DVec3::new(0.0, -0.3, -1.0),
                up: DVec3::Y,
                vfov: 90.0,
            });
            s.lights = vec![Light {
                position: DVec3::new(0.1, 0.05, -0.05),
                intensity: DVec3::ONE,
            }];
            s
        },
    );
    push(
        "clump",
        "A clump of 120 balls of radius 0.5 whose centres lie within 0.5 of a point, so that \
         each overlaps every other, a third mirrors and most of the rest glass, on the \
         ground: rays inside a ball that overlaps more than 16 others walk the hierarchy \
         instead of testing a list of them.",
        {
            let mut s = hw3();
            let mut seq = Seq(11);
            let ground = s.spheres[0];
            s.spheres = std::iter::once(ground)
                .chain((0..120).map(|k| {
                    let offset = loop {
                        let v = DVec3::new(seq.next(), seq.next(), seq.next()) * 2.0 - 1.0;
                        if v.length_squared() <= 1.0 {
                            break v;
                        }
                    };
                    let c = DVec3::new(0.0, 0.3, -1.4) + offset * 0.5;
                    let color = [0.3 + 0.5 * (k % 2) as f64, 0.6, 0.8 - 0.4 * (k % 3) as f64];
                    let (reflect, transmit) = [(0.9, 0.0), (0.1, 0.9), (0.0, 0.8)][k % 3];
                    ball(c.to_array(), 0.5, color, reflect, transmit)
                }))
                .collect();
            s
        },
    );
    out
}

/// The text of a stress scene's file: its comment, wrapped, then the scene.
pub fn stress_text(s: &Stress) -> String {
    let mut text = String::new();
    let mut line = String::from("#");
    for word in format!("{}: {}", s.name, s.comment).split_whitespace() {
        if line.len() + 1 + word.len() > 88 {
            text.push_str(&line);
            text.push('\n');
            line = String::from("#");
        }
        line.push(' ');
        line.push_str(word);
    }
    text.push_str(&line);
    text.push_str("\n# Generated by tests/support (WHITTED_WRITE_STRESS=1 cargo test --release --test stress_scenes).\n");
    text + &scene::to_toml(&s.scene)
}

/// A render's 8-bit image (top row first) and how many samples were not finite before
/// `render::resolve` zeroed them (for the reference, before `spec_reference` did).
pub struct Rendered {
    pub rgb: Vec<u8>,
    pub non_finite: usize,
    pub seconds: f64,
}

pub fn render_with(scene: &Scene, width: u32, height: u32, renderer: Precision) -> Rendered {
    let mut opts = scene.settings();
    opts.width = width;
    opts.height = height;
    opts.quality.spp = 1;
    opts.quality.precision = renderer;
    opts.check().expect("valid options");
    let start = std::time::Instant::now();
    if renderer == Precision::Reference {
        // The reference's image by the SPEC's formulas, not the renderer's.
        let image = spec_reference::spec_reference(scene, &opts);
        return Rendered {
            rgb: image.rgb,
            non_finite: image.non_finite,
            seconds: start.elapsed().as_secs_f64(),
        };
    }
    let control = RenderControl::default();
    let tracer = render::make_tracer(scene, &opts).expect("a tracer");
    let mut sums = vec![Vec3::ZERO; (width * height) as usize];
    render::accumulate(tracer.as_ref(), &opts, 0..1, &mut sums, &control).expect("rendered");
    let non_finite = sums.iter().filter(|c| !c.is_finite()).count();
    let frame = render::resolve(&sums, 1, width, height);
    Rendered {
        rgb: whitted::image_io::to_rgb8(&frame, whitted::image_io::Encoding::Linear).into_raw(),
        non_finite,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Pixels (of RGB8 images) where any channel differs by more than one level, and the
/// largest difference.
pub fn pixels_off(a: &[u8], b: &[u8]) -> (usize, u8) {
    assert_eq!(a.len(), b.len());
    let mut off = 0;
    let mut max = 0u8;
    for (p, q) in a.chunks_exact(3).zip(b.chunks_exact(3)) {
        let d = p
            .iter()
            .zip(q)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        max = max.max(d);
        if d > 1 {
            off += 1;
        }
    }
    (off, max)
}

/// The transforms of hw3 that must not change its image.
pub const TRANSFORMS: [(&str, f64, [f64; 3]); 3] = [
    ("scale 1e-3", 1e-3, [0.0; 3]),
    ("scale 1e3", 1e3, [0.0; 3]),
    ("translate (1e4,1e4,1e4)", 1.0, [1e4; 3]),
];

/// Renders hw3 and its transforms with `renderer` at `width`×`height` and checks that
/// at most `limit_fraction` of the pixels are off by more than one level; prints a
/// table row per transform. `cases` picks transforms by name.
pub fn check_transforms(
    renderer: Precision,
    cases: &[&str],
    width: u32,
    height: u32,
) -> Vec<String> {
    let base = hw3();
    let limit = (f64::from(width * height) * 1e-3).floor() as usize;
    let plain = render_with(&base, width, height, renderer);
    assert_eq!(plain.non_finite, 0);
    let mut failures = Vec::new();
    for (name, scale, shift) in TRANSFORMS.iter().filter(|t| cases.contains(&t.0)) {
        let moved = render_with(
            &transformed(&base, *scale, DVec3::from_array(*shift)),
            width,
            height,
            renderer,
        );
        let (off, max) = pixels_off(&plain.rgb, &moved.rgb);
        println!(
            "{:<24} {:<10} {:>8} {:>8.4}% {:>8} {:>8}",
            name,
            format!("{renderer:?}"),
            off,
            100.0 * off as f64 / f64::from(width * height),
            max,
            moved.non_finite
        );
        if off > limit || moved.non_finite > 0 {
            failures.push(format!(
                "{name} {renderer:?}: {off} pixels off (limit {limit}), {} non-finite",
                moved.non_finite
            ));
        }
    }
    failures
}

/// Fast vs f64 reference at `width`×`height`, 1 spp, on the named stress scenes (read
/// from their files): at most 0.01% of the pixels off by more than one level and no
/// non-finite sample. Prints a table row per scene; returns the failures.
pub fn check_fast_vs_reference(names: &[&str], width: u32, height: u32) -> Vec<String> {
    let limit = (f64::from(width * height) * 1e-4).floor() as usize;
    let mut failures = Vec::new();
    for s in stress_scenes()
        .into_iter()
        .filter(|s| names.contains(&s.name))
    {
        let scene = Scene::load(&stress_dir().join(format!("{}.toml", s.name)))
            .unwrap_or_else(|e| panic!("{e}"));
        let fast = render_with(&scene, width, height, Precision::Fast);
        let reference = render_with(&scene, width, height, Precision::Reference);
        let (off, max) = pixels_off(&fast.rgb, &reference.rgb);
        let non_finite = fast.non_finite + reference.non_finite;
        println!(
            "{:<20} {:>8} {:>8.4}% {:>8} {:>8} {:>9.3} {:>9.3}",
            s.name,
            off,
            100.0 * off as f64 / f64::from(width * height),
            max,
            non_finite,
            fast.seconds,
            reference.seconds
        );
        if off > limit || non_finite > 0 {
            failures.push(format!(
                "{}: {off} pixels off (limit {limit}), {non_finite} non-finite",
                s.name
            ));
        }
    }
    failures
}

pub const SCENE_TABLE_HEADER: &str =
    "scene                   off>1     off % max diff  NaN/Inf    fast s     ref s";
pub const TRANSFORM_TABLE_HEADER: &str =
    "transform                tracer        off>1     off % max diff  NaN/Inf";

/// A proptest runner of `cases` cases with a fixed seed and no persisted failures, so
/// that the printed figures reproduce.
pub fn runner(cases: u32) -> TestRunner {
    TestRunner::new_with_rng(
        Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    )
}

/// Log-uniform `10^U(lo, hi)`.
pub fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo..hi).prop_map(|e: f64| 10f64.powf(e))
}

/// A uniformly distributed unit vector.
pub fn unit_vector() -> impl Strategy<Value = DVec3> {
    (-1.0f64..1.0, 0.0f64..std::f64::consts::TAU).prop_map(|(z, phi)| {
        let s = (1.0 - z * z).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    })
}

/// An index of refraction 1 + 10^U(−3, 0.2) (1.001 to 2.58).
pub fn ior() -> impl Strategy<Value = f64> {
    log_uniform(-3.0, 0.2).prop_map(|x| 1.0 + x)
}

/// sin of the angle between two vectors, in `f64`.
pub fn sin_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length() / (a.length() * b.length())
}
