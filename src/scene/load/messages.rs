//! Error messages that name the file, line and column, and say what a scene file
//! says: serde's wording of a wrong type ("invalid type: string, expected f64") in
//! the words of a scene file, and the field a bad value belongs to.

use std::ops::Range;

use crate::scene::SceneError;

/// Turns byte offsets into `path:line:column` messages.
pub(super) struct Locator<'a> {
    pub(super) text: &'a str,
    pub(super) path: &'a str,
    /// Where the text that was parsed (and that spans count in) starts in `text`.
    pub(super) offset: usize,
}

impl Locator<'_> {
    pub(super) fn at(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        let offset = span.start.saturating_add(self.offset).min(self.text.len());
        let before = &self.text[..self.text.floor_char_boundary_compat(offset)];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        SceneError {
            path: self.path.to_string(),
            line: Some(line),
            column: Some(column),
            message: message.into(),
        }
    }

    pub(super) fn whole(&self, message: impl Into<String>) -> SceneError {
        SceneError::whole(self.path, message)
    }
}

pub(super) trait FloorCharBoundary {
    fn floor_char_boundary_compat(&self, i: usize) -> usize;
}

impl FloorCharBoundary for str {
    fn floor_char_boundary_compat(&self, mut i: usize) -> usize {
        while !self.is_char_boundary(i) {
            i -= 1;
        }
        i
    }
}

pub(super) fn from_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    at: &Locator,
) -> Result<T, SceneError> {
    toml::from_str(text).map_err(|e| {
        let message = e.message().trim().replace('\n', " ");
        match (e.span(), plain_type_error(&message)) {
            // A value of the wrong type or length: named by its field, as the
            // validation messages name theirs.
            (Some(span), Some(plain)) => {
                let message = match field_at(at.text, span.start.saturating_add(at.offset)) {
                    Some(field) => format!("{field}: {plain}"),
                    None => plain,
                };
                at.at(span, message)
            }
            // A missing key: named by its table ("sphere 2: missing field `radius`"),
            // counted from 1 as in the validation messages.
            (Some(span), None) if message.starts_with("missing field ") => {
                let message = match table_at(at.text, span.start.saturating_add(at.offset)) {
                    Some(table) => format!("{table}: {message}"),
                    None => message,
                };
                at.at(span, message)
            }
            (Some(span), None) => at.at(span, message),
            (None, plain) => at.whole(plain.unwrap_or(message)),
        }
    })
}

/// serde's wording of a wrong type or length in the words of a scene file: "invalid
/// type: string \"big\", expected f64" becomes "expected a number, got the string
/// \"big\"". `None` for other messages.
pub(super) fn plain_type_error(message: &str) -> Option<String> {
    let (got, expected) = if let Some(rest) = message.strip_prefix("invalid type: ") {
        // The last ", expected ": a string value may hold those words itself.
        let (got, expected) = rest.rsplit_once(", expected ")?;
        let got = if let Some(text) = got.strip_prefix("string ") {
            format!("the string {text}")
        } else if let Some((_, value)) = got.split_once(" `") {
            value.trim_end_matches('`').to_string() // integer `3`, boolean `true`
        } else {
            match got {
                "sequence" => "an array".into(),
                "map" => "a table".into(),
                other => other.into(),
            }
        };
        (got, expected)
    } else if let Some(rest) = message.strip_prefix("invalid length ") {
        let (n, expected) = rest.rsplit_once(", expected ")?;
        (format!("{n} values"), expected)
    } else {
        return None;
    };
    let expected = match expected {
        "f64" | "f32" => "a number",
        "i64" | "u64" | "i32" | "u32" => "a whole number",
        "an array of length 3" => "an array of 3 numbers",
        // The loader's own types ("struct FileImage") are tables in the file.
        other if other.starts_with("struct ") => "a table",
        other => other,
    };
    Some(format!("expected {expected}, got {got}"))
}

/// The field whose value starts at byte `offset` of the scene text, named as the
/// validation messages name fields ("sphere 2: radius", "image.width"): the key of the
/// line (when the value follows its `=`) under the table header above it. `None`
/// where that is not plain (an inline table, say): better no name than a wrong one.
pub(super) fn field_at(text: &str, offset: usize) -> Option<String> {
    let offset = text.floor_char_boundary_compat(offset.min(text.len()));
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let (key, value) = text[line_start..offset].split_once('=')?;
    let key = key.trim();
    let bare = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    if key.is_empty() || !key.chars().all(bare) || !value.trim().is_empty() {
        return None;
    }
    Some(match enclosing_table(&text[..line_start]) {
        None => key.to_string(),
        Some(Table::Array(name, index)) => format!("{name} {index}: {key}"),
        Some(Table::Plain(name)) => format!("{name}.{key}"),
    })
}

