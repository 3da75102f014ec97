//! The shifted operator A = K − σM, its sparse Cholesky factor, and block solves.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side, Spec};

use super::panel_solve::{PanelSolve, PANEL_WIDTHS};
use super::{ordering, EigenError};

/// K − σM on the union of the two patterns (both full symmetric storage, rows sorted).
pub(crate) fn shifted(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    sigma: f64,
) -> SparseColMat<usize, f64> {
    lin_comb(k, 1.0, m, -sigma)
}

/// α A + β B on the union of both patterns (full symmetric storage, rows sorted).
pub(crate) fn lin_comb(
    a: &SparseColMat<usize, f64>,
    alpha: f64,
    b: &SparseColMat<usize, f64>,
    beta: f64,
) -> SparseColMat<usize, f64> {
    let n = a.ncols();
    let (ap, ar, av) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let (bp, br, bv) = (b.symbolic().col_ptr(), b.symbolic().row_idx(), b.val());
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut rows = Vec::with_capacity(ar.len());
    let mut vals = Vec::with_capacity(ar.len());
    col_ptr.push(0);
    for j in 0..n {
        let (mut p, pe) = (ap[j], ap[j + 1]);
        let (mut q, qe) = (bp[j], bp[j + 1]);
        while p < pe || q < qe {
            let ra = if p < pe { ar[p] } else { usize::MAX };
            let rb = if q < qe { br[q] } else { usize::MAX };
            if ra == rb {
                rows.push(ra);
                vals.push(alpha * av[p] + beta * bv[q]);
                p += 1;
                q += 1;
            } else if ra < rb {
                rows.push(ra);
                vals.push(alpha * av[p]);
                p += 1;
            } else {
                rows.push(rb);
                vals.push(beta * bv[q]);
                q += 1;
            }
        }
        col_ptr.push(rows.len());
    }
    SparseColMat::new(
        SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows),
        vals,
    )
}

/// The node graph when the pattern is made of full 3×3 node blocks (node-major dofs, as
/// assembled by [`crate::fem`]); `None` when it is not blocked. Orderings computed on it and
/// expanded to the dofs of each node ([`expand_to_dofs`]) give the same fill as on the dof
/// graph (AMD merges the indistinguishable dofs of a node anyway) at ~1/9 of the size.
fn node_graph(a: &SparseColMat<usize, f64>) -> Option<SymbolicSparseColMat<usize>> {
    let n = a.nrows();
    if !n.is_multiple_of(3) || n == 0 {
        return None;
    }
    let (cp, ri) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
    let nn = n / 3;
    let mut ncp = Vec::with_capacity(nn + 1);
    let mut nri = Vec::with_capacity(ri.len() / 9 + nn);
    ncp.push(0);
    for node in 0..nn {
        let first = &ri[cp[3 * node]..cp[3 * node + 1]];
        // Each of the node's three columns must hold the same full row blocks.
        if first.len() % 3 != 0 {
            return None;
        }
        for c in 3 * node..3 * node + 3 {
            if ri[cp[c]..cp[c + 1]] != *first {
                return None;
            }
        }
        for blk in first.chunks_exact(3) {
            if blk[0] % 3 != 0 || blk[1] != blk[0] + 1 || blk[2] != blk[0] + 2 {
                return None;
            }
            nri.push(blk[0] / 3);
        }
        ncp.push(nri.len());
    }
    Some(SymbolicSparseColMat::new_checked(nn, nn, ncp, None, nri))
}

/// A node ordering expanded to the three dofs of each node: (fwd, inv) dof permutations.
fn expand_to_dofs(fwd: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let fwd3: Vec<usize> = fwd
        .iter()
        .flat_map(|&v| [3 * v, 3 * v + 1, 3 * v + 2])
        .collect();
    let inv3 = ordering::inverse(&fwd3);
    (fwd3, inv3)
}

