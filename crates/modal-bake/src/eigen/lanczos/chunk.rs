//! One Lanczos run (a chunk of pairs in the M-orthogonal complement of the locked ones):
//! expansion steps, Rayleigh–Ritz when due, the convergence test, growth or thick restart.

use faer::sparse::SparseColMat;
use faer::{Mat, MatRef};

use super::super::kernels::SplitMix64;
use super::super::ritz::CheckedPairs;
use super::super::shift_invert::ShiftInvert;
use super::super::{EigenError, EigenInfo, EigenParams, EigenProgress};
use super::convergence::ConvergenceTest;
use super::expansion::Expansion;
use super::krylov_basis::KrylovBasis;
use super::krylov_dim;
use super::rayleigh_ritz::{next_rr_step, rayleigh_ritz, wanted_pairs};

/// One shift-invert block Lanczos run for the `params.nev` (or, with `lam_lim`, up to
/// `params.max_modes`) lowest pairs in the M-orthogonal complement of `locked`. Returns the
/// pairs in ascending order and whether the max-frequency search hit `params.max_modes`.
#[allow(clippy::too_many_arguments)]
pub(super) fn lanczos_chunk(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    fac: &ShiftInvert,
    params: &EigenParams,
    lam_lim: Option<f64>,
    locked: MatRef<'_, f64>,
    mlocked: MatRef<'_, f64>,
    info: &mut EigenInfo,
    progress: &mut dyn FnMut(EigenProgress),
) -> Result<(CheckedPairs, bool), EigenError> {
    let n = k.nrows();
    let b = params.block.min(n).max(1);
    let mut basis = KrylovBasis::new(n, krylov_dim(params, params.nev.max(1), b, n), b);
    let mut expansion = Expansion {
        m,
        fac,
        deflation: (locked, mlocked),
        z: Mat::<f64>::zeros(n, b),
        mz: Mat::<f64>::zeros(n, b),
        solve_buf: fac.solve_buffer(b),
        rng: SplitMix64(params.seed),
    };
    expansion.start(&mut basis, info)?;
    let solves_at_start = info.block_solves;
    let mut kk = 0usize; // Rayleigh–Ritz size; the newest block sits at kk..kk+b
    let mut test = ConvergenceTest {
        trigger: params.tol,
        last_worst: f64::INFINITY,
    };
    // Whether the newest block is coupled to the whole basis (right after a thick restart: to
    // every kept Ritz vector) rather than only to the block before it (Lanczos recurrence).
    let mut coupled_to_all = true;
    // Next step with a Rayleigh–Ritz solve; the last (step, worst wanted estimate); the last
    // converged count (for progress reports on skipped steps).
    let mut rr_at = 0usize;
    let mut last_est: Option<(usize, f64)> = None;
    let mut last_conv = 0usize;

    loop {
        expansion.expand(&mut basis, kk, coupled_to_all, info)?;
        coupled_to_all = false;
        kk += b;
        info.iterations += 1;
        info.krylov_dim = info.krylov_dim.max(kk);

        // Rayleigh–Ritz is skipped while the last two estimates predict no convergence yet
        // (count mode only; never when the basis must be restarted or the budget is spent).
        let restart_due = kk + 2 * b > basis.cap;
        let budget_left = info.block_solves - solves_at_start < params.max_iters;
        if lam_lim.is_none() && !restart_due && budget_left && info.iterations < rr_at {
            progress(EigenProgress {
                converged: last_conv,
                requested: params.nev.min(n),
                iteration: info.iterations,
            });
            continue;
        }
        let ritz = rayleigh_ritz(basis.h.as_ref(), kk, b, params.shift)?;
        let (wanted, below, capped) = wanted_pairs(&ritz.lam, lam_lim, params, n);
        let conv = ritz
            .est
            .iter()
            .take(wanted.min(kk))
            .filter(|&&e| e <= params.tol)
            .count();
        progress(EigenProgress {
            converged: conv,
            requested: wanted,
            iteration: info.iterations,
        });
        last_conv = conv;
        if wanted <= kk {
            let worst_est = ritz.est.iter().take(wanted).fold(0.0f64, |a, &e| a.max(e));
            rr_at = next_rr_step(info.iterations, worst_est, test.trigger, last_est);
            last_est = Some((info.iterations, worst_est));
        }

        let ready = wanted <= kk
            && ritz.est.iter().take(wanted).all(|&e| e <= test.trigger)
            && (lam_lim.is_none() || capped || below < kk);
        // The step budget is per run (chunk).
        let out_of_steps = info.block_solves - solves_at_start >= params.max_iters;
        if ready || out_of_steps {
            let checked = test.check(
                (k, m, fac),
                &basis,
                kk,
                &ritz,
                wanted,
                params,
                out_of_steps,
                info,
            )?;
            if let Some(pairs) = checked {
                return Ok((pairs, capped));
            }
        }

        // Make room: grow (max-frequency mode) or thick-restart.
        basis.grow_to(krylov_dim(params, wanted, b, n), n, b);
        if kk + 2 * b > basis.cap {
            kk = basis.thick_restart(&ritz, kk, wanted, b);
            coupled_to_all = true;
            info.restarts += 1;
        }
    }
}