/// The table whose header is on the line of byte `offset`, named as the validation
/// messages name tables: "sphere 2" (the second `[[sphere]]`, counted from 1),
/// "image". `None` off a header line (an inline table, say).
pub(super) fn table_at(text: &str, offset: usize) -> Option<String> {
    let offset = text.floor_char_boundary_compat(offset.min(text.len()));
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    if !text[line_start..line_end].trim_start().starts_with('[') {
        return None;
    }
    Some(match enclosing_table(&text[..line_end])? {
        Table::Array(name, index) => format!("{name} {index}"),
        Table::Plain(name) => name,
    })
}

/// A table of a scene file: `[image]`, or the `index`-th `[[sphere]]` (from 1).
enum Table {
    Plain(String),
    Array(String, usize),
}

/// The table of the last header in `before`.
fn enclosing_table(before: &str) -> Option<Table> {
    // A header's table name: `[image]` → ("image", false), `[[sphere]]` → ("sphere", true).
    let header = |line: &str| -> Option<(String, bool)> {
        let line = line.trim();
        let array = line.starts_with("[[");
        let name = line.trim_start_matches('[').split(']').next()?.trim();
        line.starts_with('[').then(|| (name.to_string(), array))
    };
    Some(match before.lines().rev().find_map(header)? {
        (table, true) => {
            let index = before
                .lines()
                .filter_map(header)
                .filter(|(name, array)| *array && *name == table)
                .count();
            Table::Array(table, index)
        }
        (table, false) => Table::Plain(table),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_errors_read_in_the_words_of_a_scene_file() {
        for (serde, plain) in [
            (
                "invalid type: string \"big\", expected f64",
                "expected a number, got the string \"big\"",
            ),
            (
                "invalid type: floating point `1.5`, expected i64",
                "expected a whole number, got 1.5",
            ),
            (
                "invalid type: boolean `true`, expected f64",
                "expected a number, got true",
            ),
            (
                "invalid type: sequence, expected f64",
                "expected a number, got an array",
            ),
            (
                "invalid length 2, expected an array of length 3",
                "expected an array of 3 numbers, got 2 values",
            ),
            (
                // A string that holds the words of the message itself.
                "invalid type: string \"a, expected b\", expected f64",
                "expected a number, got the string \"a, expected b\"",
            ),
            (
                "invalid type: integer `3`, expected struct FileImage",
                "expected a table, got 3",
            ),
        ] {
            assert_eq!(plain_type_error(serde).as_deref(), Some(plain));
        }
        assert_eq!(plain_type_error("unknown field `shine`"), None);
    }

    #[test]
    fn fields_are_named_by_their_table_and_key() {
        let text =
            "seed = 1\n[image]\nwidth = x\n[[sphere]]\nradius = 1\n\n[[sphere]]\n  radius = y\n";
        let at = |needle: &str| field_at(text, text.find(needle).unwrap());
        assert_eq!(at("1\n[image]").as_deref(), Some("seed"));
        assert_eq!(at("x").as_deref(), Some("image.width"));
        assert_eq!(at("1\n\n").as_deref(), Some("sphere 1: radius"));
        assert_eq!(at("y").as_deref(), Some("sphere 2: radius"));
        // On a header or a key itself there is no value to name.
        assert_eq!(at("[image]"), None);
        assert_eq!(at("width"), None);
        // An inline table is not named rather than misnamed; another array of
        // tables whose name contains this one's is not counted.
        let inline = "sphere = [{ center = [0, 0, -1], radius = \"big\" }]\n";
        assert_eq!(field_at(inline, inline.find("\"big").unwrap()), None);
        let text = "[[spotlight]]\nx = 1\n[[light]]\nintensity = z\n";
        assert_eq!(
            field_at(text, text.find('z').unwrap()).as_deref(),
            Some("light 1: intensity")
        );
        // A table by its header line; not off a header.
        let header = |needle: &str| table_at(text, text.find(needle).unwrap());
        assert_eq!(header("[[light]]").as_deref(), Some("light 1"));
        assert_eq!(header("z\n"), None);
        let spheres = "[image]\n[[sphere]]\nradius = 1\n[[sphere]]\ncenter = [0, 0, 0]\n";
        assert_eq!(
            table_at(spheres, spheres.rfind("[[").unwrap()).as_deref(),
            Some("sphere 2")
        );
        assert_eq!(table_at(spheres, 0).as_deref(), Some("image"));
        // Offsets past the end or inside a character do not panic.
        assert_eq!(field_at("é = ", 1), None);
        assert_eq!(field_at("a = ", 99).as_deref(), Some("a"));
    }
}
