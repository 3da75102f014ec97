//! [`ModalAll`]: the sum over *every* mode of a small mesh (dense generalized eigensolve), with
//! the exact damped impulse response of each mode.
//!
//! K φ = λ M φ is solved densely: M = L Lᵀ (Cholesky), C = L⁻¹ K L⁻ᵀ (symmetrised), C = Q Λ Qᵀ
//! (faer `self_adjoint_eigen`), Φ = L⁻ᵀ Q, so Φᵀ M Φ = I.
//!
//! Free-free, the rigid modes are deflated before the eigensolve: with Y = Lᵀ R̃ (orthonormal,
//! R̃ the M-orthonormal rigid modes) the solve is of P C P, P = I − Y Yᵀ. In exact arithmetic
//! C Y = 0; the rigid directions are then moved to distinct values far below the elastic
//! spectrum (−σ, −2σ, …, σ = max |C_ij|) and reported as exact zeros. The six near-zero
//! eigenvalues of C form a tight cluster that the dense symmetric eigensolver resolved wrongly
//! (on a coarse order-1 steel box: five within ±400 rad²/s² and one at 1.05e7, against a first
//! elastic λ of 9.9e9 that the Lanczos bake confirms, though ‖C y‖ ≈ 2.5e-4 for every rigid y),
//! so the rigid-mode count failed; the deflated problem has no such cluster, its rigid vectors
//! are R̃ and its elastic eigenpairs are M-orthogonal to them. With Rayleigh damping every mode
//! decouples (paper Eq. 8) and an impulse f at t = 0 gives the exact displacement
//! u(t) = Σ_j φ_j (φ_jᵀ f) g_j(t), with g_j the mass-normalised impulse response for
//! ξ_j = ½(α0/ω_j + α1 ω_j) in every regime (ξ < 1, = 1, > 1) — `dcr_runtime::filter::ModeFilter`.
//!
//! Free-free: the six lowest eigenpairs (λ ≈ 0) are the rigid modes; they are dropped (the load
//! and the rows are also M-orthogonally stripped of their rigid part by
//! [`super::FullOrderSystem::remove_rigid`], so their coefficients are ≈ 0 anyway).

use std::time::Instant;

use dcr_runtime::filter::{damping_ratio, ModeFilter};
use std::num::NonZeroUsize;

use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::{Mat, Par};
use rayon::prelude::*;

use super::{FullOrderError, FullOrderSystem};

/// A near-zero eigenvalue is rigid when |λ| ≤ this × the first elastic λ (as in the bake).
const RIGID_REL_TOL: f64 = 1e-6;

/// Every elastic eigenpair of a (small) full-order system.
#[derive(Clone, Debug)]
pub struct ModalAll {
    /// Elastic eigenvalues λ = ω² (rad²/s²), ascending.
    pub eigenvalues: Vec<f64>,
    /// Elastic modes as columns (n_free × m), M-orthonormal (m·kg^-1/2).
    pub vectors: Mat<f64>,
    /// Rigid modes dropped (6 free-free, 0 clamped).
    pub rigid_dropped: usize,
    /// Seconds in the dense eigensolve.
    pub solve_s: f64,
}

impl ModalAll {
    /// Dense generalized eigensolve of the system's (K, M).
    ///
    /// # Errors
    /// [`FullOrderError::TooLarge`] above `max_dofs` free dofs; [`FullOrderError::Eigen`] if M is not
    /// positive definite, the eigensolver fails, or a free-free object does not show exactly
    /// six near-zero eigenvalues.
    pub fn new(sys: &FullOrderSystem, max_dofs: usize) -> Result<ModalAll, FullOrderError> {
        let n = sys.n();
        if n > max_dofs {
            return Err(FullOrderError::TooLarge {
                dofs: n,
                max: max_dofs,
            });
        }
        let t = Instant::now();
        let (vals, phi) =
            dense_generalized_eigen(&sys.k.to_dense(), sys.m.to_dense(), sys.rigid_modes())?;
        let rigid = if sys.free_free() { 6 } else { 0 };
        if rigid > 0 {
            let lam7 = vals.get(rigid).copied().unwrap_or(f64::INFINITY).abs();
            let near = vals
                .iter()
                .filter(|l| l.abs() <= RIGID_REL_TOL * lam7)
                .count();
            if near != rigid {
                return Err(FullOrderError::Eigen(format!(
                    "expected 6 rigid-body modes for a free-free object, found {near}"
                )));
            }
        }
        if !vals.iter().all(|v| v.is_finite()) {
            return Err(FullOrderError::Eigen("non-finite eigenvalue".into()));
        }
        let vectors = phi.subcols(rigid, n - rigid).to_owned();
        Ok(ModalAll {
            eigenvalues: vals[rigid..].to_vec(),
            vectors,
            rigid_dropped: rigid,
            solve_s: t.elapsed().as_secs_f64(),
        })
    }

    /// Modal coordinates of a dual vector: `Φᵀ x` (one per elastic mode).
    pub fn project(&self, x: &[f64]) -> Vec<f64> {
        let n = self.vectors.nrows();
        (0..self.vectors.ncols())
            .into_par_iter()
            .map(|j| (0..n).map(|i| self.vectors[(i, j)] * x[i]).sum())
            .collect()
    }