/// Symbolic factorization of `a` under the dof permutation `perm` (or faer's AMD on the dofs).
fn symbolic(
    a: &SparseColMat<usize, f64>,
    perm: Option<&(Vec<usize>, Vec<usize>)>,
) -> Result<SymbolicCholesky<usize>, EigenError> {
    let ordering = match perm {
        Some((fwd, inv)) => SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, a.nrows())),
        None => SymmetricOrdering::Amd,
    };
    factorize_symbolic_cholesky(
        a.symbolic(),
        Side::Lower,
        ordering,
        CholeskySymbolicParams::default(),
    )
    .map_err(|e| EigenError::Factorization(format!("symbolic analysis failed: {e:?}")))
}

/// Nested dissection replaces AMD when its factor of the node graph has fewer than this
/// fraction of AMD's entries, i.e. whenever it fills less. Its balanced elimination tree is
/// what lets faer's factorization and the panel sweeps (`panel_solve.rs`) use both threads,
/// which AMD's near-chain tree on a slender beam does not. METIS fills less than AMD on the
/// bake bench beams (stout 108k dofs: 83.5M vs 123.6M dof-factor entries; slender 109k: 44.2M
/// vs 54.1M); timings in docs/benchmarks.md, "Design measurements".
const ND_FILL_RATIO: f64 = 1.0;

/// Below this many dofs nested dissection is not tried: on the bake bench's 13.5k-dof beam
/// METIS fills 11% less than AMD (4.30M vs 4.83M entries), but ordering it and comparing the
/// two fills costs what the smaller factor saves (docs/benchmarks.md, "Design measurements").
const ND_MIN_DOFS: usize = 30_000;

/// The symbolic factorization of `a` under AMD or, when it fills less ([`ND_FILL_RATIO`],
/// tried from [`ND_MIN_DOFS`] on), METIS nested dissection on the node graph (see
/// [`ordering`]); faer's AMD on the dofs when the pattern is not node-blocked. The fill is
/// compared on the node graph (1/9 of the entries), so choosing costs two small symbolic
/// analyses.
fn best_symbolic(a: &SparseColMat<usize, f64>) -> Result<SymbolicCholesky<usize>, EigenError> {
    let Some(g) = node_graph(a) else {
        return symbolic(a, None);
    };
    let try_nd = a.nrows() >= ND_MIN_DOFS;
    // METIS (sequential C, ~0.3 s on the stout 108k-dof beam) runs beside AMD and AMD's fill
    // count on the other thread; the choice is the same as one after the other.
    let (nd, amd) = rayon::join(
        || {
            try_nd
                .then(|| ordering::metis_nested_dissection(&g))
                .flatten()
        },
        || ordering::amd_order(&g).map(|o| (try_nd.then(|| ordering::factor_entries(&g, &o)), o)),
    );
    let order = match (amd, nd) {
        (Some((f_amd, amd)), Some(nd)) => {
            let (f_amd, f_nd) = (
                f_amd.unwrap_or(usize::MAX),
                ordering::factor_entries(&g, &nd),
            );
            if (f_nd as f64) < ND_FILL_RATIO * f_amd as f64 {
                nd
            } else {
                amd
            }
        }
        (Some((_, o)), None) | (None, Some(o)) => o,
        (None, None) => return symbolic(a, None),
    };
    symbolic(a, Some(&expand_to_dofs(&order)))
}

/// Sparse LLᵀ factor of an SPD matrix (here A = K − σM, Newmark's K_eff and M), ordered by AMD
/// or nested dissection on nodes ([`best_symbolic`]), faer's supernodal/simplicial choice.
pub(crate) struct ShiftInvert {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    /// Our block solves on a supernodal factor ([`PanelSolve`]); `None`: faer's (simplicial).
    panel: Option<PanelSolve>,
    par: Par,
}

