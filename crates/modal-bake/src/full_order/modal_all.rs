//! [`ModalAll`]: the sum over *every* mode of a small mesh (dense generalized eigensolve), with
//! the exact damped impulse response of each mode.
//!
//! K φ = λ M φ is solved densely: M = L Lᵀ (Cholesky), C = L⁻¹ K L⁻ᵀ (symmetrised), C = Q Λ Qᵀ
//! (faer `self_adjoint_eigen`), Φ = L⁻ᵀ Q, so Φᵀ M Φ = I. With Rayleigh damping every mode
//! decouples (paper Eq. 8) and an impulse f at t = 0 gives the exact displacement
//! u(t) = Σ_j φ_j (φ_jᵀ f) g_j(t), with g_j the mass-normalised impulse response for
//! ξ_j = ½(α0/ω_j + α1 ω_j) in every regime (ξ < 1, = 1, > 1) — `dcr_runtime::ModeFilter`.
//!
//! Free-free: the six lowest eigenpairs (λ ≈ 0) are the rigid modes; they are dropped (the load
//! and the rows are also M-orthogonally stripped of their rigid part by
//! [`super::FullOrderSystem::remove_rigid`], so their coefficients are ≈ 0 anyway).

use std::time::Instant;

use dcr_runtime::{damping_ratio, ModeFilter};
use faer::{Mat, Side};
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
        let md = sys.m.to_dense();
        let kd = sys.k.to_dense();
        let llt = md
            .llt(Side::Lower)
            .map_err(|e| FullOrderError::Eigen(format!("M is not positive definite: {e:?}")))?;
        let l = llt.L().to_owned();
        // X = L⁻¹ K, C = L⁻¹ Xᵀ = L⁻¹ K L⁻ᵀ.
        let mut x = kd;
        l.solve_lower_triangular_in_place(x.as_mut());
        let mut c = x.transpose().to_owned();
        l.solve_lower_triangular_in_place(c.as_mut());
        let c = Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
        let eig = c
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| FullOrderError::Eigen(format!("dense eigensolver failed: {e:?}")))?;
        let vals: Vec<f64> = (0..n).map(|i| eig.S()[i]).collect();
        let mut phi = eig.U().to_owned();
        l.transpose().solve_upper_triangular_in_place(phi.as_mut());
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
        // y[c][k] = Σ_j w_cj r_j x_j(kΔt), accumulated per chunk of modes in parallel.
        let y = (0..m)
            .into_par_iter()
            .with_min_len(32)
            .fold(
                || vec![0.0f64; nc * steps],
                |mut acc, j| {
                    let lam = self.eigenvalues[j];
                    if lam.is_nan() || lam <= 0.0 || r[j] == 0.0 {
                        return acc;
                    }
                    let omega = lam.sqrt();
                    let filt = ModeFilter::new(omega, damping_ratio(omega, rayleigh), dt);
                    let coef: Vec<f64> = w.iter().map(|wc| wc[j] * r[j]).collect();
                    for k in 0..steps {
                        let t = (k + 1) as f64 * dt;
                        let x = match input {
                            ModalInput::Impulse => filt.impulse_response(t),
                            ModalInput::Step => filt.step_response(t),
                        };
                        for (c, a) in coef.iter().enumerate() {
                            acc[c * steps + k] += a * x;
                        }
                    }
                    acc
                },
            )
            .reduce(
                || vec![0.0f64; nc * steps],
                |mut a, b| {
                    a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                    a
                },
            );
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
            .map(|c| {
                y[c * steps..(c + 1) * steps]
                    .iter()
                    .fold(0.0f64, |p, v| p.max((v + offset[c]).abs()))
            })
            .collect()
    }
}

/// The time profile of the load in [`ModalAll::response_peaks`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModalInput {
    /// An impulse at t = 0 (load in N·s).
    Impulse,
    /// A force switched on at t = 0 and held (load in N).
    Step,
}
