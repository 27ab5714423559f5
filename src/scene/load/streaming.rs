//! Big scene files: the common layout, settings first and then a run of `[[sphere]]`
//! tables to the end of the file, parsed a batch of tables at a time, in parallel, so
//! that the `toml` tree (35 to 65 times the text) never holds the whole file.

use std::ops::Range;

use rayon::prelude::*;

use super::messages::{from_toml, Locator};
use super::plain;
use super::schema::{FileScene, FileSphereTable};
use super::validate::{settings, sphere};
use crate::limits;
use crate::scene::{Scene, SceneError, Sphere};

/// Where a file's trailing run of `[[sphere]]` tables starts, and how many there are.
pub(super) struct SphereRun {
    /// Byte offsets of the `[[sphere]]` header lines.
    first: usize,
    count: usize,
}

impl SphereRun {
    /// Scans the lines (no allocation). `Err` when there are more `[[sphere]]` headers
    /// than [`limits::MAX_SPHERES`]; `None` when the spheres are not one trailing run of
    /// plain `[[sphere]]` tables, or when multi-line strings could hide header lines:
    /// then the file is parsed whole.
    pub(super) fn find(text: &str) -> Result<Option<SphereRun>, (usize, String)> {
        let mut first = None;
        let mut count = 0usize;
        let mut other_table_after = false;
        for (start, trimmed) in table_lines(text) {
            if is_sphere_header(trimmed) {
                count += 1;
                if count > limits::MAX_SPHERES {
                    return Err((
                        start,
                        format!(
                            "more than {} [[sphere]] tables: the limit is {}",
                            limits::MAX_SPHERES,
                            limits::MAX_SPHERES
                        ),
                    ));
                }
                first.get_or_insert(start);
            } else if first.is_some() {
                other_table_after = true;
            }
        }
        let bytes = text.as_bytes();
        let multi_line_strings = memchr::memmem::find(bytes, b"\"\"\"").is_some()
            || memchr::memmem::find(bytes, b"'''").is_some();
        Ok(match first {
            Some(first) if !other_table_after && !multi_line_strings => {
                Some(SphereRun { first, count })
            }
            _ => None,
        })
    }

    /// The byte ranges of the tables of the run, in order.
    fn tables<'t>(&self, text: &'t str) -> impl Iterator<Item = Range<usize>> + 't {
        let first = self.first;
        let mut starts = table_lines(&text[first..])
            .map(move |(start, trimmed)| (first + start, trimmed))
            .filter(|&(_, trimmed)| is_sphere_header(trimmed))
            .map(|(start, _)| start)
            .peekable();
        std::iter::from_fn(move || {
            let start = starts.next()?;
            let end = starts.peek().copied().unwrap_or(text.len());
            Some(start..end)
        })
    }
}

/// The lines whose first non-blank character is `[` (`trim_start`'s blanks): each
/// line's start, and the line from that `[` to its end. Found from the `[`s of the
/// text (a vectorised search), not line by line: a scene file has a few a table, and
/// many short lines. Each byte is looked at a bounded number of times, however long
/// the lines and however many `[`s they hold.
fn table_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let bytes = text.as_bytes();
    let (mut line_start, mut scanned, mut line_seen) = (0, 0, false);
    memchr::memchr_iter(b'[', bytes).filter_map(move |at| {
        if let Some(n) = memchr::memrchr(b'\n', &bytes[scanned..at]) {
            (line_start, line_seen) = (scanned + n + 1, false);
        }
        scanned = at;
        // Only a line's first `[` can be its first non-blank character.
        if std::mem::replace(&mut line_seen, true) {
            return None;
        }
        text[line_start..at]
            .chars()
            .all(char::is_whitespace)
            .then(|| {
                let end = memchr::memchr(b'\n', &bytes[at..]).map_or(text.len(), |n| at + n + 1);
                (line_start, &text[at..end])
            })
    })
}

/// `[[sphere]]`, spaces allowed inside the brackets, then nothing or a comment.
pub(super) fn is_sphere_header(line: &str) -> bool {
    let Some(rest) = line.strip_prefix("[[") else {
        return false;
    };
    let Some(rest) = rest.trim_start_matches([' ', '\t']).strip_prefix("sphere") else {
        return false;
    };
    let Some(rest) = rest.trim_start_matches([' ', '\t']).strip_prefix("]]") else {
        return false;
    };
    let rest = rest.trim();
    rest.is_empty() || rest.starts_with('#')
}

/// The settings before the run as one document, then each sphere table on its own.
pub(super) fn parse_with_run(text: &str, path: &str, run: &SphereRun) -> Result<Scene, SceneError> {
    let at = Locator {
        text,
        path,
        offset: 0,
    };
    let head = &text[..run.first];
    let file: FileScene = from_toml(head, &at)?;
    if file.sphere.is_some() {
        return Err(at.at(
            run.first..run.first,
            "[[sphere]] tables cannot follow a `sphere` array defined above",
        ));
    }
    let mut scene = settings(&at, &file)?;
    // Batches of consecutive tables, parsed in parallel: each batch's `toml` tree is
    // small (plainly written tables build none), and the batches come back in order,
    // so the first error is the first in the file.
    let mut batches: Vec<(usize, Range<usize>)> = Vec::new();
    for (k, range) in run.tables(text).enumerate() {
        match batches.last_mut() {
            Some((first, batch)) if k - *first < TABLES_PER_BATCH => batch.end = range.end,
            _ => batches.push((k, range)),
        }
    }
    let parsed: Vec<Result<Vec<Sphere>, SceneError>> = batches
        .par_iter()
        .map(|(first, range)| {
            let batch_at = Locator {
                text,
                path,
                offset: range.start,
            };
            let batch = &text[range.clone()];
            let count = (run.count - first).min(TABLES_PER_BATCH);
            let tables = match plain::sphere_tables(batch, count) {
                Some(tables) => tables,
                None => from_toml::<FileSphereTable>(batch, &batch_at)?.sphere,
            };
            tables
                .iter()
                .enumerate()
                .map(|(i, s)| sphere(&batch_at, s, first + i))
                .collect()
        })
        .collect();
    scene.spheres.reserve_exact(run.count);
    for batch in parsed {
        scene.spheres.extend(batch?);
    }
    if scene.spheres.len() != run.count {
        // Cannot happen: each batch holds exactly its header lines' tables.
        return Err(at.whole(format!(
            "found {} spheres for {} [[sphere]] headers",
            scene.spheres.len(),
            run.count
        )));
    }
    Ok(scene)
}

/// `[[sphere]]` tables parsed as one `toml` document when streaming (about 2 MB of tree).
const TABLES_PER_BATCH: usize = 512;
