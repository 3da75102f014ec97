//! Small deterministic kernels: symmetric sparse × dense products, dense symmetric eigen,
//! small Cholesky, the start-block PRNG.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors};
use faer::reborrow::ReborrowMut;
use faer::sparse::SparseColMat;
use faer::{Accum, Mat, MatMut, MatRef, Par, Spec};
use rayon::prelude::*;

/// Rows per parallel task in [`sym_spmm`]; a fixed constant so the work split (and so the
/// result) never depends on the thread count (each output row is computed by one task anyway).
const SPMM_ROWS_PER_TASK: usize = 2048;

/// `y = A x` for a symmetric `A` stored with both triangles (column `i` of the CSC arrays is
/// read as row `i`). Each output entry is one sequential dot product over the sorted row
/// indices: deterministic, parallel over fixed-size row chunks.
pub(crate) fn sym_spmm(a: &SparseColMat<usize, f64>, x: MatRef<'_, f64>, y: MatMut<'_, f64>) {
    spmm_impl(a, x, y, None);
}

/// `y = A x` and `y_abs = |A| |x|` in one pass (the second is the rounding-error scale of the
/// first).
pub(crate) fn sym_spmm_with_abs(
    a: &SparseColMat<usize, f64>,
    x: MatRef<'_, f64>,
    y: MatMut<'_, f64>,
    y_abs: MatMut<'_, f64>,
) {
    spmm_impl(a, x, y, Some(y_abs));
}

/// Columns handled per pass over the matrix (index and value loads shared between them).
const SPMM_COLS: usize = 8;

fn spmm_impl(
    a: &SparseColMat<usize, f64>,
    x: MatRef<'_, f64>,
    mut y: MatMut<'_, f64>,
    mut y_abs: Option<MatMut<'_, f64>>,
) {
    let n = a.nrows();
    let w = x.ncols();
    assert!(x.nrows() == n && y.nrows() == n && y.ncols() == w);
    let with_abs = y_abs.is_some();
    let stride = if with_abs { 2 * SPMM_COLS } else { SPMM_COLS };
    // Row-major panels: input [x_c0 .. x_c7] per row, output [y.., |y|..] per row. Reused
    // across calls (per thread): fresh n × 8 buffers cost a page-faulting allocation per call,
    // ≈ 10% of a 3.5k-dof eigensolve (perf).
    SPMM_SCRATCH.with(|cell| {
        let mut scratch = cell.borrow_mut();
        let (xr, out) = &mut *scratch;
        if xr.len() < n * SPMM_COLS {
            xr.resize(n * SPMM_COLS, 0.0);
        }
        if out.len() < n * stride {
            out.resize(n * stride, 0.0);
        }
        let (xr, out) = (&mut xr[..n * SPMM_COLS], &mut out[..n * stride]);
        let mut c0 = 0;
        while c0 < w {
            let nc = SPMM_COLS.min(w - c0);
            for c in 0..SPMM_COLS {
                if c < nc {
                    for (i, &v) in x.col(c0 + c).iter().enumerate() {
                        xr[i * SPMM_COLS + c] = v;
                    }
                } else {
                    for i in 0..n {
                        xr[i * SPMM_COLS + c] = 0.0;
                    }
                }
            }
            spmm_panel(a, xr, out, with_abs);
            for c in 0..nc {
                for (i, v) in y.rb_mut().col_mut(c0 + c).iter_mut().enumerate() {
                    *v = out[i * stride + c];
                }
                if let Some(ya) = y_abs.as_mut() {
                    for (i, v) in ya.rb_mut().col_mut(c0 + c).iter_mut().enumerate() {
                        *v = out[i * stride + SPMM_COLS + c];
                    }
                }
            }
            c0 += nc;
        }
    });
}

thread_local! {
    /// The panels of [`spmm_impl`] (input, output), grown to the largest size seen.
    static SPMM_SCRATCH: std::cell::RefCell<(Vec<f64>, Vec<f64>)> =
        const { std::cell::RefCell::new((Vec::new(), Vec::new())) };
}

