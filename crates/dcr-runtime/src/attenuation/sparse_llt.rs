//! Simplicial sparse LLᵀ on a pattern from faer's symbolic analysis: the numeric factors of two
//! matrices with that pattern in one sweep, and the triangular solves, run per [`Part`] of a
//! [`Layout`] (the elimination tree's two halves and the chain above them, when the order
//! splits) so the halves can be solved on two threads.
//!
//! Why hand-written rather than faer's sparse Cholesky (`factorize_numeric_llt`,
//! `LltRef::solve_in_place_with_conj`), the well-kept alternative: measured on the geodesic
//! systems of the committed and scene bases (`cargo bench --workspace --bench sparse_llt`,
//! figures in docs/benchmarks.md, "The heat method's sparse Cholesky"), setting up both
//! operators here costs well under faer's numeric factorisation of them — on faer's simplicial
//! analysis and under faer's own choice, which stays simplicial on these surfaces — because the
//! pattern is known up front: the factor is left-looking over a precomputed row pattern (each
//! update a plain suffix of an earlier column), both operators share every index load (values
//! stored as `[heat, poisson]` pairs), and all indices are `u32`. The set-up is paid per
//! object at load. A full serial solve is not faster than faer's on the larger surfaces; a
//! query does not run one, though: it sweeps the two halves of [`Layout`] on two threads and,
//! for a point source, only the source's ancestors forward, which faer's solve does not offer.

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
    /// Fundamental supernodes: columns `sn_ptr[s]..sn_ptr[s + 1]`.
    sn_ptr: Vec<u32>,
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
        let sn_ptr = std::iter::once(0)
            .chain(supernodes.iter().map(|&(_, k1)| k1 as u32 + 1))
            .collect();
        Pattern {
            col_ptr,
            row_idx,
            run_ptr,
            runs,
            sn_ptr,
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

    /// The elimination tree's split into two subtrees and the chain above them, for solves on
    /// two threads: `Some((a, t0))` when columns [0, a) and [a, t0) are two unions of whole
    /// subtrees (so no entry couples them), [t0, n) is the chain of single-child ancestors
    /// above both, and each side holds at least a quarter of the entries. Nested dissection
    /// gives this (each half's columns contiguous, the top separator last); an order that does
    /// not (AMD, tiny or lopsided surfaces) gives `None`.
    fn two_subtrees(&self) -> Option<(usize, usize)> {
        let (n, cp, ri) = (self.n(), &self.col_ptr, &self.row_idx);
        let parent = |k: usize| (cp[k + 1] - cp[k] > 1).then(|| ri[cp[k] as usize + 1] as usize);
        let mut desc = vec![1usize; n];
        let mut children = vec![0u32; n];
        let mut roots = 0;
        for k in 0..n {
            match parent(k) {
                Some(p) => {
                    desc[p] += desc[k];
                    children[p] += 1;
                }
                None => roots += 1,
            }
        }
        // Down the single-child chain from the root; a forest splits at its roots.
        let mut t0 = n;
        if roots == 1 {
            t0 = n - 1;
            while children[t0] == 1 && t0 > 0 && parent(t0 - 1) == Some(t0) {
                t0 -= 1;
            }
            if children[t0] < 2 {
                return None;
            }
        }
        // The subtrees hanging from [t0, n) must tile [0, t0), each contiguous (last child
        // first); their boundaries are the candidate splits.
        let mut bounds = Vec::new();
        let mut end = t0;
        while end > 0 {
            let c = end - 1;
            if parent(c).is_some_and(|p| p < t0) || desc[c] > end {
                return None;
            }
            end -= desc[c];
            bounds.push(end);
        }
        let below = cp[t0] as usize;
        let a = bounds[..bounds.len() - 1]
            .iter()
            .copied()
            .min_by_key(|&a| (cp[a] as usize).max(below - cp[a] as usize))?;
        let smaller = (cp[a] as usize).min(below - cp[a] as usize);
        // What the split solves rely on, checked outright (the subtree sizes above assume a
        // postorder): no column of [0, a) has a row in [a, t0).
        let coupled = ri[..cp[a] as usize]
            .iter()
            .any(|&i| (a..t0).contains(&(i as usize)));
        (4 * smaller >= cp[n] as usize && !coupled).then_some((a, t0))
    }
}

/// A run of consecutive factor columns [c0, c1) with its own copy of the pattern in local
/// numbering: own rows at i − c0, rows of the top block [t0, n) at (c1 − c0) + (i − t0).
pub(super) struct Part {
    cols: std::ops::Range<usize>,
    vals: std::ops::Range<usize>,
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    sn_ptr: Vec<u32>,
}

