//! Simplicial sparse LLᵀ on a pattern from faer's symbolic analysis: the numeric factors of two
//! matrices with that pattern in one sweep, and the triangular solves.
//!
//! Hand-written rather than faer's `factorize_numeric_llt` / `LltRef::solve_in_place_with_conj`
//! (which these replaced) because faer could not reach the heat-geodesic targets on ~5k-vertex
//! surfaces (issue #3): its simplicial numeric factor (up-looking, one elimination-tree reach per
//! row, `usize` indices) took ≈ 8 ms per operator, its solve ≈ 0.3 ms. Here the pattern is known
//! up front, so the factor is left-looking over a precomputed row pattern (each update a plain
//! suffix of an earlier column), both operators share every index load (values stored as
//! `[heat, poisson]` pairs), and all indices are `u32`.

use crate::math::fmadd;

/// Lower-triangular CSC pattern of the factor (rows ascending, diagonal first in each column),
/// plus its row-wise transpose grouped by supernode for the left-looking factorisation.
pub(super) struct Pattern {
    pub(super) col_ptr: Vec<u32>,
    pub(super) row_idx: Vec<u32>,
    /// Row j's off-diagonal entries L_jk (k < j) as runs of consecutive columns of one
    /// (fundamental) supernode, which share their rows from j down:
    /// `runs[run_ptr[j]..run_ptr[j + 1]]`, per run `[k, m, p]`: first column, m ≤ [`MAX_RUN`]
    /// columns, position of L_jk in `row_idx`.
    run_ptr: Vec<u32>,
    runs: Vec<[u32; 3]>,
}

/// Longest run of supernode columns one update pass combines.
const MAX_RUN: u32 = 8;

impl Pattern {
    pub(super) fn new(col_ptr: Vec<u32>, row_idx: Vec<u32>) -> Self {
        let n = col_ptr.len() - 1;
        let (cp, ri) = (&col_ptr, &row_idx);
        let len = |k: usize| cp[k + 1] - cp[k];
        // Fundamental supernodes [k0, k1]: struct(k) = {k} ∪ struct(k + 1) inside.
        let mut supernodes = Vec::new();
        let mut k0 = 0;
        for k in 0..n {
            let continues = k + 1 < n
                && len(k) >= 2
                && ri[cp[k] as usize + 1] as usize == k + 1
                && len(k) == len(k + 1) + 1;
            if !continues {
                supernodes.push((k0, k));
                k0 = k + 1;
            }
        }
        // Rows below a supernode's last column; rows inside it see only the earlier columns.
        let below = |k1: usize| &ri[cp[k1] as usize + 1..cp[k1 + 1] as usize];
        let mut run_ptr = vec![0u32; n + 1];
        for &(k0, k1) in &supernodes {
            for j in k0 + 1..=k1 {
                run_ptr[j + 1] += ((j - k0) as u32).div_ceil(MAX_RUN);
            }
            let s = (k1 - k0 + 1) as u32;
            for &j in below(k1) {
                run_ptr[j as usize + 1] += s.div_ceil(MAX_RUN);
            }
        }
        for j in 0..n {
            run_ptr[j + 1] += run_ptr[j];
        }
        let mut next: Vec<u32> = run_ptr[..n].to_vec();
        let mut runs = vec![[0u32; 3]; run_ptr[n] as usize];
        let mut push = |j: usize, k: usize, end: usize, p: u32| {
            runs[next[j] as usize] = [k as u32, (end - k) as u32, p];
            next[j] += 1;
        };
        for &(k0, k1) in &supernodes {
            for j in k0 + 1..=k1 {
                for k in (k0..j).step_by(MAX_RUN as usize) {
                    push(j, k, j.min(k + MAX_RUN as usize), cp[k] + (j - k) as u32);
                }
            }
            for (r, &j) in below(k1).iter().enumerate() {
                for k in (k0..=k1).step_by(MAX_RUN as usize) {
                    let p = cp[k] + (k1 - k + 1 + r) as u32;
                    push(j as usize, k, (k1 + 1).min(k + MAX_RUN as usize), p);
                }
            }
        }
        Pattern {
            col_ptr,
            row_idx,
            run_ptr,
            runs,
        }
    }

    pub(super) fn n(&self) -> usize {
        self.col_ptr.len() - 1
    }

    /// Position of entry (row, col) (row ≥ col, in the pattern) in `row_idx`.
    pub(super) fn position(&self, row: u32, col: u32) -> usize {
        let start = self.col_ptr[col as usize] as usize;
        let rows = &self.row_idx[start..self.col_ptr[col as usize + 1] as usize];
        start
            + rows
                .binary_search(&row)
                .expect("entry in the factor pattern")
    }