/// One panel of [`spmm_impl`]: `out[i] = Σ_p a_ip · xr[row_p]` (and the absolute sums), each
/// output row a sequential sum in index order.
fn spmm_panel(a: &SparseColMat<usize, f64>, xr: &[f64], out: &mut [f64], with_abs: bool) {
    let (xrows, _) = xr.as_chunks::<SPMM_COLS>();
    let stride = if with_abs { 2 * SPMM_COLS } else { SPMM_COLS };
    let task = |(t, chunk): (usize, &mut [f64])| {
        let rows = PanelRows {
            a,
            xrows,
            first: t * SPMM_ROWS_PER_TASK,
            out: chunk,
        };
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            return if with_abs {
                pulp::Simd::vectorize(simd, AbsKernel::<true>(rows))
            } else {
                pulp::Simd::vectorize(simd, AbsKernel::<false>(rows))
            };
        }
        if with_abs {
            rows.run::<true>()
        } else {
            rows.run::<false>()
        }
    };
    // Same fixed chunks either way (identical results); small products run on this thread,
    // where waking the rayon pool per call cost more than the product (measured on 2 cores).
    let chunks = out.chunks_mut(SPMM_ROWS_PER_TASK * stride).enumerate();
    if a.nrows() < SPMM_SEQ_BELOW {
        chunks.for_each(task);
    } else {
        out.par_chunks_mut(SPMM_ROWS_PER_TASK * stride)
            .enumerate()
            .for_each(task);
    }
}

/// One chunk of output rows of [`spmm_panel`], starting at row `first`.
struct PanelRows<'a> {
    a: &'a SparseColMat<usize, f64>,
    xrows: &'a [[f64; SPMM_COLS]],
    first: usize,
    out: &'a mut [f64],
}

/// [`PanelRows::run`] under `pulp` dispatch: AVX2 lanes, with the same operations per lane
/// and no fused products, so the same bits as the portable (SSE2) path, and faster
/// (docs/benchmarks.md, "Design measurements").
struct AbsKernel<'a, const ABS: bool>(PanelRows<'a>);

impl PanelRows<'_> {
    /// `out[i] = Σ_p a_ip · xr[row_p]` (and, with `ABS`, the absolute sums) for each row of
    /// the chunk, each a sequential sum in index order.
    #[inline(always)]
    fn run<const ABS: bool>(self) {
        const W: usize = SPMM_COLS;
        let (ptr, rows, vals) = (
            self.a.symbolic().col_ptr(),
            self.a.symbolic().row_idx(),
            self.a.val(),
        );
        let stride = if ABS { 2 * W } else { W };
        for (ri, o) in self.out.chunks_exact_mut(stride).enumerate() {
            let i = self.first + ri;
            let (p0, p1) = (ptr[i], ptr[i + 1]);
            let mut acc = [0.0f64; W];
            let mut acc_abs = [0.0f64; W];
            for (&r, &v) in rows[p0..p1].iter().zip(&vals[p0..p1]) {
                let xv = &self.xrows[r];
                for c in 0..W {
                    let t = v * xv[c];
                    acc[c] += t;
                    if ABS {
                        acc_abs[c] += t.abs();
                    }
                }
            }
            o[..W].copy_from_slice(&acc);
            if ABS {
                o[W..].copy_from_slice(&acc_abs);
            }
        }
    }
}

impl<const ABS: bool> pulp::WithSimd for AbsKernel<'_, ABS> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        self.0.run::<ABS>()
    }
}

/// Rows below which [`sym_spmm`] runs sequentially.
const SPMM_SEQ_BELOW: usize = 20_000;

/// `dst (+)= alpha · lhs · rhs` with faer's dense kernel, sequential.
///
/// The Lanczos products are tall and skinny (n × ≤ 100 against n × b, or n × ≤ 100 times a
/// small matrix), memory-bound, and faer 0.24.4's parallel path is much slower on them than
/// its sequential one (up to 20× on 2 cores at n = 108 900; docs/benchmarks.md, "Design measurements").
pub(crate) fn gemm(
    dst: MatMut<'_, f64>,
    accum: Accum,
    lhs: MatRef<'_, f64>,
    rhs: MatRef<'_, f64>,
    alpha: f64,
) {
    faer::linalg::matmul::matmul(dst, accum, lhs, rhs, alpha, Par::Seq);
}

/// Eigen-decomposition of a small symmetric matrix (both triangles filled): eigenvalues
/// ascending and the orthonormal eigenvectors. Sequential (bit-reproducible).
pub(crate) fn sym_eig(a: MatRef<'_, f64>) -> Result<(Vec<f64>, Mat<f64>), String> {
    sym_eig_with(a, Spec::default())
}

/// [`sym_eig`] by the implicit QR iteration on the tridiagonal form instead of divide and
/// conquer: slower, and backward stable to a few ε·‖A‖ where faer's divide and conquer left
/// ‖Aq − θq‖ ≈ 3e-12·‖A‖ (570-dof beam, shift-inverted), too much for the small eigenvalues
/// of a spectrum spanning 10⁶.
pub(crate) fn sym_eig_qr(a: MatRef<'_, f64>) -> Result<(Vec<f64>, Mat<f64>), String> {
    let mut p = <faer::linalg::evd::SelfAdjointEvdParams as faer::Auto<f64>>::auto();
    p.recursion_threshold = usize::MAX;
    sym_eig_with(a, Spec::new(p))
}

