//! Block triangular solves x ← (LLᵀ)⁻¹ x on faer's supernodal Cholesky factor, with the
//! right-hand sides stored as a row-major *panel* (the w ≤ 8 entries of one row side by side).
//!
//! Why not faer's own `solve_in_place` (which the rest of the crate still uses for single
//! vectors and wide blocks): for a few right-hand sides it runs, per supernode, a dense GEMM
//! that packs the supernode's rows below and then scatters the product column by column, and
//! ends up 2–3× above one pass over the factor's memory. Measured on the bake bench beams
//! (faer 0.24.4), 6 right-hand sides: 13.5k dofs (4.8 M factor entries) faer 21–30 ms, one
//! right-hand side 11–13 ms; 109k dofs (54 M entries) faer with two threads 250–350 ms, one
//! right-hand side 120 ms. Here each factor entry is loaded once per solve and multiplies a
//! row of w values held in SIMD registers; the columns of a supernode are taken in passes of
//! [`PASS`], so each indexed row of x is loaded and stored once per pass rather than once per
//! factor column. Same measurements with this solve, one thread: 13.5k 17–18 ms, 109k
//! 185–205 ms; at 3.5k dofs (0.6 M entries, cache-resident) it only matches faer (2.0 vs
//! 1.8 ms). In the bake bench's 13.5k eigensolve (interleaved runs, 18 solves): 0.50 s vs
//! 0.58 s (fastest of 7), 0.55 s vs 0.62 s (median).
//!
//! Determinism: sequential, every sum in a fixed order; each right-hand side (lane) sees the
//! same operations whatever w or the SIMD width, so the results do not depend on how the
//! columns are grouped into panels. With FMA available (x86-64 AVX2+FMA, detected at run time)
//! products are fused; machines without it round differently (as for faer, whose kernels
//! also dispatch on the CPU).

use faer::sparse::linalg::cholesky::supernodal::{SupernodalLltRef, SymbolicSupernodalCholesky};

/// Factor columns per pass over the rows below a supernode.
const PASS: usize = 8;

/// Panel widths (right-hand sides per pass over the factor) this solve is used for; wider
/// blocks go to faer, whose packed GEMM is the faster one there (measured at 13.5k and 109k
/// dofs: 20 right-hand sides 49 vs 34 ms and 617 vs 464 ms, as two panels of 10).
pub(crate) const PANEL_WIDTHS: std::ops::RangeInclusive<usize> = 2..=8;

/// One supernode: columns `start..start + ncols` of L, stored column-major with leading
/// dimension `ncols + pattern.len()` at `values[offset..]`; `rows` is the range of its pattern
/// (row indices below the diagonal block) in [`PanelSolve::row_idx`].
#[derive(Clone, Copy, Debug)]
struct Supernode {
    start: usize,
    ncols: usize,
    offset: usize,
    rows: (usize, usize),
}

/// The supernode layout of a faer supernodal LLᵀ factor and the reciprocals of its diagonal,
/// for [`PanelSolve::solve`].
pub(crate) struct PanelSolve {
    supernodes: Vec<Supernode>,
    row_idx: Vec<usize>,
    inv_diag: Vec<f64>,
}

impl PanelSolve {
    /// Layout of the factor `values` on the supernodal symbolic structure `sym`.
    pub fn new(sym: &SymbolicSupernodalCholesky<usize>, values: &[f64]) -> PanelSolve {
        let llt = SupernodalLltRef::new(sym, values);
        let ns = sym.n_supernodes();
        let mut supernodes = Vec::with_capacity(ns);
        let mut row_idx = Vec::new();
        let mut inv_diag = vec![0.0; sym.nrows()];
        for (s, &offset) in sym.col_ptr_for_val()[..ns].iter().enumerate() {
            let node = llt.supernode(s);
            let l = node.val();
            let (start, ncols) = (node.start(), l.ncols());
            let r0 = row_idx.len();
            row_idx.extend_from_slice(node.pattern());
            for j in 0..ncols {
                inv_diag[start + j] = 1.0 / l[(j, j)];
            }
            supernodes.push(Supernode {
                start,
                ncols,
                offset,
                rows: (r0, row_idx.len()),
            });
        }
        PanelSolve {
            supernodes,
            row_idx,
            inv_diag,
        }
    }

