//! Rayleigh–Ritz on the projected matrix H = VᵀMTV of a Lanczos basis: Ritz values, vectors
//! and residual estimates; how many pairs are wanted; when the next solve is due.

use faer::{Mat, MatRef};

use super::super::kernels::sym_eig;
use super::super::ritz::symmetrized;
use super::super::{EigenError, EigenParams};

/// Fraction of the steps a geometric extrapolation of the worst wanted residual estimate says
/// remain before convergence during which the Rayleigh–Ritz solve is skipped.
const RR_SKIP_FRACTION: f64 = 0.3;

/// Result of one Rayleigh–Ritz solve on the leading `kk` × `kk` block of H, pairs in
/// descending θ (ascending λ) order.
pub(super) struct RitzEstimates {
    /// Eigenvectors of H's leading block (columns), in ascending θ order.
    pub(super) s_asc: Mat<f64>,
    /// Columns of `s_asc` in descending θ order.
    pub(super) order: Vec<usize>,
    /// Ritz values θ of T = A⁻¹M (s²/rad²), descending.
    pub(super) theta: Vec<f64>,
    /// Eigenvalue estimates λ = σ + 1/θ (rad²/s²), ascending; +∞ where θ ≤ 0.
    pub(super) lam: Vec<f64>,
    /// Subdiagonal block of H coupling the newest block (b × b).
    pub(super) r_last: Mat<f64>,
    /// Lanczos residual estimates ‖R_last s_last‖ / |θ| per pair.
    pub(super) est: Vec<f64>,
}

/// Rayleigh–Ritz on H = VᵀMTV: Ritz values and vectors of the leading `kk` × `kk` block
/// (block size `b`, shift `sigma` in rad²/s²) with their Lanczos residual estimates.
pub(super) fn rayleigh_ritz(
    h: MatRef<'_, f64>,
    kk: usize,
    b: usize,
    sigma: f64,
) -> Result<RitzEstimates, EigenError> {
    let hk = symmetrized(h.submatrix(0, 0, kk, kk));
    let (theta_asc, s_asc) = sym_eig(hk.as_ref()).map_err(EigenError::Dense)?;
    // Descending θ = ascending λ.
    let order: Vec<usize> = (0..kk).rev().collect();
    let theta: Vec<f64> = order.iter().map(|&i| theta_asc[i]).collect();
    let lam: Vec<f64> = theta
        .iter()
        .map(|&t| {
            if t > 0.0 {
                sigma + 1.0 / t
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let r_last = h.submatrix(kk, kk - b, b, b).to_owned();
    let est: Vec<f64> = order
        .iter()
        .zip(&theta)
        .map(|(&i, &t)| {
            let mut s2 = 0.0;
            for row in 0..b {
                let mut acc = 0.0;
                for col in 0..b {
                    acc += r_last[(row, col)] * s_asc[(kk - b + col, i)];
                }
                s2 += acc * acc;
            }
            s2.sqrt() / t.abs()
        })
        .collect();
    Ok(RitzEstimates {
        s_asc,
        order,
        theta,
        lam,
        r_last,
        est,
    })
}

/// How many pairs are wanted of a problem with `n` dofs: `params.nev`, or with `lam_lim`
/// (rad²/s²) every pair below it plus one, at least `params.nev` and at most
/// `params.max_modes`. Returns (wanted, Ritz values below `lam_lim`, whether capped).
pub(super) fn wanted_pairs(
    lam: &[f64],
    lam_lim: Option<f64>,
    params: &EigenParams,
    n: usize,
) -> (usize, usize, bool) {
    match lam_lim {
        None => (params.nev.min(n), 0, false),
        Some(lim) => {
            let below = lam.iter().take_while(|&&l| l < lim).count();
            let capped = below >= params.max_modes;
            let w = if capped {
                params.max_modes
            } else {
                (below + 1).max(params.nev)
            };
            (w.min(n), below, capped)
        }
    }
}

/// Step of the next Rayleigh–Ritz solve after the one at `iteration` with worst wanted
/// estimate `worst_est`: the next step, advanced by [`RR_SKIP_FRACTION`] of the steps the
/// geometric rate since `last_est` (step, estimate) predicts until `trigger` is met.
pub(super) fn next_rr_step(
    iteration: usize,
    worst_est: f64,
    trigger: f64,
    last_est: Option<(usize, f64)>,
) -> usize {
    let mut rr_at = iteration + 1;
    if let Some((step0, est0)) = last_est {
        if worst_est > trigger && worst_est < est0 {
            // Steps to go at the observed geometric rate; Lanczos converges
            // superlinearly, so only a fraction of them is skipped.
            let rate = (est0 / worst_est).ln() / (iteration - step0) as f64;
            let to_go = (worst_est / trigger).ln() / rate;
            rr_at += (RR_SKIP_FRACTION * to_go).floor() as usize;
        }
    }
    rr_at
}
