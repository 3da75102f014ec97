//! [`write_outcomes_svg`]: each outcome figure of a scene over time, one panel per figure, one
//! line per run (response on vs off), drawn with plotters' SVG backend.

use std::path::Path;

use anyhow::{bail, Result};
use modal_bake::export::write_file_atomic;
use plotters::prelude::*;

use crate::runner::{measure_outcome, unit_of, RunReport, Trajectory};
use crate::scene::{OutcomeDesc, SceneDesc};

/// Most points per curve in [`write_outcomes_svg`] (each point measures the trajectory up to
/// it, so a curve costs points × rows).
pub const SVG_CURVE_POINTS: usize = 500;

/// The figure `o` as measured on rows 0..=k of `traj`, at up to `max_points` rows k evenly
/// spread over the run (always the first and the last): `(t_k in s, value)`. The running
/// value whose last entry is the run's reported figure (`max_*` kinds rise monotonically;
/// slides and counts follow the current state). NaN where the figure is undefined (no body
/// matches).
pub fn outcome_series(o: &OutcomeDesc, traj: &Trajectory, max_points: usize) -> Vec<(f64, f64)> {
    let n = traj.rows();
    if n == 0 {
        return Vec::new();
    }
    let nb = traj.names.len();
    let stride = n.div_ceil(max_points.max(2) - 1).max(1);
    let mut rows: Vec<usize> = (0..n).step_by(stride).collect();
    if rows.last() != Some(&(n - 1)) {
        rows.push(n - 1);
    }
    let mut t = traj.clone();
    let mut out = Vec::with_capacity(rows.len());
    for &k in rows.iter().rev() {
        t.time.truncate(k + 1);
        t.positions.truncate((k + 1) * nb * 3);
        t.rotations.truncate((k + 1) * nb * 4);
        out.push((traj.time[k], measure_outcome(o, &t).unwrap_or(f64::NAN)));
    }
    out.reverse();
    out
}

/// Writes one panel per outcome of `desc` with one line per run in `runs` (labelled `dcr on`
/// / `dcr off`), x = time (s), y = the figure in its unit, to `path` (SVG, atomically).
///
/// # Errors
/// No runs, a scene without outcomes, a drawing error or I/O failure.
pub fn write_outcomes_svg(desc: &SceneDesc, runs: &[&RunReport], path: &Path) -> Result<()> {
    if runs.is_empty() {
        bail!("no run to plot");
    }
    let outcomes = &desc.outcomes;
    if outcomes.is_empty() {
        bail!("scene {} defines no outcomes", desc.name);
    }
    let panel_h = 240u32;
    let size = (820u32, panel_h * outcomes.len() as u32);
    let mut svg = String::new();
    {
        let rootarea = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        rootarea.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        let panels = rootarea.split_evenly((outcomes.len(), 1));
        for (o, area) in outcomes.iter().zip(panels.iter()) {
            let series: Vec<(bool, Vec<(f64, f64)>)> = runs
                .iter()
                .map(|r| {
                    let pts = outcome_series(o, &r.trajectory, SVG_CURVE_POINTS)
                        .into_iter()
                        .filter(|(_, y)| y.is_finite())
                        .collect();
                    (r.dcr, pts)
                })
                .collect();
            let t_max = runs
                .iter()
                .filter_map(|r| r.trajectory.time.last().copied())
                .fold(0.0, f64::max)
                .max(1e-9);
            let y_max = series
                .iter()
                .flat_map(|(_, p)| p.iter().map(|q| q.1))
                .fold(0.0, f64::max);
            let y_top = if y_max > 0.0 { 1.1 * y_max } else { 1.0 };
            let unit = unit_of(&o.kind);
            let mut chart = ChartBuilder::on(area)
                .caption(format!("{} ({unit})", o.name), ("sans-serif", 16))
                .margin(8)
                .x_label_area_size(32)
                .y_label_area_size(56)
                .build_cartesian_2d(0.0..t_max, 0.0..y_top)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            chart
                .configure_mesh()
                .x_desc("time (s)")
                .y_desc(unit)
                .draw()
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            // Off first, so the on curve is drawn on top where they coincide.
            let mut series = series;
            series.sort_by_key(|(dcr, _)| *dcr);
            for (dcr, pts) in series {
                let (colour, label) = if dcr {
                    (RGBColor(200, 60, 40), "dcr on")
                } else {
                    (RGBColor(90, 90, 90), "dcr off")
                };
                chart
                    .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                    .map_err(|e| anyhow::anyhow!("{e}"))?
                    .label(label)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        rootarea.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    write_file_atomic(path, svg.as_bytes())?;
    Ok(())
}
