//! Block triangular solves x ← (LLᵀ)⁻¹ x on faer's supernodal Cholesky factor, with the
//! right-hand sides stored as a row-major *panel* (the w ≤ 8 entries of one row side by side).
//!
//! Why not faer's own `solve_in_place` (which the crate uses for single vectors and wide
//! blocks): for a few right-hand sides it runs, per supernode, a dense GEMM that packs the
//! supernode's rows below and then scatters the product column by column, well above one pass
//! over the factor's memory (the comparison is in docs/benchmarks.md, "Design measurements").
//! Here each factor entry is loaded once per solve and multiplies a row of w values held in
//! SIMD registers; the columns of a supernode are taken in passes of [`PASS`], so each indexed
//! row of x is loaded and stored once per pass rather than once per factor column.
//!
//! Two threads: from 20 000 rows on, when the supernodal elimination tree splits into two
//! groups of whole subtrees holding similar weights below a top of at most 25% of the factor
//! ([`Split`]), the two groups are swept at the same time. That is the case for nested
//! dissection orderings of bulky meshes, not for the AMD ordering of a slender beam (a near
//! chain: no split within 25%, swept on one thread).
//!
//! Determinism: every sum in a fixed order that depends on the factor only; each right-hand side (lane) sees the
//! same operations whatever w or the SIMD width, so the results do not depend on how the
//! columns are grouped into panels. With FMA available (x86-64 AVX2+FMA, detected at run time)
//! products are fused; machines without it round differently (as for faer, whose kernels
//! also dispatch on the CPU).

use faer::sparse::linalg::cholesky::supernodal::{SupernodalLltRef, SymbolicSupernodalCholesky};

/// Factor columns per pass over the rows below a supernode. Six, not eight: a pass keeps its
/// PASS solved rows of x in registers (2 AVX registers each at w = 8) next to two partial
/// sums, and 8 rows already fill the 16 AVX2 registers (spills); and FEM supernodes hold
/// whole 3-dof nodes, so their widths are multiples of 3 and a pass of 6 leaves either
/// nothing or a pass of [`REM`], which also runs on fixed-size arrays (passes of 8 execute
/// more instructions; docs/benchmarks.md, "Design measurements").
const PASS: usize = 6;

/// The pass width left over in supernodes of an odd number of 3-dof nodes (specialised like a
/// full pass; other remainders take the generic path).
const REM: usize = 3;

/// Panel widths (right-hand sides per pass over the factor) this solve is used for; wider
/// blocks go to faer, whose packed GEMM is the faster one there (docs/benchmarks.md, "Design measurements").
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
    /// Every supernode, in order (the sequential sweeps).
    all: Vec<usize>,
    /// Two independent subtree groups and the rest, for sweeps on two threads.
    split: Option<Split>,
}

/// A split of the supernodal elimination tree into two groups of whole subtrees of similar
/// weight (`lists[0]`, `lists[1]`) and the supernodes above them (`lists[2]`, the "top").
/// A supernode's rows below its diagonal block belong to its ancestors, so a group only
/// touches its own rows and top rows: the two groups can be swept at the same time, group 1 on
/// a copy whose top rows collect its updates from zero, added to group 0's afterwards.
struct Split {
    lists: [Vec<usize>; 3],
    /// Rows (in the factor's order) of group 1's supernodes, and of the top supernodes.
    rows1: Vec<usize>,
    top_rows: Vec<usize>,
}

/// Factors with fewer rows are swept on one thread (the split costs two joins and copies of
/// the panel's rows; below this size a sweep takes about a millisecond or less).
const SPLIT_MIN_ROWS: usize = 20_000;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Sweep {
    Forward,
    Backward,
}

impl PanelSolve {
    /// Whether the sweeps run on two subtree groups.
    #[cfg(test)]
    pub(super) fn is_split(&self) -> bool {
        self.split.is_some()
    }

    /// Layout of the factor `values` on the supernodal symbolic structure `sym`.
    pub fn new(sym: &SymbolicSupernodalCholesky<usize>, values: &[f64]) -> PanelSolve {
        Self::with_split_from(sym, values, SPLIT_MIN_ROWS)
    }

