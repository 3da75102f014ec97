//! The dense path for small problems: every eigenpair of K u = λ M u at once, so a count up
//! to the number of free dofs, or a frequency cap beyond the highest mode, is answered exactly
//! (Lanczos needs a Krylov basis larger than the wanted set, which such problems do not have).
//!
//! 1. Shift-invert in dense form: A = K − σM = R Rᵀ (dense Cholesky), C = R⁻¹ M R⁻ᵀ, whose
//!    eigenvalues are θ = 1/(λ − σ), and C = Q Θ Qᵀ; the largest θ are the lowest λ, and
//!    u = R⁻ᵀ q / √θ is M-normalised. The shifted form makes the backward error ε·‖C‖ = ε/(λ₁ − σ)
//!    small against the θ of the low modes, whose residuals K would otherwise amplify (the
//!    unshifted C = L⁻¹ K L⁻ᵀ left relative residuals of 1e-1 for the rigid modes and 1e-4
//!    for the elastic ones of the 570-dof free-free beam).
//! 2. C's eigendecomposition uses the implicit QR iteration on the tridiagonal form
//!    ([`super::kernels::sym_eig_qr`]): faer's default divide and conquer reached only
//!    ‖Cq − θq‖ ≈ 3e-12·‖C‖ on that beam, which left most of its 250 lowest pairs above the
//!    1e-8 residual tolerance; the QR iteration reaches 1.3e-15·‖C‖ and every pair passes
//!    without refinement (worst 1.2e-10 for all 564 elastic modes).
//! 3. The pairs are M-orthonormalised by one Cholesky-QR in ascending λ with λ = uᵀKu and
//!    checked on the explicit residual, as Lanczos's. A pair that fails is purified
//!    (u ← A⁻¹ M u with the Cholesky factor of step 1; Nour-Omid, Parlett, Ericsson & Jensen
//!    1987), which damps the component of eigenvalue μ by (λ − σ)/(μ − σ), and the set is
//!    orthonormalised and checked again, at most [`PASSES`] times.
//!
//! Every step runs sequentially (`Par::Seq`, our fixed-order sparse products), so the results
//! are bit-identical on any thread count. Cost, O(n³) with vectors: see `DENSE_MAX_DOFS` in
//! `lanczos.rs`.

use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{
    cholesky_in_place, cholesky_in_place_scratch, LltRegularization,
};
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::sparse::SparseColMat;
use faer::{Mat, MatRef, Par, Spec};

use super::kernels::{sym_eig_qr, sym_spmm};
use super::ritz::{normalize_signs, orthonormalize_ascending, RitzPairs};
use super::shift_invert::shifted;
use super::{EigenError, EigenInfo, EigenParams, EigenProgress, EigenResult};

/// Purification passes before a pair that still fails the residual check is an error.
const PASSES: usize = 2;

/// Every eigenpair below `lam_lim` (at least `params.nev`, at most `params.max_modes`), or the
/// `params.nev` lowest, by the dense solve and refinement of the module docs.
pub(super) fn solve(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    params: &EigenParams,
    lam_lim: Option<f64>,
    mut info: EigenInfo,
    progress: &mut dyn FnMut(EigenProgress),
) -> Result<EigenResult, EigenError> {
    let t0 = Instant::now();
    let n = k.nrows();
    let sigma = params.shift;
    let r = dense_cholesky(shifted(k, m, sigma).to_dense()).map_err(|e| {
        EigenError::Factorization(format!(
            "K − σM with σ = {sigma:e} is not positive definite ({e}); the shift must lie below the lowest eigenvalue"
        ))
    })?;
    info.factor_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    // C = R⁻¹ M R⁻ᵀ.
    let mut x = m.to_dense();
    solve_lower_triangular_in_place(r.as_ref(), x.as_mut(), Par::Seq);
    let mut c = x.transpose().to_owned();
    drop(x);
    solve_lower_triangular_in_place(r.as_ref(), c.as_mut(), Par::Seq);
    let c = Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
    let (theta, q) = sym_eig_qr(c.as_ref()).map_err(EigenError::Dense)?;
    drop(c);
    // Descending θ is ascending λ.
    let lam: Vec<f64> = theta.iter().rev().map(|&t| sigma + 1.0 / t).collect();
    let wanted = match lam_lim {
        None => params.nev,
        Some(lim) => {
            let below = lam.iter().take_while(|&&v| v < lim).count();
            info.capped = below > params.max_modes;
            below.max(params.nev).min(params.max_modes)
        }
    }
    .min(n);
    let mut u = Mat::from_fn(n, wanted, |i, j| q[(i, n - 1 - j)]);
    drop(q);
    solve_upper_triangular_in_place(r.as_ref().transpose(), u.as_mut(), Par::Seq);
    let ((vals, u, res), passes) = refine(k, m, r.as_ref(), u, &[], sigma, params.tol, &mut info)?;
    info.dense = true;
    info.iterations = 1;
    info.krylov_dim = n;
    info.solve_seconds = t1.elapsed().as_secs_f64();
    let good = res.iter().filter(|r| r.converged(params.tol)).count();
    progress(EigenProgress {
        converged: good,
        requested: wanted,
        iteration: passes + 1,
    });
    if good < wanted {
        return Err(EigenError::NotConverged {
            converged: good,
            requested: wanted,
            worst_residual: res.iter().map(|r| r.rel).fold(0.0, f64::max),
        });
    }
    let mut vectors = u;
    normalize_signs(vectors.as_mut());
    Ok(EigenResult {
        eigenvalues: vals,
        vectors,
        residuals: res.iter().map(|r| r.rel).collect(),
        residual_floors: res.iter().map(|r| r.floor).collect(),
        info,
    })
}

