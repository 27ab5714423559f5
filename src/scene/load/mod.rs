//! Scene files (TOML, SPEC §4): parsing with `serde` + `toml`, then validation of every
//! value with the line and column of the offending key. Nothing here panics on input.
//!
//! Memory: `toml` builds a tree of the whole document before `serde` sees it, about 35
//! to 65 times the size of the text (483 MB for the 13.5 MB many_100000 scene, 2.3 GB
//! for a million minimal spheres). So the common layout of big scenes, the settings
//! first and then a run of `[[sphere]]` tables to the end of the file, is parsed in
//! batches of tables, in parallel ([`SphereRun`]: many_100000 peaks at 24 MB), and
//! every other layout only up to
//! [`limits::MAX_WHOLE_PARSE_BYTES`]. The sphere count is known from a scan of the
//! lines before anything is parsed, so a file with too many spheres is refused first.
//!
//! The steps: [`schema`] (serde types), [`streaming`] (big files in batches, their
//! plainly written `[[sphere]]` tables read by [`plain`] without `toml`'s tree),
//! [`validate`] (values against SPEC §3) and [`messages`] (positions and wording).

mod messages;
mod plain;
mod schema;
mod streaming;
mod validate;

use std::path::Path;

use messages::{from_toml, Locator};
use schema::FileScene;
use streaming::{parse_with_run, SphereRun};
use validate::{settings, sphere};

use super::{Scene, SceneError};
use crate::limits;

pub(super) fn load(path: &Path) -> Result<Scene, SceneError> {
    let shown = path.display().to_string();
    let io_error = |e: std::io::Error| {
        SceneError::whole(shown.clone(), format!("cannot read scene file: {e}"))
    };
    let size = std::fs::metadata(path).map_err(io_error)?.len();
    if size > limits::MAX_FILE_BYTES {
        return Err(SceneError::whole(
            shown,
            format!(
                "scene file is {size} bytes, more than the limit of {}",
                limits::MAX_FILE_BYTES
            ),
        ));
    }
    let bytes = std::fs::read(path).map_err(io_error)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        SceneError::whole(
            shown.clone(),
            format!(
                "scene file is not UTF-8 text (byte {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })?;
    let mut scene = parse(&text, &shown)?;
    scene.name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    Ok(scene)
}

/// Parses and validates scene text, streaming a trailing run of `[[sphere]]` tables.
pub(super) fn parse(text: &str, path: &str) -> Result<Scene, SceneError> {
    let at = Locator {
        text,
        path,
        offset: 0,
    };
    if text.len() as u64 > limits::MAX_FILE_BYTES {
        return Err(at.whole(format!(
            "scene text is {} bytes, more than the limit of {}",
            text.len(),
            limits::MAX_FILE_BYTES
        )));
    }
    match SphereRun::find(text).map_err(|(offset, m)| at.at(offset..offset, m))? {
        Some(run) => parse_with_run(text, path, &run),
        None => parse_whole(text, path),
    }
}

/// Parses and validates scene text as one TOML document (no streaming).
pub(super) fn parse_whole(text: &str, path: &str) -> Result<Scene, SceneError> {
    let at = Locator {
        text,
        path,
        offset: 0,
    };
    if text.len() as u64 > limits::MAX_WHOLE_PARSE_BYTES {
        return Err(at.whole(format!(
            "scene text is {} bytes: files over {} bytes must put their spheres last, as \
             [[sphere]] tables with no other table after them",
            text.len(),
            limits::MAX_WHOLE_PARSE_BYTES
        )));
    }
    let file: FileScene = from_toml(text, &at)?;
    let mut scene = settings(&at, &file)?;
    let list = file.sphere.map(|b| b.0).unwrap_or_default();
    scene.spheres.reserve_exact(list.len());
    for (k, s) in list.iter().enumerate() {
        scene.spheres.push(sphere(&at, s, k)?);
    }
    Ok(scene)
}