    /// [`Self::new`], splitting the tree for two threads from `min_rows` rows on.
    pub(super) fn with_split_from(
        sym: &SymbolicSupernodalCholesky<usize>,
        values: &[f64],
        min_rows: usize,
    ) -> PanelSolve {
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
        let split = if sym.nrows() >= min_rows {
            split_tree(&supernodes, &row_idx, sym.nrows())
        } else {
            None
        };
        PanelSolve {
            all: (0..supernodes.len()).collect(),
            supernodes,
            row_idx,
            inv_diag,
            split,
        }
    }

    /// `x ← (LLᵀ)⁻¹ x` for a row-major panel `x` (n rows of `w` values, 1 ≤ `w` ≤ 8) in the
    /// factor's (permuted) order; `values` are the factor's values given to [`Self::new`];
    /// `scratch` is resized as needed. With a [`Split`] the two subtree groups are swept by
    /// `rayon::join` (same arithmetic on a pool of one thread: the split depends on the factor
    /// only, never on the thread count).
    pub fn solve(&self, values: &[f64], x: &mut [f64], w: usize, scratch: &mut Vec<f64>) {
        assert!((1..=8).contains(&w) && x.len() == w * self.inv_diag.len());
        let Some(sp) = &self.split else {
            self.sweep(values, x, w, Sweep::Forward, &self.all);
            self.sweep(values, x, w, Sweep::Backward, &self.all);
            return;
        };
        scratch.clear();
        scratch.resize(x.len(), 0.0);
        let x1 = &mut scratch[..];
        let copy_rows = |dst: &mut [f64], src: &[f64], rows: &[usize]| {
            for &i in rows {
                dst[i * w..(i + 1) * w].copy_from_slice(&src[i * w..(i + 1) * w]);
            }
        };
        copy_rows(x1, x, &sp.rows1);
        rayon::join(
            || self.sweep(values, x, w, Sweep::Forward, &sp.lists[0]),
            || self.sweep(values, x1, w, Sweep::Forward, &sp.lists[1]),
        );
        copy_rows(x, x1, &sp.rows1);
        for &i in &sp.top_rows {
            for c in i * w..(i + 1) * w {
                x[c] += x1[c];
            }
        }
        self.sweep(values, x, w, Sweep::Forward, &sp.lists[2]);
        self.sweep(values, x, w, Sweep::Backward, &sp.lists[2]);
        copy_rows(x1, x, &sp.top_rows);
        rayon::join(
            || self.sweep(values, x, w, Sweep::Backward, &sp.lists[0]),
            || self.sweep(values, x1, w, Sweep::Backward, &sp.lists[1]),
        );
        copy_rows(x, x1, &sp.rows1);
    }

