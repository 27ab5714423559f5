//! The built-in scene of the assignment ("hw3") and its seeded generator.
//!
//! The 48 small balls are drawn with the Mersenne Twister exactly as Python's
//! `random.Random(seed)` draws them (`random()`, `randrange()`), in the order of the
//! peers' `make_hw3.py`; so seed 2020, the default, gives the very scene the peer
//! programs render, and benchmarks compare identical work.

use glam::DVec3;
use rand_mt::Mt;

use super::{Light, Scene, Sky, Sphere};
use crate::settings::{Overrides, Settings};

/// The seed of the built-in scene's 48 small balls.
pub const HW3_DEFAULT_SEED: u64 = 2020;

const PALETTE: [[f64; 3]; 8] = [
    [0.8, 0.3, 0.3],
    [0.3, 0.8, 0.3],
    [0.3, 0.3, 0.8],
    [0.8, 0.8, 0.3],
    [0.3, 0.8, 0.8],
    [0.8, 0.3, 0.8],
    [0.8, 0.8, 0.8],
    [0.3, 0.3, 0.3],
];

/// Python's `random.Random(seed)` for the calls the generator makes.
pub(super) struct PyRandom(Mt);

impl PyRandom {
    pub(super) fn new(seed: u64) -> Self {
        // Python seeds with the 32-bit words of the integer, least significant first.
        let key: Vec<u32> = if seed >> 32 == 0 {
            vec![seed as u32]
        } else {
            vec![seed as u32, (seed >> 32) as u32]
        };
        PyRandom(Mt::new_with_key(key))
    }

    /// `random()`: 53 random bits in [0, 1).
    pub(super) fn random(&mut self) -> f64 {
        let a = f64::from(self.0.next_u32() >> 5);
        let b = f64::from(self.0.next_u32() >> 6);
        (a * 67_108_864.0 + b) * (1.0 / 9_007_199_254_740_992.0)
    }

    /// `randrange(n)`: rejection sampling on `n.bit_length()` random bits.
    fn randrange(&mut self, n: u32) -> u32 {
        let bits = 32 - n.leading_zeros();
        loop {
            let r = self.0.next_u32() >> (32 - bits);
            if r < n {
                return r;
            }
        }
    }
}

/// A small ball's colour and weights `(kd, w_r, w_t)`: a palette colour, then one of
/// three kinds with equal chance: mirror-ish, glassy or plain diffuse.
pub(super) fn random_material(rng: &mut PyRandom) -> (DVec3, f64, f64) {
    let color = DVec3::from_array(PALETTE[rng.randrange(8) as usize]);
    let a = rng.random();
    let b = rng.random();
    let (reflect, transmit) = match rng.randrange(3) {
        0 => (a, 0.0), // mirror-ish
        1 => (0.0, b), // glassy
        _ => (0.0, 0.0),
    };
    (color, reflect, transmit)
}

/// The assignment's scene with the small balls drawn from `seed`.
pub fn hw3_scene(seed: u64) -> Scene {
    let mut spheres = vec![
        // ground
        Sphere::new(DVec3::new(0.0, -100.5, -2.0), 100.0),
        // glass ball
        Sphere {
            transmit: 0.9,
            ..Sphere::new(DVec3::new(0.0, 0.0, -2.0), 0.5)
        },
        // mirror ball
        Sphere {
            reflect: 0.9,
            ..Sphere::new(DVec3::new(1.0, 0.0, -1.75), 0.5)
        },
        // diffuse orange ball
        Sphere {
            color: DVec3::new(1.0, 0.7, 0.3),
            ..Sphere::new(DVec3::new(-1.0, 0.0, -2.25), 0.5)
        },
    ];
    let mut rng = PyRandom::new(seed);
    for _ in 0..48 {
        let x = rng.random() * 3.0 - 1.5;
        let z = rng.random() * 3.0 - 1.5;
        let (color, reflect, transmit) = random_material(&mut rng);
        spheres.push(Sphere {
            color,
            reflect,
            transmit,
            ..Sphere::new(DVec3::new(x, -0.4, z - 2.0), 0.1)
        });
    }
    Scene {
        name: "hw3".into(),
        camera: None,
        image: explicit(&Settings::default()),
        sky: Sky::default(),
        lights: vec![Light::default()],
        spheres,
        animation: None,
    }
}

/// The hw3 scene as a scene file (what `whitted scene hw3 --seed N` prints).
pub fn hw3_toml(seed: u64) -> String {
    let header = format!(
        "# The built-in \"hw3\" scene of the assignment: a huge ground sphere, a glass ball,\n\
         # a mirror ball, a diffuse orange ball and 48 small balls drawn from seed {seed}\n\
         # (`whitted scene hw3 --seed {seed}`). No [camera] table: the assignment's camera\n\
         # applies (origin 0, lower-left (-4,-2.25,-1), spans (8,0,0) and (0,4.5,0) at 16:9).\n"
    );
    // Label the spheres for a reader (the serializer writes no comments).
    let labels = [
        "# The ground.".to_string(),
        "# The glass ball.".into(),
        "# The mirror ball.".into(),
        "# The diffuse orange ball.".into(),
        format!("# 48 small balls from seed {seed}."),
    ];
    let body = super::write::to_toml(&hw3_scene(seed));
    let mut out = header + "\n";
    for (k, part) in body.split("[[sphere]]\n").enumerate() {
        if k > 0 {
            if let Some(label) = labels.get(k - 1) {
                out.push_str(label);
                out.push('\n');
            }
            out.push_str("[[sphere]]\n");
        }
        out.push_str(part);
    }
    out
}

/// Every value of `[image]` spelled out, as the built-in scene's file gives them.
fn explicit(s: &Settings) -> Overrides {
    Overrides {
        width: Some(s.width),
        height: Some(s.height),
        max_depth: Some(s.quality.max_depth),
        spp: Some(s.quality.spp),
        seed: Some(s.seed),
        ..Overrides::default()
    }
}
