//! The window (SPEC §6). Being written; see issue 3.

use crate::scene::Scene;

/// Opens the viewer on `scene` and returns when the window closes.
pub fn run(scene: Scene) -> anyhow::Result<()> {
    let _ = scene;
    anyhow::bail!("the viewer is not built yet: use `whitted render`")
}
