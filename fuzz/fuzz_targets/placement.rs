//! A part's record of its place (the `whitted-part` text of PNG and EXR parts): any
//! text gives a placement or an error. A placement lies inside an image a render could
//! make, prints as text that reads back the same, and survives a PNG and an EXR part
//! written with it and read back, pixels included.
#![no_main]

use std::io::Cursor;

use glam::Vec3;
use libfuzzer_sys::fuzz_target;
use whitted::image_io::parts::{decode_part, encode_part, PartPixels, Placement};
use whitted::image_io::{to_rgb32f, to_rgb8, Format};
use whitted::limits::{MAX_PIXELS, MAX_SIDE};
use whitted::Frame;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(p) = text.parse::<Placement>() else {
        return;
    };
    assert!(p.width >= 1 && p.width <= MAX_SIDE && p.height >= 1 && p.height <= MAX_SIDE);
    assert!(u64::from(p.width) * u64::from(p.height) <= MAX_PIXELS);
    assert!(p.region.fits_in(p.width, p.height), "{p:?}");
    let printed = p.to_string();
    assert_eq!(printed.parse::<Placement>(), Ok(p), "{printed:?}");

    let r = p.region;
    if u64::from(r.width) * u64::from(r.height) > 4096 {
        return;
    }
    // Pixels from the text's bytes, some beyond [0, 1].
    let mut frame = Frame::new(r.width, r.height);
    for (k, pixel) in frame.pixels.iter_mut().enumerate() {
        let b = |c: usize| f32::from(data[(3 * k + c) % data.len()]) / 200.0;
        *pixel = Vec3::new(b(0), b(1), b(2));
    }
    for format in [Format::Png, Format::Exr] {
        let bytes = encode_part(&frame, &p, format, p.encoding).expect("a part encodes");
        let part = decode_part(Cursor::new(bytes), format, "fuzz")
            .unwrap_or_else(|e| panic!("a part written does not read back: {e}"));
        assert_eq!(part.placement, p);
        match part.pixels {
            PartPixels::Bytes(image) => assert_eq!(image, to_rgb8(&frame, p.encoding)),
            PartPixels::Linear(image) => assert_eq!(image, to_rgb32f(&frame)),
        }
    }
});
