//! The shifted operator A = K − σM, its sparse Cholesky factor, and block solves.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side, Spec};

use super::EigenError;

/// A − σB on the union of the two patterns (both full symmetric storage, rows sorted).
pub(crate) fn shifted(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    sigma: f64,
) -> SparseColMat<usize, f64> {
    let n = k.ncols();
    let (kp, kr, kv) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let (mp, mr, mv) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut rows = Vec::with_capacity(kr.len());
    let mut vals = Vec::with_capacity(kr.len());
    col_ptr.push(0);
    for j in 0..n {
        let (mut a, ae) = (kp[j], kp[j + 1]);
        let (mut b, be) = (mp[j], mp[j + 1]);
        while a < ae || b < be {
            let ra = if a < ae { kr[a] } else { usize::MAX };
            let rb = if b < be { mr[b] } else { usize::MAX };
            if ra == rb {
                rows.push(ra);
                vals.push(kv[a] - sigma * mv[b]);
                a += 1;
                b += 1;
            } else if ra < rb {
                rows.push(ra);
                vals.push(kv[a]);
                a += 1;
            } else {
                rows.push(rb);
                vals.push(-sigma * mv[b]);
                b += 1;
            }
        }
        col_ptr.push(rows.len());
    }
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows), vals)
}

/// Sparse LLᵀ factor of A = K − σM (AMD ordering, faer's supernodal/simplicial choice).
pub(crate) struct ShiftInvert {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    par: Par,
}

impl ShiftInvert {
    /// Factors `a` (symmetric positive definite, full storage; the lower triangle is read).
    pub fn new(a: &SparseColMat<usize, f64>, par: Par) -> Result<ShiftInvert, EigenError> {
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| EigenError::Factorization(format!("symbolic analysis failed: {e:?}")))?;
        let mut values = vec![0.0f64; symbolic.len_val()];
        let scratch = symbolic.factorize_numeric_llt_scratch::<f64>(par, Spec::default());
        let mut mem = MemBuffer::try_new(scratch)
            .map_err(|_| EigenError::Factorization("out of memory".into()))?;
        symbolic
            .factorize_numeric_llt(
                &mut values,
                a.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Spec::default(),
            )
            .map_err(|e| {
                EigenError::Factorization(format!(
                    "K - sigma*M is not positive definite ({e:?}); the shift must lie below the \
                     lowest eigenvalue"
                ))
            })?;
        Ok(ShiftInvert { symbolic, values, par })
    }

    /// Number of stored factor entries.
    pub fn factor_nnz(&self) -> usize {
        self.values.len()
    }

    /// Overwrites every column of `rhs` with A⁻¹ rhs.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>, mem: &mut MemBuffer) {
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            self.par,
            MemStack::new(mem),
        );
    }

    /// Scratch buffer for solves of up to `ncols` right-hand sides.
    pub fn solve_buffer(&self, ncols: usize) -> MemBuffer {
        MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(ncols, self.par))
    }
}