    /// `x ← (LLᵀ)⁻¹ x` for a row-major panel `x` (n rows of `w` values, 1 ≤ `w` ≤ 8) in the
    /// factor's (permuted) order; `values` are the factor's values given to [`Self::new`].
    pub fn solve(&self, values: &[f64], x: &mut [f64], w: usize) {
        assert!((1..=8).contains(&w) && x.len() == w * self.inv_diag.len());
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            return pulp::Simd::vectorize(
                simd,
                SolveKernel {
                    solver: self,
                    values,
                    x,
                    w,
                },
            );
        }
        self.solve_dispatch::<false>(values, x, w);
    }

    #[inline(always)]
    fn solve_dispatch<const FMA: bool>(&self, values: &[f64], x: &mut [f64], w: usize) {
        macro_rules! go {
            ($w:literal) => {
                self.solve_w::<$w, FMA>(values, x.as_chunks_mut::<$w>().0)
            };
        }
        match w {
            1 => go!(1),
            2 => go!(2),
            3 => go!(3),
            4 => go!(4),
            5 => go!(5),
            6 => go!(6),
            7 => go!(7),
            _ => go!(8),
        }
    }

    #[inline(always)]
    fn solve_w<const W: usize, const FMA: bool>(&self, l: &[f64], x: &mut [[f64; W]]) {
        let inv = &self.inv_diag;
        // L y = b, supernodes in order; each in passes of PASS columns: the small triangle of
        // the pass, then every row below it in the supernode (the rest of the diagonal block,
        // then the pattern rows), one load and store of each x row per pass.
        for sn in &self.supernodes {
            let (c0, nc) = (sn.start, sn.ncols);
            let rows = &self.row_idx[sn.rows.0..sn.rows.1];
            let ld = nc + rows.len();
            let col = |j: usize| &l[sn.offset + j * ld..sn.offset + (j + 1) * ld];
            for j0 in (0..nc).step_by(PASS) {
                let m = PASS.min(nc - j0);
                for j in j0..j0 + m {
                    let c = col(j);
                    let xj = scale(x[c0 + j], inv[c0 + j]);
                    x[c0 + j] = xj;
                    for i in j + 1..j0 + m {
                        axpy::<W, FMA>(&mut x[c0 + i], -c[i], &xj);
                    }
                }
                let xs: [[f64; W]; PASS] =
                    std::array::from_fn(|t| if t < m { x[c0 + j0 + t] } else { [0.0; W] });
                let cols: [&[f64]; PASS] =
                    std::array::from_fn(|t| if t < m { &col(j0 + t)[j0 + m..] } else { &[] });
                let targets = (c0 + j0 + m..c0 + nc).chain(rows.iter().copied());
                if m == PASS {
                    for (r, i) in targets.enumerate() {
                        x[i] = update_row::<W, PASS, FMA>(x[i], &cols, r, &xs);
                    }
                } else {
                    for (r, i) in targets.enumerate() {
                        x[i] = update_row_dyn::<W, FMA>(x[i], &cols[..m], r, &xs[..m]);
                    }
                }
            }
        }
        // Lᵀ z = y, supernodes in reverse order, passes last first: the dot products of the
        // pass's columns with every row below its triangle, then the triangle.
        for sn in self.supernodes.iter().rev() {
            let (c0, nc) = (sn.start, sn.ncols);
            let rows = &self.row_idx[sn.rows.0..sn.rows.1];
            let ld = nc + rows.len();
            let col = |j: usize| &l[sn.offset + j * ld..sn.offset + (j + 1) * ld];
            let passes = nc.div_ceil(PASS);
            for p in (0..passes).rev() {
                let j0 = p * PASS;
                let m = PASS.min(nc - j0);
                let cols: [&[f64]; PASS] =
                    std::array::from_fn(|t| if t < m { &col(j0 + t)[j0 + m..] } else { &[] });
                let mut acc = [[0.0f64; W]; PASS];
                let targets = (c0 + j0 + m..c0 + nc).chain(rows.iter().copied());
                if m == PASS {
                    for (r, i) in targets.enumerate() {
                        let xi = x[i];
                        for t in 0..PASS {
                            axpy::<W, FMA>(&mut acc[t], cols[t][r], &xi);
                        }
                    }
                } else {
                    for (r, i) in targets.enumerate() {
                        let xi = x[i];
                        for t in 0..m {
                            axpy::<W, FMA>(&mut acc[t], cols[t][r], &xi);
                        }
                    }
                }
                for j in (j0..j0 + m).rev() {
                    let c = col(j);
                    let mut xj = x[c0 + j];
                    for cidx in 0..W {
                        xj[cidx] -= acc[j - j0][cidx];
                    }
                    for i in j + 1..j0 + m {
                        axpy::<W, FMA>(&mut xj, -c[i], &x[c0 + i]);
                    }
                    x[c0 + j] = scale(xj, inv[c0 + j]);
                }
            }
        }
    }
}

