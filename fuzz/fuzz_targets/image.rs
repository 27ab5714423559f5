//! The image reader of `whitted compare`: any bytes give an image or an error. A decoded
//! image becomes 8-bit levels within [0, 255] that agree with the bytes that display it,
//! and compared with itself it differs by nothing.
#![no_main]

use std::io::Cursor;

use libfuzzer_sys::fuzz_target;
use whitted::bench::{measure, Levels};
use whitted::image_io::decode_image;

fuzz_target!(|data: &[u8]| {
    // 64 MB at most (the files' limit is 512 MB): large images only slow the search.
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(64 << 20);
    let Ok(image) = decode_image(Cursor::new(data), None, limits) else {
        return;
    };
    let levels = Levels::from_image(image);
    let (w, h) = (levels.width, levels.height);
    assert_eq!(levels.values.len(), w as usize * h as usize * 3);
    assert_eq!(levels.bytes.dimensions(), (w, h));
    for (&value, &byte) in levels.values.iter().zip(levels.bytes.as_raw()) {
        assert!((0.0..=255.0).contains(&value), "a level {value}");
        assert!(
            (value - f64::from(byte)).abs() <= 0.5 + 1e-4,
            "level {value} shown as byte {byte}"
        );
    }
    // FLIP's cost grows with the pixels: small images only.
    if w > 0 && h > 0 && u64::from(w) * u64::from(h) <= 4096 {
        let same = measure(&levels, &levels).expect("same size").errors;
        assert_eq!(
            (same.rmse, same.max, same.off_by_more_than_1),
            (0.0, 0, 0.0)
        );
        assert_eq!(same.flip, 0.0);
    }
});