    /// One sweep over the supernodes `list` (ascending; the backward sweep walks it in
    /// reverse), under the best SIMD instruction set available.
    fn sweep(&self, values: &[f64], x: &mut [f64], w: usize, dir: Sweep, list: &[usize]) {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            return pulp::Simd::vectorize(
                simd,
                SolveKernel {
                    solver: self,
                    values,
                    x,
                    w,
                    dir,
                    list,
                },
            );
        }
        self.solve_dispatch::<false>(values, x, w, dir, list);
    }

    #[inline(always)]
    fn solve_dispatch<const FMA: bool>(
        &self,
        values: &[f64],
        x: &mut [f64],
        w: usize,
        dir: Sweep,
        list: &[usize],
    ) {
        macro_rules! go {
            ($w:literal) => {{
                let x = x.as_chunks_mut::<$w>().0;
                match dir {
                    Sweep::Forward => self.forward_w::<$w, FMA>(values, x, list),
                    Sweep::Backward => self.backward_w::<$w, FMA>(values, x, list),
                }
            }};
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

    /// L y = b over the supernodes `list` in order; each in passes of PASS columns: the small
    /// triangle of the pass, then every row below it in the supernode (the rest of the
    /// diagonal block, then the pattern rows), one load and store of each x row per pass.
    #[inline(always)]
    fn forward_w<const W: usize, const FMA: bool>(
        &self,
        l: &[f64],
        x: &mut [[f64; W]],
        list: &[usize],
    ) {
        let inv = &self.inv_diag;
        for sn in list.iter().map(|&s| &self.supernodes[s]) {
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
                // Rows below the pass: the rest of the diagonal block (contiguous), then the
                // pattern rows. Each column slice has exactly `len` entries, so the indexing
                // in the loops needs no bounds checks.
                let first = c0 + j0 + m;
                let nrest = c0 + nc - first;
                let len = nrest + rows.len();
                let cols: [&[f64]; PASS] = std::array::from_fn(|t| {
                    if t < m {
                        &col(j0 + t)[j0 + m..j0 + m + len]
                    } else {
                        &[]
                    }
                });
                match m {
                    PASS => forward_below::<W, PASS, FMA>(x, &cols, &xs, first, nrest, rows),
                    REM => forward_below::<W, REM, FMA>(x, &cols, &xs, first, nrest, rows),
                    _ => {
                        let targets = (first..first + nrest).chain(rows.iter().copied());
                        for (r, i) in targets.enumerate() {
                            x[i] = update_row_dyn::<W, FMA>(x[i], &cols[..m], r, &xs[..m]);
                        }
                    }
                }
            }
        }
    }

    /// Lᵀ z = y over the supernodes `list` in reverse order, passes last first: the dot
    /// products of the pass's columns with every row below its triangle, then the triangle.
    #[inline(always)]
    fn backward_w<const W: usize, const FMA: bool>(
        &self,
        l: &[f64],
        x: &mut [[f64; W]],
        list: &[usize],
    ) {
        let inv = &self.inv_diag;
        for sn in list.iter().rev().map(|&s| &self.supernodes[s]) {
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
                let first = c0 + j0 + m;
                let nrest = c0 + nc - first;
                let targets = (first..first + nrest).chain(rows.iter().copied());
                match m {
                    PASS => {
                        let a = backward_below::<W, PASS, FMA>(x, &cols, first, nrest, rows);
                        acc[..PASS].copy_from_slice(&a);
                    }
                    REM => {
                        let a = backward_below::<W, REM, FMA>(x, &cols, first, nrest, rows);
                        acc[..REM].copy_from_slice(&a);
                    }
                    _ => {
                        for (r, i) in targets.enumerate() {
                            let xi = x[i];
                            for t in 0..m {
                                axpy::<W, FMA>(&mut acc[t], cols[t][r], &xi);
                            }
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

/// Forward sweep below a pass of `P` columns (`cols[..P]`, `xs[..P]`): the contiguous rows
/// `first..first + nrest` of the diagonal block, then the pattern `rows`, on column slices of
/// exact length (no bounds checks in the loops). Same arithmetic per row as
/// [`update_row_dyn`] with `P` columns.
#[inline(always)]
fn forward_below<const W: usize, const P: usize, const FMA: bool>(
    x: &mut [[f64; W]],
    cols: &[&[f64]; PASS],
    xs: &[[f64; W]; PASS],
    first: usize,
    nrest: usize,
    rows: &[usize],
) {
    let cols: [&[f64]; P] = std::array::from_fn(|t| cols[t]);
    let xs: [[f64; W]; P] = std::array::from_fn(|t| xs[t]);
    let (rest, below) = cols_split::<P>(&cols, nrest);
    for (r, xi) in x[first..first + nrest].iter_mut().enumerate() {
        *xi = update_row::<W, P, FMA>(*xi, &rest, r, &xs);
    }
    let below: [&[f64]; P] = std::array::from_fn(|t| &below[t][..rows.len()]);
    for (r, &i) in rows.iter().enumerate() {
        x[i] = update_row::<W, P, FMA>(x[i], &below, r, &xs);
    }
}

/// Backward sweep below a pass of `P` columns: the dot products of `cols[..P]` with the
/// contiguous rows `first..first + nrest`, then the pattern `rows` (as [`forward_below`]).
#[inline(always)]
fn backward_below<const W: usize, const P: usize, const FMA: bool>(
    x: &[[f64; W]],
    cols: &[&[f64]; PASS],
    first: usize,
    nrest: usize,
    rows: &[usize],
) -> [[f64; W]; P] {
    let cols: [&[f64]; P] = std::array::from_fn(|t| cols[t]);
    let (rest, below) = cols_split::<P>(&cols, nrest);
    let mut acc = [[0.0f64; W]; P];
    for (r, xi) in x[first..first + nrest].iter().enumerate() {
        for t in 0..P {
            axpy::<W, FMA>(&mut acc[t], rest[t][r], xi);
        }
    }
    let below: [&[f64]; P] = std::array::from_fn(|t| &below[t][..rows.len()]);
    for (r, &i) in rows.iter().enumerate() {
        let xi = x[i];
        for t in 0..P {
            axpy::<W, FMA>(&mut acc[t], below[t][r], &xi);
        }
    }
    acc
}

/// The first `n` entries of each column and the rest.
#[inline(always)]
fn cols_split<'a, const P: usize>(
    cols: &[&'a [f64]; P],
    n: usize,
) -> ([&'a [f64]; P], [&'a [f64]; P]) {
    (
        std::array::from_fn(|t| &cols[t][..n]),
        std::array::from_fn(|t| &cols[t][n..]),
    )
}

/// `x_i − Σ_t cols[t][r]·xs[t]` for one row (P columns; two partial sums for FMA latency).
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
    dir: Sweep,
    list: &'a [usize],
}

impl pulp::WithSimd for SolveKernel<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        self.solver
            .solve_dispatch::<true>(self.values, self.x, self.w, self.dir, self.list);
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

/// A [`Split`] of the supernodal elimination tree, or `None` when no two groups of whole
/// subtrees hold most of the factor evenly. Weights are factor entries (each sweep reads each
/// entry once). Starting from the roots, the heaviest subtree of the frontier is replaced by
/// its children (its supernode joins the top) until a greedy two-way partition of the
/// frontier puts at most 55% of the frontier's weight in one group, giving up once the top
/// holds more than 25% of the factor.
fn split_tree(supernodes: &[Supernode], row_idx: &[usize], n: usize) -> Option<Split> {
    let ns = supernodes.len();
    let mut sn_of_row = vec![0usize; n];
    for (s, sn) in supernodes.iter().enumerate() {
        sn_of_row[sn.start..sn.start + sn.ncols].fill(s);
    }
    // Parent: the supernode holding the first row below the diagonal block (rows are sorted).
    let parent: Vec<Option<usize>> = supernodes
        .iter()
        .map(|sn| (sn.rows.0 < sn.rows.1).then(|| sn_of_row[row_idx[sn.rows.0]]))
        .collect();
    let weight: Vec<f64> = supernodes
        .iter()
        .map(|sn| (sn.ncols * (sn.ncols + 1) / 2 + sn.ncols * (sn.rows.1 - sn.rows.0)) as f64)
        .collect();
    let mut sub = weight.clone();
    let mut children = vec![Vec::new(); ns];
    for s in 0..ns {
        if let Some(p) = parent[s] {
            debug_assert!(p > s);
            sub[p] += sub[s];
            children[p].push(s);
        }
    }
    let total: f64 = weight.iter().sum();
    let mut frontier: Vec<usize> = (0..ns).filter(|&s| parent[s].is_none()).collect();
    let mut top_weight = 0.0;
    let mut group = vec![2u8; ns];
    loop {
        frontier.sort_by(|&a, &b| sub[b].total_cmp(&sub[a]).then(a.cmp(&b)));
        let mut load = [0.0f64; 2];
        let mut assign = Vec::with_capacity(frontier.len());
        for &s in &frontier {
            let g = usize::from(load[1] < load[0]);
            load[g] += sub[s];
            assign.push((s, g as u8));
        }
        let sum = load[0] + load[1];
        if sum > 0.0 && load[0].max(load[1]) <= 0.55 * sum && frontier.len() >= 2 {
            for (s, g) in assign {
                group[s] = g;
            }
            break;
        }
        let heaviest = *frontier.first()?;
        frontier.remove(0);
        top_weight += weight[heaviest];
        if top_weight > 0.25 * total {
            return None;
        }
        frontier.extend(children[heaviest].iter().copied());
    }
    // Descendants of the frontier roots inherit their group (parents have larger indices).
    for s in (0..ns).rev() {
        if group[s] == 2 && !frontier.contains(&s) {
            if let Some(p) = parent[s] {
                if group[p] != 2 || frontier.contains(&p) {
                    group[s] = group[p];
                }
            }
        }
    }
    let lists: [Vec<usize>; 3] =
        std::array::from_fn(|g| (0..ns).filter(|&s| group[s] == g as u8).collect());
    let rows_of = |list: &[usize]| -> Vec<usize> {
        list.iter()
            .flat_map(|&s| supernodes[s].start..supernodes[s].start + supernodes[s].ncols)
            .collect()
    };
    Some(Split {
        rows1: rows_of(&lists[1]),
        top_rows: rows_of(&lists[2]),
        lists,
    })
}