    /// Peak |wᵀ u(kΔt)|, k = 1 … `steps`, per row, summing the lowest `modes` elastic modes
    /// (`None`: all), after the impulse `f` (N·s, free dofs) at t = 0; Rayleigh `[α0, α1]`.
    pub fn peaks(
        &self,
        f: &[f64],
        rows: &[Vec<f64>],
        rayleigh: [f64; 2],
        dt: f64,
        steps: usize,
        modes: Option<usize>,
    ) -> Vec<f64> {
        let r = self.project(f);
        let w: Vec<Vec<f64>> = rows.iter().map(|w| self.project(w)).collect();
        self.peaks_projected(&r, &w, rayleigh, dt, steps, modes)
    }

    /// As [`ModalAll::peaks`] with the load and rows already projected ([`ModalAll::project`]),
    /// for sweeps over `modes`.
    pub fn peaks_projected(
        &self,
        r: &[f64],
        w: &[Vec<f64>],
        rayleigh: [f64; 2],
        dt: f64,
        steps: usize,
        modes: Option<usize>,
    ) -> Vec<f64> {
        self.response_peaks(r, w, rayleigh, dt, steps, modes, ModalInput::Impulse, false)
    }

    /// Peak |Σ_j w_cj r_j x_j(kΔt)| per row c over k = 1 … `steps`, summing the lowest `modes`
    /// elastic modes (`None`: all); x_j is the impulse response g_j (r in N·s units, paper Eq. 10)
    /// or the step response (1 − φ_j)/ω_j² (r in N: a force switched on at t = 0 and held).
    ///
    /// `static_correction` (step input only; ignored for impulses, whose truncated part has
    /// no static component): adds the residual flexibility of the dropped modes,
    /// Σ_{j > m} w_cj r_j / ω_j² = wᵀ(K⁻¹ − U_m Λ_m⁻¹ U_mᵀ) f, to every sample — the
    /// quasi-static response of modes far above the excitation (mode-acceleration method).
    #[allow(clippy::too_many_arguments)]
    pub fn response_peaks(
        &self,
        r: &[f64],
        w: &[Vec<f64>],
        rayleigh: [f64; 2],
        dt: f64,
        steps: usize,
        modes: Option<usize>,
        input: ModalInput,
        static_correction: bool,
    ) -> Vec<f64> {
        let m = modes.unwrap_or(usize::MAX).min(self.eigenvalues.len());
        let nc = w.len();
        if nc == 0 || steps == 0 {
            return vec![0.0; nc];
        }
        // y[c][k] = Σ_j w_cj r_j x_j(kΔt), summed over j in order for each sample k; samples are
        // split over threads (the same bits on any thread count).
        let active: Vec<(ModeFilter, Vec<f64>)> = (0..m)
            .filter(|&j| self.eigenvalues[j] > 0.0 && r[j] != 0.0)
            .map(|j| {
                let omega = self.eigenvalues[j].sqrt();
                let filt = ModeFilter::new(omega, damping_ratio(omega, rayleigh), dt);
                (filt, w.iter().map(|wc| wc[j] * r[j]).collect())
            })
            .collect();
        const BLOCK: usize = 64;
        let mut y = vec![0.0f64; steps * nc];
        y.par_chunks_mut(BLOCK * nc)
            .enumerate()
            .for_each(|(b, out)| {
                for (kk, yk) in out.chunks_mut(nc).enumerate() {
                    let t = (b * BLOCK + kk + 1) as f64 * dt;
                    for (filt, coef) in &active {
                        let x = match input {
                            ModalInput::Impulse => filt.impulse_response(t),
                            ModalInput::Step => filt.step_response(t),
                        };
                        for (v, a) in yk.iter_mut().zip(coef) {
                            *v += a * x;
                        }
                    }
                }
            });
        let offset: Vec<f64> = if static_correction && input == ModalInput::Step {
            w.iter()
                .map(|wc| {
                    (m..self.eigenvalues.len())
                        .filter(|&j| self.eigenvalues[j] > 0.0)
                        .map(|j| wc[j] * r[j] / self.eigenvalues[j])
                        .sum()
                })
                .collect()
        } else {
            vec![0.0; nc]
        };
        (0..nc)
            .map(|c| (0..steps).fold(0.0f64, |p, k| p.max((y[k * nc + c] + offset[c]).abs())))
            .collect()
    }
}

/// The thread split of the dense factorization, triangular solves and eigensolve. Fixed (not the
/// pool's size): faer's blocked dense kernels partition their work by this count, so a fixed
/// count gives the same bits whatever `RAYON_NUM_THREADS` is (with fewer threads in the pool
/// the parts run one after another).
const DENSE_PAR: Par = Par::Rayon(match NonZeroUsize::new(2) {
    Some(n) => n,
    None => unreachable!(),
});

