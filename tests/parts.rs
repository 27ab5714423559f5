//! Parts of an image (SPEC §5): `--tile I/N` and `--region` files record where they
//! belong, and `whitted stitch` puts them back into exactly the bytes of the whole
//! render, or refuses with one line and writes nothing.
#![cfg(all(feature = "cli", feature = "viewer"))]

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::{AtomicUsize, Ordering};

use whitted::image_io::Format;

use common::run as whitted;

fn ok(args: &[&str]) {
    let out = whitted(args);
    assert!(
        out.status.success(),
        "whitted {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs a command that must fail with `code` and one line on stderr containing `needle`.
fn fails(args: &[&str], code: i32, needle: &str) {
    let out = whitted(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "whitted {args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.contains(needle), "{needle:?} not in {err}");
}

fn path(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().unwrap().to_string()
}

const SIZE: [&str; 4] = ["--width", "160", "--height", "90"];

/// Renders tiles `0..count` of hw3 at 160×90 with `extra` options into `dir` as `ext`.
fn tiles(dir: &Path, count: u32, ext: &str, extra: &[&str]) -> Vec<String> {
    (0..count)
        .map(|i| {
            let file = path(dir, &format!("tile{i}.{ext}"));
            let tile = format!("{i}/{count}");
            let mut args = vec!["render", "--quiet", "--tile", &tile, "-o", &file];
            args.extend(SIZE);
            args.extend(extra);
            ok(&args);
            file
        })
        .collect()
}

fn stitch(out: &str, parts: &[String]) -> Output {
    let mut args = vec!["stitch", "-o", out];
    args.extend(parts.iter().map(String::as_str));
    whitted(&args)
}

fn same_bytes(a: &str, b: &str) {
    let (x, y) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    assert!(
        x == y,
        "{a} and {b} differ ({} and {} bytes)",
        x.len(),
        y.len()
    );
}

#[test]
fn tiles_stitch_into_the_bytes_of_the_whole_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (count, extra) in [
        (16, &[][..]),
        (7, &["--spp", "4"][..]),
        (1, &[][..]),
        (4, &["--encoding", "srgb"][..]),
    ] {
        let whole_png = path(d, "whole.png");
        let whole_exr = path(d, "whole.exr");
        let whole_ppm = path(d, "whole.ppm");
        let mut args = vec![
            "render", "--quiet", "-o", &whole_png, "-o", &whole_exr, "-o", &whole_ppm,
        ];
        args.extend(SIZE);
        args.extend(extra);
        ok(&args);

        let pngs = tiles(d, count, "png", extra);
        let out = path(d, "stitched.png");
        assert!(stitch(&out, &pngs).status.success());
        same_bytes(&out, &whole_png);
        let ppm = path(d, "stitched.ppm");
        assert!(stitch(&ppm, &pngs).status.success());
        same_bytes(&ppm, &whole_ppm);

        let exrs = tiles(d, count, "exr", extra);
        let out = path(d, "stitched.exr");
        assert!(stitch(&out, &exrs).status.success());
        same_bytes(&out, &whole_exr);
        // Linear parts make the 8-bit files too, in the parts' encoding.
        let png = path(d, "from-exr.png");
        assert!(stitch(&png, &exrs).status.success());
        same_bytes(&png, &whole_png);
        // The order of the parts does not matter.
        let mut reversed = exrs.clone();
        reversed.reverse();
        assert!(stitch(&out, &reversed).status.success());
        same_bytes(&out, &whole_exr);
    }
}

#[test]
fn regions_of_any_shape_stitch_too() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let whole = path(d, "whole.png");
    let mut args = vec!["render", "--quiet", "--quality", "default", "-o", &whole];
    args.extend(SIZE);
    ok(&args);
    let mut parts = Vec::new();
    for (k, region) in ["0,0,160,31", "0,31,13,59", "13,31,147,59"]
        .iter()
        .enumerate()
    {
        let file = path(d, &format!("r{k}.png"));
        let mut args = vec![
            "render",
            "--quiet",
            "--quality",
            "default",
            "--region",
            region,
            "-o",
            &file,
        ];
        args.extend(SIZE);
        ok(&args);
        parts.push(file);
    }
    let out = path(d, "out.png");
    assert!(stitch(&out, &parts).status.success());
    same_bytes(&out, &whole);
}

#[test]
fn gaps_overlaps_and_foreign_parts_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let pngs = tiles(d, 4, "png", &[]);
    let out = path(d, "out.png");
    let mut args = vec!["stitch", "-o", &out];
    args.extend(pngs[..3].iter().map(String::as_str));
    fails(&args, 1, "uncovered");

    let mut args = vec!["stitch", "-o", &out];
    args.extend(pngs.iter().map(String::as_str));
    args.push(&pngs[2]);
    fails(&args, 1, "overlap");

    // The same tile of another image (another seed for the small balls' jitter is
    // not enough at 1 spp: another size is).
    let other = path(d, "other.png");
    ok(&[
        "render", "--quiet", "--tile", "3/4", "--width", "160", "--height", "91", "-o", &other,
    ]);
    let mut args = vec!["stitch", "-o", &out];
    args.extend(pngs[..3].iter().map(String::as_str));
    args.push(&other);
    fails(&args, 1, "part of another image");

    // Another scene with the same size.
    let scene = path(d, "s.toml");
    std::fs::write(&scene, "[[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\n").unwrap();
    let foreign = path(d, "foreign.png");
    let mut args = vec!["render", &scene, "--quiet", "--tile", "3/4", "-o", &foreign];
    args.extend(SIZE);
    ok(&args);
    let mut args = vec!["stitch", "-o", &out];
    args.extend(pngs[..3].iter().map(String::as_str));
    args.push(&foreign);
    fails(&args, 1, "part of another image");

    // A whole image is no part; PNG and EXR parts do not mix; 8-bit parts make no EXR.
    let whole = path(d, "whole.png");
    let mut args = vec!["render", "--quiet", "-o", &whole];
    args.extend(SIZE);
    ok(&args);
    fails(&["stitch", "-o", &out, &whole], 1, "records no place");
    let exr = tiles(d, 4, "exr", &[]);
    fails(
        &["stitch", "-o", &out, &pngs[0], &pngs[1], &pngs[2], &exr[3]],
        1,
        "all be PNG or all be EXR",
    );
    let out_exr = path(d, "out.exr");
    let mut args = vec!["stitch", "-o", &out_exr];
    args.extend(pngs.iter().map(String::as_str));
    fails(&args, 1, "cannot make an EXR");
    assert!(!PathBuf::from(&out).exists() && !PathBuf::from(&out_exr).exists());
}

