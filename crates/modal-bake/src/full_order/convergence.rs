//! [`converged_peaks`]: full-order peaks whose time step is refined until they stop changing.
//!
//! The peaks of a run with step Δt (the maximum over the samples t = kΔt, k = 1 … h/Δt, of the
//! normal displacement) carry two errors that vanish as Δt → 0: Newmark's period error
//! (≈ (ωΔt)²/12 per mode; none for the exact all-mode sum) and the sampling of the maximum
//! (the sampled maximum of a smooth peak is low by O(Δt²)). Both vanish as Δt → 0, but not
//! monotonically: a sharp maximum can fall between the samples of two nested grids alike (the
//! grids share every other sample), so one small change proves little. The run is repeated at
//! Δt, Δt/2, Δt/4, … until every peak changes by less than the tolerance (relative to itself;
//! peaks below 10⁻¹² of the largest are ignored) over **two** successive halvings; the estimated
//! error of the last level is the larger of those two changes (a conservative bound when the
//! error at least halves per level; a second-order error would be a third of it).
//!
//! The exact all-mode sum starts no coarser than 8 samples per period of its highest mode.
//! A run that reaches the refinement or sample budget first is reported as not converged, with
//! its last change: it is never called converged.

use std::time::Instant;

use super::{newmark_run, FullOrderError, FullOrderSystem, ModalAll};

/// Which full-order solver computes the peaks.
#[derive(Clone, Copy, Debug)]
pub enum PeakSolver<'a> {
    /// Implicit Newmark (β = ¼, γ = ½) on every dof, one factorization per step size.
    Newmark,
    /// The exact sum over the modes of a dense all-mode solve (exact in time; only the sampling
    /// of the maximum is refined): every elastic mode, or the lowest `Some(m)`.
    ModalAll(&'a ModalAll, Option<usize>),
}

/// The window the peaks are taken over and the first step (s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeakWindow {
    /// Window h (s): peaks over t ∈ (0, h].
    pub h: f64,
    /// First step (s); the first level uses h/⌈h/dt⌉.
    pub dt: f64,
}

/// Refinement settings (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineParams {
    /// Largest relative change of any peak between the last two levels for the run to count as
    /// converged. Default 0.005 (0.5 %).
    pub tolerance: f64,
    /// Halvings of the step after the first run (0: one run, no check). Default 6.
    pub max_refinements: usize,
    /// Most samples (steps) of one level; a refinement beyond it is not run. Default 2·10⁶.
    pub max_samples: usize,
}

impl Default for RefineParams {
    fn default() -> Self {
        RefineParams {
            tolerance: 0.005,
            max_refinements: 6,
            max_samples: 2_000_000,
        }
    }
}

/// One level of the refinement.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Refinement {
    /// Step / sample period (s).
    pub dt: f64,
    /// Samples over the window.
    pub samples: usize,
    /// Largest relative change of a peak from the previous level (NaN on the first).
    pub change: f64,
    /// Wall seconds of this level.
    pub seconds: f64,
}

/// Peaks of the finest level and how they converged.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ConvergedPeaks {
    /// `peaks[i][c]`: peak |normal displacement| (m) at row c after load i, finest level.
    pub peaks: Vec<Vec<f64>>,
    /// Step of the finest level (s).
    pub dt: f64,
    /// Samples of the finest level.
    pub samples: usize,
    /// Whether the last two changes are below the tolerance.
    pub converged: bool,
    /// Tolerance used (relative).
    pub tolerance: f64,
    /// Largest relative change between the last two levels (NaN with a single level).
    pub last_change: f64,
    /// Estimated relative error of the finest level: the larger of the last two changes (NaN
    /// with fewer than three levels).
    pub estimated_error: f64,
    /// Every level, coarsest first.
    pub history: Vec<Refinement>,
}

/// Where a refinement is, for progress reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineProgress {
    /// Level (0: the first run).
    pub level: usize,
    /// Its step (s).
    pub dt: f64,
    /// Samples done at this level.
    pub done: usize,
    /// Samples of this level.
    pub total: usize,
}