impl Part {
    fn new(p: &Pattern, c0: usize, c1: usize, t0: usize) -> Self {
        let (v0, v1) = (p.col_ptr[c0], p.col_ptr[c1]);
        let col_ptr = p.col_ptr[c0..=c1].iter().map(|&q| q - v0).collect();
        let row_idx = p.row_idx[v0 as usize..v1 as usize]
            .iter()
            .map(|&i| {
                let i = i as usize;
                let local = if i < c1 { i - c0 } else { c1 - c0 + (i - t0) };
                local as u32
            })
            .collect();
        // Global supernodes cut at the run's ends (any run of a supernode's columns is one).
        let sn_ptr = std::iter::once(0)
            .chain(
                p.sn_ptr
                    .iter()
                    .map(|&k| k as usize)
                    .filter(|&k| k > c0 && k < c1)
                    .map(|k| (k - c0) as u32),
            )
            .chain(std::iter::once((c1 - c0) as u32))
            .collect();
        Part {
            cols: c0..c1,
            vals: v0 as usize..v1 as usize,
            col_ptr,
            row_idx,
            sn_ptr,
        }
    }

    /// Number of columns.
    pub(super) fn len(&self) -> usize {
        self.cols.len()
    }

    /// One sweep of the run on `x` (its local vector); `l`, `inv_diag`: the whole factor's.
    pub(super) fn sweep(&self, dir: Direction, l: &[f64], inv_diag: &[f64], x: &mut [f64]) {
        let sweep = Sweep {
            col_ptr: &self.col_ptr,
            row_idx: &self.row_idx,
            sn_ptr: &self.sn_ptr,
        };
        sweep.run(dir, &l[self.vals.clone()], &inv_diag[self.cols.clone()], x);
    }
}

/// How the solves lay out a vector: with a [`Pattern::two_subtrees`] split, the storage is
/// `[half 0 | copy of top | half 1 | copy of top | top]`, so each half sweeps its own
/// contiguous slice (own rows, then the top block's rows, which its forward sweep accumulates
/// into and its backward sweep reads) and the two halves can run on two threads; the copies
/// are merged into / refreshed from the top block in between, in a fixed order, so one and two
/// threads give the same bits. Without a split, the storage is the factor order itself.
pub(super) struct Layout {
    pub(super) halves: Option<[Part; 2]>,
    pub(super) top: Part,
}

impl Layout {
    pub(super) fn new(p: &Pattern) -> Self {
        let n = p.n();
        match p.two_subtrees() {
            Some((a, t0)) => Layout {
                halves: Some([Part::new(p, 0, a, t0), Part::new(p, a, t0, t0)]),
                top: Part::new(p, t0, n, t0),
            },
            None => Layout {
                halves: None,
                top: Part::new(p, 0, n, 0),
            },
        }
    }

    /// Storage length: n, plus two copies of the top block with a split.
    pub(super) fn len(&self) -> usize {
        let nt = self.top.len();
        match &self.halves {
            Some([h0, h1]) => h0.len() + h1.len() + 3 * nt,
            None => nt,
        }
    }

    /// Storage position of factor row k.
    pub(super) fn position(&self, k: usize) -> usize {
        let nt = self.top.len();
        match &self.halves {
            Some([h0, _]) if k < h0.cols.end => k,
            Some([_, h1]) if k < h1.cols.end => nt + k,
            Some(_) => 2 * nt + k,
            None => k,
        }
    }

    /// Storage position of factor row k as seen by the part that `group` names (0, 1: the
    /// halves, 2: the top block), whose local vector starts at its own offset.
    pub(super) fn local_position(&self, group: usize, k: usize) -> usize {
        match (&self.halves, group) {
            (Some(h), 0 | 1) => {
                let part = &h[group];
                if part.cols.contains(&k) {
                    k - part.cols.start
                } else {
                    part.len() + (k - self.top.cols.start)
                }
            }
            _ => k - self.top.cols.start,
        }
    }

    /// The group (0, 1: halves; 2: top block) holding factor row k.
    pub(super) fn group(&self, k: usize) -> usize {
        match &self.halves {
            Some([h0, _]) if k < h0.cols.end => 0,
            Some([_, h1]) if k < h1.cols.end => 1,
            _ => 2,
        }
    }

