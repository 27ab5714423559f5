//! What the study measures: its scenes and the grid of quality settings.

use glam::DVec3;

use crate::scene::{hw3_scene, many_scene, Scene, HW3_DEFAULT_SEED};
use crate::settings::{Adaptive, Precision, Preset, Quality};

/// A scene of the study.
#[derive(Clone, Debug)]
pub struct BenchScene {
    pub name: String,
    pub scene: Scene,
}

/// The scenes of the study: the built-in hw3; "stress", hw3 on a ground sphere of
/// radius 1e5 (grazing precision); "many_N", N small random balls on a large ground
/// (many tiny features: aliasing everywhere); "glass", hw3 with every ball glassy
/// (long transmission chains, where depth and the cutoff matter).
pub fn study_scenes(tiny: bool) -> Vec<BenchScene> {
    let hw3 = hw3_scene(HW3_DEFAULT_SEED);

    let mut stress = hw3.clone();
    stress.name = "stress".into();
    stress.spheres[0].center = DVec3::new(0.0, -1e5 - 0.5, -2.0);
    stress.spheres[0].radius = 1e5;

    let mut glass = hw3.clone();
    glass.name = "glass".into();
    for s in glass.spheres.iter_mut().skip(1) {
        // Transmission only: with a reflected branch too, every glass hit doubles the
        // rays and the depth-16 reference becomes exponentially slow.
        s.transmit = 0.9;
        s.reflect = 0.0;
        s.ior = 1.5;
    }

    let n = if tiny { 50 } else { 1000 };
    vec![
        BenchScene {
            name: "hw3".into(),
            scene: hw3,
        },
        BenchScene {
            name: "stress".into(),
            scene: stress,
        },
        BenchScene {
            name: format!("many_{n}"),
            scene: many_scene(n),
        },
        BenchScene {
            name: "glass".into(),
            scene: glass,
        },
    ]
}

/// One setting of the grid; `preset` names it when it is a preset's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    pub quality: Quality,
    pub preset: Option<Preset>,
}

/// A setting of the fast (`f32`) tracer.
fn fast(spp: u32, threshold: Option<f32>, cutoff: f32, max_depth: u32) -> Quality {
    Quality {
        spp,
        adaptive: threshold.map(Adaptive::with_threshold),
        cutoff,
        max_depth,
        precision: Precision::Fast,
    }
}

/// The plain setting, from which each knob is swept: 1 spp, depth 5, exact (the
/// program's default).
pub(crate) fn plain() -> Quality {
    fast(1, None, 0.0, 5)
}

/// The settings measured on every scene. Each knob is swept alone from the plain
/// setting (1 spp, depth 5, exact), then a few combinations, then the presets (the
/// reference preset is the converged reference itself, rendered once per scene).
pub fn grid(tiny: bool) -> Vec<Setting> {
    let mut qs: Vec<Quality> = Vec::new();
    if tiny {
        qs.push(plain());
        qs.push(fast(4, Some(0.05), 0.0, 5));
        qs.push(fast(1, None, 0.05, 3));
    } else {
        // Square counts (and 2) only: the stratification fills an n×n grid of cells,
        // and other counts leave part of its last row empty, a bias in the error.
        for spp in [1, 2, 4, 9, 16, 36, 64] {
            qs.push(fast(spp, None, 0.0, 5));
        }
        for spp in [16, 64] {
            for t in [0.01, 0.03, 0.1] {
                qs.push(fast(spp, Some(t), 0.0, 5));
            }
        }
        for eps in [0.01, 0.05, 0.2] {
            qs.push(fast(1, None, eps, 5));
        }
        for d in [1, 2, 3, 4, 8, 16] {
            qs.push(fast(1, None, 0.0, d));
        }
        // Fixed spp at depth 16, the comparison for the presets (same depth, no
        // adaptive sampling); 1 spp at depth 16 is in the depth sweep.
        for spp in [4, 9, 16, 36, 64] {
            qs.push(fast(spp, None, 0.0, 16));
        }
        qs.push(fast(9, Some(0.03), 0.0, 16));
        qs.push(fast(16, Some(0.1), 0.0, 16));
        qs.push(fast(16, Some(0.03), 0.0, 16));
        qs.push(fast(16, Some(0.03), 0.01, 16));
        qs.push(fast(64, Some(0.03), 0.0, 16));
        qs.push(fast(64, Some(0.01), 0.0, 16));
        qs.push(Quality {
            precision: Precision::Reference,
            ..plain()
        });
    }
    let mut settings: Vec<Setting> = qs
        .into_iter()
        .map(|quality| Setting {
            quality,
            preset: None,
        })
        .collect();
    for p in [Preset::Draft, Preset::Default, Preset::High] {
        let q = p.quality();
        match settings.iter_mut().find(|s| s.quality == q) {
            Some(s) => s.preset = Some(p),
            None => settings.push(Setting {
                quality: q,
                preset: Some(p),
            }),
        }
    }
    settings
}