/// Peaks at `rows` after each impulse in `loads` (N·s, free dofs of `sys`) over the window,
/// with the step refined from the window's first step until converged (see the module docs).
///
/// # Errors
/// [`FullOrderError::Params`] for a non-positive h or dt0 or a first level above the sample
/// budget; [`FullOrderError::Factorization`] from Newmark.
pub fn converged_peaks(
    sys: &FullOrderSystem,
    solver: PeakSolver<'_>,
    loads: &[Vec<f64>],
    rows: &[Vec<f64>],
    window: PeakWindow,
    refine: &RefineParams,
    progress: &mut dyn FnMut(RefineProgress),
) -> Result<ConvergedPeaks, FullOrderError> {
    let PeakWindow { h, dt: dt0 } = window;
    if !(h.is_finite() && h > 0.0 && dt0.is_finite() && dt0 > 0.0) {
        return Err(FullOrderError::Params(format!(
            "the window h and step dt must be finite and > 0 s, got h = {h}, dt = {dt0}"
        )));
    }
    let first = (h / dt0).ceil();
    if !(first <= refine.max_samples as f64) {
        return Err(FullOrderError::Params(format!(
            "h/dt = {first:.3e} samples exceeds the limit {}",
            refine.max_samples
        )));
    }
    let mut steps = (first as usize).max(1);
    if let PeakSolver::ModalAll(ma, modes) = solver {
        // At least 8 samples per period of the highest mode summed.
        let m = modes.unwrap_or(usize::MAX).min(ma.eigenvalues.len());
        if let Some(&lam) = ma.eigenvalues[..m].last() {
            let period = std::f64::consts::TAU / lam.sqrt();
            let need = (8.0 * h / period).ceil();
            if need <= refine.max_samples as f64 {
                steps = steps.max(need as usize);
            }
        }
    }
    // Modal coordinates of the loads and rows, once.
    let projected = match solver {
        PeakSolver::ModalAll(ma, _) => Some((
            loads.iter().map(|f| ma.project(f)).collect::<Vec<_>>(),
            rows.iter().map(|w| ma.project(w)).collect::<Vec<_>>(),
        )),
        PeakSolver::Newmark => None,
    };
    let mut history: Vec<Refinement> = Vec::new();
    let mut prev: Option<Vec<Vec<f64>>> = None;
    let mut last_change = f64::NAN;
    let mut estimated_error = f64::NAN;
    for level in 0..=refine.max_refinements {
        if level > 0 && steps > refine.max_samples {
            break;
        }
        let dt = h / steps as f64;
        let t = Instant::now();
        progress(RefineProgress {
            level,
            dt,
            done: 0,
            total: steps,
        });
        let peaks = match (solver, &projected) {
            (PeakSolver::ModalAll(ma, modes), Some((r, w))) => {
                let mut out = Vec::with_capacity(r.len());
                for (i, ri) in r.iter().enumerate() {
                    out.push(ma.peaks_projected(ri, w, sys.rayleigh, dt, steps, modes));
                    // Loads done, in samples.
                    progress(RefineProgress {
                        level,
                        dt,
                        done: steps * (i + 1) / r.len(),
                        total: steps,
                    });
                }
                out
            }
            _ => newmark_level(sys, loads, rows, dt, steps, level, progress)?,
        };
        let change = prev.as_ref().map_or(f64::NAN, |p| max_change(p, &peaks));
        estimated_error = match history.len() {
            0 | 1 => f64::NAN,
            _ => change.max(history[history.len() - 1].change),
        };
        last_change = change;
        history.push(Refinement {
            dt,
            samples: steps,
            change,
            seconds: t.elapsed().as_secs_f64(),
        });
        prev = Some(peaks);
        if estimated_error < refine.tolerance {
            break;
        }
        steps *= 2;
    }
    let last = history.last().expect("one level at least");
    Ok(ConvergedPeaks {
        peaks: prev.expect("one level at least"),
        dt: last.dt,
        samples: last.samples,
        converged: estimated_error < refine.tolerance,
        tolerance: refine.tolerance,
        last_change,
        estimated_error,
        history,
    })
}

/// One Newmark level: peaks of every load at every row.
fn newmark_level(
    sys: &FullOrderSystem,
    loads: &[Vec<f64>],
    rows: &[Vec<f64>],
    dt: f64,
    steps: usize,
    level: usize,
    progress: &mut dyn FnMut(RefineProgress),
) -> Result<Vec<Vec<f64>>, FullOrderError> {
    let n = sys.n();
    let mut peaks = vec![vec![0.0f64; rows.len()]; loads.len()];
    let every = (steps / 100).max(1);
    newmark_run(sys, loads, dt, steps, &mut |k, u| {
        for (i, pk) in peaks.iter_mut().enumerate() {
            let ui = &u[i * n..(i + 1) * n];
            for (p, w) in pk.iter_mut().zip(rows) {
                let y: f64 = w.iter().zip(ui).map(|(a, b)| a * b).sum();
                *p = p.max(y.abs());
            }
        }
        if k % every == 0 {
            progress(RefineProgress {
                level,
                dt,
                done: k,
                total: steps,
            });
        }
    })?;
    Ok(peaks)
}

/// Largest relative change |b − a|/|b| over every entry whose |b| exceeds 10⁻¹² of the largest.
fn max_change(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    let top = b.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .filter(|(_, y)| y.abs() > 1e-12 * top)
        .fold(0.0f64, |m, (x, y)| m.max(((y - x) / y).abs()))
}