    /// `x ← A⁻¹ x` for A = L Lᵀ, x in storage order (`l`, `inv_diag` = 1/L_kk: the whole
    /// factor's): every step of a query's solve in one serial call, for tests and the
    /// `sparse_llt` benchmark.
    #[cfg(any(test, feature = "bench-internals"))]
    pub(super) fn solve(&self, l: &[f64], inv_diag: &[f64], x: &mut [f64]) {
        let (halves, xt) = self.split_mut(x);
        if let (Some(parts), Some([x0, x1])) = (&self.halves, halves) {
            let (n0, n1) = (parts[0].len(), parts[1].len());
            parts[0].sweep(Direction::Forward, l, inv_diag, x0);
            parts[1].sweep(Direction::Forward, l, inv_diag, x1);
            merge_top(xt, &x0[n0..], &x1[n1..]);
            self.top.sweep(Direction::Forward, l, inv_diag, xt);
            self.top.sweep(Direction::Backward, l, inv_diag, xt);
            x0[n0..].copy_from_slice(xt);
            x1[n1..].copy_from_slice(xt);
            parts[0].sweep(Direction::Backward, l, inv_diag, x0);
            parts[1].sweep(Direction::Backward, l, inv_diag, x1);
        } else {
            self.top.sweep(Direction::Forward, l, inv_diag, xt);
            self.top.sweep(Direction::Backward, l, inv_diag, xt);
        }
    }

    /// Whether the solves split into two halves.
    pub(super) fn is_split(&self) -> bool {
        self.halves.is_some()
    }

    /// Splits a storage vector into the halves' slices and the top block.
    pub(super) fn split_mut<'a>(
        &self,
        x: &'a mut [f64],
    ) -> (Option<[&'a mut [f64]; 2]>, &'a mut [f64]) {
        let nt = self.top.len();
        match &self.halves {
            Some([h0, h1]) => {
                let (x0, rest) = x.split_at_mut(h0.len() + nt);
                let (x1, xt) = rest.split_at_mut(h1.len() + nt);
                (Some([x0, x1]), xt)
            }
            None => (None, x),
        }
    }
}

/// `top[i] += c0[i] + c1[i]`: the halves' contributions to the top block (or, for the
/// divergence, the halves' faces'), in a fixed order.
pub(super) fn merge_top(top: &mut [f64], c0: &[f64], c1: &[f64]) {
    for ((t, &a), &b) in top.iter_mut().zip(c0).zip(c1) {
        *t += a + b;
    }
}

/// Which triangular sweep: L y = b (forward) or Lᵀ z = y (backward).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Direction {
    Forward,
    Backward,
}

/// A run of consecutive factor columns in local numbering: their column pointers from 0, row
/// indices as positions in the vector the sweep works on, supernode boundaries.
#[derive(Clone, Copy)]
struct Sweep<'a> {
    col_ptr: &'a [u32],
    row_idx: &'a [u32],
    sn_ptr: &'a [u32],
}

