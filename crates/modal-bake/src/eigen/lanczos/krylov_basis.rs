//! The Krylov basis of one Lanczos run (V, MV, the projected matrix H) and its thick restart.

use faer::{Accum, Mat};

use super::super::kernels::gemm;
use super::rayleigh_ritz::RitzEstimates;
use super::{grow, select_cols};

/// Krylov basis of one Lanczos run: V, MV = M V and the projected matrix H = VᵀMTV, with
/// spare basis workspaces for the thick restart (allocated at the first restart).
pub(super) struct KrylovBasis {
    /// Basis vectors (columns), n × `cap`.
    pub(super) v: Mat<f64>,
    /// M times the basis vectors (kg), n × `cap`.
    pub(super) mv: Mat<f64>,
    /// Projected block-tridiagonal (after a restart: arrowhead) matrix, `cap` × `cap`.
    pub(super) h: Mat<f64>,
    /// Spare workspace for the restarted V.
    pub(super) v2: Mat<f64>,
    /// Spare workspace for the restarted MV.
    pub(super) mv2: Mat<f64>,
    /// Krylov dimension the basis is restarted at.
    pub(super) ncv: usize,
    /// Allocated columns: `ncv` plus one block.
    pub(super) cap: usize,
}

impl KrylovBasis {
    /// An empty basis of `n`-vectors for Krylov dimension `ncv` and block size `b`.
    pub(super) fn new(n: usize, ncv: usize, b: usize) -> Self {
        let cap = ncv + b;
        Self {
            v: Mat::<f64>::zeros(n, cap),
            mv: Mat::<f64>::zeros(n, cap),
            h: Mat::<f64>::zeros(cap, cap),
            v2: Mat::<f64>::zeros(0, 0),
            mv2: Mat::<f64>::zeros(0, 0),
            ncv,
            cap,
        }
    }

    /// Raises the Krylov dimension to `need` (max-frequency mode), keeping the basis and H.
    pub(super) fn grow_to(&mut self, need: usize, n: usize, b: usize) {
        if need > self.ncv {
            self.ncv = need;
            let new_cap = self.ncv + b;
            grow(&mut self.v, n, new_cap);
            grow(&mut self.mv, n, new_cap);
            let mut h2 = Mat::<f64>::zeros(new_cap, new_cap);
            h2.as_mut()
                .submatrix_mut(0, 0, self.cap, self.cap)
                .copy_from(&self.h);
            self.h = h2;
            self.cap = new_cap;
        }
    }

    /// Thick restart: keeps the best p Ritz vectors of the `kk`-column basis plus its newest
    /// block, H becoming diag(θ) with the newest block's coupling row. Returns p.
    pub(super) fn thick_restart(
        &mut self,
        ritz: &RitzEstimates,
        kk: usize,
        wanted: usize,
        b: usize,
    ) -> usize {
        let (n, ncv, cap) = (self.v.nrows(), self.ncv, self.cap);
        let p = (wanted + (kk - wanted) / 2)
            .min(ncv - b)
            .max(wanted.min(ncv - b));
        let sp = select_cols(ritz.s_asc.as_ref(), &ritz.order[..p]);
        // New basis [V S, W] built in the spare workspaces, then swapped in (no
        // allocation, no copies of the n × p products).
        if self.v2.ncols() != cap {
            self.v2 = Mat::<f64>::zeros(n, cap);
            self.mv2 = Mat::<f64>::zeros(n, cap);
        }
        gemm(
            self.v2.as_mut().subcols_mut(0, p),
            Accum::Replace,
            self.v.as_ref().subcols(0, kk),
            sp.as_ref(),
            1.0,
        );
        gemm(
            self.mv2.as_mut().subcols_mut(0, p),
            Accum::Replace,
            self.mv.as_ref().subcols(0, kk),
            sp.as_ref(),
            1.0,
        );
        self.v2
            .as_mut()
            .subcols_mut(p, b)
            .copy_from(self.v.as_ref().subcols(kk, b));
        self.mv2
            .as_mut()
            .subcols_mut(p, b)
            .copy_from(self.mv.as_ref().subcols(kk, b));
        std::mem::swap(&mut self.v, &mut self.v2);
        std::mem::swap(&mut self.mv, &mut self.mv2);
        let mut coupling = Mat::<f64>::zeros(b, p);
        gemm(
            coupling.as_mut(),
            Accum::Replace,
            ritz.r_last.as_ref(),
            sp.as_ref().subrows(kk - b, b),
            1.0,
        );
        self.h.fill(0.0);
        for i in 0..p {
            self.h[(i, i)] = ritz.theta[i];
        }
        self.h
            .as_mut()
            .submatrix_mut(p, 0, b, p)
            .copy_from(&coupling);
        p
    }
}
