//! Bad input that never hurts: a proptest fuzzer on the scene loader (arbitrary text,
//! TOML-like token soup, and the hw3 and stress scene files mutated), the limits checked
//! before any allocation, and giant images refused by the command line. An error is one
//! line (the loader's start with the file and position); nothing panics, and nothing
//! the limits forbid is allocated.

mod support;

use std::cell::RefCell;
use std::time::Instant;

use proptest::prelude::*;
use support::*;
use whitted::limits;
use whitted::render::{render, RenderControl};
use whitted::scene::{self, Scene};
use whitted::settings::{Precision, Settings, SettingsError};

const PATH: &str = "fuzz.toml";

#[derive(Default, Debug)]
struct Fuzzed {
    inputs: u64,
    accepted: u64,
    rejected: u64,
    with_line_col: u64,
}

/// Loads `text` both ways (streamed spheres and whole document): the two agree, an
/// error is one line that starts with the path, and an accepted scene renders a tiny
/// image with both tracers without a panic or a non-finite pixel.
fn check_input(text: &str, stats: &RefCell<Fuzzed>) -> Result<(), TestCaseError> {
    let streamed = Scene::from_toml_str(text, PATH);
    let whole = Scene::from_toml_str_whole(text, PATH);
    let mut s = stats.borrow_mut();
    s.inputs += 1;
    match (&streamed, &whole) {
        (Ok(a), Ok(b)) => {
            prop_assert_eq!(a, b, "the two parsing paths disagree");
            s.accepted += 1;
            let mut scene = a.clone();
            scene.image.max_depth = Some(scene.settings().quality.max_depth.min(4));
            for renderer in [Precision::Fast, Precision::Reference] {
                let mut opts = scene.settings();
                (opts.width, opts.height, opts.quality.spp) = (4, 3, 1);
                opts.quality.precision = renderer;
                let frame = match render(&scene, &opts, &RenderControl::default()) {
                    Ok((frame, _)) => frame,
                    Err(e) => return Err(TestCaseError::fail(format!("{renderer:?}: {e}"))),
                };
                prop_assert_eq!(frame.pixels.len(), 12);
                // A sample may overflow (a light of 1e300), but no pixel is non-finite.
                prop_assert!(
                    frame.pixels.iter().all(|p| p.is_finite()),
                    "{:?}: a non-finite pixel in {:?}",
                    renderer,
                    frame.pixels
                );
            }
        }
        (Err(e), Err(_)) => {
            s.rejected += 1;
            let line = e.to_string();
            prop_assert!(!line.contains('\n'), "multi-line error: {line:?}");
            prop_assert!(e.location().starts_with(PATH), "no location: {line:?}");
            prop_assert!(!e.message.trim().is_empty(), "empty message");
            let rest = &e.location()[PATH.len()..];
            if let Some(line_col) = rest.strip_prefix(':') {
                s.with_line_col += 1;
                let parts: Vec<&str> = line_col.split(':').collect();
                prop_assert!(
                    parts.len() == 2
                        && parts.iter().all(|p| p.parse::<u32>().is_ok_and(|n| n >= 1)),
                    "bad line:column in {line:?}"
                );
            }
        }
        _ => prop_assert!(
            false,
            "streamed {:?} but whole {:?}",
            streamed.as_ref().map(|_| "ok"),
            whole.as_ref().map(|_| "ok")
        ),
    }
    Ok(())
}

/// Replacement values for numbers: non-finite, out of range, too large, wrong type.
const BAD_NUMBERS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "+nan",
    "-1",
    "0",
    "-0.0",
    "1e400",
    "-1e400",
    "1e-400",
    "99999999999999999999",
    "9223372036854775807",
    "-9223372036854775808",
    "4294967296",
    "65537",
    "1e308",
    "0x10",
    "1_000",
    "\"1\"",
    "true",
    "[]",
    "[1, 2]",
    "{}",
    "1979-05-27",
];

/// One edit of a text: flip a byte, delete a range, duplicate a range, or replace the
/// number at a position by a bad one.
#[derive(Clone, Debug)]
enum Mutation {
    Flip(usize, u8),
    Delete(usize, usize),
    Duplicate(usize, usize),
    BadNumber(usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Flip(i, b)),
        (any::<usize>(), 1usize..64).prop_map(|(i, n)| Mutation::Delete(i, n)),
        (any::<usize>(), 1usize..200).prop_map(|(i, n)| Mutation::Duplicate(i, n)),
        (any::<usize>(), 0..BAD_NUMBERS.len()).prop_map(|(i, k)| Mutation::BadNumber(i, k)),
    ]
}