fn sym_eig_with(
    a: MatRef<'_, f64>,
    spec: Spec<faer::linalg::evd::SelfAdjointEvdParams, f64>,
) -> Result<(Vec<f64>, Mat<f64>), String> {
    let n = a.nrows();
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    let mut mem = MemBuffer::new(self_adjoint_evd_scratch::<f64>(
        n,
        ComputeEigenvectors::Yes,
        Par::Seq,
        spec,
    ));
    self_adjoint_evd(
        a,
        s.as_mut(),
        Some(u.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        spec,
    )
    .map_err(|e| format!("dense symmetric eigensolver failed: {e:?}"))?;
    let vals = (0..n).map(|i| s[i]).collect();
    Ok((vals, u))
}

/// In-place lower Cholesky of a small SPD matrix (upper part left as is). Returns the index of
/// the first pivot ≤ `rel_tol`·(original diagonal) on failure.
pub(crate) fn small_cholesky(mut a: MatMut<'_, f64>, rel_tol: f64) -> Result<(), usize> {
    let n = a.nrows();
    for j in 0..n {
        let orig = a[(j, j)];
        let mut d = orig;
        for k in 0..j {
            d -= a[(j, k)] * a[(j, k)];
        }
        let acceptable = d > rel_tol * orig.abs() && d.is_finite() && d > 0.0;
        if !acceptable {
            return Err(j);
        }
        let l = d.sqrt();
        a[(j, j)] = l;
        for i in j + 1..n {
            let mut s = a[(i, j)];
            for k in 0..j {
                s -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = s / l;
        }
    }
    Ok(())
}

/// Inverse of a small lower-triangular matrix (forward substitution on the identity).
pub(crate) fn lower_inverse(l: MatRef<'_, f64>) -> Mat<f64> {
    let n = l.nrows();
    let mut x = Mat::<f64>::zeros(n, n);
    for c in 0..n {
        for i in c..n {
            let mut s = if i == c { 1.0 } else { 0.0 };
            for k in c..i {
                s -= l[(i, k)] * x[(k, c)];
            }
            x[(i, c)] = s / l[(i, i)];
        }
    }
    x
}

/// The fixed-seed generator of the Lanczos start block and of an accuracy target's seeded
/// points (one definition, in the runtime).
pub use dcr_runtime::rng::SplitMix64;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::{assemble_clamped, Material};
    use crate::mesh::TetMesh;

    /// The products (whichever SIMD path runs) give, bit for bit, each output entry as the
    /// sequential sum over its row's stored entries in index order, and the absolute sums
    /// likewise: the order the determinism of the bake relies on. Widths around the panel
    /// width of 8 columns.
    #[test]
    fn sym_spmm_sums_each_row_in_index_order() {
        let mesh = TetMesh::structured_box([4, 3, 2], [1.0, 0.6, 0.4]);
        let mat = Material::new(2e11, 0.3, 7800.0).unwrap();
        let (_, k, m) = assemble_clamped(&mesh, &mat, false, &mesh.groups["xmin"]).unwrap();
        for a in [&k, &m] {
            let n = a.nrows();
            let (ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
            for w in [1, 5, 8, 9, 20] {
                let x =
                    Mat::<f64>::from_fn(n, w, |i, j| ((i * 31 + j * 17) % 13) as f64 / 7.0 - 0.9);
                let (mut y, mut ya, mut y1) =
                    (Mat::zeros(n, w), Mat::zeros(n, w), Mat::zeros(n, w));
                sym_spmm_with_abs(a, x.as_ref(), y.as_mut(), ya.as_mut());
                sym_spmm(a, x.as_ref(), y1.as_mut());
                for c in 0..w {
                    for i in 0..n {
                        let (mut s, mut sa) = (0.0f64, 0.0f64);
                        for p in ptr[i]..ptr[i + 1] {
                            let t = vals[p] * x[(rows[p], c)];
                            s += t;
                            sa += t.abs();
                        }
                        assert_eq!(y[(i, c)].to_bits(), s.to_bits(), "w {w}, ({i}, {c})");
                        assert_eq!(y1[(i, c)].to_bits(), s.to_bits(), "w {w}, ({i}, {c})");
                        assert_eq!(ya[(i, c)].to_bits(), sa.to_bits(), "w {w}, |.| ({i}, {c})");
                    }
                }
            }
        }
    }
}