impl Sweep<'_> {
    /// One sweep on `x` (`l`, `inv_diag` = 1/L_kk: this run's values), under `pulp` dispatch.
    fn run(self, dir: Direction, l: &[f64], inv_diag: &[f64], x: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            return pulp::Simd::vectorize(
                simd,
                SweepKernel {
                    sweep: self,
                    dir,
                    l,
                    inv_diag,
                    x,
                },
            );
        }
        self.run_impl::<false>(dir, l, inv_diag, x);
    }

    #[inline(always)]
    fn run_impl<const FMA: bool>(self, dir: Direction, l: &[f64], inv_diag: &[f64], x: &mut [f64]) {
        match dir {
            Direction::Forward => self.forward::<FMA>(l, inv_diag, x),
            Direction::Backward => self.backward::<FMA>(l, inv_diag, x),
        }
    }

    /// L y = b, supernode by supernode: the dense triangle of its diagonal block on contiguous
    /// x, then its rows below in passes of up to [`MAX_RUN`] columns (one index load and one x
    /// access per row and pass instead of per entry). Skips supernodes whose entries are still
    /// zero, so a right-hand side with a few non-zeros only walks their elimination-tree
    /// ancestors.
    #[inline(always)]
    fn forward<const FMA: bool>(self, l: &[f64], inv_diag: &[f64], x: &mut [f64]) {
        let (cp, ri) = (self.col_ptr, self.row_idx);
        let ns = self.sn_ptr.len() - 1;
        // Column k of supernode [k0, k1]: L_kk, the block rows k+1..=k1, then the rows below.
        let block = |k: usize, k1: usize| cp[k] as usize + 1..cp[k] as usize + 1 + (k1 - k);
        let below_start = |k: usize, k1: usize| cp[k] as usize + 1 + (k1 - k);
        for s in 0..ns {
            let (k0, k1) = (self.sn_ptr[s] as usize, self.sn_ptr[s + 1] as usize - 1);
            if k0 == k1 {
                // A lone column (most supernodes): plain column axpy.
                let (start, end) = (cp[k0] as usize, cp[k0 + 1] as usize);
                if x[k0] == 0.0 {
                    continue;
                }
                let xk = x[k0] * inv_diag[k0];
                x[k0] = xk;
                for (&i, &lv) in ri[start + 1..end].iter().zip(&l[start + 1..end]) {
                    let xi = &mut x[i as usize];
                    *xi = fmadd::<FMA>(-lv, xk, *xi);
                }
                continue;
            }
            if x[k0..=k1].iter().all(|&v| v == 0.0) {
                continue;
            }
            for k in k0..=k1 {
                let xk = x[k] * inv_diag[k];
                x[k] = xk;
                for (xi, &lv) in x[k + 1..=k1].iter_mut().zip(&l[block(k, k1)]) {
                    *xi = fmadd::<FMA>(-lv, xk, *xi);
                }
            }
            let rows = &ri[below_start(k1, k1)..cp[k1 + 1] as usize];
            if rows.is_empty() {
                continue;
            }
            for ka in (k0..=k1).step_by(MAX_RUN as usize) {
                let m = (k1 + 1 - ka).min(MAX_RUN as usize);
                let mut offs = [0usize; MAX_RUN as usize];
                let mut xs = [0.0f64; MAX_RUN as usize];
                for i in 0..m {
                    offs[i] = below_start(ka + i, k1);
                    xs[i] = x[ka + i];
                }
                match m {
                    1 => forward_below::<1, FMA>(rows, &offs, &xs, l, x),
                    2 => forward_below::<2, FMA>(rows, &offs, &xs, l, x),
                    3 => forward_below::<3, FMA>(rows, &offs, &xs, l, x),
                    4 => forward_below::<4, FMA>(rows, &offs, &xs, l, x),
                    5 => forward_below::<5, FMA>(rows, &offs, &xs, l, x),
                    6 => forward_below::<6, FMA>(rows, &offs, &xs, l, x),
                    7 => forward_below::<7, FMA>(rows, &offs, &xs, l, x),
                    _ => forward_below::<{ MAX_RUN as usize }, FMA>(rows, &offs, &xs, l, x),
                }
            }
        }
    }

    /// Lᵀ z = y, last supernode first: gathers (dot products) from the rows below, then the
    /// diagonal block's triangle.
    #[inline(always)]
    fn backward<const FMA: bool>(self, l: &[f64], inv_diag: &[f64], x: &mut [f64]) {
        let (cp, ri) = (self.col_ptr, self.row_idx);
        let ns = self.sn_ptr.len() - 1;
        let block = |k: usize, k1: usize| cp[k] as usize + 1..cp[k] as usize + 1 + (k1 - k);
        let below_start = |k: usize, k1: usize| cp[k] as usize + 1 + (k1 - k);
        for s in (0..ns).rev() {
            let (k0, k1) = (self.sn_ptr[s] as usize, self.sn_ptr[s + 1] as usize - 1);
            let rows = &ri[below_start(k1, k1)..cp[k1 + 1] as usize];
            if k0 == k1 {
                // A lone column: one dot product in four partial sums (add latency).
                let lk = &l[below_start(k1, k1)..cp[k1 + 1] as usize];
                let mut acc = [0.0f64; 4];
                let (ri4, lk4) = (rows.chunks_exact(4), lk.chunks_exact(4));
                let (ri_r, lk_r) = (ri4.remainder(), lk4.remainder());
                for (i4, l4) in ri4.zip(lk4) {
                    for i in 0..4 {
                        acc[i] = fmadd::<FMA>(l4[i], x[i4[i] as usize], acc[i]);
                    }
                }
                for (&i, &lv) in ri_r.iter().zip(lk_r) {
                    acc[0] = fmadd::<FMA>(lv, x[i as usize], acc[0]);
                }
                x[k0] = (x[k0] - ((acc[0] + acc[1]) + (acc[2] + acc[3]))) * inv_diag[k0];
                continue;
            }
            if !rows.is_empty() {
                for ka in (k0..=k1).step_by(MAX_RUN as usize) {
                    let m = (k1 + 1 - ka).min(MAX_RUN as usize);
                    let mut offs = [0usize; MAX_RUN as usize];
                    for (i, o) in offs[..m].iter_mut().enumerate() {
                        *o = below_start(ka + i, k1);
                    }
                    // Few columns: split each dot product into partial sums (add latency).
                    let dots: [f64; MAX_RUN as usize] = match m {
                        1 => backward_below::<1, 4, FMA>(rows, &offs, l, x),
                        2 => backward_below::<2, 2, FMA>(rows, &offs, l, x),
                        3 => backward_below::<3, 2, FMA>(rows, &offs, l, x),
                        4 => backward_below::<4, 1, FMA>(rows, &offs, l, x),
                        5 => backward_below::<5, 1, FMA>(rows, &offs, l, x),
                        6 => backward_below::<6, 1, FMA>(rows, &offs, l, x),
                        7 => backward_below::<7, 1, FMA>(rows, &offs, l, x),
                        _ => backward_below::<{ MAX_RUN as usize }, 1, FMA>(rows, &offs, l, x),
                    };
                    for (xk, d) in x[ka..ka + m].iter_mut().zip(dots) {
                        *xk -= d;
                    }
                }
            }
            for k in (k0..=k1).rev() {
                let (col, xb) = (&l[block(k, k1)], &x[k + 1..=k1]);
                let mut acc = [0.0f64; 4];
                let (col4, xb4) = (col.chunks_exact(4), xb.chunks_exact(4));
                let (col_r, xb_r) = (col4.remainder(), xb4.remainder());
                for (c4, x4) in col4.zip(xb4) {
                    for i in 0..4 {
                        acc[i] = fmadd::<FMA>(c4[i], x4[i], acc[i]);
                    }
                }
                for (&c, &xv) in col_r.iter().zip(xb_r) {
                    acc[0] = fmadd::<FMA>(c, xv, acc[0]);
                }
                x[k] = (x[k] - ((acc[0] + acc[1]) + (acc[2] + acc[3]))) * inv_diag[k];
            }
        }
    }
}