/// The lower Cholesky factor of the dense SPD matrix `a` (strict upper part zeroed).
fn dense_cholesky(mut a: Mat<f64>) -> Result<Mat<f64>, String> {
    let n = a.nrows();
    let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(
        n,
        Par::Seq,
        Spec::default(),
    ));
    cholesky_in_place(
        a.as_mut(),
        LltRegularization::default(),
        Par::Seq,
        MemStack::new(&mut mem),
        Spec::default(),
    )
    .map_err(|e| format!("{e:?}"))?;
    for j in 1..n {
        for i in 0..j {
            a[(i, j)] = 0.0;
        }
    }
    Ok(a)
}

/// M-normalises the columns of `u` (ascending λ), purifies the columns in `purify` by
/// u ← A⁻¹ M u with A = R Rᵀ, M-orthonormalises the set in ascending λ with λ = uᵀKu, and
/// repeats on the pairs failing the residual check, at most [`PASSES`] times. Returns the
/// pairs with their residuals and the passes made.
#[allow(clippy::too_many_arguments)]
fn refine(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    r: MatRef<'_, f64>,
    mut u: Mat<f64>,
    purify: &[usize],
    sigma: f64,
    tol: f64,
    info: &mut EigenInfo,
) -> Result<(RitzPairs, usize), EigenError> {
    let (n, w) = (u.nrows(), u.ncols());
    let mut pick = purify.to_vec();
    let mut passes = 0;
    loop {
        if !pick.is_empty() {
            let mut up = Mat::<f64>::zeros(n, pick.len());
            let sel = Mat::from_fn(n, pick.len(), |i, c| u[(i, pick[c])]);
            sym_spmm(m, sel.as_ref(), up.as_mut());
            solve_lower_triangular_in_place(r, up.as_mut(), Par::Seq);
            solve_upper_triangular_in_place(r.transpose(), up.as_mut(), Par::Seq);
            info.block_solves += 1;
            info.purified += pick.len();
            for (c, &j) in pick.iter().enumerate() {
                u.as_mut().col_mut(j).copy_from(up.col(c));
            }
        }
        let mut mu = Mat::<f64>::zeros(n, w);
        sym_spmm(m, u.as_ref(), mu.as_mut());
        for j in 0..w {
            let s: f64 = u
                .col(j)
                .iter()
                .zip(mu.col(j).iter())
                .map(|(a, b)| a * b)
                .sum();
            let nrm = s.max(0.0).sqrt();
            if nrm > 0.0 {
                let inv = 1.0 / nrm;
                u.as_mut().col_mut(j).iter_mut().for_each(|x| *x *= inv);
                mu.as_mut().col_mut(j).iter_mut().for_each(|x| *x *= inv);
            }
        }
        let ((vals, uu, res), _): (RitzPairs, _) = orthonormalize_ascending(k, m, u, mu, sigma)?;
        info.residual_checks += 1;
        pick = (0..w).filter(|&j| !res[j].converged(tol)).collect();
        if pick.is_empty() || passes == PASSES {
            return Ok(((vals, uu, res), passes));
        }
        passes += 1;
        u = uu;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::{assemble_clamped, Material};
    use crate::mesh::TetMesh;

    /// Purification repairs pairs spoiled by high-frequency noise (what K amplifies into the
    /// residual): exact pairs of a clamped bar plus 1e-8 of each mode in the upper half of the
    /// spectrum fail the 1e-8 residual check; after the refinement every pair passes again
    /// with its eigenvalue to 1e-12.
    #[test]
    fn purification_repairs_noisy_pairs() {
        let mesh = TetMesh::structured_box([8, 2, 2], [1.0, 0.2, 0.2]);
        let mat = Material::new(2e11, 0.3, 7800.0).unwrap();
        let (_, k, m) = assemble_clamped(&mesh, &mat, false, &mesh.groups["xmin"]).unwrap();
        let n = k.nrows();
        let params = EigenParams {
            nev: n,
            tol: 1e-8,
            ..Default::default()
        };
        let mut info = EigenInfo::default();
        let all = solve(&k, &m, &params, None, info.clone(), &mut |_| {}).unwrap();
        let mut rng = super::super::kernels::SplitMix64(7);
        let coef = Mat::from_fn(n - n / 2, 10, |_, _| 1e-8 * rng.next_sym());
        let high = all.vectors.as_ref().subcols(n / 2, n - n / 2);
        let noisy = all.vectors.as_ref().subcols(0, 10).to_owned() + high * &coef;
        let r = dense_cholesky(shifted(&k, &m, 0.0).to_dense()).unwrap();
        let ((_, _, before), p0) = refine(
            &k,
            &m,
            r.as_ref(),
            noisy.clone(),
            &[],
            0.0,
            1e300,
            &mut info,
        )
        .unwrap();
        assert_eq!(p0, 0);
        assert!(
            before.iter().all(|r| r.rel > 1e-6),
            "the noise must spoil every pair"
        );
        let ((vals, _, after), passes) =
            refine(&k, &m, r.as_ref(), noisy, &[], 0.0, 1e-8, &mut info).unwrap();
        assert!(passes >= 1);
        for (j, r) in after.iter().enumerate() {
            assert!(r.rel <= 1e-8, "pair {j}: residual {:e}", r.rel);
            let e = all.eigenvalues[j];
            assert!((vals[j] - e).abs() <= 1e-12 * e, "λ{j} {} vs {e}", vals[j]);
        }
    }
}
