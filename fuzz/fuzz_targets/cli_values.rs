//! The command line's value parsers (`--region X,Y,W,H`, `--tile I/N`, `--frame K|A..B`):
//! any text gives a value or an error; a value keeps its invariants, prints as text
//! that parses to the same value, and agrees with a plain reading of the numbers.
#![no_main]

use libfuzzer_sys::fuzz_target;
use whitted::limits::MAX_FRAMES;
use whitted::settings::{FrameRange, Region, Tile};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    region(text);
    tile(text);
    frames(text);
});

/// Whole numbers between `separator`s, spaces allowed around them, as `u32`s.
fn numbers(text: &str, separator: &str) -> Option<Vec<u32>> {
    text.split(separator)
        .map(|n| n.trim().parse().ok())
        .collect()
}

fn region(text: &str) {
    let parsed = text.parse::<Region>();
    let expected = match numbers(text, ",").as_deref() {
        Some(&[x, y, width, height]) if width > 0 && height > 0 => Some(Region {
            x,
            y,
            width,
            height,
        }),
        _ => None,
    };
    assert_eq!(parsed.clone().ok(), expected, "{text:?}");
    if let Ok(r) = parsed {
        assert!(r.width > 0 && r.height > 0);
        let printed = r.to_string();
        assert_eq!(printed.parse::<Region>(), Ok(r), "{printed:?}");
        // The region fits in the image that just holds it, and in no smaller one.
        let (right, bottom) = (
            u64::from(r.x) + u64::from(r.width),
            u64::from(r.y) + u64::from(r.height),
        );
        if let (Ok(w), Ok(h)) = (u32::try_from(right), u32::try_from(bottom)) {
            assert!(r.fits_in(w, h));
            assert!(!r.fits_in(w - 1, h) && !r.fits_in(w, h - 1));
        }
    } else {
        assert!(parsed
            .unwrap_err()
            .to_string()
            .starts_with("expected X,Y,W,H"));
    }
}

fn tile(text: &str) {
    let parsed = text.parse::<Tile>();
    let expected = match numbers(text, "/").as_deref() {
        Some(&[index, count]) if index < count => Some(Tile { index, count }),
        _ => None,
    };
    assert_eq!(parsed.clone().ok(), expected, "{text:?}");
    if let Ok(t) = parsed {
        assert!(t.index < t.count);
        assert_eq!(t.to_string().parse::<Tile>(), Ok(t));
        // In an image with room for the grid, the tile is a rectangle inside it.
        if t.count <= 64 {
            let (w, h) = (97, 61);
            if let Some(r) = t.region(w, h) {
                assert!(r.fits_in(w, h), "{t} in {w}x{h}: {r}");
            }
        }
    }
}

fn frames(text: &str) {
    let parsed = text.parse::<FrameRange>();
    let expected = match text.split_once("..") {
        None => numbers(text, "..").and_then(|n| match n[..] {
            [k] => Some(FrameRange {
                start: k,
                end: k.checked_add(1)?,
            }),
            _ => None,
        }),
        Some(_) => match numbers(text, "..").as_deref() {
            Some(&[start, end]) => Some(FrameRange { start, end }),
            _ => None,
        },
    }
    .filter(|r| r.start < r.end && r.end <= MAX_FRAMES);
    assert_eq!(parsed.clone().ok(), expected, "{text:?}");
    if let Ok(r) = parsed {
        assert!(r.start < r.end && r.end <= MAX_FRAMES);
        assert!(!r.is_empty() && r.len() == r.end - r.start);
        let printed = r.to_string();
        assert_eq!(printed.parse::<FrameRange>(), Ok(r), "{printed:?}");
        assert_eq!(printed.contains(".."), r.len() > 1, "{printed:?}");
    }
}