/// Every eigenpair of K φ = λ M φ (dense, M symmetric positive definite), ascending, with
/// Φᵀ M Φ = I: M = L Lᵀ, C = L⁻¹ K L⁻ᵀ (symmetrised), C = Q Λ Qᵀ, Φ = L⁻ᵀ Q. Bit-identical on
/// any thread count ([`DENSE_PAR`]).
fn dense_generalized_eigen(
    k: &Mat<f64>,
    mut l: Mat<f64>,
    rigid: Option<&Mat<f64>>,
) -> Result<(Vec<f64>, Mat<f64>), FullOrderError> {
    use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
    use faer::linalg::evd::{self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors};
    use faer::linalg::triangular_solve::{
        solve_lower_triangular_in_place, solve_upper_triangular_in_place,
    };
    let n = l.nrows();
    let scratch = cholesky_in_place_scratch::<f64>(n, DENSE_PAR, Default::default()).or(
        self_adjoint_evd_scratch::<f64>(n, ComputeEigenvectors::Yes, DENSE_PAR, Default::default()),
    );
    let mut mem = MemBuffer::try_new(scratch)
        .map_err(|_| FullOrderError::Eigen(format!("no memory for the workspace of {n} dofs")))?;
    let stack = MemStack::new(&mut mem);
    cholesky_in_place(
        l.as_mut(),
        Default::default(),
        DENSE_PAR,
        stack,
        Default::default(),
    )
    .map_err(|e| FullOrderError::Eigen(format!("M is not positive definite: {e:?}")))?;
    let l = l.as_ref();
    // X = L⁻¹ K, C = L⁻¹ Xᵀ = L⁻¹ K L⁻ᵀ (only L's lower triangle is read).
    let mut x = k.clone();
    solve_lower_triangular_in_place(l, x.as_mut(), DENSE_PAR);
    let mut c = x.transpose().to_owned();
    solve_lower_triangular_in_place(l, c.as_mut(), DENSE_PAR);
    let mut c = Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
    let rigid_count = rigid.map_or(0, |r| r.ncols());
    if let Some(r) = rigid {
        deflate(&mut c, l, r);
    }
    let mut s = Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    self_adjoint_evd(
        c.as_ref(),
        s.as_mut(),
        Some(u.as_mut()),
        DENSE_PAR,
        stack,
        Default::default(),
    )
    .map_err(|e| FullOrderError::Eigen(format!("dense eigensolver failed: {e:?}")))?;
    solve_upper_triangular_in_place(l.transpose(), u.as_mut(), DENSE_PAR);
    // The deflated rigid directions sit at −σ, −2σ, … (the lowest, in that order): exactly zero.
    Ok((
        (0..n)
            .map(|i| if i < rigid_count { 0.0 } else { s[i] })
            .collect(),
        u,
    ))
}

/// The time profile of the load in [`ModalAll::response_peaks`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModalInput {
    /// An impulse at t = 0 (load in N·s).
    Impulse,
    /// A force switched on at t = 0 and held (load in N).
    Step,
}

/// `C ← P C P − σ Y D Yᵀ` with `P = I − Y Yᵀ`, `Y = Lᵀ R̃` (orthonormal: R̃ᵀ M R̃ = I,
/// M = L Lᵀ), D = diag(1, 2, …, 6) and σ = max |C_ij|: the rigid directions become exact, distinct
/// eigenvectors far below the elastic spectrum, which P C P leaves unchanged (see the module doc).
/// `l` holds L in its lower triangle.
fn deflate(c: &mut Mat<f64>, l: faer::MatRef<'_, f64>, r: &Mat<f64>) {
    let n = c.nrows();
    let k = r.ncols();
    // Y = Lᵀ R̃: Y[i, j] = Σ_{p ≥ i} L[p, i] R̃[p, j] (lower triangle of l only).
    let y = Mat::from_fn(n, k, |i, j| {
        (i..n).map(|p| l[(p, i)] * r[(p, j)]).sum::<f64>()
    });
    let cy = Mat::from_fn(n, k, |i, j| {
        (0..n).map(|p| c[(i, p)] * y[(p, j)]).sum::<f64>()
    });
    let ycy = Mat::from_fn(k, k, |a, b| {
        (0..n).map(|p| y[(p, a)] * cy[(p, b)]).sum::<f64>()
    });
    let sigma = (0..n)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max(c[(i, j)].abs()));
    // P C P − σ Y D Yᵀ = C − (CY) Yᵀ − Y (CY)ᵀ + W Yᵀ, W = Y (Yᵀ C Y − σ D).
    let w = Mat::from_fn(n, k, |i, b| {
        (0..k).map(|a| y[(i, a)] * ycy[(a, b)]).sum::<f64>() - sigma * (b + 1) as f64 * y[(i, b)]
    });
    let cols: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|j| {
            (0..n)
                .map(|i| {
                    let mut v = c[(i, j)];
                    for a in 0..k {
                        v += -cy[(i, a)] * y[(j, a)] - y[(i, a)] * cy[(j, a)]
                            + w[(i, a)] * y[(j, a)];
                    }
                    v
                })
                .collect()
        })
        .collect();
    for (j, col) in cols.iter().enumerate() {
        for (i, &v) in col.iter().enumerate() {
            c[(i, j)] = v;
        }
    }
}
