//! The expansion steps of a Lanczos run: the start block and the block Lanczos step
//! Z = A⁻¹ M W, M-orthogonalised against the basis and the locked vectors and
//! M-orthonormalised (Cholesky-QR twice, column-wise Gram–Schmidt on breakdown).

use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::Reborrow;
use faer::sparse::SparseColMat;
use faer::{Accum, Mat, MatMut, MatRef, Par};

use super::super::kernels::{gemm, small_cholesky, sym_spmm, SplitMix64};
use super::super::ritz::symmetrized;
use super::super::shift_invert::{ShiftInvert, SolveBuffer};
use super::super::{EigenError, EigenInfo};
use super::krylov_basis::KrylovBasis;
use super::m_norm;

/// Breakdown threshold: a new direction whose M-norm after orthogonalisation is below this
/// fraction of its norm before is treated as lying in the current basis.
const BREAKDOWN: f64 = 1e-12;

/// Operators and workspaces of one Lanczos run's expansion steps.
pub(super) struct Expansion<'a> {
    /// Mass matrix M (kg).
    pub(super) m: &'a SparseColMat<usize, f64>,
    /// Factorisation of A = K − σM.
    pub(super) fac: &'a ShiftInvert,
    /// Locked (M-orthonormal) vectors the basis is kept M-orthogonal to, and M times them.
    pub(super) deflation: (MatRef<'a, f64>, MatRef<'a, f64>),
    /// Newest block Z (n × b).
    pub(super) z: Mat<f64>,
    /// M Z (kg).
    pub(super) mz: Mat<f64>,
    /// Workspace of the block solves.
    pub(super) solve_buf: SolveBuffer,
    /// Random source for the start block and breakdown replacements.
    pub(super) rng: SplitMix64,
}

impl Expansion<'_> {
    /// Start block: a random block mapped into the range of T (z ← A⁻¹Mz), deflated twice
    /// against the locked vectors, M-orthonormalised and stored as the basis's first block.
    pub(super) fn start(
        &mut self,
        basis: &mut KrylovBasis,
        info: &mut EigenInfo,
    ) -> Result<(), EigenError> {
        let (n, b) = (self.z.nrows(), self.z.ncols());
        let (locked, mlocked) = self.deflation;
        for j in 0..b {
            for i in 0..n {
                self.z[(i, j)] = self.rng.next_sym();
            }
        }
        // Start in the range of T (z ← A⁻¹Mz): a random block is white noise whose
        // high-frequency content would otherwise survive in the Ritz vectors (Ericsson & Ruhe
        // 1980) and, amplified by K, dominate their residuals.
        sym_spmm(self.m, self.z.as_ref(), self.mz.as_mut());
        self.z.copy_from(&self.mz);
        self.fac
            .solve_in_place(self.z.as_mut(), &mut self.solve_buf);
        info.block_solves += 1;
        deflate(self.z.as_mut(), locked, mlocked);
        deflate(self.z.as_mut(), locked, mlocked);
        sym_spmm(self.m, self.z.as_ref(), self.mz.as_mut());
        let pre: Vec<f64> = (0..b)
            .map(|j| m_norm(self.z.as_ref(), self.mz.as_ref(), j))
            .collect();
        orthonormalize(
            &mut self.z,
            &mut self.mz,
            basis.v.as_ref().subcols(0, 0),
            basis.mv.as_ref().subcols(0, 0),
            self.deflation,
            &pre,
            self.m,
            &mut self.rng,
        )?;
        basis.v.as_mut().subcols_mut(0, b).copy_from(&self.z);
        basis.mv.as_mut().subcols_mut(0, b).copy_from(&self.mz);
        Ok(())
    }

    /// Block Lanczos step: Z = T W = A⁻¹ M W for the newest block W at `kk..kk + b`,
    /// M-orthogonalised against the basis in two passes (the first only against the blocks Z
    /// couples to in exact arithmetic unless `coupled_to_all`), M-orthonormalised and
    /// appended at `kk + b`; H receives the projections and the new subdiagonal block.
    pub(super) fn expand(
        &mut self,
        basis: &mut KrylovBasis,
        kk: usize,
        coupled_to_all: bool,
        info: &mut EigenInfo,
    ) -> Result<(), EigenError> {
        let b = self.z.ncols();
        let (locked, mlocked) = self.deflation;
        let (v, mv) = (&mut basis.v, &mut basis.mv);
        let nb = kk + b;
        self.z.copy_from(mv.as_ref().subcols(kk, b));
        self.fac
            .solve_in_place(self.z.as_mut(), &mut self.solve_buf);
        info.block_solves += 1;
        let mut c = Mat::<f64>::zeros(nb, b);
        for pass in 0..2 {
            // First pass: only the blocks Z is coupled to in exact arithmetic (the newest
            // and the one before it, or all after a restart); second pass: the whole basis.
            let lo = if pass == 0 && !coupled_to_all {
                kk - b
            } else {
                0
            };
            deflate(self.z.as_mut(), locked, mlocked);
            let mut cp = Mat::<f64>::zeros(nb - lo, b);
            gemm(
                cp.as_mut(),
                Accum::Replace,
                mv.as_ref().subcols(lo, nb - lo).transpose(),
                self.z.as_ref(),
                1.0,
            );
            gemm(
                self.z.as_mut(),
                Accum::Add,
                v.as_ref().subcols(lo, nb - lo),
                cp.as_ref(),
                -1.0,
            );
            let mut cs = c.as_mut().subrows_mut(lo, nb - lo);
            cs += &cp;
        }
        basis.h.as_mut().submatrix_mut(0, kk, nb, b).copy_from(&c);
        sym_spmm(self.m, self.z.as_ref(), self.mz.as_mut());
        let pre: Vec<f64> = (0..b)
            .map(|j| {
                let cn: f64 = (0..nb).map(|i| c[(i, j)] * c[(i, j)]).sum();
                (cn + m_norm(self.z.as_ref(), self.mz.as_ref(), j).powi(2)).sqrt()
            })
            .collect();
        let r = orthonormalize(
            &mut self.z,
            &mut self.mz,
            v.as_ref().subcols(0, nb),
            mv.as_ref().subcols(0, nb),
            self.deflation,
            &pre,
            self.m,
            &mut self.rng,
        )?;
        v.as_mut().subcols_mut(nb, b).copy_from(&self.z);
        mv.as_mut().subcols_mut(nb, b).copy_from(&self.mz);
        basis.h.as_mut().submatrix_mut(nb, kk, b, b).copy_from(&r);
        Ok(())
    }
}