/// Factors with fewer rows solve blocks wider than 8 columns (the purification of the Ritz
/// vectors: 20 at once for the bake's 20 modes) as panels of 8 with [`PanelSolve`]; larger
/// ones use faer's solve, whose packed GEMM (on two threads from 20 000 dofs) is faster there
/// (docs/benchmarks.md, "Design measurements").
const WIDE_PANEL_MAX_ROWS: usize = 20_000;

/// Scratch of [`ShiftInvert::solve_in_place`].
pub(crate) struct SolveBuffer {
    /// faer's solve scratch (simplicial factors).
    mem: MemBuffer,
    /// Row-major panel of the right-hand sides in the factor's order.
    panel: Vec<f64>,
    /// Second panel for the split sweeps of [`PanelSolve::solve`].
    panel2: Vec<f64>,
}

impl ShiftInvert {
    /// Factors `a` (symmetric positive definite, full storage; the lower triangle is read).
    pub fn new(a: &SparseColMat<usize, f64>, par: Par) -> Result<ShiftInvert, EigenError> {
        Self::with_symbolic(a, best_symbolic(a)?, par)
    }

    /// Numeric factorization of `a` on a given symbolic analysis.
    fn with_symbolic(
        a: &SparseColMat<usize, f64>,
        symbolic: SymbolicCholesky<usize>,
        par: Par,
    ) -> Result<ShiftInvert, EigenError> {
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
                let faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } = e;
                EigenError::Factorization(format!(
                    "the matrix is not positive definite to working precision (non-positive \
                     pivot at free dof {index})"
                ))
            })?;
        let panel = match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sym) => Some(PanelSolve::new(sym, &values)),
            SymbolicCholeskyRaw::Simplicial(_) => None,
        };
        Ok(ShiftInvert {
            symbolic,
            values,
            panel,
            par,
        })
    }

    /// Number of stored factor entries.
    pub fn factor_nnz(&self) -> usize {
        self.values.len()
    }

    /// Whether blocks of `w` columns are solved by [`PanelSolve`]: 2 to 8 columns in one
    /// panel, and wider blocks as panels of 8 (and the rest) below [`WIDE_PANEL_MAX_ROWS`].
    fn uses_panel(&self, w: usize) -> bool {
        self.panel.is_some()
            && (PANEL_WIDTHS.contains(&w)
                || (w > *PANEL_WIDTHS.end() && self.symbolic.nrows() < WIDE_PANEL_MAX_ROWS))
    }

    /// Overwrites every column of `rhs` with A⁻¹ rhs: blocks of 2 to 8 columns on a supernodal
    /// factor through [`PanelSolve`] (one pass over the factor for the block), wider blocks as
    /// panels of 8 columns (and the rest) below [`WIDE_PANEL_MAX_ROWS`] rows, others through
    /// faer's solve (single columns: its vector path is as fast; wider blocks on large
    /// factors: its packed GEMM). Each column sees the same operations in any panel, and each
    /// call site uses a fixed width, so results stay reproducible.
    pub fn solve_in_place(&self, mut rhs: MatMut<'_, f64>, buf: &mut SolveBuffer) {
        let (n, w) = (rhs.nrows(), rhs.ncols());
        let panel = match &self.panel {
            Some(p) if self.uses_panel(w) => p,
            _ => {
                LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
                    Conj::No,
                    rhs,
                    self.par,
                    MemStack::new(&mut buf.mem),
                );
                return;
            }
        };
        let identity: Vec<usize>;
        let (fwd, inv) = match self.symbolic.perm() {
            Some(p) => p.arrays(),
            None => {
                identity = (0..n).collect();
                (&identity[..], &identity[..])
            }
        };
        let pw = *PANEL_WIDTHS.end();
        for c0 in (0..w).step_by(pw) {
            let wc = pw.min(w - c0);
            buf.panel.resize(n * wc, 0.0);
            let x = &mut buf.panel[..n * wc];
            for c in 0..wc {
                let col = rhs.rb().col(c0 + c);
                for (i, &f) in fwd.iter().enumerate() {
                    x[i * wc + c] = col[f];
                }
            }
            panel.solve(&self.values, x, wc, &mut buf.panel2);
            for c in 0..wc {
                let mut col = rhs.rb_mut().col_mut(c0 + c);
                for (i, &v) in inv.iter().enumerate() {
                    col[i] = x[v * wc + c];
                }
            }
        }
    }

    /// Scratch buffer for solves of `ncols` right-hand sides.
    pub fn solve_buffer(&self, ncols: usize) -> SolveBuffer {
        let (mem, panel) = if self.uses_panel(ncols) {
            let n = self.symbolic.nrows();
            let w = ncols.min(*PANEL_WIDTHS.end());
            (MemBuffer::new(StackReq::EMPTY), vec![0.0; n * w])
        } else {
            let req = self.symbolic.solve_in_place_scratch::<f64>(ncols, self.par);
            (MemBuffer::new(req), Vec::new())
        };
        SolveBuffer {
            mem,
            panel,
            panel2: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::{assemble_mass, assemble_stiffness, reduce_fixed, Material};
    use crate::mesh::TetMesh;

    /// x = A⁻¹ b by faer's own solve on the factor: the reference for our panel sweeps.
    fn faer_solve(fac: &ShiftInvert, mut b: faer::Mat<f64>) -> faer::Mat<f64> {
        let w = b.ncols();
        let mut mem = MemBuffer::new(fac.symbolic.solve_in_place_scratch::<f64>(w, Par::Seq));
        LltRef::new(&fac.symbolic, &fac.values).solve_in_place_with_conj(
            Conj::No,
            b.as_mut(),
            Par::Seq,
            MemStack::new(&mut mem),
        );
        b
    }

    /// K − σM (σ = −1) of a structured box (cells, size in m; E = 1 GPa, ν = 0.3,
    /// ρ = 1000 kg/m³) clamped at its `xmin` face.
    fn clamped_operator(cells: [usize; 3], size: [f64; 3]) -> SparseColMat<usize, f64> {
        let mesh = TetMesh::structured_box(cells, size);
        let mat = Material::new(1e9, 0.3, 1000.0).unwrap();
        let (k, m) = (
            assemble_stiffness(&mesh, &mat),
            assemble_mass(&mesh, &mat, false),
        );
        let (_, kf, mf) = reduce_fixed(&k, &m, &mesh.groups["xmin"]).unwrap();
        shifted(&kf, &mf, -1.0)
    }

    /// The nested-dissection path (chosen in bakes only from [`ND_MIN_DOFS`] dofs) factors and
    /// solves like the AMD one: forced here on a small clamped block, A⁻¹b agrees to 1e-10.
    #[test]
    fn nested_dissection_factor_solves_like_amd() {
        let a = clamped_operator([16, 4, 4], [1.0, 1.0, 1.0]);
        let g = node_graph(&a).expect("node-blocked pattern");
        let nd = ordering::metis_nested_dissection(&g).expect("nd ordering");
        let amd = ordering::amd_order(&g).expect("amd ordering");
        assert_ne!(nd, amd, "the test must exercise a different ordering");
        let by = |order: &[usize]| {
            let sym = symbolic(&a, Some(&expand_to_dofs(order))).unwrap();
            ShiftInvert::with_symbolic(&a, sym, Par::Seq).unwrap()
        };
        let (f_nd, f_amd) = (by(&nd), by(&amd));
        let n = a.nrows();
        let b = faer::Mat::<f64>::from_fn(n, 3, |i, j| ((i * 7 + j * 13) % 11) as f64 - 5.0);
        let solve = |f: &ShiftInvert| {
            let mut x = b.clone();
            let mut mem = f.solve_buffer(3);
            f.solve_in_place(x.as_mut(), &mut mem);
            x
        };
        let (x_nd, x_amd) = (solve(&f_nd), solve(&f_amd));
        let rel = (&x_nd - &x_amd).norm_l2() / x_amd.norm_l2();
        assert!(rel < 1e-10, "nd vs amd solve: relative difference {rel:e}");
        // And it is a solve: A x = b.
        let r = &a * &x_nd - &b;
        assert!(
            r.norm_l2() < 1e-8 * b.norm_l2(),
            "residual {:e}",
            r.norm_l2()
        );
    }

    /// The block solves on a supernodal factor ([`PanelSolve`], 2–8 columns, and 20 as panels
    /// of 8, 8 and 4) agree with faer's solve to 1e-12, solve A x = b, and give each column the
    /// same bits whatever block it is solved in (what makes the Lanczos results independent of
    /// how columns are grouped).
    #[test]
    fn panel_solve_matches_faer_and_is_independent_of_grouping() {
        let a = clamped_operator([16, 5, 5], [1.0, 0.3, 0.3]);
        let fac = ShiftInvert::new(&a, Par::Seq).unwrap();
        assert!(fac.panel.is_some(), "the test needs a supernodal factor");
        let n = a.nrows();
        let b = faer::Mat::<f64>::from_fn(n, 20, |i, j| ((i * 7 + j * 13) % 11) as f64 - 5.0);
        let solve = |x: &mut faer::Mat<f64>| {
            let mut buf = fac.solve_buffer(x.ncols());
            fac.solve_in_place(x.as_mut(), &mut buf);
        };
        for w in [2, 6, 8, 20] {
            let mut x = b.as_ref().subcols(0, w).to_owned();
            solve(&mut x);
            let y = faer_solve(&fac, b.as_ref().subcols(0, w).to_owned());
            let rel = (&x - &y).norm_l2() / y.norm_l2();
            assert!(rel < 1e-12, "{w} columns: panel vs faer {rel:e}");
            let r = &a * &x - b.as_ref().subcols(0, w);
            assert!(
                r.norm_l2() < 1e-8 * b.norm_l2(),
                "residual {:e}",
                r.norm_l2()
            );
        }
        // Column 5 solved among 8, among 6 and beside column 0 only, and columns 13 and 17
        // solved among 20 (in the second and the last panel) and beside column 0: the same bits.
        let mut x20 = b.clone();
        solve(&mut x20);
        for col in [13, 17] {
            let mut pair = faer::Mat::<f64>::from_fn(n, 2, |i, j| b[(i, [0, col][j])]);
            solve(&mut pair);
            for i in 0..n {
                assert_eq!(x20[(i, col)].to_bits(), pair[(i, 1)].to_bits(), "row {i}");
            }
        }
        let mut x8 = b.as_ref().subcols(0, 8).to_owned();
        solve(&mut x8);
        let mut x6 = b.as_ref().subcols(0, 6).to_owned();
        solve(&mut x6);
        let mut x2 = faer::Mat::<f64>::from_fn(n, 2, |i, j| b[(i, [0, 5][j])]);
        solve(&mut x2);
        for i in 0..n {
            assert_eq!(x8[(i, 5)].to_bits(), x6[(i, 5)].to_bits(), "row {i}");
            assert_eq!(x8[(i, 5)].to_bits(), x2[(i, 1)].to_bits(), "row {i}");
        }
    }

    /// The two-thread sweeps of [`PanelSolve`] (forced here on a small beam ordered by nested
    /// dissection, whose tree branches at the top) agree with faer's solve to 1e-12 and give
    /// the same bits on rayon pools of 1 and 2 threads.
    #[test]
    fn split_panel_solve_matches_faer_and_does_not_depend_on_threads() {
        let a = clamped_operator([16, 4, 4], [1.0, 1.0, 1.0]);
        let g = node_graph(&a).expect("node-blocked pattern");
        let nd = ordering::metis_nested_dissection(&g).expect("nd ordering");
        let sym = symbolic(&a, Some(&expand_to_dofs(&nd))).unwrap();
        let mut fac = ShiftInvert::with_symbolic(&a, sym, Par::Seq).unwrap();
        let SymbolicCholeskyRaw::Supernodal(sn) = fac.symbolic.raw() else {
            panic!("the test needs a supernodal factor");
        };
        let split = PanelSolve::with_split_from(sn, &fac.values, 0);
        assert!(split.is_split(), "the nested-dissection tree must split");
        fac.panel = Some(split);
        let n = a.nrows();
        let b = faer::Mat::<f64>::from_fn(n, 6, |i, j| ((i * 7 + j * 13) % 11) as f64 - 5.0);
        let solve = || {
            let mut x = b.clone();
            let mut buf = fac.solve_buffer(6);
            fac.solve_in_place(x.as_mut(), &mut buf);
            x
        };
        let x = solve();
        let y = faer_solve(&fac, b.clone());
        let rel = (&x - &y).norm_l2() / y.norm_l2();
        assert!(rel < 1e-12, "split sweeps vs faer: {rel:e}");
        let bits = |x: &faer::Mat<f64>| -> Vec<u64> {
            (0..6)
                .flat_map(|c| x.col(c).iter().map(|v| v.to_bits()).collect::<Vec<_>>())
                .collect()
        };
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(bits(&x), bits(&pool.install(solve)), "pool of {threads}");
        }
    }
}

