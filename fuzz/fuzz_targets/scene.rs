//! The scene loader: TOML text → a scene or a one-line error. A scene that loads
//! renders small images without a non-finite pixel (still, and the first and last
//! frames of its animation, with both tracers), and the scene writer turns it into text
//! that loads to the same scene.
#![no_main]

use libfuzzer_sys::fuzz_target;
use whitted::settings::{Overrides, Precision};
use whitted::{render, RenderControl, Scene};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match Scene::from_toml_str(text, "fuzz.toml") {
        Err(e) => check_error(text, &e),
        Ok(scene) => {
            renders_finite(&scene);
            writes_back(&scene);
        }
    }
});

/// One line, and a position inside the text.
fn check_error(text: &str, e: &whitted::SceneError) {
    let shown = e.to_string();
    assert!(
        !shown.contains('\n'),
        "an error of more than one line: {shown:?}"
    );
    assert!(shown.starts_with("fuzz.toml"), "{shown:?}");
    if let (Some(line), Some(column)) = (e.line, e.column) {
        let lines = text.split('\n').count();
        assert!(
            line >= 1 && line <= lines,
            "line {line} of {lines}: {shown:?}"
        );
        assert!(column >= 1, "{shown:?}");
    }
}

/// Renders `scene` at a few pixels: the scene's own settings but for the size, at most
/// 2 samples and depth 5, on one thread.
fn renders_finite(scene: &Scene) {
    let base = scene.settings();
    let small = |width, height, precision| {
        base.clone().with(&Overrides {
            width: Some(width),
            height: Some(height),
            spp: Some(base.quality.spp.min(2)),
            max_depth: Some(base.quality.max_depth.min(5)),
            precision: Some(precision),
            threads: Some(1),
            ..Overrides::default()
        })
    };
    let last = scene.frames() - 1;
    // 16×9 takes the assignment's exact frame when the scene has no camera; 12×12 its
    // look-at form.
    let cases = [
        (scene.clone(), small(16, 9, Precision::Fast)),
        (scene.frame(0, 12, 12), small(12, 12, Precision::Fast)),
        (scene.frame(last, 12, 12), small(12, 12, Precision::Fast)),
        (
            scene.frame(last / 2, 8, 6),
            small(8, 6, Precision::Reference),
        ),
    ];
    for (scene, settings) in cases {
        let (frame, _) = render(&scene, &settings, &RenderControl::default())
            .unwrap_or_else(|e| panic!("a loaded scene does not render: {e}"));
        assert_eq!(
            frame.pixels.len(),
            (settings.width * settings.height) as usize
        );
        if let Some(p) = frame.pixels.iter().find(|p| !p.is_finite()) {
            panic!(
                "a non-finite pixel {p:?} ({:?})",
                settings.quality.precision
            );
        }
    }
}

/// The writer's text loads to the same scene, and writes to the same text.
fn writes_back(scene: &Scene) {
    let text = whitted::scene::to_toml(scene);
    let again = Scene::from_toml_str(&text, "fuzz.toml")
        .unwrap_or_else(|e| panic!("the written scene does not load: {e}\n{text}"));
    assert_eq!(&again, scene, "written as:\n{text}");
    assert_eq!(whitted::scene::to_toml(&again), text);
}