#[test]
fn tiles_of_an_animation_frame_stitch_into_that_frame() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spin = ["--frames", "4", "--orbit", "90", "--frame", "2"];
    let whole = path(d, "whole-%d.png");
    let mut args = vec!["render", "--quiet", "-o", &whole];
    args.extend(SIZE);
    args.extend(spin);
    ok(&args);
    let mut parts = Vec::new();
    for i in 0..4 {
        let pattern = path(d, &format!("tile{i}-%d.png"));
        let tile = format!("{i}/4");
        let mut args = vec!["render", "--quiet", "--tile", &tile, "-o", &pattern];
        args.extend(SIZE);
        args.extend(spin);
        ok(&args);
        parts.push(path(d, &format!("tile{i}-2.png")));
    }
    let out = path(d, "out.png");
    let run = stitch(&out, &parts);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    same_bytes(&out, &path(d, "whole-2.png"));
}

#[test]
fn bad_tiles_are_usage_errors() {
    fails(&["render", "--tile", "4/4", "-o", "x.png"], 2, "0 <= I < N");
    fails(&["render", "--tile", "a/b", "-o", "x.png"], 2, "I/N");
    fails(
        &[
            "render", "--tile", "0/2", "--region", "0,0,1,1", "-o", "x.png",
        ],
        2,
        "cannot be used with",
    );
    // More tiles than the image has rows and columns for: a bad option value too.
    fails(
        &[
            "render", "--tile", "0/7", "--width", "2", "--height", "3", "-o", "x.png",
        ],
        2,
        "does not exist in a 2x3 image",
    );
}

/// A 1×1 8-bit RGB PNG whose `whitted-part` text is `record`.
fn png_with_record(record: &str) -> Vec<u8> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, 1, 1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .add_text_chunk("whitted-part".into(), record.into())
        .unwrap();
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(&[10, 20, 30]).unwrap();
    writer.finish().unwrap();
    out
}

/// A record of a whole image larger than a render can make is refused: `stitch`
/// allocates the whole image its parts name, and 4000000000x4000000000 pixels panicked
/// (capacity overflow), 100000x100000 aborted (40 GB) (found by reading `stitch` for
/// the `part` fuzz target).
#[test]
fn a_record_of_an_image_no_render_makes_is_refused() {
    use whitted::image_io::parts::{BadPlacement, Placement};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = path(d, "out.png");
    for (k, image) in [
        "4000000000x4000000000",
        "100000x100000",
        "65537x1",
        "16385x16385",
        "0x1",
    ]
    .iter()
    .enumerate()
    {
        let record = format!("region=0,0,1,1 image={image} id=0");
        assert_eq!(record.parse::<Placement>(), Err(BadPlacement), "{record}");
        let part = path(d, &format!("p{k}.png"));
        std::fs::write(&part, png_with_record(&record)).unwrap();
        fails(&["stitch", "-o", &out, &part], 1, "records no place");
        assert!(!Path::new(&out).exists());
    }
    // The largest images a render makes: 65536 wide, or 16384x16384.
    for image in ["65536x4096", "16384x16384", "1x65536"] {
        let record = format!("region=0,0,1,1 image={image} id=0");
        let p: Placement = record.parse().unwrap();
        assert_eq!(p.to_string().parse(), Ok(p));
    }
}

