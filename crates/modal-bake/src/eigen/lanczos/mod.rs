//! Shift-invert block Lanczos with full M-reorthogonalisation and thick restart
//! (see the module docs of [`crate::eigen`]): [`solve_lanczos`] runs chunks of at most
//! [`CHUNK`] pairs (`chunk.rs`), each deflated against the ones before, on one factorisation
//! of K − σM. A run's parts: the Krylov basis and its thick restart (`krylov_basis.rs`), the
//! expansion steps (`expansion.rs`), Rayleigh–Ritz (`rayleigh_ritz.rs`) and the convergence
//! test on purified Ritz vectors (`convergence.rs`).

mod chunk;
mod convergence;
mod expansion;
mod krylov_basis;
mod rayleigh_ritz;

use std::time::Instant;

use faer::sparse::SparseColMat;
use faer::{Mat, MatRef, Par};

use super::ritz::{orthonormalize_ascending, trim_and_sign, Residual};
use super::shift_invert::{shifted, ShiftInvert};
use super::{
    EigenError, EigenInfo, EigenParams, EigenProgress, EigenResult, AUTO_SEQ_BELOW,
    DENSE_FRACTION_INV, DENSE_MAX_DOFS,
};
use chunk::lanczos_chunk;

/// Dofs for which the default Krylov dimension grows by [`SMALL_EXTRA_BLOCKS`] blocks.
const SMALL_KRYLOV_DOFS: std::ops::Range<usize> = 1000..AUTO_SEQ_BELOW;

/// Extra blocks of the default Krylov dimension for small problems.
const SMALL_EXTRA_BLOCKS: usize = 8;

/// The Lanczos path of [`solve_lowest`](super::solve_lowest) (inputs checked, not tiny).
pub(super) fn solve_lanczos(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    params: &EigenParams,
    lam_lim: Option<f64>,
    par: Par,
    mut info: EigenInfo,
    progress: &mut dyn FnMut(EigenProgress),
) -> Result<EigenResult, EigenError> {
    let n = k.nrows();
    let sigma = params.shift;

    // --- factorization of A = K − σM -------------------------------------------------------
    let t0 = Instant::now();
    let fac = {
        let a = shifted(k, m, sigma);
        ShiftInvert::new(&a, par).map_err(|e| {
            EigenError::Factorization(format!(
                "K − σM with σ = {sigma:e}: {e}; the shift must lie below the lowest eigenvalue"
            ))
        })?
    };
    info.factor_seconds = t0.elapsed().as_secs_f64();
    info.factor_nnz = fac.factor_nnz();
    let t1 = Instant::now();

    // --- chunks of at most CHUNK pairs, each deflated against the ones before ---------------
    let mut locked = Mat::<f64>::zeros(n, 0);
    let mut mlocked = Mat::<f64>::zeros(n, 0);
    let mut vals: Vec<f64> = Vec::new();
    let mut res: Vec<Residual> = Vec::new();
    let mut capped = false;
    let mut runs = 0;
    let mut chunk = CHUNK;
    loop {
        runs += 1;
        let found = locked.ncols();
        let mut cp = params.clone();
        let more = match lam_lim {
            None => {
                cp.nev = (params.nev - found).min(chunk);
                false
            }
            Some(_) => {
                cp.max_modes = params.max_modes.saturating_sub(found).min(chunk);
                cp.nev = params.nev.saturating_sub(found).min(cp.max_modes);
                true
            }
        };
        let run = lanczos_chunk(
            k,
            m,
            &fac,
            &cp,
            lam_lim,
            locked.as_ref(),
            mlocked.as_ref(),
            &mut info,
            &mut |p| {
                progress(EigenProgress {
                    converged: p.converged + found,
                    // Count mode: the whole request, so a progress bar spans all runs.
                    requested: (p.requested + found).max(if more { 0 } else { params.nev }),
                    iteration: p.iteration,
                })
            },
        );
        let (((cv, cu, cres), mcu), chunk_capped) = match run {
            // A run that drifts (too many restarts for its size) is retried with fewer pairs;
            // the pairs already locked are kept.
            Err(EigenError::NotConverged { .. }) if chunk > MIN_CHUNK => {
                chunk /= 2;
                continue;
            }
            // Report against the whole request, counting the pairs already locked.
            Err(EigenError::NotConverged {
                converged,
                requested,
                worst_residual,
            }) => {
                return Err(EigenError::NotConverged {
                    converged: converged + found,
                    requested: (requested + found).max(if more { 0 } else { params.nev }),
                    worst_residual,
                })
            }
            other => other?,
        };
        append_cols(&mut locked, cu.as_ref());
        append_cols(&mut mlocked, mcu.as_ref());
        vals.extend_from_slice(&cv);
        res.extend(cres);
        let total = locked.ncols();
        if more && n <= DENSE_MAX_DOFS && total * DENSE_FRACTION_INV > n {
            // A frequency cap taking in much of a small problem's spectrum: the dense path
            // of the caller is faster than growing Lanczos further (and reaches the top).
            return Err(EigenError::NotConverged {
                converged: total,
                requested: total + 1,
                worst_residual: f64::NAN,
            });
        }
        let done = if more {
            let global_cap = total >= params.max_modes;
            capped = chunk_capped && global_cap;
            !chunk_capped || global_cap
        } else {
            total >= params.nev
        };
        if done || cv.is_empty() {
            break;
        }
    }
    // One Cholesky-QR over all chunks (ascending λ, so each vector only mixes in lower ones)
    // restores UᵀMU = I across chunk boundaries; residuals are measured on the result.
    let (vals, u, res) = if runs > 1 {
        orthonormalize_ascending(k, m, locked, mlocked, sigma)?.0
    } else {
        (vals, locked, res)
    };
    let good = res.iter().filter(|r| r.converged(params.tol)).count();
    if good < res.len() {
        return Err(EigenError::NotConverged {
            converged: good,
            requested: res.len(),
            worst_residual: res.iter().map(|r| r.rel).fold(0.0, f64::max),
        });
    }
    info.solve_seconds = t1.elapsed().as_secs_f64();
    info.capped = capped;
    Ok(trim_and_sign(vals, u, res, lam_lim, params, info))
}

