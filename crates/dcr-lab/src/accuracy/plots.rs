//! The report's plot: median and worst |error| per object, 20 modes vs the default table.

use std::path::Path;

use plotters::prelude::*;

use super::study::{maxv, median, ObjectStudy, BASE_MODES};
use super::{GOAL_MEDIAN_PCT, GOAL_WORST_PCT};

/// Writes `summary.svg` (log scale, 0.01 … 100 %+), creating its folder, through the one
/// writer ([`dcr_files::write_atomic`]).
///
/// # Errors
/// The file cannot be written.
pub fn summary(path: &Path, studies: &[ObjectStudy]) -> anyhow::Result<()> {
    let mut svg = String::new();
    let mut draw = || -> Result<(), Box<dyn std::error::Error>> {
        let root = SVGBackend::with_string(&mut svg, (760, 440)).into_drawing_area();
        root.fill(&WHITE)?;
        let n = studies.len().max(1) as f64;
        let names: Vec<&str> = studies.iter().map(|s| s.spec.name).collect();
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "|peak error| vs the converged full-order truth",
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5f64..n - 0.5, (0.01f64..300.0).log_scale())?;
        chart
            .configure_mesh()
            .x_labels(studies.len().max(1))
            .x_label_formatter(&|x| {
                let i = x.round();
                if (x - i).abs() < 1e-6 && i >= 0.0 {
                    names.get(i as usize).copied().unwrap_or("").to_string()
                } else {
                    String::new()
                }
            })
            .y_desc("|error| % (median ○, worst ●)")
            .draw()?;
        for (goal, label) in [
            (GOAL_MEDIAN_PCT, "median goal"),
            (GOAL_WORST_PCT, "worst goal"),
        ] {
            chart
                .draw_series(LineSeries::new(
                    vec![(-0.5, goal), (n - 0.5, goal)],
                    BLACK.mix(0.4).stroke_width(1),
                ))?
                .label(format!("{label} ({goal} %)"))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.mix(0.4)));
        }
        let series = |pick: &dyn Fn(&ObjectStudy) -> Option<Vec<f64>>| -> Vec<(f64, f64, f64)> {
            studies
                .iter()
                .enumerate()
                .filter_map(|(i, s)| {
                    let e = pick(s)?;
                    Some((i as f64, median(&e).max(0.01), maxv(&e).max(0.01)))
                })
                .collect()
        };
        let m20 = series(&|s| {
            s.rows
                .iter()
                .find(|r| r.label == format!("modal, {BASE_MODES} modes"))
                .map(|r| r.abs(|_| true))
        });
        let best = series(&|s| s.rows.iter().find(|r| r.best).map(|r| r.abs(|_| true)));
        for (pts, color, off, label) in [
            (m20, RED, -0.12, "modal, 20 modes"),
            (best, BLUE, 0.12, "★ transfer table (default)"),
        ] {
            chart
                .draw_series(
                    pts.iter()
                        .map(|&(x, _, w)| Circle::new((x + off, w), 5, color.filled())),
                )?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 9, y), 5, color.filled()));
            chart.draw_series(
                pts.iter()
                    .map(|&(x, m, _)| Circle::new((x + off, m), 5, color.stroke_width(2))),
            )?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()?;
        root.present()?;
        Ok(())
    };
    draw().map_err(|e| anyhow::anyhow!("drawing {}: {e}", path.display()))?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("creating {}: {e}", dir.display()))?;
    }
    dcr_files::write_atomic(path, svg.as_bytes())?;
    Ok(())
}