/// Subtracts from the columns of `z` their M-projection on the (M-orthonormal) `locked`
/// vectors: z ← z − L (MLᵀ z).
fn deflate(z: MatMut<'_, f64>, locked: MatRef<'_, f64>, mlocked: MatRef<'_, f64>) {
    if locked.ncols() == 0 {
        return;
    }
    let mut c = Mat::<f64>::zeros(locked.ncols(), z.ncols());
    gemm(c.as_mut(), Accum::Replace, mlocked.transpose(), z.rb(), 1.0);
    gemm(z, Accum::Add, locked, c.as_ref(), -1.0);
}

/// M-orthonormalises the columns of `z` (already M-orthogonal to `v`) in place, keeping
/// `mz = M z`; returns R with z_before = z_after · R (upper triangular). Cholesky-QR twice; on
/// breakdown (a column with norm below [`BREAKDOWN`]·`pre`) column-wise Gram–Schmidt with
/// random replacement.
#[allow(clippy::too_many_arguments)]
fn orthonormalize(
    z: &mut Mat<f64>,
    mz: &mut Mat<f64>,
    v: MatRef<'_, f64>,
    mv: MatRef<'_, f64>,
    (locked, mlocked): (MatRef<'_, f64>, MatRef<'_, f64>),
    pre: &[f64],
    m: &SparseColMat<usize, f64>,
    rng: &mut SplitMix64,
) -> Result<Mat<f64>, EigenError> {
    let b = z.ncols();
    let healthy =
        (0..b).all(|j| m_norm(z.as_ref(), mz.as_ref(), j) > BREAKDOWN * pre[j] && pre[j] > 0.0);
    if healthy {
        let mut r_total = Mat::<f64>::identity(b, b);
        let mut ok = true;
        for _pass in 0..2 {
            let mut g = Mat::<f64>::zeros(b, b);
            gemm(
                g.as_mut(),
                Accum::Replace,
                z.as_ref().transpose(),
                mz.as_ref(),
                1.0,
            );
            let mut g = symmetrized(g.as_ref());
            if small_cholesky(g.as_mut(), 1e-14).is_err() {
                ok = false;
                break;
            }
            let l = Mat::from_fn(b, b, |i, j| if i >= j { g[(i, j)] } else { 0.0 });
            // z ← z L⁻ᵀ, i.e. zᵀ ← L⁻¹ zᵀ, in place.
            solve_lower_triangular_in_place(l.as_ref(), z.as_mut().transpose_mut(), Par::Seq);
            solve_lower_triangular_in_place(l.as_ref(), mz.as_mut().transpose_mut(), Par::Seq);
            r_total = l.transpose() * &r_total;
        }
        if ok {
            return Ok(r_total);
        }
    }
    // Column-wise fallback (rare: Krylov breakdown or a nearly dependent block).
    let n = z.nrows();
    let mut r = Mat::<f64>::zeros(b, b);
    for j in 0..b {
        let mut replaced = false;
        for attempt in 0..3 {
            let reference = if replaced {
                m_norm(z.as_ref(), mz.as_ref(), j)
            } else {
                pre[j]
            };
            for _pass in 0..2 {
                project_out_col(z, mz, j, locked, mlocked);
                project_out_col(z, mz, j, v, mv);
                for i in 0..j {
                    let c: f64 = mz
                        .col(i)
                        .iter()
                        .zip(z.col(j).iter())
                        .map(|(a, b)| a * b)
                        .sum();
                    let (zi, mzi) = (z.col(i).to_owned(), mz.col(i).to_owned());
                    for (t, s) in z.as_mut().col_mut(j).iter_mut().zip(zi.iter()) {
                        *t -= c * s;
                    }
                    for (t, s) in mz.as_mut().col_mut(j).iter_mut().zip(mzi.iter()) {
                        *t -= c * s;
                    }
                    if !replaced {
                        r[(i, j)] += c;
                    }
                }
            }
            let nrm = m_norm(z.as_ref(), mz.as_ref(), j);
            if nrm > BREAKDOWN * reference && reference > 0.0 {
                if !replaced {
                    r[(j, j)] = nrm;
                }
                for t in z.as_mut().col_mut(j).iter_mut() {
                    *t /= nrm;
                }
                for t in mz.as_mut().col_mut(j).iter_mut() {
                    *t /= nrm;
                }
                break;
            }
            if attempt == 2 {
                return Err(EigenError::InvalidInput(
                    "Krylov space exhausted: the problem is too small for the requested basis"
                        .into(),
                ));
            }
            // Replace by a fresh random direction; the Lanczos relation gets a zero column.
            replaced = true;
            for i in 0..j + 1 {
                r[(i, j)] = 0.0;
            }
            for i in 0..n {
                z[(i, j)] = rng.next_sym();
            }
            let zj = z.as_ref().subcols(j, 1).to_owned();
            sym_spmm(m, zj.as_ref(), mz.as_mut().subcols_mut(j, 1));
        }
    }
    Ok(r)
}

/// Removes from column `j` of `z` (and of `mz = M z`) its M-projection on the M-orthonormal
/// `basis` (`mbasis = M basis`).
fn project_out_col(
    z: &mut Mat<f64>,
    mz: &mut Mat<f64>,
    j: usize,
    basis: MatRef<'_, f64>,
    mbasis: MatRef<'_, f64>,
) {
    if basis.ncols() == 0 {
        return;
    }
    let mut c = Mat::<f64>::zeros(basis.ncols(), 1);
    gemm(
        c.as_mut(),
        Accum::Replace,
        mbasis.transpose(),
        z.as_ref().subcols(j, 1),
        1.0,
    );
    gemm(
        z.as_mut().subcols_mut(j, 1),
        Accum::Add,
        basis,
        c.as_ref(),
        -1.0,
    );
    gemm(
        mz.as_mut().subcols_mut(j, 1),
        Accum::Add,
        mbasis,
        c.as_ref(),
        -1.0,
    );
}