fn mutate(text: &str, edits: &[Mutation]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for m in edits {
        if bytes.is_empty() {
            break;
        }
        let len = bytes.len();
        match *m {
            Mutation::Flip(i, b) => bytes[i % len] = b,
            Mutation::Delete(i, n) => {
                let i = i % len;
                bytes.drain(i..(i + n).min(len));
            }
            Mutation::Duplicate(i, n) => {
                let i = i % len;
                let piece = bytes[i..(i + n).min(len)].to_vec();
                bytes.splice(i..i, piece);
            }
            Mutation::BadNumber(i, k) => {
                // The number starting at or after position i, if any.
                let Some(start) = (i % len..len).find(|&j| {
                    bytes[j].is_ascii_digit() && (j == 0 || !bytes[j - 1].is_ascii_alphanumeric())
                }) else {
                    continue;
                };
                let start = if start > 0 && bytes[start - 1] == b'-' {
                    start - 1
                } else {
                    start
                };
                let end = (start + 1..len)
                    .find(|&j| !(bytes[j].is_ascii_digit() || b".eE+-".contains(&bytes[j])))
                    .unwrap_or(len);
                bytes.splice(start..end, BAD_NUMBERS[k].bytes());
            }
        }
    }
    // Scene text is a &str: invalid UTF-8 from a flip is replaced (the file loader
    // rejects it before parsing, tested below).
    String::from_utf8_lossy(&bytes).into_owned()
}

/// TOML-like token soup: keys and headers of the scene format, brackets, numbers.
fn token_soup() -> impl Strategy<Value = String> {
    let token = prop_oneof![
        Just("[[sphere]]\n"),
        Just("[[light]]\n"),
        Just("[image]\n"),
        Just("[camera]\n"),
        Just("[sky]\n"),
        Just("center = "),
        Just("radius = "),
        Just("color = "),
        Just("reflect = "),
        Just("transmit = "),
        Just("ior = "),
        Just("width = "),
        Just("height = "),
        Just("spp = "),
        Just("max_depth = "),
        Just("look_from = "),
        Just("look_at = "),
        Just("vfov = "),
        Just("position = "),
        Just("["),
        Just("]"),
        Just("{"),
        Just("}"),
        Just(", "),
        Just("\n"),
        Just("1"),
        Just("0.5"),
        Just("-2"),
        Just("[0, 0, -1]"),
        Just("[1, 1, 1]"),
        Just("\"\"\""),
        Just("# c\n"),
        Just("nan"),
        Just("1e400"),
    ];
    prop::collection::vec(token, 0..60).prop_map(|t| t.concat())
}