    /// In place: `vals` holds the lower triangles of two matrices A₀, A₁ (pairs per entry,
    /// zeros on fill) and becomes their Cholesky factors. Left-looking: column j gathers the
    /// updates −L_jk · L_{j:,k} from the columns k of row j's pattern into a dense scatter
    /// workspace (`w`, length n), then scales by the pivot. Columns of one supernode share their
    /// rows, so up to [`MAX_RUN`] of them update `w` in one pass (one index load and one
    /// read-modify-write of `w` per row instead of one per column).
    ///
    /// # Errors
    /// The first column whose pivot is not positive (either matrix).
    pub(super) fn factor_pair(
        &self,
        vals: &mut [[f64; 2]],
        w: &mut [[f64; 2]],
    ) -> Result<(), usize> {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            // Through `WithSimd` (as the peak kernel): compiled with AVX2/FMA.
            return pulp::Simd::vectorize(
                simd,
                FactorKernel {
                    pattern: self,
                    vals,
                    w,
                },
            );
        }
        self.factor_pair_impl::<false>(vals, w)
    }

    #[inline(always)]
    fn factor_pair_impl<const FMA: bool>(
        &self,
        vals: &mut [[f64; 2]],
        w: &mut [[f64; 2]],
    ) -> Result<(), usize> {
        let (cp, ri) = (&self.col_ptr, &self.row_idx);
        for j in 0..self.n() {
            let (start, end) = (cp[j] as usize, cp[j + 1] as usize);
            for (&i, &v) in ri[start..end].iter().zip(&vals[start..end]) {
                w[i as usize] = v;
            }
            for &[k, m, p] in &self.runs[self.run_ptr[j] as usize..self.run_ptr[j + 1] as usize] {
                let (k, m, p) = (k as usize, m as usize, p as usize);
                let rows = &ri[p..cp[k + 1] as usize];
                // Row j sits one entry further from the top in each earlier supernode column.
                let mut ps = [p; MAX_RUN as usize];
                for i in 1..m {
                    ps[i] = ps[i - 1] + (cp[k + i] - cp[k + i - 1]) as usize - 1;
                }
                match m {
                    1 => update::<1, FMA>(rows, &ps, vals, w),
                    2 => update::<2, FMA>(rows, &ps, vals, w),
                    3 => update::<3, FMA>(rows, &ps, vals, w),
                    4 => update::<4, FMA>(rows, &ps, vals, w),
                    5 => update::<5, FMA>(rows, &ps, vals, w),
                    6 => update::<6, FMA>(rows, &ps, vals, w),
                    7 => update::<7, FMA>(rows, &ps, vals, w),
                    _ => update::<{ MAX_RUN as usize }, FMA>(rows, &ps, vals, w),
                }
            }
            let d = w[j];
            if !(d[0] > 0.0 && d[1] > 0.0) {
                return Err(j);
            }
            let d = [d[0].sqrt(), d[1].sqrt()];
            let inv = [1.0 / d[0], 1.0 / d[1]];
            vals[start] = d;
            for (&i, v) in ri[start + 1..end].iter().zip(&mut vals[start + 1..end]) {
                let wi = w[i as usize];
                *v = [wi[0] * inv[0], wi[1] * inv[1]];
            }
        }
        Ok(())
    }

    /// `x ← A⁻¹ x` for A = L Lᵀ (x in the factor's order).
    ///
    /// The forward sweep skips columns whose entry is still zero, so a right-hand side with a
    /// few non-zeros only walks their elimination-tree ancestors. Column axpy forward, row dot
    /// backward (summed in four partial sums, so results differ from faer's in the last bits).
    pub(super) fn solve(&self, l: &[f64], x: &mut [f64]) {
        let (cp, ri) = (&self.col_ptr, &self.row_idx);
        // L y = b, column by column (diagonal first in each column).
        for j in 0..self.n() {
            let (start, end) = (cp[j] as usize, cp[j + 1] as usize);
            let yj = x[j];
            if yj == 0.0 {
                continue;
            }
            let yj = yj / l[start];
            x[j] = yj;
            for (&i, &lij) in ri[start + 1..end].iter().zip(&l[start + 1..end]) {
                x[i as usize] -= lij * yj;
            }
        }
        // Lᵀ z = y, last row first. The column dot products use four partial sums: one chain
        // would be bound by add latency (≈ 23 entries per column on ~5k-vertex surfaces).
        for j in (0..self.n()).rev() {
            let (start, end) = (cp[j] as usize, cp[j + 1] as usize);
            let (ri, lj) = (&ri[start + 1..end], &l[start + 1..end]);
            let mut acc = [0.0f64; 4];
            let mut ri4 = ri.chunks_exact(4);
            let mut lj4 = lj.chunks_exact(4);
            for (i4, l4) in (&mut ri4).zip(&mut lj4) {
                for k in 0..4 {
                    acc[k] += l4[k] * x[i4[k] as usize];
                }
            }
            for (&i, &lij) in ri4.remainder().iter().zip(lj4.remainder()) {
                acc[0] += lij * x[i as usize];
            }
            x[j] = (x[j] - ((acc[0] + acc[1]) + (acc[2] + acc[3]))) / l[start];
        }
    }
}

/// `w[rows[q]] −= Σ_m L[p_m + q] · L[p_m]` for M columns of one supernode whose entries of row
/// j sit at positions `ps` (pairs: both matrices at once).
#[inline(always)]
fn update<const M: usize, const FMA: bool>(
    rows: &[u32],
    ps: &[usize],
    vals: &[[f64; 2]],
    w: &mut [[f64; 2]],
) {
    let len = rows.len();
    let cols: [&[[f64; 2]]; M] = std::array::from_fn(|m| &vals[ps[m]..ps[m] + len]);
    let ljk: [[f64; 2]; M] = std::array::from_fn(|m| cols[m][0]);
    for (q, &i) in rows.iter().enumerate() {
        let mut s = [0.0f64; 2];
        for m in 0..M {
            let l = cols[m][q];
            s[0] = fmadd::<FMA>(l[0], ljk[m][0], s[0]);
            s[1] = fmadd::<FMA>(l[1], ljk[m][1], s[1]);
        }
        let wi = &mut w[i as usize];
        wi[0] -= s[0];
        wi[1] -= s[1];
    }
}

/// [`Pattern::factor_pair`]'s arguments, run under `pulp` dispatch.
struct FactorKernel<'a> {
    pattern: &'a Pattern,
    vals: &'a mut [[f64; 2]],
    w: &'a mut [[f64; 2]],
}

impl pulp::WithSimd for FactorKernel<'_> {
    type Output = Result<(), usize>;
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Self::Output {
        self.pattern.factor_pair_impl::<true>(self.vals, self.w)
    }
}