/// Pairs computed per Lanczos run. Beyond this the next pairs come from a fresh run in the
/// M-orthogonal complement of the ones found (deflation, "locking"): within one run the Ritz
/// values θ = 1/(λ − σ) of the wanted pairs span λ_w/λ₁, the dense eigensolver of the projected
/// matrix is accurate to ε·θ_max, and every thick restart feeds that error back into the
/// basis — measured on the 1016-node table, 160 modes in one run ended at residuals 1e-7
/// after 7 restarts. How many pairs a run can hold depends on the block size (restarts come
/// sooner with smaller blocks): with b = 6, runs of 64 drifted to 5e-7 on a 24×3×3 beam, runs
/// of 48 converge; a run that fails anyway is retried with half as many pairs.
const CHUNK: usize = 48;

/// Smallest run size [`CHUNK`] is halved down to when a run fails to converge.
const MIN_CHUNK: usize = 6;

fn append_cols(a: &mut Mat<f64>, b: MatRef<'_, f64>) {
    let (n, c) = (a.nrows(), a.ncols());
    let mut out = Mat::<f64>::zeros(n, c + b.ncols());
    out.as_mut().subcols_mut(0, c).copy_from(&*a);
    out.as_mut().subcols_mut(c, b.ncols()).copy_from(b);
    *a = out;
}

/// Krylov basis size for `wanted` pairs of a problem with `n` dofs: the parameter, or
/// wanted + max(wanted, 4b) + b (+ [`SMALL_EXTRA_BLOCKS`]·b for n in [`SMALL_KRYLOV_DOFS`]),
/// at least wanted + 2b, rounded up to a multiple of b.
pub(super) fn krylov_dim(params: &EigenParams, wanted: usize, b: usize, n: usize) -> usize {
    let base = params.krylov_dim.unwrap_or_else(|| {
        let extra = if SMALL_KRYLOV_DOFS.contains(&n) {
            SMALL_EXTRA_BLOCKS * b
        } else {
            0
        };
        wanted + wanted.max(4 * b) + b + extra
    });
    let d = base.max(wanted + 2 * b);
    d.div_ceil(b) * b
}

pub(super) fn m_norm(z: MatRef<'_, f64>, mz: MatRef<'_, f64>, j: usize) -> f64 {
    let s: f64 = z
        .col(j)
        .iter()
        .zip(mz.col(j).iter())
        .map(|(a, b)| a * b)
        .sum();
    s.max(0.0).sqrt()
}

pub(super) fn select_cols(s: MatRef<'_, f64>, cols: &[usize]) -> Mat<f64> {
    Mat::from_fn(s.nrows(), cols.len(), |i, j| s[(i, cols[j])])
}

pub(super) fn grow(a: &mut Mat<f64>, n: usize, cols: usize) {
    let mut b = Mat::<f64>::zeros(n, cols);
    b.as_mut().subcols_mut(0, a.ncols()).copy_from(&*a);
    *a = b;
}

#[cfg(test)]
mod tests;