/// `x[rows[r]] −= Σ_m L[offs[m] + r] · xs[m]`: M columns of one supernode on its rows below.
#[inline(always)]
fn forward_below<const M: usize, const FMA: bool>(
    rows: &[u32],
    offs: &[usize],
    xs: &[f64],
    l: &[f64],
    x: &mut [f64],
) {
    let len = rows.len();
    let cols: [&[f64]; M] = std::array::from_fn(|m| &l[offs[m]..offs[m] + len]);
    for (r, &i) in rows.iter().enumerate() {
        let mut s = 0.0;
        for m in 0..M {
            s = fmadd::<FMA>(cols[m][r], xs[m], s);
        }
        x[i as usize] -= s;
    }
}

/// `Σ_r L[offs[m] + r] · x[rows[r]]` for M columns of one supernode on its rows below, each in
/// P partial sums; unused entries of the result are zero.
#[inline(always)]
fn backward_below<const M: usize, const P: usize, const FMA: bool>(
    rows: &[u32],
    offs: &[usize],
    l: &[f64],
    x: &[f64],
) -> [f64; MAX_RUN as usize] {
    let len = rows.len();
    let cols: [&[f64]; M] = std::array::from_fn(|m| &l[offs[m]..offs[m] + len]);
    let mut acc = [[0.0f64; M]; P];
    let full = len / P * P;
    for r0 in (0..full).step_by(P) {
        for p in 0..P {
            let xi = x[rows[r0 + p] as usize];
            for m in 0..M {
                acc[p][m] = fmadd::<FMA>(cols[m][r0 + p], xi, acc[p][m]);
            }
        }
    }
    for r in full..len {
        let xi = x[rows[r] as usize];
        for m in 0..M {
            acc[0][m] = fmadd::<FMA>(cols[m][r], xi, acc[0][m]);
        }
    }
    let mut out = [0.0; MAX_RUN as usize];
    for m in 0..M {
        out[m] = acc.iter().map(|a| a[m]).sum();
    }
    out
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

/// [`Sweep::run`]'s arguments, run under `pulp` dispatch.
struct SweepKernel<'a> {
    sweep: Sweep<'a>,
    dir: Direction,
    l: &'a [f64],
    inv_diag: &'a [f64],
    x: &'a mut [f64],
}

impl pulp::WithSimd for SweepKernel<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        self.sweep
            .run_impl::<true>(self.dir, self.l, self.inv_diag, self.x);
    }
}
