//! The part reader of `whitted stitch`: any bytes, read as a PNG part and as an EXR
//! part, give a part or an error. A part read holds the pixels its record announces,
//! at a place inside an image a render could make, and stitched alone it makes that
//! image exactly when it covers all of it.
#![no_main]

use std::io::Cursor;

use libfuzzer_sys::fuzz_target;
use whitted::image_io::parts::{decode_part, stitch, Part, PartPixels, StitchError};
use whitted::image_io::Format;
use whitted::limits::{MAX_PIXELS, MAX_SIDE};

fuzz_target!(|data: &[u8]| {
    for format in [Format::Png, Format::Exr] {
        match decode_part(Cursor::new(data), format, "fuzz") {
            Ok(part) => check(part),
            Err(e) => {
                let shown = e.to_string();
                assert!(
                    shown.starts_with("fuzz: ") && !shown.contains('\n'),
                    "{shown:?}"
                );
            }
        }
    }
});

fn check(part: Part) {
    let p = part.placement;
    let r = p.region;
    assert!(p.width >= 1 && p.width <= MAX_SIDE && p.height >= 1 && p.height <= MAX_SIDE);
    assert!(u64::from(p.width) * u64::from(p.height) <= MAX_PIXELS);
    assert!(r.fits_in(p.width, p.height), "{p:?}");
    let size = match &part.pixels {
        PartPixels::Bytes(image) => image.dimensions(),
        PartPixels::Linear(image) => image.dimensions(),
    };
    assert_eq!(size, (r.width, r.height));
    // Stitching allocates the whole image: small ones only, to keep runs fast.
    if u64::from(p.width) * u64::from(p.height) > 1 << 16 {
        return;
    }
    let whole = (r.width, r.height) == (p.width, p.height);
    let stitched = stitch(&[("fuzz".into(), part.clone())]);
    match (stitched, whole) {
        (Ok(PartPixels::Bytes(image)), true) => {
            let PartPixels::Bytes(original) = &part.pixels else {
                panic!("bytes from linear pixels");
            };
            assert_eq!(&image, original);
        }
        (Ok(PartPixels::Linear(image)), true) => {
            let PartPixels::Linear(original) = &part.pixels else {
                panic!("linear pixels from bytes");
            };
            // Bit for bit, NaN included.
            let bits = |i: &image::Rgb32FImage| i.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&image), bits(original));
        }
        (Err(StitchError::Gap { missing, .. }), false) => {
            let expected =
                u64::from(p.width) * u64::from(p.height) - u64::from(r.width) * u64::from(r.height);
            assert_eq!(missing, expected);
        }
        (other, whole) => panic!("stitched alone (whole: {whole}): {other:?}"),
    }
    // Twice, the part overlaps itself.
    let twice = stitch(&[("a".into(), part.clone()), ("b".into(), part)]);
    assert!(
        matches!(twice, Err(StitchError::Overlap { .. })),
        "{twice:?}"
    );
}