/// `x_i − Σ_t cols[t][r]·xs[t]` for one row (PASS columns; two partial sums for FMA latency).
#[inline(always)]
fn update_row<const W: usize, const P: usize, const FMA: bool>(
    xi: [f64; W],
    cols: &[&[f64]; P],
    r: usize,
    xs: &[[f64; W]; P],
) -> [f64; W] {
    let mut a = xi;
    let mut b = [0.0f64; W];
    for t in (0..P).step_by(2) {
        axpy::<W, FMA>(&mut a, -cols[t][r], &xs[t]);
        if t + 1 < P {
            axpy::<W, FMA>(&mut b, -cols[t + 1][r], &xs[t + 1]);
        }
    }
    std::array::from_fn(|c| a[c] + b[c])
}

/// [`update_row`] for a pass of fewer than PASS columns.
#[inline(always)]
fn update_row_dyn<const W: usize, const FMA: bool>(
    xi: [f64; W],
    cols: &[&[f64]],
    r: usize,
    xs: &[[f64; W]],
) -> [f64; W] {
    let mut a = xi;
    let mut b = [0.0f64; W];
    for t in (0..cols.len()).step_by(2) {
        axpy::<W, FMA>(&mut a, -cols[t][r], &xs[t]);
        if t + 1 < cols.len() {
            axpy::<W, FMA>(&mut b, -cols[t + 1][r], &xs[t + 1]);
        }
    }
    std::array::from_fn(|c| a[c] + b[c])
}

/// [`PanelSolve::solve`]'s arguments, run under `pulp` dispatch (AVX2 + FMA).
struct SolveKernel<'a> {
    solver: &'a PanelSolve,
    values: &'a [f64],
    x: &'a mut [f64],
    w: usize,
}

impl pulp::WithSimd for SolveKernel<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        self.solver
            .solve_dispatch::<true>(self.values, self.x, self.w);
    }
}

/// `a ← a + s·b` lane by lane (fused when `FMA`).
#[inline(always)]
fn axpy<const W: usize, const FMA: bool>(a: &mut [f64; W], s: f64, b: &[f64; W]) {
    for c in 0..W {
        a[c] = if FMA {
            s.mul_add(b[c], a[c])
        } else {
            a[c] + s * b[c]
        };
    }
}

#[inline(always)]
fn scale<const W: usize>(a: [f64; W], s: f64) -> [f64; W] {
    a.map(|v| v * s)
}