/// The largest single allocation this test process has made since [`Largest::reset`]:
/// reading a part must not allocate what its header claims before the file shows it
/// holds that much.
struct Largest;

static LARGEST: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call goes to the system allocator unchanged; only the size is noted.
unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Largest = Largest;

/// A part of one pixel whose header and record state a 16384×16384 part of a
/// 16384×16384 image (what a render of `MAX_PIXELS` pixels makes).
fn lying_part(format: Format) -> Vec<u8> {
    use whitted::image_io::parts::{encode_part, Placement};
    use whitted::settings::{Encoding, Region};
    let side = 16384u32;
    let placement = Placement {
        region: Region {
            x: 0,
            y: 0,
            width: side,
            height: side,
        },
        width: side,
        height: side,
        image: 0,
        encoding: Encoding::Linear,
    };
    let frame = whitted::render::Frame::new(1, 1);
    let mut bytes = encode_part(&frame, &placement, format, Encoding::Linear).unwrap();
    let (w, h) = (side.to_be_bytes(), side.to_be_bytes());
    match format {
        Format::Png => {
            // IHDR's width and height, then its CRC (of the chunk's type and data).
            assert_eq!(&bytes[12..16], b"IHDR");
            bytes[16..20].copy_from_slice(&w);
            bytes[20..24].copy_from_slice(&h);
            let crc = crc32fast::hash(&bytes[12..29]);
            bytes[29..33].copy_from_slice(&crc.to_be_bytes());
        }
        _ => {
            // The data window (box2i: x and y min, then max, little-endian).
            let name = b"dataWindow\0box2i\0";
            let at = bytes.windows(name.len()).position(|w| w == name).unwrap();
            let max = at + name.len() + 4 + 8;
            let last = (side as i32 - 1).to_le_bytes();
            bytes[max..max + 4].copy_from_slice(&last);
            bytes[max + 4..max + 8].copy_from_slice(&last);
        }
    }
    bytes
}

/// A part of a few hundred bytes whose header states 16384×16384 pixels is refused
/// before they are allocated (805 MB for a PNG part, 3.2 GB for an EXR part were
/// allocated before its data was found short), by `stitch` and by `compare`, with one
/// line; a file large enough to hold its pixels still reads.
#[test]
fn a_part_whose_header_states_more_than_its_file_holds_is_refused_unallocated() {
    use std::io::Cursor;
    use whitted::image_io::parts::{decode_part, encode_part, Placement};
    use whitted::settings::Encoding;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (format, ext) in [(Format::Png, "png"), (Format::Exr, "exr")] {
        let bytes = lying_part(format);
        let len = bytes.len();
        LARGEST.store(0, Ordering::SeqCst);
        let error = decode_part(Cursor::new(&bytes), format, "lying").unwrap_err();
        let largest = LARGEST.load(Ordering::SeqCst);
        let expected = format!("16384x16384 pixels, more than its {len} bytes can hold");
        assert!(error.to_string().contains(&expected), "{ext}: {error}");
        assert!(
            largest < 1 << 24,
            "{ext}: {largest} bytes allocated at once"
        );
        // What `compare` reads (`image` refuses an EXR without the chunks its header
        // calls for before it allocates the pixels).
        LARGEST.store(0, Ordering::SeqCst);
        let limits = image::Limits::default();
        let error = whitted::image_io::decode_image(Cursor::new(&bytes), None, limits).unwrap_err();
        let largest = LARGEST.load(Ordering::SeqCst);
        if format == Format::Png {
            assert!(error.to_string().contains(&expected), "{ext}: {error}");
        }
        assert!(
            largest < 1 << 24,
            "{ext}: {largest} bytes allocated at once"
        );

        let part = path(d, &format!("lying.{ext}"));
        std::fs::write(&part, &bytes).unwrap();
        let out = path(d, &format!("out.{ext}"));
        fails(&["stitch", "-o", &out, &part], 1, &expected);
        assert!(!Path::new(&out).exists());
        let needle = if format == Format::Png {
            &expected
        } else {
            "lying.exr"
        };
        fails(&["compare", &part, &part], 1, needle);
    }
    // A real part is never refused, however well it compresses: a black one.
    let side = 2048;
    let placement: Placement = format!("region=0,0,{side},{side} image={side}x{side} id=0")
        .parse()
        .unwrap();
    let black = whitted::render::Frame::new(side, side);
    for format in [Format::Png, Format::Exr] {
        let bytes = encode_part(&black, &placement, format, Encoding::Linear).unwrap();
        let part = decode_part(Cursor::new(&bytes), format, "black")
            .unwrap_or_else(|e| panic!("{} bytes: {e}", bytes.len()));
        assert_eq!(part.placement, placement);
    }
}
