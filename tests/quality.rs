//! Quality settings: the contribution cutoff's error bound, adaptive anti-aliasing and
//! the presets, each checked against an independent render (no cutoff, full
//! anti-aliasing, the f64 reference).

mod support;

use glam::{DVec3, Vec3};
use proptest::prelude::*;
use support::spec_reference::{check_close, spec_reference};
use whitted::image_io::{to_rgb8, Encoding};

use whitted::render::{
    accumulate, first_pass_samples, make_tracer, render, render_bounded, resolve, RenderControl,
    RenderError,
};
use whitted::sampling::sample_offset;
use whitted::scene::{hw3_scene, Light, Scene, Sphere};
use whitted::settings::{
    Adaptive, Overrides, Precision, Preset, Quality, Region, Settings, SettingsError,
};

/// A layer of settings that names only a preset.
fn preset(p: Preset) -> Overrides {
    Overrides {
        quality: Some(p),
        ..Overrides::default()
    }
}

fn hw3_opts(width: u32, height: u32, spp: u32) -> (Scene, Settings) {
    let scene = hw3_scene(2020);
    let mut opts = scene.settings();
    opts.width = width;
    opts.height = height;
    opts.quality.spp = spp;
    (scene, opts)
}

/// A random small scene: spheres in front of the camera with any weights, 0–2 lights.
fn small_scene() -> impl Strategy<Value = Scene> {
    let sphere = (
        (-2.0f64..2.0, -1.5f64..1.5, -5.0f64..-1.5),
        0.1f64..1.2,
        (0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0),
        prop_oneof![Just(0.0), Just(1.0), 0.0f64..1.0],
        prop_oneof![Just(0.0), Just(1.0), 0.0f64..1.0],
        1.0f64..2.5,
    )
        .prop_map(
            |((x, y, z), r, (cr, cg, cb), reflect, transmit, ior)| Sphere {
                color: DVec3::new(cr, cg, cb),
                reflect,
                transmit,
                ior,
                ..Sphere::new(DVec3::new(x, y, z), r)
            },
        );
    let light =
        ((-10.0f64..10.0, 0.0f64..10.0, -5.0f64..5.0), 0.0f64..1.0).prop_map(|((x, y, z), i)| {
            Light {
                position: DVec3::new(x, y, z),
                intensity: DVec3::splat(i),
            }
        });
    (
        prop::collection::vec(sphere, 1..7),
        prop::collection::vec(light, 0..3),
        any::<bool>(),
    )
        .prop_map(|(mut spheres, lights, ground)| {
            if ground {
                spheres.push(Sphere::new(DVec3::new(0.0, -100.5, -2.0), 100.0));
            }
            // Start from the built-in scene so that new scene fields keep defaults.
            let mut scene = hw3_scene(2020);
            scene.spheres = spheres;
            scene.lights = lights;
            scene
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The per-pixel bound the cutoff reports is never below the true error against
    /// the same render without a cutoff.
    #[test]
    fn cutoff_bound_covers_the_true_error(
        scene in small_scene(),
        eps in prop_oneof![Just(1e-3f32), 0.0f32..0.6],
        depth in 1u32..7,
        spp in 1u32..3,
    ) {
        let mut opts = scene.settings();
        opts.width = 12;
        opts.height = 8;
        opts.quality.max_depth = depth;
        opts.quality.spp = spp;
        let exact = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
        prop_assert!(exact.cutoff_bound.iter().all(|&b| b == 0.0));
        opts.quality.cutoff = eps;
        let cut = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
        for ((a, b), bound) in cut.frame.pixels.iter().zip(&exact.frame.pixels).zip(&cut.cutoff_bound) {
            let err = (*a - *b).abs().max_element();
            // Slack for the f32 rounding of sums that differ in one term.
            prop_assert!(err <= bound + 1e-5, "error {err} above bound {bound} (eps {eps})");
        }
    }
}

#[test]
fn cutoff_skips_work_and_reports_a_nonzero_bound_on_hw3() {
    let (scene, mut opts) = hw3_opts(64, 36, 1);
    let exact = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
    opts.quality.cutoff = 0.2;
    let cut = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
    assert!(cut.stats.rays.total() < exact.stats.rays.total());
    let max_bound = cut.cutoff_bound.iter().fold(0.0f32, |m, &b| m.max(b));
    assert!(max_bound > 0.0);
    assert_ne!(cut.frame, exact.frame);
}

/// `SampleTracer::sample_row` gives the colours `sample` gives one by one, and
/// `sample_row_bounded` what `sample_bounded` gives (colour and bound), each casting the
/// same rays, whatever the cutoff, with both tracers: the fast tracer shares work along
/// a row with a cutoff too, where it shades each hit as `sample` does; the reference
/// tracer takes the trait's rows. At ε = 1.5 the fast tracer skips every branch (a
/// primary hit's weights are at most 1), so every pixel but the sky's is black; the
/// reference tracer has no cutoff.
#[test]
fn a_row_of_samples_is_its_samples_one_by_one_at_any_cutoff() {
    let (scene, mut opts) = hw3_opts(96, 54, 1);
    let s: Vec<f32> = (0..96).map(|i| (i as f32 + 0.5) / 96.0).collect();
    for (precision, cutoff) in [
        (Precision::Fast, 0.0),
        (Precision::Fast, 0.05),
        (Precision::Fast, 0.25),
        (Precision::Fast, 1.5),
        (Precision::Reference, 0.05),
    ] {
        opts.quality.cutoff = cutoff;
        opts.quality.precision = precision;
        let tracer = make_tracer(&scene, &opts).unwrap();
        let (mut black, mut bounded) = (0, 0);
        for j in 0..54 {
            let t = (j as f32 + 0.5) / 54.0;
            let (mut row, mut row_rays) = (vec![Vec3::NAN; 96], Default::default());
            tracer.sample_row(&s, t, &mut row, &mut row_rays);
            let (mut with_bounds, mut bounded_rays) =
                (vec![(Vec3::NAN, f32::NAN); 96], Default::default());
            tracer.sample_row_bounded(&s, t, &mut with_bounds, &mut bounded_rays);
            let mut one_by_one_rays = Default::default();
            let one_by_one: Vec<(Vec3, f32)> = s
                .iter()
                .map(|&s| tracer.sample_bounded(s, t, &mut one_by_one_rays))
                .collect();
            let colours: Vec<Vec3> = one_by_one.iter().map(|p| p.0).collect();
            let at = format!("{precision:?}, ε {cutoff}, row {j}");
            assert_eq!(row, colours, "{at}");
            assert_eq!(with_bounds, one_by_one, "{at}");
            assert_eq!(row_rays, one_by_one_rays, "{at}");
            assert_eq!(bounded_rays, one_by_one_rays, "{at}");
            black += row.iter().filter(|c| **c == Vec3::ZERO).count();
            bounded += one_by_one.iter().filter(|p| p.1 > 0.0).count();
        }
        let skips = precision == Precision::Fast && cutoff > 0.0;
        assert_eq!(
            bounded > 0,
            skips,
            "{precision:?}, ε {cutoff}: {bounded} bounded"
        );
        // hw3's view is about half ground and balls.
        assert_eq!(
            black > 96 * 54 / 4,
            skips && cutoff > 1.0,
            "{precision:?}, ε {cutoff}: {black} black"
        );
    }
}

#[test]
fn adaptive_with_threshold_zero_is_full_anti_aliasing_bit_for_bit() {
    // Both tracers: the reference one takes its bounded samples from the trait's default.
    for (precision, spp) in [
        (Precision::Fast, 5),
        (Precision::Fast, 9),
        (Precision::Fast, 16),
        (Precision::Reference, 5),
    ] {
        let (scene, mut opts) = hw3_opts(48, 27, spp);
        opts.quality.precision = precision;
        let (full, _) = render(&scene, &opts, &RenderControl::default()).unwrap();
        // The viewer's path: passes of accumulate, then resolve.
        let tracer = make_tracer(&scene, &opts).unwrap();
        let mut sums = vec![Vec3::ZERO; 48 * 27];
        let control = RenderControl::default();
        accumulate(tracer.as_ref(), &opts, 0..2, &mut sums, &control).unwrap();
        accumulate(tracer.as_ref(), &opts, 2..spp, &mut sums, &control).unwrap();
        assert_eq!(
            resolve(&sums, spp, 48, 27),
            full,
            "accumulate, {precision:?}, spp {spp}"
        );

        opts.quality.adaptive = Some(Adaptive::with_threshold(0.0));
        let adaptive = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
        assert_eq!(adaptive.refined, 48 * 27);
        assert_eq!(adaptive.frame, full, "{precision:?}, spp {spp}");
        assert!(adaptive.cutoff_bound.iter().all(|&b| b == 0.0));
    }
}

#[test]
fn adaptive_pixels_carry_the_cutoff_bound_of_their_samples() {
    // With the cutoff on, an adaptive pixel's value and bound are the means of its
    // samples' colours and bounds. Threshold 0 refines every pixel: a full render of
    // the same 9 samples. A threshold above any clamped difference refines none: each
    // pixel has its 4 first samples, traced here at the SPEC's film positions
    // (s = (i + sx)/W, t = (j + sy)/H).
    let (scene, mut opts) = hw3_opts(24, 14, 9);
    opts.quality.cutoff = 0.05;
    let full = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
    assert!(full.cutoff_bound.iter().any(|&b| b > 0.0));
    opts.quality.adaptive = Some(Adaptive::with_threshold(0.0));
    let a = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
    assert_eq!(a.refined, 24 * 14);
    assert_eq!(a.frame, full.frame);
    assert_eq!(a.cutoff_bound, full.cutoff_bound);

    opts.quality.spp = 16;
    opts.quality.adaptive = Some(Adaptive::with_threshold(2.0));
    let a = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
    assert_eq!(a.refined, 0);
    let tracer = make_tracer(&scene, &opts).unwrap();
    let first = first_pass_samples(16, Adaptive::FIRST, opts.seed);
    for j in 0..14 {
        for i in 0..24 {
            let (mut sum, mut bound) = (Vec3::ZERO, 0.0);
            for &k in &first {
                let (sx, sy) = sample_offset(i, j, k, 16, opts.seed);
                let (s, t) = ((i as f32 + sx) / 24.0, (j as f32 + sy) / 14.0);
                let (c, b) = tracer.sample_bounded(s, t, &mut Default::default());
                sum += c;
                bound += b;
            }
            let n = (j * 24 + i) as usize;
            let (got, got_bound) = (a.frame.pixels[n], a.cutoff_bound[n]);
            assert!((got - sum / 4.0).abs().max_element() < 1e-6, "{i},{j}");
            assert!((got_bound - bound / 4.0).abs() <= 1e-6 * bound, "{i},{j}");
        }
    }
    assert!(a.cutoff_bound.iter().any(|&b| b > 0.0));
}

#[test]
fn adaptive_region_is_the_crop_of_the_whole_image() {
    let (scene, mut opts) = hw3_opts(64, 36, 16);
    opts.quality.adaptive = Some(Adaptive::with_threshold(0.05));
    let (whole, _) = render(&scene, &opts, &RenderControl::default()).unwrap();
    for region in [
        Region {
            x: 0,
            y: 0,
            width: 64,
            height: 36,
        },
        Region {
            x: 10,
            y: 5,
            width: 17,
            height: 9,
        },
        Region {
            x: 63,
            y: 35,
            width: 1,
            height: 1,
        },
        Region {
            x: 0,
            y: 20,
            width: 30,
            height: 16,
        },
    ]
    .into_iter()
    // Every column alone and every row alone: each pixel's neighbours left and right,
    // then above and below, lie outside its region, and still flag it as in the whole.
    .chain((0..64).map(|x| Region {
        x,
        y: 0,
        width: 1,
        height: 36,
    }))
    .chain((0..36).map(|y| Region {
        x: 0,
        y,
        width: 64,
        height: 1,
    })) {
        opts.region = Some(region);
        let control = RenderControl::default();
        let rendered = render_bounded(&scene, &opts, &control).unwrap();
        let part = rendered.frame;
        // Rays from the eye: 4 first samples in each pixel of the region and of a
        // one-pixel margin around it inside the image, then 12 more in each refined
        // pixel; the progress counts them all and its total ends exact.
        let (x0, y0) = (region.x.saturating_sub(1), region.y.saturating_sub(1));
        let x1 = (region.x + region.width + 1).min(64);
        let y1 = (region.y + region.height + 1).min(36);
        let samples = u64::from((x1 - x0) * (y1 - y0)) * 4 + rendered.refined * 12;
        assert_eq!(rendered.stats.rays.primary, samples, "region {region:?}");
        assert_eq!(control.pixels_done(), samples, "region {region:?}");
        assert_eq!(control.samples_total(), samples, "region {region:?}");
        for y in 0..region.height {
            for x in 0..region.width {
                // Frames count rows from the bottom; regions from the top.
                let j_part = region.height - 1 - y;
                let j_whole = 36 - 1 - (region.y + y);
                assert_eq!(
                    part.get(x, j_part),
                    whole.get(region.x + x, j_whole),
                    "region {region:?} pixel {x},{y}"
                );
            }
        }
    }
}

#[test]
fn adaptive_refines_edges_not_flat_sky_and_stays_close_to_full_aa() {
    let (scene, mut opts) = hw3_opts(96, 54, 16);
    let (full, _) = render(&scene, &opts, &RenderControl::default()).unwrap();
    opts.quality.adaptive = Some(Adaptive::with_threshold(0.03));
    let a = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
    let n = 96 * 54;
    assert!(
        a.refined > 0 && a.refined < n as u64 / 2,
        "refined {}",
        a.refined
    );
    // Unrefined pixels: the mean of 4 samples that agreed within the threshold, so
    // within the threshold of the full mean wherever the pixel is smooth.
    let far: usize = a
        .frame
        .pixels
        .iter()
        .zip(&full.pixels)
        .filter(|(x, y)| (**x - **y).abs().max_element() > 0.03)
        .count();
    assert!(
        far * 100 < n,
        "{far} pixels differ by more than the threshold"
    );

    // Only sky, no ball: nothing but smooth gradients, so no pixel needs refining.
    let mut sky = scene.clone();
    sky.spheres.clear();
    let b = render_bounded(&sky, &opts, &RenderControl::default()).unwrap();
    assert_eq!(b.refined, 0);
}

#[test]
fn adaptive_refines_the_pixels_its_rule_names_and_gives_their_means() {
    // The rule, from the f64 reference tracer's colours at the first samples' film
    // positions (SPEC §2: s = (i + sx)/W, t = (j + sy)/H): a pixel takes all its
    // samples when its first samples, clamped as shown, spread by the threshold or
    // more in a channel, or its first samples' clamped mean differs by that much from
    // a 4-neighbour's; otherwise it is the mean of its first samples.
    let (w, h, spp, threshold) = (32u32, 18u32, 16u32, 0.05);
    let (scene, mut opts) = hw3_opts(w, h, spp);
    opts.quality.cutoff = 0.0;
    opts.quality.adaptive = Some(Adaptive::with_threshold(threshold as f32));
    let camera = support::spec_reference::spec_camera(&scene, w, h);
    let tracer =
        whitted::trace::reference::ReferenceTracer::new(&scene, camera, opts.quality.max_depth);
    let first = first_pass_samples(spp, Adaptive::FIRST, opts.seed);
    let colour = |i: u32, j: u32, k: u32| {
        let (sx, sy) = sample_offset(i, j, k, spp, opts.seed);
        let s = (f64::from(i) + f64::from(sx)) / f64::from(w);
        let t = (f64::from(j) + f64::from(sy)) / f64::from(h);
        let c = tracer.sample_f64(s, t, &mut Default::default());
        assert!(c.is_finite());
        c
    };
    let shown = |c: DVec3| c.clamp(DVec3::ZERO, DVec3::ONE);
    let firsts: Vec<Vec<DVec3>> = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| first.iter().map(|&k| colour(i, j, k)).collect())
        .collect();
    let mean = |p: &[DVec3]| p.iter().sum::<DVec3>() / p.len() as f64;
    let at = |i: u32, j: u32| &firsts[(j * w + i) as usize];
    let mut refined = 0;
    let mut far = 0;
    let a = render_bounded(&scene, &opts, &RenderControl::default()).unwrap();
    for j in 0..h {
        for i in 0..w {
            let p = at(i, j);
            let lo = p.iter().fold(DVec3::ONE, |m, &c| m.min(shown(c)));
            let hi = p.iter().fold(DVec3::ZERO, |m, &c| m.max(shown(c)));
            let m = shown(mean(p));
            let neighbours = [(-1, 0), (1, 0), (0, -1), (0, 1)]
                .into_iter()
                .map(|(di, dj)| (i as i64 + di, j as i64 + dj))
                .filter(|&(x, y)| (0..w as i64).contains(&x) && (0..h as i64).contains(&y));
            let refine = (hi - lo).max_element() >= threshold
                || neighbours.into_iter().any(|(x, y)| {
                    (shown(mean(at(x as u32, y as u32))) - m)
                        .abs()
                        .max_element()
                        >= threshold
                });
            let want = if refine {
                refined += 1;
                (0..spp).map(|k| colour(i, j, k)).sum::<DVec3>() / f64::from(spp)
            } else {
                mean(p)
            };
            let got = a.frame.get(i, j).as_dvec3();
            if (got - want).abs().max_element() > 1e-4 {
                far += 1;
            }
        }
    }
    assert!(refined > 0 && refined < w * h / 2, "refined {refined}");
    assert_eq!(a.refined, u64::from(refined));
    assert_eq!(far, 0, "pixels off the rule's values");
}

#[test]
fn first_pass_samples_spread_over_the_pixel() {
    for (spp, first) in [(16, 4), (64, 4), (9, 4), (5, 4), (32, 9), (16, 1)] {
        let ks = first_pass_samples(spp, first, 7);
        assert_eq!(ks.len(), first as usize);
        assert!(ks.windows(2).all(|w| w[0] < w[1]) && ks.iter().all(|&k| k < spp));
        if first == 4 && spp >= 16 {
            let mut quadrants: Vec<(bool, bool)> = ks
                .iter()
                .map(|&k| {
                    let (x, y) = sample_offset(3, 4, k, spp, 7);
                    (x < 0.5, y < 0.5)
                })
                .collect();
            quadrants.sort();
            quadrants.dedup();
            assert_eq!(quadrants.len(), 4, "spp {spp}: {ks:?}");
        }
    }
    assert_eq!(first_pass_samples(3, 4, 0), vec![0, 1, 2]);
}

#[test]
fn first_pass_samples_take_one_sample_in_each_block_of_the_target_grid() {
    // spp = n² samples in an n×n grid of strata, `first` = g² targets at the centres
    // of a g×g grid of blocks, n/g odd: a target is the centre of its block's middle
    // stratum, whose sample lies within √2/2n of it, and every sample outside the
    // block at least 1/2g > √2/2n away; so the sample nearest each target lies in its
    // block. Other pixels turn pixel (0, 0)'s strata by one rotation of their row-major
    // order, which keeps one sample in each block.
    for (spp, first) in [(36u32, 4u32), (81, 9), (100, 4), (144, 16)] {
        let g = (first as f32).sqrt() as u32;
        let ks = first_pass_samples(spp, first, 7);
        for (i, j) in [(0, 0), (3, 4), (17, 5)] {
            let mut blocks: Vec<(u32, u32)> = ks
                .iter()
                .map(|&k| {
                    let (x, y) = sample_offset(i, j, k, spp, 7);
                    ((x * g as f32) as u32, (y * g as f32) as u32)
                })
                .collect();
            blocks.sort();
            blocks.dedup();
            assert_eq!(
                blocks.len(),
                first as usize,
                "spp {spp}, pixel {i},{j}: {ks:?}"
            );
        }
    }
}

#[test]
fn every_preset_renders_and_better_presets_err_less() {
    let (scene, base) = hw3_opts(32, 18, 1);
    let reference = {
        let opts = base.clone().with(&preset(Preset::Reference));
        render(&scene, &opts, &RenderControl::default()).unwrap().0
    };
    let mut errors = Vec::new();
    for p in Preset::ALL {
        let q = p.quality();
        let opts = base.clone().with(&preset(p));
        assert_eq!(opts.quality, q);
        let (frame, stats) =
            render(&scene, &opts, &RenderControl::default()).unwrap_or_else(|e| panic!("{p}: {e}"));
        assert!(frame.pixels.iter().all(|p| p.is_finite()), "{p}");
        assert!(stats.rays.total() > 0);
        let sq: f32 = frame
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(a, b)| {
                (a.clamp(Vec3::ZERO, Vec3::ONE) - b.clamp(Vec3::ZERO, Vec3::ONE)).length_squared()
            })
            .sum();
        errors.push(sq);
        assert_eq!(p.name().parse::<Preset>(), Ok(p));
    }
    // The reference preset's image is the SPEC's `f64` image of its settings, made
    // without the renderer's film mapping, sample loop or bytes.
    let opts = base.clone().with(&preset(Preset::Reference));
    let bytes = to_rgb8(&reference, Encoding::Linear).into_raw();
    check_close(
        "reference preset, 32x18",
        &bytes,
        &spec_reference(&scene, &opts),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
}

#[test]
fn unknown_preset_and_bad_knobs_are_clear_errors() {
    let e = "fast".parse::<Preset>().unwrap_err().to_string();
    assert!(
        e.contains("fast") && e.contains("draft, default, high or reference"),
        "{e}"
    );
    let (scene, mut opts) = hw3_opts(8, 8, 1);
    let refused = |opts: &Settings| match render(&scene, opts, &RenderControl::default()) {
        Err(RenderError::Settings(e)) => e,
        Err(e) => panic!("refused for another reason: {e}"),
        Ok(_) => panic!("rendered {:?}", opts.quality),
    };
    opts.quality.cutoff = f32::NAN;
    assert!(matches!(refused(&opts), SettingsError::Cutoff(c) if c.is_nan()));
    opts.quality.cutoff = 0.0;
    opts.quality.adaptive = Some(Adaptive {
        first: 0,
        threshold: 0.1,
    });
    assert_eq!(refused(&opts), SettingsError::AdaptiveFirst);
    opts.quality.adaptive = Some(Adaptive::with_threshold(-1.0));
    assert_eq!(refused(&opts), SettingsError::AdaptiveThreshold(-1.0));
}

#[test]
fn reference_precision_ignores_the_cutoff() {
    let (scene, mut opts) = hw3_opts(16, 9, 1);
    opts.quality.precision = Precision::Reference;
    let (exact, _) = render(&scene, &opts, &RenderControl::default()).unwrap();
    opts.quality.cutoff = 0.3;
    let (cut, _) = render(&scene, &opts, &RenderControl::default()).unwrap();
    assert_eq!(exact, cut);
}

#[test]
fn scene_file_quality_key_sets_the_preset_and_explicit_keys_win() {
    let text = "[image]\nquality = \"default\"\nwidth = 16\nheight = 9\n\n\
                [[sphere]]\ncenter = [0, 0, -2]\nradius = 0.5\n";
    let scene = Scene::from_toml_str(text, "q.toml").unwrap();
    let q = Preset::Default.quality();
    assert_eq!(scene.image.quality, Some(Preset::Default));
    assert_eq!((scene.image.spp, scene.image.max_depth), (None, None));
    assert_eq!(scene.settings().quality, q);
    // The written scene keeps the key and loads back the same.
    let again = Scene::from_toml_str(&whitted::scene::to_toml(&scene), "w.toml").unwrap();
    assert_eq!(again.image, scene.image);

    let text =
        "[image]\nquality = \"high\"\nspp = 4\n\n[[sphere]]\ncenter = [0, 0, -2]\nradius = 0.5\n";
    let scene = Scene::from_toml_str(text, "q.toml").unwrap();
    let opts = scene.settings();
    assert_eq!(opts.quality.spp, 4);
    assert_eq!(opts.quality.max_depth, Preset::High.quality().max_depth);
    assert_eq!(opts.quality.adaptive, Preset::High.quality().adaptive);

    let text = "[image]\nquality = \"ultra\"\n";
    let e = Scene::from_toml_str(text, "bad.toml")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("bad.toml:2:"), "{e}");
    assert!(
        e.contains("ultra") && e.contains("draft, default, high or reference"),
        "{e}"
    );
}

#[test]
fn scenes_without_the_key_render_as_before() {
    let scene = hw3_scene(2020);
    assert_eq!(scene.image.quality, None);
    let opts = scene.settings();
    assert_eq!(opts.quality, Quality::default());
    assert_eq!(Quality::default(), Preset::Draft.quality());
}
