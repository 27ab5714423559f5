//! The study's figure, `bench.svg`: time against RMSE, log-log, one panel per scene,
//! each setting coloured by the knob it sweeps and the Pareto front joined by a line.

use std::path::Path;

use super::analysis::scene_names;
use super::Row;
use crate::settings::Precision;

/// The labelled and the unlabelled grid lines of a log axis over `(lo, hi)`: 1, 2 and 5
/// times the powers of ten in the range (only the powers when that would make more
/// than 8 labels, every multiple when fewer than 3), and every multiple 1–9 as light
/// lines. Explicit, because plotters' own choice crowds the labels of a range of two
/// decades and draws light lines so dense that they merge into grey bands.
fn ticks((lo, hi): (f64, f64)) -> (Vec<f64>, Vec<f64>) {
    let decades = lo.log10().floor() as i32..=hi.log10().ceil() as i32;
    let within = |multiples: &[f64]| -> Vec<f64> {
        decades
            .clone()
            .flat_map(|d| multiples.iter().map(move |m| m * 10f64.powi(d)))
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let every: Vec<f64> = (1..=9).map(f64::from).collect();
    let mut bold = within(&[1.0, 2.0, 5.0]);
    if bold.len() > 8 {
        bold = within(&[1.0]);
    } else if bold.len() < 3 {
        bold = within(&every);
    }
    (bold, within(&every))
}

/// A tick value without trailing zeros: 0.5, 2, 10, 200.
fn tick_label(v: f64) -> String {
    let decimals = (-v.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// Time against RMSE, log-log, one panel per scene; the Pareto front joined by a line.
pub(crate) fn plot(rows: &[Row], path: &Path) -> anyhow::Result<()> {
    use plotters::prelude::*;
    let names = scene_names(rows);
    let cols = 2usize;
    let panels_y = names.len().div_ceil(cols).max(1);
    let legend_h = 36;
    let root = SVGBackend::new(path, (1200, 480 * panels_y as u32 + legend_h)).into_drawing_area();
    let e = |err: &dyn std::fmt::Display| anyhow::anyhow!("plot: {err}");
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let (top, bottom) = root.split_vertically(480 * panels_y as u32);
    let panels = top.split_evenly((panels_y, cols));
    // Explicit light greys: some SVG renderers ignore opacity.
    let grid_bold = RGBColor(205, 205, 205);
    let grid_light = RGBColor(238, 238, 238);
    for (name, panel) in names.iter().zip(panels.iter()) {
        // The reference itself (error 0) has no place on a log axis; the tables give
        // its time.
        let these: Vec<&Row> = rows
            .iter()
            .filter(|r| &r.scene == name && r.errors.rmse > 0.0)
            .collect();
        let pts: Vec<(f64, f64)> = these
            .iter()
            .map(|r| (r.median_s * 1e3, r.errors.rmse))
            .collect();
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(x, y) in &pts {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let (xs, ys) = ((x0 * 0.8, x1 * 1.25), (y0 * 0.8, y1 * 1.25));
        let ((x_bold, x_light), (y_bold, y_light)) = (ticks(xs), ticks(ys));
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("{name}: time against error, Pareto front in red"),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(
                (xs.0..xs.1)
                    .log_scale()
                    .with_key_points(x_bold)
                    .with_light_points(x_light),
                (ys.0..ys.1)
                    .log_scale()
                    .with_key_points(y_bold)
                    .with_light_points(y_light),
            )
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .bold_line_style(grid_bold)
            .light_line_style(grid_light)
            .x_label_formatter(&|v| tick_label(*v))
            .y_label_formatter(&|v| tick_label(*v))
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 15))
            .x_desc("median render time (ms, log)")
            .y_desc("RMSE vs reference (8-bit levels, log)")
            .draw()
            .map_err(|x| e(&x))?;
        let kind_color = |r: &Row| {
            let q = &r.setting.quality;
            if r.setting.preset.is_some() {
                RED
            } else if q.precision == Precision::Reference {
                BLACK
            } else if q.adaptive.is_some() {
                GREEN
            } else if q.cutoff > 0.0 {
                MAGENTA
            } else if q.max_depth != 5 {
                CYAN
            } else {
                BLUE
            }
        };
        chart
            .draw_series(
                these
                    .iter()
                    .zip(&pts)
                    .map(|(r, &p)| Circle::new(p, 4, kind_color(r).filled())),
            )
            .map_err(|x| e(&x))?;
        let mut front: Vec<(f64, f64)> = these
            .iter()
            .zip(&pts)
            .filter(|(r, _)| r.pareto)
            .map(|(_, &p)| p)
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Segment by segment: some renderers fill a polyline's area despite fill="none".
        chart
            .draw_series(
                front
                    .windows(2)
                    .map(|w| PathElement::new(vec![w[0], w[1]], RED.stroke_width(2))),
            )
            .map_err(|x| e(&x))?;
        chart
            .draw_series(
                front
                    .iter()
                    .map(|&p| Circle::new(p, 7, RED.stroke_width(2))),
            )
            .map_err(|x| e(&x))?;
        for (r, &p) in these.iter().zip(&pts) {
            if let Some(preset) = r.setting.preset {
                // Beside the point, clear of its rings, rather than on it.
                let label = EmptyElement::at(p)
                    + Text::new(preset.name().to_string(), (9, 2), ("sans-serif", 15));
                chart
                    .draw_series(std::iter::once(label))
                    .map_err(|x| e(&x))?;
            }
        }
    }
    // A legend of the colours, drawn once at the bottom of the image.
    let legend = [
        ("plain spp", BLUE),
        ("adaptive AA", GREEN),
        ("cutoff", MAGENTA),
        ("max depth", CYAN),
        ("f64", BLACK),
        ("preset", RED),
    ];
    for (n, (label, color)) in legend.iter().enumerate() {
        let x = 60 + 115 * n as i32;
        let y = 18;
        bottom
            .draw(&Circle::new((x, y), 5, color.filled()))
            .map_err(|x| e(&x))?;
        bottom
            .draw(&Text::new(
                label.to_string(),
                (x + 10, y - 7),
                ("sans-serif", 14),
            ))
            .map_err(|x| e(&x))?;
    }
    bottom
        .draw(&Text::new(
            "red rings and line: the Pareto front of each scene".to_string(),
            (60 + 115 * legend.len() as i32, 11),
            ("sans-serif", 14),
        ))
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_get_few_readable_labels() {
        // many_1000's time axis: 3.5 to 380 ms.
        let (bold, light) = ticks((3.5, 380.0));
        assert_eq!(bold, [5.0, 10.0, 20.0, 50.0, 100.0, 200.0]);
        assert_eq!(light.len(), 6 + 9 + 3);
        let labels: Vec<String> = bold.iter().map(|&v| tick_label(v)).collect();
        assert_eq!(labels, ["5", "10", "20", "50", "100", "200"]);
        // Six decades: the powers of ten only.
        assert_eq!(ticks((0.5, 2e5)).0, [1.0, 10.0, 100.0, 1e3, 1e4, 1e5]);
        // Less than a decade: every multiple.
        assert_eq!(ticks((0.45, 0.95)).0.len(), 5);
        assert_eq!(tick_label(0.5), "0.5");
        assert_eq!(tick_label(0.02), "0.02");
    }
}
