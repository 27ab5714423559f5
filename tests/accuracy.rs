//! The fast `f32` tracer against the `f64` reference on the built-in scene:
//! at 640×360, at most 0.01% of the pixels may differ by more than one 8-bit level, and
//! none by more than 8 except a handful on silhouettes (where an `f32` ray may pass on
//! the other side of an edge than the `f64` one).

use whitted::image_io::{to_rgb8, Encoding};
use whitted::render::{self, RenderControl};
use whitted::scene::{hw3_scene, HW3_DEFAULT_SEED};
use whitted::settings::Precision;

/// Pixels that may differ by more than 8 levels, if each sits on a silhouette.
const HANDFUL: usize = 5;

#[test]
fn fast_matches_reference_on_hw3_640x360() {
    let scene = hw3_scene(HW3_DEFAULT_SEED);
    let mut opts = scene.settings();
    opts.width = 640;
    opts.height = 360;
    let control = RenderControl::default();
    let (fast, _) = render::render(&scene, &opts, &control).expect("fast render");
    opts.quality.precision = Precision::Reference;
    let (reference, _) = render::render(&scene, &opts, &control).expect("reference render");
    let (fast, reference) = (
        to_rgb8(&fast, Encoding::Linear),
        to_rgb8(&reference, Encoding::Linear),
    );
    let (w, h) = reference.dimensions();

    let level = |x: u32, y: u32| -> u8 {
        let (a, b) = (fast.get_pixel(x, y).0, reference.get_pixel(x, y).0);
        (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap()
    };
    // A silhouette pixel: the reference itself jumps by more than 8 levels to one of
    // the 8 neighbours, so a tiny change of the ray can land on the other side.
    let on_silhouette = |x: u32, y: u32| -> bool {
        let p = reference.get_pixel(x, y).0;
        (-1i64..=1)
            .flat_map(|dy| (-1i64..=1).map(move |dx| (dx, dy)))
            .filter_map(|(dx, dy)| {
                let (nx, ny) = (i64::from(x) + dx, i64::from(y) + dy);
                (nx >= 0 && ny >= 0 && nx < i64::from(w) && ny < i64::from(h))
                    .then(|| reference.get_pixel(nx as u32, ny as u32).0)
            })
            .any(|q| (0..3).any(|c| p[c].abs_diff(q[c]) > 8))
    };

    let total = (w * h) as usize;
    let mut histogram = [0usize; 256];
    let mut big = Vec::new();
    let mut sum_abs = 0f64;
    for y in 0..h {
        for x in 0..w {
            let d = level(x, y);
            histogram[d as usize] += 1;
            for c in 0..3 {
                sum_abs +=
                    f64::from(fast.get_pixel(x, y)[c].abs_diff(reference.get_pixel(x, y)[c]));
            }
            if d > 8 {
                big.push((x, y, d, on_silhouette(x, y)));
            }
        }
    }
    let over = |n: usize| histogram[n + 1..].iter().sum::<usize>();
    let max = histogram.iter().rposition(|&n| n > 0).unwrap();
    println!(
        "fast vs reference, hw3 640x360 ({total} pixels): {} differ at all, {} by >1 level \
         ({:.4}%), {} by >8; largest difference {max} levels; mean |difference| {:.2e} \
         levels per channel",
        over(0),
        over(1),
        100.0 * over(1) as f64 / total as f64,
        over(8),
        sum_abs / (3 * total) as f64
    );
    for (x, y, d, edge) in &big {
        println!("  pixel ({x}, {y}) from the top-left: {d} levels, silhouette: {edge}");
    }

    assert!(
        over(1) * 10_000 <= total,
        "{} pixels differ by more than one level: more than 0.01%",
        over(1)
    );
    assert!(
        big.len() <= HANDFUL,
        "{} pixels differ by more than 8 levels",
        big.len()
    );
    assert!(
        big.iter().all(|&(_, _, _, edge)| edge),
        "a pixel away from any silhouette differs by more than 8 levels: {big:?}"
    );
}
