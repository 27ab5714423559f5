//! The fast path of big scene files: `[[sphere]]` tables written plainly, as scene
//! generators write them: one `key = value` a line, each value a decimal number or an
//! array of three on one line, comments and blank lines between. They are read here
//! without `toml`'s tree of the batch, which costs about 180 instructions a byte of
//! text (24 billion for a million spheres, several seconds on two cores).
//!
//! Anything else in a batch (another key, a quoted key, a number with `_`, `inf`, a
//! leading zero, a trailing comma, a duplicate or missing key, a stray character)
//! makes [`sphere_tables`] return `None`, and the batch goes to `toml`, which stays
//! the authority on the syntax and on every message. So this path changes how fast
//! the same tables come back, never what comes back: the tests compare the two on
//! generated tables, values to the bit and spans to the byte.

use std::ops::Range;

use toml::Spanned;

use super::schema::FileSphere;
use super::streaming::is_sphere_header;

/// The `[[sphere]]` tables of `text` (a batch: its first line a `[[sphere]]` header),
/// with spans counted from the start of `text`, as `toml` gives them; `None` when
/// any line is not in the plain form.
pub(super) fn sphere_tables(text: &str, expected: usize) -> Option<Vec<FileSphere>> {
    let mut tables = Vec::with_capacity(expected);
    let mut table: Option<Table> = None;
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let body = line.strip_suffix('\n').unwrap_or(line);
        let body = body.strip_suffix('\r').unwrap_or(body);
        let indent = body.len() - body.trim_start_matches([' ', '\t']).len();
        let content = &body[indent..];
        if content.is_empty() || content.starts_with('#') {
            comment_is_plain(content)?;
            continue;
        }
        if content.starts_with('[') {
            if !is_sphere_header(content) {
                return None;
            }
            if let Some(done) = table.take() {
                tables.push(done.finish()?);
            }
            let (_, comment) = content.split_once(']').unwrap_or((content, ""));
            comment_is_plain(comment.trim_start_matches([']', ' ', '\t']))?;
            table = Some(Table::default());
            continue;
        }
        let current = table.as_mut()?;
        current.entry(content, start + indent)?;
    }
    if let Some(done) = table.take() {
        tables.push(done.finish()?);
    }
    (tables.len() == expected).then_some(tables)
}

/// A table's keys as they are read.
#[derive(Default)]
struct Table {
    center: Option<Spanned<[f64; 3]>>,
    radius: Option<Spanned<f64>>,
    color: Option<Spanned<[f64; 3]>>,
    reflect: Option<Spanned<f64>>,
    transmit: Option<Spanned<f64>>,
    ior: Option<Spanned<f64>>,
}

impl Table {
    /// Reads `key = value` (with a comment after it, if any), the line's content
    /// starting at byte `at` of the batch.
    fn entry(&mut self, content: &str, at: usize) -> Option<()> {
        let key_end = content.find([' ', '\t', '='])?;
        let key = &content[..key_end];
        let rest = content[key_end..].trim_start_matches([' ', '\t']);
        let rest = rest.strip_prefix('=')?;
        let value = rest.trim_start_matches([' ', '\t']);
        let value_at = at + content.len() - value.len();
        match key {
            "center" => set(&mut self.center, triple(value, value_at)?),
            "color" => set(&mut self.color, triple(value, value_at)?),
            "radius" => set(&mut self.radius, single(value, value_at)?),
            "reflect" => set(&mut self.reflect, single(value, value_at)?),
            "transmit" => set(&mut self.transmit, single(value, value_at)?),
            "ior" => set(&mut self.ior, single(value, value_at)?),
            _ => None,
        }
    }

    fn finish(self) -> Option<FileSphere> {
        Some(FileSphere {
            center: self.center?,
            radius: self.radius?,
            color: self.color,
            reflect: self.reflect,
            transmit: self.transmit,
            ior: self.ior,
        })
    }
}

/// Sets a key once: a second time is `toml`'s error to report.
fn set<T>(slot: &mut Option<T>, value: (T, &str)) -> Option<()> {
    if slot.is_some() {
        return None;
    }
    let (value, after) = value;
    comment_is_plain(after.trim_start_matches([' ', '\t']))?;
    *slot = Some(value);
    Some(())
}

/// Nothing, or a comment of characters TOML allows in one (tab, and no other control
/// character).
fn comment_is_plain(text: &str) -> Option<()> {
    if text.is_empty() {
        return Some(());
    }
    let allowed = |c: char| c == '\t' || !(c.is_control());
    (text.starts_with('#') && text.chars().all(allowed)).then_some(())
}