/// Timing probe (ignored; speed is measured, never asserted): on the bake bench's 3k and 15k
/// beams (`benches/bake.rs`), the factorization of K − σM (best and median of 5) and one
/// block solve of 8 right-hand sides (best and median of 20), and the best factorization plus
/// as many best solves as a 20-mode bake takes there (17 and 15, `EigenInfo::block_solves`):
/// the floor of a shift-invert Lanczos bake before any orthogonalisation.
/// `cargo test --release -p modal-bake --lib factor_and_solve_floor -- --ignored --nocapture`
#[cfg(test)]
mod timing {
    use super::*;
    use crate::fem::{assemble_clamped, Material};
    use crate::mesh::TetMesh;

    #[test]
    #[ignore = "timing probe"]
    fn factor_and_solve_floor() {
        let beams = [
            ("bench3k", [24, 6, 6], [1.0, 0.25, 0.25], 17),
            ("bench15k", [45, 9, 9], [2.0, 0.4, 0.4], 15),
        ];
        for (name, cells, size, solves) in beams {
            let mesh = TetMesh::structured_box(cells, size);
            let mat = Material::new(2e11, 0.3, 7800.0).unwrap();
            let (_, k, m) = assemble_clamped(&mesh, &mat, false, &mesh.groups["xmin"]).unwrap();
            let a = shifted(&k, &m, 0.0);
            let mut factor = Vec::new();
            let mut fac = None;
            for _ in 0..5 {
                let t = std::time::Instant::now();
                fac = Some(ShiftInvert::new(&a, Par::Seq).unwrap());
                factor.push(t.elapsed().as_secs_f64());
            }
            let fac = fac.unwrap();
            let n = a.nrows();
            let b = faer::Mat::<f64>::from_fn(n, 8, |i, j| ((i * 7 + j * 13) % 11) as f64 - 5.0);
            let mut buf = fac.solve_buffer(8);
            let mut solve = Vec::new();
            for _ in 0..20 {
                let mut x = b.clone();
                let t = std::time::Instant::now();
                fac.solve_in_place(x.as_mut(), &mut buf);
                solve.push(t.elapsed().as_secs_f64());
            }
            factor.sort_by(f64::total_cmp);
            solve.sort_by(f64::total_cmp);
            let (f, s) = (factor[0], solve[0]);
            println!(
                "{name}: {n} dofs, {} factor entries; factor best {:.1} ms (median {:.1}); \
                 8-column solve best {:.2} ms (median {:.2}); factor + {solves} solves {:.0} ms",
                fac.factor_nnz(),
                f * 1e3,
                factor[2] * 1e3,
                s * 1e3,
                solve[10] * 1e3,
                (f + solves as f64 * s) * 1e3
            );
        }
    }
}
