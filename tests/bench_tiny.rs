//! The trade-off study on its tiny grid: it runs, and its outputs are complete.
#![cfg(feature = "cli")]

use glam::Vec3;

use whitted::bench::{self, BenchOptions, CSV_HEADER};
use whitted::render::Frame;

#[test]
fn tiny_study_writes_a_complete_csv_table_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let opts = BenchOptions {
        out: dir.path().to_path_buf(),
        width: 32,
        height: 18,
        runs: 5,
        tiny: true,
        threads: Some(2),
        progress: false,
    };
    let rows = bench::run(&opts).unwrap();
    let scenes = bench::study_scenes(true);
    // Every setting on every scene, plus the reference preset row per scene.
    assert_eq!(rows.len(), scenes.len() * (bench::grid(true).len() + 1));

    let csv = std::fs::read_to_string(dir.path().join("bench.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header, CSV_HEADER.split(',').collect::<Vec<_>>());
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let body: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(body.len(), rows.len());
    for row in &body {
        assert_eq!(row.len(), header.len(), "{row:?}");
        assert!(
            row.iter().all(|c| !c.trim().is_empty()),
            "empty cell in {row:?}"
        );
        let median: f64 = row[col("median_s")].parse().unwrap();
        assert!(median > 0.0);
        let rmse: f64 = row[col("rmse_levels")].parse().unwrap();
        let flip: f64 = row[col("flip_mean")].parse().unwrap();
        assert!(rmse >= 0.0 && (0.0..=1.0).contains(&flip));
    }
    for s in &scenes {
        let these: Vec<&Vec<&str>> = body.iter().filter(|r| r[0] == s.name).collect();
        assert!(
            these.iter().any(|r| r[col("pareto")] == "true"),
            "{}",
            s.name
        );
        // The fastest setting is on the front by definition. The CSV rounds times to
        // microseconds, where tiny renders can tie: one of the tied is the fastest.
        let t = |r: &Vec<&str>| r[col("median_s")].parse::<f64>().unwrap();
        let fastest = these.iter().map(|r| t(r)).fold(f64::INFINITY, f64::min);
        assert!(
            these
                .iter()
                .filter(|r| t(r) == fastest)
                .any(|r| r[col("pareto")] == "true"),
            "{}: no setting of the least time ({fastest} s) is on the front",
            s.name
        );
        let reference = these
            .iter()
            .find(|r| r[col("preset")] == "reference")
            .unwrap();
        assert_eq!(reference[col("rmse_levels")], "0.0000");
        // Timed settings ran at least the asked number of times, at most ten times it.
        assert!(these
            .iter()
            .filter(|r| r[col("preset")] != "reference")
            .all(|r| (5..=50).contains(&r[col("runs")].parse::<usize>().unwrap())));
    }
    // The cutoff setting reports a bound; the others none.
    assert!(body
        .iter()
        .filter(|r| r[col("cutoff")] != "0")
        .any(|r| r[col("cutoff_bound_levels")].parse::<f64>().unwrap() > 0.0));

    let md = std::fs::read_to_string(dir.path().join("bench.md")).unwrap();
    assert!(md.contains("## Presets") && md.contains("| hw3 | default |"));
    let svg = std::fs::read_to_string(dir.path().join("bench.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("Pareto front"));

    // A second run reuses the cached references and measures the same errors.
    let again = bench::run(&opts).unwrap();
    let errs = |rs: &[bench::Row]| rs.iter().map(|r| r.errors.rmse).collect::<Vec<_>>();
    let first: Vec<f64> = errs(&rows)
        .into_iter()
        .zip(&rows)
        .filter(|(_, r)| r.runs > 1)
        .map(|(e, _)| e)
        .collect();
    let second: Vec<f64> = errs(&again)
        .into_iter()
        .zip(&again)
        .filter(|(_, r)| r.runs > 1)
        .map(|(e, _)| e)
        .collect();
    assert_eq!(first, second);
}

fn frame(pixels: Vec<Vec3>) -> Frame {
    Frame {
        width: pixels.len() as u32,
        height: 1,
        pixels,
    }
}

#[test]
fn errors_are_measured_in_displayed_levels() {
    let reference = frame(vec![Vec3::splat(0.5); 4]);
    let same = bench::compare(&reference, &reference);
    assert_eq!(same.rmse, 0.0);
    assert!(same.psnr.is_infinite());
    assert_eq!(
        (same.max, same.off_by_more_than_1, same.flip),
        (0, 0.0, 0.0)
    );

    // One channel of one pixel 10 levels off; another pixel above 1 (clamped: no error).
    let mut pixels = vec![Vec3::splat(0.5); 4];
    pixels[1].x += 10.0 / 255.0;
    let mut reference = reference.clone();
    reference.pixels[3] = Vec3::splat(1.0);
    pixels[3] = Vec3::splat(3.0);
    let e = bench::compare(&frame(pixels), &reference);
    let rmse = (100.0f64 / 12.0).sqrt();
    assert!((e.rmse - rmse).abs() < 1e-3, "{}", e.rmse);
    assert!((e.psnr - 20.0 * (255.0 / rmse).log10()).abs() < 1e-3);
    assert_eq!(e.max, 10);
    assert_eq!(e.off_by_more_than_1, 0.25);
    assert!(e.flip > 0.0);
}

#[test]
fn size_option_parses_and_rejects_clearly() {
    assert_eq!(bench::parse_size("320x180"), Ok((320, 180)));
    assert_eq!(bench::parse_size("16X9"), Ok((16, 9)));
    for bad in ["0x9", "320", "x", "320x", "5000x10", "-1x5", "axb"] {
        let e = bench::parse_size(bad).unwrap_err();
        assert!(e.contains("WxH") && e.contains(bad), "{e}");
    }
}

/// A row of a made-up scene "s" with the given setting, time and RMSE.
fn row(spp: u32, threshold: Option<f32>, depth: u32, seconds: f64, rmse: f64) -> bench::Row {
    use whitted::settings::{Adaptive, Quality};
    bench::Row {
        scene: "s".into(),
        setting: bench::Setting {
            quality: Quality {
                spp,
                adaptive: threshold.map(Adaptive::with_threshold),
                max_depth: depth,
                ..Quality::default()
            },
            preset: None,
        },
        runs: 5,
        median_s: seconds,
        min_s: seconds,
        rays: 1,
        refined: 1.0,
        errors: bench::Errors {
            rmse,
            ..Default::default()
        },
        cutoff_bound: 0.0,
        cutoff_error: 0,
        pareto: true,
    }
}

#[test]
fn fixed_spp_time_interpolates_log_log_at_the_same_depth() {
    let rows = vec![
        row(1, None, 5, 1.0, 8.0),
        row(4, None, 5, 4.0, 2.0),
        // Another depth: not part of the depth-5 sweep.
        row(4, None, 16, 100.0, 3.0),
        // Adaptive: not a fixed-spp setting.
        row(16, Some(0.1), 5, 2.0, 1.0),
    ];
    // RMSE 4 is halfway between 8 and 2 in log: time halfway between 1 and 4 in log.
    let t = bench::fixed_spp_time_for(&rows, "s", 5, 4.0).unwrap();
    assert!((t - 2.0).abs() < 1e-12, "{t}");
    assert_eq!(bench::fixed_spp_time_for(&rows, "s", 5, 1.0), None);
    assert_eq!(bench::fixed_spp_time_for(&rows, "s", 16, 3.0), None);
}

#[test]
fn knee_is_the_front_point_farthest_below_the_scaled_chord() {
    // Plain (1 spp, depth 5) at (1 s, RMSE 10); best RMSE 1 first reached at 10 s.
    // Scaled: x = (t − 1)/9, y = (e − 1)/9; distance below the chord = 1 − x − y.
    let rows = vec![
        row(1, None, 5, 1.0, 10.0),
        row(4, None, 5, 2.0, 6.0),       // 1 − 1/9 − 5/9 = 3/9
        row(16, Some(0.1), 5, 3.0, 2.0), // 1 − 2/9 − 1/9 = 6/9: the knee
        row(16, None, 5, 6.0, 1.5),      // 1 − 5/9 − 0.5/9 = 3.5/9
        row(64, None, 5, 10.0, 1.0),
        row(256, None, 5, 40.0, 0.95), // beyond the chord's end (within 10% of best)
    ];
    let k = bench::knee(&rows, "s").unwrap();
    assert_eq!((k.median_s, k.errors.rmse), (3.0, 2.0));
}