/// A number at the start of `text` (byte `at` of the batch), and what follows it.
fn single(text: &str, at: usize) -> Option<(Spanned<f64>, &str)> {
    let end = text.find([' ', '\t', '#', ',', ']']).unwrap_or(text.len());
    let x = number(&text[..end])?;
    Some((Spanned::new(at..at + end, x), &text[end..]))
}

/// `[a, b, c]` at the start of `text` (byte `at` of the batch), and what follows it.
fn triple(text: &str, at: usize) -> Option<(Spanned<[f64; 3]>, &str)> {
    let mut rest = text.strip_prefix('[')?;
    let mut values = [0.0; 3];
    for (k, value) in values.iter_mut().enumerate() {
        rest = rest.trim_start_matches([' ', '\t']);
        let (x, after) = single(rest, 0)?;
        *value = *x.get_ref();
        rest = after.trim_start_matches([' ', '\t']);
        rest = if k < 2 {
            rest.strip_prefix(',')?
        } else {
            rest.strip_prefix(']')?
        };
    }
    let end = text.len() - rest.len();
    let span: Range<usize> = at..at + end;
    Some((Spanned::new(span, values), rest))
}

/// A decimal number as TOML writes it, the integers converted as `toml` and serde
/// convert them (`i64`, then `as f64`); `None` for any other form (underscores,
/// `inf`, `nan`, hexadecimal, leading zeros, a bare `.`) and for a value `toml` could
/// refuse or give otherwise (an integer beyond `i64`, a float beyond `f64`).
fn number(text: &str) -> Option<f64> {
    let bytes = text.as_bytes();
    let unsigned = match bytes.first()? {
        b'+' | b'-' => &bytes[1..],
        _ => bytes,
    };
    let int_len = unsigned.iter().take_while(|b| b.is_ascii_digit()).count();
    if int_len == 0 || (int_len > 1 && unsigned[0] == b'0') {
        return None;
    }
    let mut rest = &unsigned[int_len..];
    let mut is_float = false;
    if let Some(frac) = rest.strip_prefix(b".") {
        let digits = frac.iter().take_while(|b| b.is_ascii_digit()).count();
        if digits == 0 {
            return None;
        }
        rest = &frac[digits..];
        is_float = true;
    }
    if let Some(exp) = rest.strip_prefix(b"e").or_else(|| rest.strip_prefix(b"E")) {
        let exp = match exp.first() {
            Some(b'+' | b'-') => &exp[1..],
            _ => exp,
        };
        let digits = exp.iter().take_while(|b| b.is_ascii_digit()).count();
        if digits == 0 {
            return None;
        }
        rest = &exp[digits..];
        is_float = true;
    }
    if !rest.is_empty() {
        return None;
    }
    let x = if is_float {
        text.parse::<f64>().ok()?
    } else {
        text.parse::<i64>().ok()? as f64
    };
    x.is_finite().then_some(x)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::messages::{from_toml, Locator};
    use super::super::schema::{FileSphere, FileSphereTable};
    use super::*;

    /// What `toml` makes of a batch, as comparable values: `None` for an error.
    fn by_toml(text: &str) -> Option<Vec<FileSphere>> {
        let at = Locator {
            text,
            path: "t.toml",
            offset: 0,
        };
        from_toml::<FileSphereTable>(text, &at)
            .ok()
            .map(|t| t.sphere)
    }

    fn same(a: &[FileSphere], b: &[FileSphere]) -> bool {
        fn v3(a: &Spanned<[f64; 3]>, b: &Spanned<[f64; 3]>) -> bool {
            a.span() == b.span() && a.get_ref().map(f64::to_bits) == b.get_ref().map(f64::to_bits)
        }
        fn n(a: &Spanned<f64>, b: &Spanned<f64>) -> bool {
            a.span() == b.span() && a.get_ref().to_bits() == b.get_ref().to_bits()
        }
        fn opt<T>(a: &Option<T>, b: &Option<T>, eq: fn(&T, &T) -> bool) -> bool {
            match (a, b) {
                (Some(a), Some(b)) => eq(a, b),
                (None, None) => true,
                _ => false,
            }
        }
        a.len() == b.len()
            && a.iter().zip(b).all(|(a, b)| {
                v3(&a.center, &b.center)
                    && n(&a.radius, &b.radius)
                    && opt(&a.color, &b.color, v3)
                    && opt(&a.reflect, &b.reflect, n)
                    && opt(&a.transmit, &b.transmit, n)
                    && opt(&a.ior, &b.ior, n)
            })
    }

    /// Number spellings, plain and not: what the fast path reads must be what `toml`
    /// reads, and the rest must go to `toml`.
    fn number_text() -> impl Strategy<Value = String> {
        prop_oneof![
            any::<f64>().prop_map(|x| format!("{x}")),
            any::<f64>().prop_map(|x| format!("{x:e}")),
            any::<f32>().prop_map(|x| format!("{x}")),
            any::<i64>().prop_map(|x| format!("{x}")),
            (-1000i32..1000).prop_map(|x| format!("{x}")),
            (-1000i32..1000, 0u32..1000).prop_map(|(a, b)| format!("{a}.{b}")),
            prop::sample::select(vec![
                "0",
                "-0",
                "+0",
                "0.0",
                "-0.0",
                "+1.5",
                "01",
                "1_000",
                "1.",
                ".5",
                "1e5",
                "1E-3",
                "1e+2",
                "1.5e",
                "inf",
                "-inf",
                "nan",
                "0x10",
                "1e400",
                "1.0.0",
                "--1",
                "9223372036854775807",
                "9223372036854775808",
                "-9223372036854775808",
                "0.1e-400",
                "1__0",
                "true",
                "\"1\"",
                "",
                "e5",
            ])
            .prop_map(String::from),
        ]
    }

    fn line() -> impl Strategy<Value = String> {
        let key = prop::sample::select(vec![
            "center",
            "radius",
            "color",
            "reflect",
            "transmit",
            "ior",
            "\"radius\"",
            "other",
            "center.x",
        ]);
        let sep = prop::sample::select(vec![" = ", "=", " =\t", "\t= ", " == "]);
        let value = prop_oneof![
            3 => number_text(),
            3 => (number_text(), number_text(), number_text())
                .prop_map(|(a, b, c)| format!("[{a}, {b}, {c}]")),
            1 => (number_text(), number_text(), number_text())
                .prop_map(|(a, b, c)| format!("[ {a},{b} ,\t{c} ,]")),
            1 => (number_text(), number_text()).prop_map(|(a, b)| format!("[{a}, {b}]")),
        ];
        let tail = prop::sample::select(vec!["", "  ", " # note", "\t#\tnote", " #\u{1}", " x"]);
        prop_oneof![
            8 => (" {0,2}", key, sep, value, tail)
                .prop_map(|(i, k, s, v, t)| format!("{i}{k}{s}{v}{t}")),
            1 => prop::sample::select(vec!["", "# comment", "  ", "[[sphere]] # next", "[sphere]"])
                .prop_map(String::from),
        ]
    }

    fn table() -> impl Strategy<Value = String> {
        let plain = (number_text(), number_text(), number_text(), number_text())
            .prop_map(|(x, y, z, r)| format!("center = [{x}, {y}, {z}]\nradius = {r}\n"));
        (plain, prop::collection::vec(line(), 0..6)).prop_map(|(p, lines)| {
            let mut text = String::from("[[sphere]]\n");
            text.push_str(&p);
            for l in lines {
                text.push_str(&l);
                text.push('\n');
            }
            text
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]
        #[test]
        fn the_fast_path_reads_what_toml_reads(
            tables in prop::collection::vec(table(), 1..4),
            crlf in any::<bool>(),
        ) {
            let mut text = tables.concat();
            if crlf {
                text = text.replace('\n', "\r\n");
            }
            let expected = text.matches("[[sphere]]").count();
            if let Some(fast) = sphere_tables(&text, expected) {
                let slow = by_toml(&text);
                prop_assert!(slow.is_some(), "toml refuses what the fast path read:\n{text}");
                prop_assert!(same(&fast, &slow.unwrap()), "they differ:\n{text}");
            }
        }
    }

    /// The generators' own layout takes the fast path (else it would buy nothing).
    #[test]
    fn generated_scenes_take_the_fast_path() {
        let text = "[[sphere]]\ncenter = [42.41408, -0.999446, 27.777597]\nradius = 0.286287\n\
                    color = [0.3, 0.3, 0.8]\nreflect = 0\ntransmit = 0\nior = 2\n\n\
                    [[sphere]]\ncenter = [0, -1000, 0]\nradius = 1000\n";
        let fast = sphere_tables(text, 2).expect("plain tables");
        assert!(same(&fast, &by_toml(text).unwrap()));
        assert_eq!(fast[0].center.get_ref(), &[42.41408, -0.999446, 27.777597]);
        assert_eq!(
            fast[1].radius.span(),
            text.rfind("1000\n").unwrap()..text.len() - 1
        );
    }

    #[test]
    fn numbers_in_other_forms_go_to_toml() {
        for text in [
            "01",
            "1_0",
            "inf",
            "nan",
            "1.",
            ".5",
            "0x1",
            "1e",
            "+",
            "9223372036854775808",
        ] {
            assert_eq!(number(text), None, "{text}");
        }
        assert_eq!(number("-0").map(f64::to_bits), Some(0.0f64.to_bits()));
        assert_eq!(number("-0.0").map(f64::to_bits), Some((-0.0f64).to_bits()));
        assert_eq!(number("+2.5e-1"), Some(0.25));
    }
}