#[test]
fn the_loader_never_panics_and_every_error_is_one_located_line() {
    let stats = RefCell::new(Fuzzed::default());
    // 1. Arbitrary text.
    runner(3000)
        .run(&any::<String>(), |t| check_input(&t, &stats))
        .unwrap_or_else(|e| panic!("{e}"));
    // 2. Token soup.
    runner(5000)
        .run(&token_soup(), |t| check_input(&t, &stats))
        .unwrap_or_else(|e| panic!("{e}"));
    // 3. The hw3 scene file and the stress scenes, mutated.
    let mut bases = vec![scene::hw3_toml(scene::HW3_DEFAULT_SEED)];
    for s in stress_scenes() {
        bases.push(stress_text(&s));
    }
    let bases = &bases;
    runner(20_000)
        .run(
            &(0..bases.len(), prop::collection::vec(mutation(), 1..6)),
            |(k, edits)| check_input(&mutate(&bases[k], &edits), &stats),
        )
        .unwrap_or_else(|e| panic!("{e}"));
    // 4. A scene of 1300 spheres (three batches of the streamed parser), mutated: the
    //    two paths agree on accepting, and on a bad value give the very same message.
    let mut many = scene::hw3_scene(scene::HW3_DEFAULT_SEED);
    let balls = many.spheres.clone();
    for k in 0..24 {
        many.spheres.extend(balls.iter().map(|b| {
            let mut b = *b;
            b.center.x += 4.0 * f64::from(k);
            b
        }));
    }
    let many = scene::to_toml(&many);
    let same_error = RefCell::new((0u64, 0u64));
    runner(300)
        .run(&prop::collection::vec(mutation(), 1..3), |edits| {
            let text = mutate(&many, &edits);
            check_input(&text, &stats)?;
            if let (Err(a), Err(b)) = (
                Scene::from_toml_str(&text, PATH),
                Scene::from_toml_str_whole(&text, PATH),
            ) {
                let mut n = same_error.borrow_mut();
                n.0 += 1;
                n.1 += u64::from(a == b);
                // When the text parses, both report the first bad value (a syntax error
                // later in the file may instead be what the whole-document parse sees).
                if a.message.starts_with("sphere ") && b.message.starts_with("sphere ") {
                    prop_assert_eq!(a, b);
                }
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let (errors, same) = same_error.into_inner();
    println!("1300-sphere scene mutated: {errors} errors, {same} identical from both paths");
    let s = stats.into_inner();
    println!(
        "loader fuzz: {} inputs, {} accepted (rendered 4x3 with both tracers), {} rejected \
         ({} with line:column, the rest with the file name only)",
        s.inputs, s.accepted, s.rejected, s.with_line_col
    );
    assert!(s.inputs >= 28_300);
    assert!(
        s.accepted > 100 && s.rejected > 1000,
        "both outcomes exercised: {s:?}"
    );
}

/// An error from `text`, which must be refused.
fn refused(text: &str) -> scene::SceneError {
    match Scene::from_toml_str(text, PATH) {
        Ok(_) => panic!("accepted: {}", &text[..text.len().min(200)]),
        Err(e) => {
            assert!(!e.to_string().contains('\n'));
            e
        }
    }
}

#[test]
fn image_limits_are_refused_with_a_located_message() {
    let e = refused("[image]\nwidth = 100000\n");
    assert_eq!(e.location(), "fuzz.toml:2:9");
    assert!(
        e.message.contains("width") && e.message.contains("65536"),
        "{e}"
    );
    // Each side within its limit, the product beyond 2^28 pixels: no buffer is made.
    let e = refused("# big\n[image]\nwidth = 65536\nheight = 65536\n");
    assert!(e.location().starts_with("fuzz.toml:2:"), "{e}");
    assert!(e.message.contains("268435456 pixels"), "{e}");
    for text in [
        "[image]\nspp = 0\n",
        "[image]\nspp = 65537\n",
        "[image]\nmax_depth = 65\n",
        "[image]\nheight = -1\n",
        "[image]\nwidth = 99999999999999999999\n",
        "[image]\nwidth = 1e12\n",
    ] {
        // The value's own position: line 2, after the key.
        let e = refused(text);
        let col = text[8..].find('=').unwrap() + 3;
        assert_eq!(e.location(), format!("fuzz.toml:2:{col}"), "{text:?}: {e}");
        println!("{text:?} -> {e}");
    }
    // The settings check itself, at the edge.
    let ok = Settings {
        width: 16384,
        height: 16384,
        ..Default::default()
    };
    assert!(ok.check().is_ok());
    let over = Settings {
        height: 16385,
        ..ok.clone()
    };
    assert!(over.check().unwrap_err().to_string().contains("pixels"));
    let depth = |max_depth| {
        let mut s = ok.clone();
        s.quality.max_depth = max_depth;
        s.check()
    };
    assert_eq!(depth(65), Err(SettingsError::Depth(65)));
    assert!(depth(64).is_ok());
}

#[test]
fn too_many_spheres_are_refused_before_parsing() {
    let one = "[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\n";
    let n = limits::MAX_SPHERES + 1;
    let text = one.repeat(n);
    let start = Instant::now();
    let e = refused(&text);
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "{} [[sphere]] tables ({} MB): refused in {seconds:.3} s: {e}",
        n,
        text.len() / 1_000_000
    );
    assert_eq!(
        e.location(),
        format!("fuzz.toml:{}:1", 3 * limits::MAX_SPHERES + 1)
    );
    assert!(
        e.message.contains("[[sphere]]") && e.message.contains("limit"),
        "{e}"
    );
    // The same spheres inline: beyond the size parsed as one document.
    let inline = format!(
        "sphere = [{}]\n",
        "{center = [0, 0, 0], radius = 1},".repeat(n)
    );
    let e = refused(&inline);
    assert!(e.message.contains("[[sphere]] tables"), "{e}");
    // Lights inline, few bytes each: refused by the bounded array, with a location.
    let lights = format!("light = [{}]\n", "{},".repeat(limits::MAX_LIGHTS + 1));
    let e = refused(&lights);
    assert!(e.location().starts_with("fuzz.toml:1:"), "{e}");
    assert!(e.message.contains("1024 lights"), "{e}");
    // At the limit it loads (streamed), and fast.
    let at_limit = Scene::from_toml_str(&one.repeat(1000), PATH).unwrap();
    assert_eq!(at_limit.spheres.len(), 1000);
}

/// The largest scene the limits allow loads: `MAX_SPHERES` tables as a scene generator
/// writes them (145 MB, over the 64 MiB that once was the file limit), every value
/// read back as written; a file with one error among them names its line.
#[test]
fn a_scene_of_the_most_spheres_loads_from_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("million.toml");
    let n = limits::MAX_SPHERES;
    let mut text = String::with_capacity(140 * n);
    text.push_str("[image]\nwidth = 16\nheight = 9\n\n");
    for k in 0..n {
        let x = k as f64 * 0.001 - 500.0;
        text.push_str(&format!(
            "[[sphere]]\ncenter = [{x}, -0.5, {k}]\nradius = 0.25\ncolor = [0.3, 0.8, 0.3]\n\
             reflect = 0\ntransmit = 0.5\nior = 1.5\n\n"
        ));
    }
    assert!(text.len() as u64 > 1 << 26 && text.len() as u64 <= limits::MAX_FILE_BYTES);
    std::fs::write(&path, &text).unwrap();
    let scene = Scene::load(&path).unwrap();
    assert_eq!(scene.spheres.len(), n);
    for k in [0, 1, n / 2, n - 1] {
        let s = &scene.spheres[k];
        assert_eq!(s.center.x, k as f64 * 0.001 - 500.0, "sphere {k}");
        assert_eq!(
            (s.center.z, s.radius, s.transmit, s.ior),
            (k as f64, 0.25, 0.5, 1.5)
        );
    }
    // A bad value deep in the file: located by line, the same as in a small file.
    let bad = text.replacen("radius = 0.25\ncolor = [0.3, 0.8, 0.3]\nreflect = 0\ntransmit = 0.5\nior = 1.5\n\n[[sphere]]\ncenter = [500", "radius = -1\ncolor = [0.3, 0.8, 0.3]\nreflect = 0\ntransmit = 0.5\nior = 1.5\n\n[[sphere]]\ncenter = [500", 1);
    assert_ne!(bad, text);
    std::fs::write(&path, &bad).unwrap();
    let e = Scene::load(&path).unwrap_err();
    let line = bad[..bad.find("radius = -1").unwrap()]
        .matches('\n')
        .count()
        + 1;
    assert_eq!(e.location(), format!("{}:{line}:10", path.display()), "{e}");
    assert!(e.message.contains("radius must be > 0"), "{e}");
}

#[test]
fn files_too_large_or_not_text_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.toml");
    // A sparse file: no disk space, but its size says it all.
    std::fs::File::create(&big)
        .unwrap()
        .set_len(limits::MAX_FILE_BYTES + 1)
        .unwrap();
    let e = Scene::load(&big).unwrap_err();
    assert!(
        e.message.contains("bytes") && e.message.contains("limit"),
        "{e}"
    );
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, b"[image]\nwidth = 3\xff\n").unwrap();
    let e = Scene::load(&bad).unwrap_err();
    assert!(e.message.contains("UTF-8"), "{e}");
    let e = Scene::load(&dir.path().join("missing.toml")).unwrap_err();
    assert!(e.to_string().contains("missing.toml"), "{e}");
}

