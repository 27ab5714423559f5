//! The stress scenes (`assets/scenes/stress/`): the files load, say what they stress
//! and hold what the generator in `support` builds; the fast tracer matches the f64
//! reference on every one of them; moving or scaling hw3 does not change its image.
//!
//! `WHITTED_WRITE_STRESS=1 cargo test --release --test stress_scenes` rewrites the files.

mod support;

use support::*;
use whitted::scene::Scene;
use whitted::settings::Precision;

const W: u32 = 320;
const H: u32 = 180;

#[test]
fn stress_files_load_and_match_their_generator() {
    let dir = stress_dir();
    let write = std::env::var_os("WHITTED_WRITE_STRESS").is_some();
    if write {
        std::fs::create_dir_all(&dir).unwrap();
    }
    let scenes = stress_scenes();
    for s in &scenes {
        let path = dir.join(format!("{}.toml", s.name));
        let text = stress_text(s);
        if write {
            std::fs::write(&path, &text).unwrap();
        }
        let on_disk = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e} (generate with WHITTED_WRITE_STRESS=1)",
                path.display()
            )
        });
        assert!(
            on_disk.starts_with(&format!("# {}: ", s.name)),
            "{}: the file must open with a comment saying what it stresses",
            path.display()
        );
        let loaded = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(loaded.name, s.name);
        assert_eq!(
            loaded,
            s.scene,
            "{}: the file differs from the generator",
            path.display()
        );
    }
    // No stray files: every scene in the folder is one of the generated ones.
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    on_disk.sort();
    let mut expected: Vec<String> = scenes.iter().map(|s| format!("{}.toml", s.name)).collect();
    expected.sort();
    assert_eq!(on_disk, expected);
}

/// Fast vs f64 reference at 320×180: at most 0.01% of the pixels off by more than one
/// level, 0 non-finite samples.
#[test]
fn fast_matches_reference_on_the_stress_scenes() {
    let names: Vec<&str> = stress_scenes().iter().map(|s| s.name).collect();
    println!("\n{SCENE_TABLE_HEADER}");
    let failures = check_fast_vs_reference(&names, W, H);
    assert!(failures.is_empty(), "{failures:?}");
}

/// Scaling by 1e-3 or 1e3 or translating by 1e4 changes nothing in the shading model
/// (no distance fall-off), so the image must stay the same: at most 0.1% of the pixels
/// off by more than one level, with either tracer.
#[test]
fn transformed_hw3_renders_like_hw3() {
    println!("\n{TRANSFORM_TABLE_HEADER}");
    let all = ["scale 1e-3", "scale 1e3", "translate (1e4,1e4,1e4)"];
    let mut failures = check_transforms(Precision::Fast, &all, W, H);
    failures.extend(check_transforms(Precision::Reference, &all, W, H));
    assert!(failures.is_empty(), "{failures:?}");
}
