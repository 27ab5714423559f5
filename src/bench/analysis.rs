//! Reading the measured rows: medians of run times, each scene's Pareto front of
//! (time, RMSE), its knee, and what a fixed-spp render would need for the same error.

use super::grid::plain;
use super::Row;
use crate::settings::Precision;

/// The median of `xs` (sorted in place); `xs` is not empty.
pub(crate) fn median(xs: &mut [f64]) -> f64 {
    xs.sort_by(f64::total_cmp);
    let m = xs.len() / 2;
    if xs.len() % 2 == 1 {
        xs[m]
    } else {
        (xs[m - 1] + xs[m]) / 2.0
    }
}

/// The scenes of `rows`, in the order they first appear.
pub(crate) fn scene_names(rows: &[Row]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        if !names.contains(&r.scene) {
            names.push(r.scene.clone());
        }
    }
    names
}

/// Marks the rows of each scene that no other row of that scene beats in both median
/// time and RMSE.
pub(crate) fn mark_pareto(rows: &mut [Row]) {
    for i in 0..rows.len() {
        let (t, e) = (rows[i].median_s, rows[i].errors.rmse);
        rows[i].pareto = !rows.iter().any(|o| {
            o.scene == rows[i].scene
                && o.median_s <= t
                && o.errors.rmse <= e
                && (o.median_s < t || o.errors.rmse < e)
        });
    }
}

/// The time a fixed-spp render at depth `max_depth` (no other knob) would need for
/// `rmse`, interpolated log-log between the measured spp sweep; `None` outside it.
pub fn fixed_spp_time_for(rows: &[Row], scene: &str, max_depth: u32, rmse: f64) -> Option<f64> {
    let mut sweep: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| {
            let q = &r.setting.quality;
            r.scene == scene
                && q.adaptive.is_none()
                && q.cutoff == 0.0
                && q.max_depth == max_depth
                && q.precision == Precision::Fast
        })
        .map(|r| (r.errors.rmse, r.median_s))
        .collect();
    sweep.sort_by(|a, b| b.0.total_cmp(&a.0));
    sweep.windows(2).find_map(|w| {
        let ((e0, t0), (e1, t1)) = (w[0], w[1]);
        (rmse <= e0 && rmse >= e1 && e0 > e1).then(|| {
            let f = (e0.ln() - rmse.ln()) / (e0.ln() - e1.ln());
            (t0.ln() + f * (t1.ln() - t0.ln())).exp()
        })
    })
}

/// The row of `scene` with the plain setting (1 spp, depth 5, exact).
pub(crate) fn plain_row<'a>(rows: &'a [Row], scene: &str) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.scene == scene && r.setting.quality == plain())
}

/// The knee of a scene's front, "Kneedle" style: time and RMSE scaled to \[0, 1\] between
/// the plain setting (1 spp, depth 5, exact: the program's default) and the cheapest
/// front point within 10% of the best RMSE of the fast tracer; the knee is the front
/// point in between farthest below the straight line joining those two, where extra
/// time stops buying much error.
pub fn knee<'a>(rows: &'a [Row], scene: &str) -> Option<&'a Row> {
    let plain = plain_row(rows, scene)?;
    let mut front: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            r.scene == scene
                && r.pareto
                && r.setting.quality.precision == Precision::Fast
                && r.median_s >= plain.median_s
                && r.errors.rmse <= plain.errors.rmse
        })
        .collect();
    front.sort_by(|a, b| a.median_s.total_cmp(&b.median_s));
    let best = front
        .iter()
        .map(|r| r.errors.rmse)
        .fold(f64::INFINITY, f64::min);
    let end = front.iter().position(|r| r.errors.rmse <= best * 1.1)?;
    let last = front[end];
    let (t0, t1) = (plain.median_s, last.median_s);
    let (e0, e1) = (plain.errors.rmse, last.errors.rmse);
    if t1 <= t0 || e0 <= e1 {
        return None;
    }
    // Scaled so that the chord runs from (0, 1) to (1, 0): distance below it is 1 − x − y.
    let below = |r: &Row| 1.0 - (r.median_s - t0) / (t1 - t0) - (r.errors.rmse - e1) / (e0 - e1);
    front[..=end]
        .iter()
        .copied()
        .max_by(|a, b| below(a).total_cmp(&below(b)))
}