#[cfg(all(feature = "cli", feature = "viewer"))] // the binary needs both features
fn whitted() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_whitted"))
}

/// A giant image from the command line or from the file is refused before anything is
/// allocated (65536² pixels of 12 bytes would be 51 GB: an attempt would abort, not
/// print one line and exit 1).
#[cfg(all(feature = "cli", feature = "viewer"))]
#[test]
fn giant_images_are_refused_by_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("giant.toml");
    std::fs::write(&scene, "[image]\nwidth = 65536\nheight = 65536\n").unwrap();
    let out_file = dir.path().join("out.png");
    let runs: [Vec<&std::ffi::OsStr>; 2] = [
        ["render", "--width", "65536", "--height", "65536", "-o"]
            .iter()
            .map(std::ffi::OsStr::new)
            .chain([out_file.as_os_str()])
            .collect(),
        ["render"]
            .iter()
            .map(std::ffi::OsStr::new)
            .chain([scene.as_os_str(), "-o".as_ref(), out_file.as_os_str()])
            .collect(),
    ];
    // From the command line a usage error (2), from the file a bad scene (1).
    for (args, code) in runs.into_iter().zip([2, 1]) {
        let out = whitted().args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        println!("{args:?}: {:?} {stderr:?}", out.status.code());
        assert_eq!(out.status.code(), Some(code), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains("268435456 pixels"), "{stderr}");
    }
    assert!(!out_file.exists());
}
