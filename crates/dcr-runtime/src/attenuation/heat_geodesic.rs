//! [`HeatGeodesic`]: geodesic distances on a triangle surface by the heat method
//! (Crane, Weischedel & Wardetzky 2013), factor once, query many.
//!
//! Set-up: cotan Laplacian L (positive semi-definite, `L_ij = −½(cot α_ij + cot β_ij)`), lumped
//! vertex mass M (⅓ of the incident triangle areas), t = (mean edge length)²; one symbolic
//! sparse Cholesky (faer, simplicial pattern; under the base's stored elimination order,
//! METIS nested dissection planned at bake time, else AMD) shared by the two numeric factors
//! of (M + tL) and (L + εM), ε = 1e-8/t (scale-free regularisation of the closed-surface null
//! space), both computed in one left-looking sweep ([`super::sparse_llt`]).
//! Per source: heat solve (M + tL) u = δ, X = −∇u/|∇u| per face, integrated divergence
//! b_i = Σ_f A_f X_f·∇φ_i, Poisson solve (L + εM) φ = b, shift so the source is at 0.
//! No boundary-condition averaging (open surfaces get the natural Neumann condition).
//! Range: u falls by about e⁻⁰·⁸ per mean edge length h; with the source scaled to the top of
//! the double range and far faces rescaled, distances hold up to ≈ 1,000 h from the source
//! (a 10 m strip of 1 cm edges is tested); beyond that u underflows and distances saturate —
//! use Euclidean distances on such surfaces (flat terrain) or a coarser mesh.
//! When the elimination order is a nested dissection (the base's stored order), the solves and
//! the face loop split into the elimination tree's two halves and the top separator
//! ([`super::sparse_llt::Layout`]); a [`HeatWorkspace::set_parallel`] query runs the halves on
//! two threads, with the same bits as serially.

use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SymbolicSparseColMatRef;
use faer::Side;

use super::sparse_llt::{merge_top, Direction, Layout, Pattern};
use crate::math::{cross, dot, norm, sub};
use crate::surface_point::SurfacePoint;

/// Why a [`HeatGeodesic`] could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GeodesicError {
    /// No vertices or no triangles.
    #[error("empty surface")]
    Empty,
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} names a vertex ≥ {vertices}")]
    BadIndex {
        /// Triangle index.
        triangle: usize,
        /// Vertex count.
        vertices: usize,
    },
    /// A triangle has (near) zero area.
    #[error("triangle {triangle} is degenerate (area {area} m²)")]
    Degenerate {
        /// Triangle index.
        triangle: usize,
        /// Its area (m²).
        area: f64,
    },
    /// The supplied vertex ordering is not a permutation of the vertices.
    #[error("the vertex ordering is not a permutation of the surface vertices")]
    BadOrdering,
    /// The sparse Cholesky factorisation failed (e.g. a vertex used by no triangle).
    #[error("sparse Cholesky failed: {0}")]
    Factorization(String),
}

/// One operator's factor values in [`Pattern`] order and its inverse diagonal (1/L_kk).
struct Factor {
    vals: Vec<f64>,
    inv_diag: Vec<f64>,
}

impl Factor {
    fn new(pattern: &Pattern, vals: Vec<f64>) -> Self {
        let inv_diag = pattern.col_ptr[..pattern.n()]
            .iter()
            .map(|&p| 1.0 / vals[p as usize])
            .collect();
        Factor { vals, inv_diag }
    }
}

/// Reusable scratch for [`HeatGeodesic`] queries, so repeated queries do not allocate; it
/// also says whether a query may use two threads ([`HeatWorkspace::set_parallel`]).
pub struct HeatWorkspace {
    /// Heat u, and the divergence b / distance φ, in the solves' storage order
    /// ([`Layout`]).
    u: Vec<f64>,
    x: Vec<f64>,
    parallel: bool,
}

impl HeatWorkspace {
    /// Lets queries run the two halves of the factor's elimination tree on two threads
    /// (`rayon::join` in the caller's rayon pool, else rayon's global pool): faster when a
    /// second core is free (less gain where the two threads share a physical core or wait to
    /// be woken; docs/benchmarks.md). The distances are bit-identical either way. Serial by default. Called from a thread outside
    /// any rayon pool, rayon's job injection may allocate now and then; called from inside a
    /// pool (or serial) a query does not allocate. No effect where the elimination order does
    /// not split into two balanced halves (AMD orders: bases without a stored
    /// `surface_order`) or the factor is too small for two threads to pay
    /// ([`HeatGeodesic::PARALLEL_MIN_ENTRIES`]).
    pub fn set_parallel(&mut self, parallel: bool) {
        self.parallel = parallel;
    }

    /// Whether queries may use two threads (see [`HeatWorkspace::set_parallel`]).
    pub fn parallel(&self) -> bool {
        self.parallel
    }
}

impl std::fmt::Debug for HeatWorkspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeatWorkspace")
            .field("len", &self.u.len())
            .field("parallel", &self.parallel)
            .finish()
    }
}

/// Heat-method geodesic distances (m) on a fixed triangle surface: factor once, many sources.
pub struct HeatGeodesic {
    n: usize,
    /// The surface's triangles (original vertex indices), for point sources.
    triangles: Vec<[u32; 3]>,
    /// The triangles grouped by the [`Layout`] part that owns them (`faces[face_ptr[g]..
    /// face_ptr[g + 1]]`: g = 0, 1 those with a vertex in a half, 2 the rest), their vertices
    /// renumbered to positions in that part's local vector, and per triangle the Gram matrix
    /// ¼[e₁·e₁, e₁·e₂, e₂·e₂] (m²) of its edges e₁ = x₀ − x₂, e₂ = x₁ − x₀, i.e. of A∇φ₁,
    /// A∇φ₂ (A the area, φ_i the hat functions): the whole per-source face loop works in
    /// storage order on these, without a permutation pass.
    faces: Vec<[u32; 3]>,
    gram: Vec<[f64; 3]>,
    face_ptr: [usize; 4],
    symbolic: SymbolicCholesky<u32>,
    /// The solves' split of the factor's columns and storage order.
    layout: Layout,
    /// Storage position of each vertex (see [`Layout`]).
    spos: Vec<u32>,
    /// Factors of (M + tL) and (L + εM).
    heat: Factor,
    poisson: Factor,
    /// Fill-reducing permutation: factor row i is vertex `perm[i]`.
    perm: Vec<u32>,
    mean_edge: f64,
    /// Power of two the unit heat source is scaled by (see [`HeatGeodesic::distances_with`]).
    source_scale: f64,
}

impl std::fmt::Debug for HeatGeodesic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeatGeodesic")
            .field("vertices", &self.n)
            .field("triangles", &self.triangles.len())
            .field("mean_edge", &self.mean_edge)
            .finish()
    }
}

impl HeatGeodesic {
    /// Factor size (stored entries) from which a [`HeatWorkspace::set_parallel`] query forks:
    /// below it, two `rayon::join`s cost more than half the sweeps save
    /// (docs/benchmarks.md, "Design measurements").
    pub const PARALLEL_MIN_ENTRIES: usize = 20_000;

    /// Builds and factors the operators for a surface (vertices in m, any consistent orientation).
    ///
    /// # Errors
    /// [`GeodesicError`] for an empty surface, bad indices, degenerate triangles, or a failed
    /// factorisation (e.g. unused vertices).
    pub fn new(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self, GeodesicError> {
        Self::with_ordering(vertices, triangles, None)
    }

    /// As [`HeatGeodesic::new`], with a fill-reducing vertex ordering computed elsewhere
    /// (`order[i]` = the vertex eliminated i-th), e.g. stored in the base by the bake;
    /// `None` computes AMD here.
    ///
    /// # Errors
    /// As [`HeatGeodesic::new`], and [`GeodesicError::BadOrdering`] if `order` is not a
    /// permutation of the vertices.
    pub fn with_ordering(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        order: Option<&[u32]>,
    ) -> Result<Self, GeodesicError> {
        let asm = Assembly::new(vertices, triangles)?;
        let n = vertices.len();
        let symbolic = Self::symbolic(&asm, order)?;
        let SymbolicCholeskyRaw::Simplicial(simp) = symbolic.raw() else {
            unreachable!("simplicial factorisation forced")
        };
        let pattern = Pattern::new(simp.col_ptr().to_vec(), simp.row_idx().to_vec());
        let (perm, iperm) = match symbolic.perm() {
            Some(p) => (p.arrays().0.to_vec(), p.arrays().1.to_vec()),
            None => ((0..n as u32).collect(), (0..n as u32).collect()),
        };
        let vals = factor_operators(&asm, &pattern, &perm, &iperm)?;
        let layout = Layout::new(&pattern);
        let spos = iperm
            .iter()
            .map(|&k| layout.position(k as usize) as u32)
            .collect();
        // Faces grouped by owner (a face never has vertices in both halves: no entry couples
        // them), in their original order within a group.
        let owner: Vec<usize> = triangles
            .iter()
            .map(|t| {
                t.iter()
                    .map(|&v| layout.group(iperm[v as usize] as usize))
                    .min()
                    .expect("three corners")
            })
            .collect();
        let mut face_ptr = [0usize; 4];
        for &g in &owner {
            face_ptr[g + 1] += 1;
        }
        for g in 0..3 {
            face_ptr[g + 1] += face_ptr[g];
        }
        let mut next = face_ptr;
        let mut order = vec![0usize; triangles.len()];
        for (f, &g) in owner.iter().enumerate() {
            order[next[g]] = f;
            next[g] += 1;
        }
        let faces = order
            .iter()
            .map(|&f| {
                let g = owner[f];
                triangles[f].map(|v| layout.local_position(g, iperm[v as usize] as usize) as u32)
            })
            .collect();
        let gram = order.iter().map(|&f| asm.gram[f]).collect();
        Ok(HeatGeodesic {
            n,
            triangles: triangles.to_vec(),
            faces,
            gram,
            face_ptr,
            layout,
            spos,
            symbolic,
            heat: Factor::new(&pattern, vals.iter().map(|v| v[0]).collect()),
            poisson: Factor::new(&pattern, vals.iter().map(|v| v[1]).collect()),
            perm,
            mean_edge: asm.mean_edge,
            source_scale: source_scale(&asm.mass),
        })
    }

    /// The surface Laplacian's sparsity as a symmetric graph, in the layout graph partitioners
    /// take (METIS `xadj`/`adjncy`): vertex v's neighbours are
    /// `neighbours[offsets[v]..offsets[v + 1]]`, ascending, without v itself. What a baker
    /// orders to plan the `surface_order` a base stores for [`HeatGeodesic::with_ordering`].
    ///
    /// # Errors
    /// As [`HeatGeodesic::new`].
    pub fn laplacian_graph(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> Result<(Vec<usize>, Vec<usize>), GeodesicError> {
        let asm = Assembly::new(vertices, triangles)?;
        let n = vertices.len();
        let col_ptr: Vec<usize> = asm.col_ptr.iter().map(|&p| p as usize).collect();
        let row_idx: Vec<usize> = asm.row_idx.iter().map(|&r| r as usize).collect();
        // Both triangles of the adjacency; the assembly holds the lower one.
        let mut offsets = vec![0usize; n + 1];
        for c in 0..n {
            for &r in &row_idx[col_ptr[c]..col_ptr[c + 1]] {
                if r != c {
                    offsets[r + 1] += 1;
                    offsets[c + 1] += 1;
                }
            }
        }
        for v in 0..n {
            offsets[v + 1] += offsets[v];
        }
        let mut next = offsets.clone();
        let mut neighbours = vec![0usize; offsets[n]];
        for c in 0..n {
            for &r in &row_idx[col_ptr[c]..col_ptr[c + 1]] {
                if r != c {
                    neighbours[next[r]] = c;
                    next[r] += 1;
                    neighbours[next[c]] = r;
                    next[c] += 1;
                }
            }
        }
        Ok((offsets, neighbours))
    }

    /// The elimination order and the number of stored factor entries of the Laplacian's
    /// Cholesky factor under `order` (`None`: AMD, as [`HeatGeodesic::new`] computes it), from
    /// the symbolic analysis alone: what a baker compares to choose the stored order.
    ///
    /// # Errors
    /// As [`HeatGeodesic::with_ordering`].
    pub fn ordering_fill(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        order: Option<&[u32]>,
    ) -> Result<(Vec<u32>, usize), GeodesicError> {
        let asm = Assembly::new(vertices, triangles)?;
        let symbolic = Self::symbolic(&asm, order)?;
        let used: Vec<u32> = match (order, symbolic.perm()) {
            (Some(o), _) => o.to_vec(),
            (None, Some(p)) => p.arrays().0.to_vec(),
            (None, None) => (0..vertices.len() as u32).collect(),
        };
        Ok((used, symbolic.len_val()))
    }

    /// Simplicial symbolic Cholesky of the Laplacian's pattern (faer), under `order` or AMD.
    fn symbolic(
        asm: &Assembly,
        order: Option<&[u32]>,
    ) -> Result<SymbolicCholesky<u32>, GeodesicError> {
        let n = asm.mass.len();
        let lap = SymbolicSparseColMatRef::new_checked(n, n, &asm.col_ptr, None, &asm.row_idx);
        let inverse;
        let ordering = match order {
            None => SymmetricOrdering::Amd,
            Some(fwd) => {
                inverse = inverse_permutation(fwd, n).ok_or(GeodesicError::BadOrdering)?;
                SymmetricOrdering::Custom(PermRef::new_checked(fwd, &inverse, n))
            }
        };
        factorize_symbolic_cholesky(
            lap,
            Side::Lower,
            ordering,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                ..Default::default()
            },
        )
        .map_err(|e| GeodesicError::Factorization(format!("{e:?}")))
    }

    /// Stored values of the Cholesky factor (fill), for diagnostics.
    pub fn factor_len(&self) -> usize {
        self.symbolic.len_val()
    }

    /// The vertex elimination order of the factor (`order[k]` = the vertex eliminated k-th), as
    /// [`HeatGeodesic::with_ordering`] takes it.
    pub fn elimination_order(&self) -> &[u32] {
        &self.perm
    }

    /// Whether the elimination order splits the solves into two independent halves, so that
    /// [`HeatWorkspace::set_parallel`] queries can use two threads (nested-dissection orders,
    /// e.g. a base's stored `surface_order`, do; AMD orders do not).
    pub fn splits_in_two(&self) -> bool {
        self.layout.is_split()
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.n
    }

    /// Mean edge length (m); the heat time step is its square.
    pub fn mean_edge_length(&self) -> f64 {
        self.mean_edge
    }

    /// Scratch sized for this surface (allocate once, reuse for allocation-free queries).
    pub fn workspace(&self) -> HeatWorkspace {
        HeatWorkspace {
            u: vec![0.0; self.layout.len()],
            x: vec![0.0; self.layout.len()],
            parallel: false,
        }
    }

    /// Distances (m) from vertex `v` to every vertex, written to `out` (length ns).
    ///
    /// # Panics
    /// If `v` ≥ ns or `out.len()` ≠ ns.
    pub fn distances_from_vertex(&self, v: usize, out: &mut [f64]) {
        assert!(v < self.n, "vertex {v} out of range");
        let mut ws = self.workspace();
        self.distances_with(&[(v, 1.0)], out, &mut ws);
    }

    /// As [`HeatGeodesic::distances_from_vertex`] with caller-owned scratch: does not allocate.
    ///
    /// # Panics
    /// If `v` ≥ ns or `out.len()` ≠ ns.
    pub fn distances_from_vertex_with(&self, v: usize, out: &mut [f64], ws: &mut HeatWorkspace) {
        assert!(v < self.n, "vertex {v} out of range");
        self.distances_with(&[(v, 1.0)], out, ws);
    }

    /// Distances (m) from a surface point (its triangle and barycentric weights; the triangle
    /// indexes the `triangles` this was built with) to every vertex, written to `out`.
    ///
    /// # Panics
    /// If `out.len()` ≠ ns or the triangle is out of range.
    pub fn distances_from_point(&self, sp: &SurfacePoint, out: &mut [f64]) {
        let mut ws = self.workspace();
        self.distances_from_point_with(sp, out, &mut ws);
    }

    /// As [`HeatGeodesic::distances_from_point`] with caller-owned scratch: does not allocate.
    pub fn distances_from_point_with(
        &self,
        sp: &SurfacePoint,
        out: &mut [f64],
        ws: &mut HeatWorkspace,
    ) {
        let tri = self.triangles[sp.triangle as usize];
        let src = [0, 1, 2].map(|i| (tri[i] as usize, sp.bary[i]));
        self.distances_with(&src, out, ws);
    }

    /// Core: heat from a weighted vertex source, normalised gradient, divergence, Poisson, shift;
    /// all in storage order until the final gather to `out`. The heat u falls by about e⁻⁰·⁸
    /// per mean edge length away from the source (t = h²), so the source is scaled up (by a
    /// power of two: the normalised gradient keeps its bits) to put the peak near 1e140, and
    /// [`divergence`] rescales faces whose |A∇u|² leaves [1e-290, 1e290]: directions hold until
    /// u nears the bottom of the double range, 1,050–1,250 edge lengths from the source on a
    /// 1 cm strip (unscaled and unrescaled they failed beyond ≈ 450, where |A∇u|² underflowed).
    /// With a [`Layout`] split, the
    /// halves' sweeps and face loops run as two independent tasks (on two threads when the
    /// workspace allows) between the top block's sweeps.
    fn distances_with(&self, source: &[(usize, f64)], out: &mut [f64], ws: &mut HeatWorkspace) {
        assert_eq!(out.len(), self.n);
        let (u, b) = (&mut ws.u, &mut ws.x);
        let (heat, poisson) = (&self.heat, &self.poisson);
        let (top, fp) = (&self.layout.top, &self.face_ptr);
        u.iter_mut().for_each(|x| *x = 0.0);
        b.iter_mut().for_each(|x| *x = 0.0);
        for &(v, w) in source {
            u[self.spos[v] as usize] += w * self.source_scale;
        }
        let faces_of = |g: usize| (&self.faces[fp[g]..fp[g + 1]], &self.gram[fp[g]..fp[g + 1]]);
        match (
            &self.layout.halves,
            self.layout.split_mut(u),
            self.layout.split_mut(b),
        ) {
            (Some(halves), (Some([u0, u1]), ut), (Some([b0, b1]), bt)) => {
                let (n0, n1) = (halves[0].len(), halves[1].len());
                // Heat: the halves' forward sweeps walk only the source's ancestors (cheap,
                // serial); then the top block, whose solution both halves read.
                halves[0].sweep(Direction::Forward, &heat.vals, &heat.inv_diag, u0);
                halves[1].sweep(Direction::Forward, &heat.vals, &heat.inv_diag, u1);
                merge_top(ut, &u0[n0..], &u1[n1..]);
                top.sweep(Direction::Forward, &heat.vals, &heat.inv_diag, ut);
                top.sweep(Direction::Backward, &heat.vals, &heat.inv_diag, ut);
                u0[n0..].copy_from_slice(ut);
                u1[n1..].copy_from_slice(ut);
                // Per half: the rest of the heat solve, its faces' divergence, its part of the
                // Poisson forward sweep (contributions to the top block land in its copy).
                let half = |h: usize, uh: &mut [f64], bh: &mut [f64]| {
                    halves[h].sweep(Direction::Backward, &heat.vals, &heat.inv_diag, uh);
                    let (faces, gram) = faces_of(h);
                    divergence(faces, gram, uh, bh);
                    halves[h].sweep(Direction::Forward, &poisson.vals, &poisson.inv_diag, bh);
                };
                let parallel = ws.parallel && self.factor_len() >= Self::PARALLEL_MIN_ENTRIES;
                fork(parallel, || half(0, u0, b0), || half(1, u1, b1));
                let (faces, gram) = faces_of(2);
                divergence(faces, gram, ut, bt);
                merge_top(bt, &b0[n0..], &b1[n1..]);
                top.sweep(Direction::Forward, &poisson.vals, &poisson.inv_diag, bt);
                top.sweep(Direction::Backward, &poisson.vals, &poisson.inv_diag, bt);
                b0[n0..].copy_from_slice(bt);
                b1[n1..].copy_from_slice(bt);
                let back = |h: usize, bh: &mut [f64]| {
                    halves[h].sweep(Direction::Backward, &poisson.vals, &poisson.inv_diag, bh)
                };
                fork(parallel, || back(0, b0), || back(1, b1));
            }
            (_, (_, ut), (_, bt)) => {
                top.sweep(Direction::Forward, &heat.vals, &heat.inv_diag, ut);
                top.sweep(Direction::Backward, &heat.vals, &heat.inv_diag, ut);
                let (faces, gram) = faces_of(2);
                divergence(faces, gram, ut, bt);
                top.sweep(Direction::Forward, &poisson.vals, &poisson.inv_diag, bt);
                top.sweep(Direction::Backward, &poisson.vals, &poisson.inv_diag, bt);
            }
        }
        let shift: f64 = source
            .iter()
            .map(|&(v, w)| w * b[self.spos[v] as usize])
            .sum();
        for (o, &p) in out.iter_mut().zip(&self.spos) {
            *o = (b[p as usize] - shift).max(0.0);
        }
    }

    /// `rhs ← A⁻¹ rhs` (original vertex order) through the permuted factor, for tests:
    /// `which` 0 = heat, 1 = Poisson.
    #[cfg(test)]
    pub(crate) fn solve_own(&self, which: usize, rhs: &mut [f64], x: &mut Vec<f64>) {
        let factor = [&self.heat, &self.poisson][which];
        x.clear();
        x.resize(self.layout.len(), 0.0);
        for (&r, &p) in rhs.iter().zip(&self.spos) {
            x[p as usize] = r;
        }
        self.layout.solve(&factor.vals, &factor.inv_diag, x);
        for (r, &p) in rhs.iter_mut().zip(&self.spos) {
            *r = x[p as usize];
        }
    }

    /// Factor values by index, for tests: `which` 0 = heat, 1 = Poisson.
    #[cfg(test)]
    pub(crate) fn factor(&self, which: usize) -> &[f64] {
        &[&self.heat, &self.poisson][which].vals
    }

    /// faer's solve on the same factor (the implementation [`Pattern::solve`] replaced), for
    /// tests and the timing probe: `which` 0 = heat, 1 = Poisson.
    #[cfg(test)]
    pub(crate) fn solve_faer(&self, which: usize, rhs: &mut [f64]) {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::sparse::linalg::cholesky::LltRef;
        use faer::Par;
        let mut buf = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        LltRef::<u32, f64>::new(&self.symbolic, self.factor(which)).solve_in_place_with_conj(
            faer::Conj::No,
            faer::MatMut::from_column_major_slice_mut(rhs, self.n, 1),
            Par::Seq,
            MemStack::new(&mut buf),
        );
    }

    /// faer's numeric factors (the implementation [`Pattern::factor_pair`] replaced) of the two
    /// operators of the surface this was built from, on the same symbolic analysis, for tests
    /// and the timing probe: `[heat, poisson]` values in the factor's pattern order.
    #[cfg(test)]
    pub(crate) fn factors_faer(
        &self,
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> [Vec<f64>; 2] {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::sparse::{SparseColMat, SymbolicSparseColMat};
        use faer::Par;
        let asm = Assembly::new(vertices, triangles).unwrap();
        let n = self.n;
        let t = asm.mean_edge * asm.mean_edge;
        [(t, 1.0), (1.0, 1e-8 / t)].map(|(a, b)| {
            let mut val: Vec<f64> = asm.val.iter().map(|v| a * v).collect();
            for c in 0..n {
                // The diagonal leads each column.
                val[asm.col_ptr[c] as usize] += b * asm.mass[c];
            }
            let pat = SymbolicSparseColMat::new_checked(
                n,
                n,
                asm.col_ptr.clone(),
                None,
                asm.row_idx.clone(),
            );
            let mat = SparseColMat::new(pat, val);
            let mut buf = MemBuffer::new(
                self.symbolic
                    .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            );
            let mut values = vec![0.0; self.symbolic.len_val()];
            self.symbolic
                .factorize_numeric_llt::<f64>(
                    &mut values,
                    mat.as_ref(),
                    Side::Lower,
                    Default::default(),
                    Par::Seq,
                    MemStack::new(&mut buf),
                    Default::default(),
                )
                .unwrap();
            values
        })
    }
}

/// The heat method's two operators factored three ways on one surface and elimination order,
/// for the `sparse_llt` benchmark (feature `bench-internals`): the hand-written left-looking
/// factor (`sparse_llt::Pattern::factor_pair`) with its solves, faer's simplicial numeric factor on the
/// same symbolic analysis, and faer's own choice (supernodal when its flop-ratio threshold
/// says so) under the same order. Not part of the runtime's API.
#[cfg(feature = "bench-internals")]
#[doc(hidden)]
pub struct LltProbe {
    asm: Assembly,
    perm: Vec<u32>,
    iperm: Vec<u32>,
    /// [simplicial (the runtime's), faer's default threshold].
    symbolic: [SymbolicCholesky<u32>; 2],
    /// (M + tL), (L + εM), lower triangles, original vertex order.
    mats: [faer::sparse::SparseColMat<u32, f64>; 2],
    own: Option<(Layout, [Factor; 2])>,
    /// faer's factors per symbolic: `[heat, poisson]` values.
    faer: [[Vec<f64>; 2]; 2],
}

#[cfg(feature = "bench-internals")]
impl LltProbe {
    /// Assembles the operators and runs both symbolic analyses under `order` (`None`: AMD).
    ///
    /// # Errors
    /// As [`HeatGeodesic::with_ordering`].
    pub fn new(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        order: Option<&[u32]>,
    ) -> Result<Self, GeodesicError> {
        use faer::sparse::{SparseColMat, SymbolicSparseColMat};
        let asm = Assembly::new(vertices, triangles)?;
        let n = vertices.len();
        let simplicial = HeatGeodesic::symbolic(&asm, order)?;
        let (perm, iperm) = match simplicial.perm() {
            Some(p) => (p.arrays().0.to_vec(), p.arrays().1.to_vec()),
            None => ((0..n as u32).collect(), (0..n as u32).collect()),
        };
        let lap = SymbolicSparseColMatRef::new_checked(n, n, &asm.col_ptr, None, &asm.row_idx);
        let auto = factorize_symbolic_cholesky(
            lap,
            Side::Lower,
            SymmetricOrdering::Custom(PermRef::new_checked(&perm, &iperm, n)),
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| GeodesicError::Factorization(format!("{e:?}")))?;
        let t = asm.mean_edge * asm.mean_edge;
        let mats = [(t, 1.0), (1.0, 1e-8 / t)].map(|(a, b)| {
            let mut val: Vec<f64> = asm.val.iter().map(|v| a * v).collect();
            for c in 0..n {
                val[asm.col_ptr[c] as usize] += b * asm.mass[c];
            }
            let pat = SymbolicSparseColMat::new_checked(
                n,
                n,
                asm.col_ptr.clone(),
                None,
                asm.row_idx.clone(),
            );
            SparseColMat::new(pat, val)
        });
        Ok(LltProbe {
            asm,
            perm,
            iperm,
            symbolic: [simplicial, auto],
            mats,
            own: None,
            faer: Default::default(),
        })
    }

    /// Vertices, stored factor entries (the runtime's simplicial pattern), whether faer's
    /// default analysis chose a supernodal factor, and its stored entries.
    pub fn info(&self) -> (usize, usize, bool, usize) {
        let sn = matches!(self.symbolic[1].raw(), SymbolicCholeskyRaw::Supernodal(_));
        (
            self.perm.len(),
            self.symbolic[0].len_val(),
            sn,
            self.symbolic[1].len_val(),
        )
    }

    /// The runtime's numeric set-up of both factors: pattern, left-looking factor, layout.
    pub fn factor_own(&mut self) {
        let SymbolicCholeskyRaw::Simplicial(simp) = self.symbolic[0].raw() else {
            unreachable!("simplicial factorisation forced")
        };
        let pattern = Pattern::new(simp.col_ptr().to_vec(), simp.row_idx().to_vec());
        let vals = factor_operators(&self.asm, &pattern, &self.perm, &self.iperm)
            .expect("positive definite operators");
        let layout = Layout::new(&pattern);
        let factors = [0, 1].map(|k| Factor::new(&pattern, vals.iter().map(|v| v[k]).collect()));
        self.own = Some((layout, factors));
    }

    /// faer's numeric factors of both operators: on the runtime's simplicial analysis
    /// (`supernodal` false) or on faer's default one (true).
    pub fn factor_faer(&mut self, supernodal: bool) {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::Par;
        let s = usize::from(supernodal);
        let sym = &self.symbolic[s];
        let mut buf =
            MemBuffer::new(sym.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
        for k in 0..2 {
            let mut values = vec![0.0; sym.len_val()];
            sym.factorize_numeric_llt::<f64>(
                &mut values,
                self.mats[k].as_ref(),
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut buf),
                Default::default(),
            )
            .expect("positive definite operators");
            self.faer[s][k] = values;
        }
    }

    /// `rhs ← A⁻¹ rhs` (original vertex order) with the runtime's factor and serial solves
    /// (`which` 0 = heat, 1 = Poisson); `x` is scratch. Call [`LltProbe::factor_own`] first.
    pub fn solve_own(&self, which: usize, rhs: &mut [f64], x: &mut Vec<f64>) {
        let (layout, factors) = self.own.as_ref().expect("factor_own first");
        let f = &factors[which];
        x.clear();
        x.resize(layout.len(), 0.0);
        for (v, &r) in rhs.iter().enumerate() {
            x[layout.position(self.iperm[v] as usize)] = r;
        }
        layout.solve(&f.vals, &f.inv_diag, x);
        for (v, r) in rhs.iter_mut().enumerate() {
            *r = x[layout.position(self.iperm[v] as usize)];
        }
    }

    /// `rhs ← A⁻¹ rhs` with faer's factor and `solve_in_place_with_conj` (serial). Call
    /// [`LltProbe::factor_faer`] with the same `supernodal` first.
    pub fn solve_faer(&self, supernodal: bool, which: usize, rhs: &mut [f64]) {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::sparse::linalg::cholesky::LltRef;
        use faer::Par;
        let s = usize::from(supernodal);
        let sym = &self.symbolic[s];
        let mut buf = MemBuffer::new(sym.solve_in_place_scratch::<f64>(1, Par::Seq));
        LltRef::<u32, f64>::new(sym, &self.faer[s][which]).solve_in_place_with_conj(
            faer::Conj::No,
            faer::MatMut::from_column_major_slice_mut(rhs, self.perm.len(), 1),
            Par::Seq,
            MemStack::new(&mut buf),
        );
    }
}

/// The numeric factors of (M + tL) and (L + εM) (t = mean edge², ε = 1e-8/t) on `pattern`,
/// as `[heat, poisson]` pairs in pattern order: both operators' lower triangles, permuted by
/// `iperm` (vertex → factor row), scattered into the pattern, then factored in one sweep
/// ([`Pattern::factor_pair`]).
fn factor_operators(
    asm: &Assembly,
    pattern: &Pattern,
    perm: &[u32],
    iperm: &[u32],
) -> Result<Vec<[f64; 2]>, GeodesicError> {
    let n = asm.mass.len();
    let t = asm.mean_edge * asm.mean_edge;
    let eps = 1e-8 / t;
    let mut vals = vec![[0.0f64; 2]; pattern.row_idx.len()];
    for c in 0..n {
        for q in asm.col_ptr[c] as usize..asm.col_ptr[c + 1] as usize {
            let (r, lv) = (asm.row_idx[q] as usize, asm.val[q]);
            let (pr, pc) = (iperm[r], iperm[c]);
            let m = if r == c { asm.mass[c] } else { 0.0 };
            vals[pattern.position(pr.max(pc), pr.min(pc))] = [t * lv + m, lv + eps * m];
        }
    }
    let mut w = vec![[0.0f64; 2]; n];
    pattern.factor_pair(&mut vals, &mut w).map_err(|j| {
        GeodesicError::Factorization(format!("pivot of vertex {} is not positive", perm[j]))
    })?;
    Ok(vals)
}

/// The power of two nearest 1e140 × (smallest lumped vertex mass, m²): the heat solution of a
/// unit source peaks near 1/(its vertex mass), so a source scaled by this peaks at ≤ ≈ 1e140,
/// where |A∇u|² (≈ u²·h²) cannot overflow.
fn source_scale(mass: &[f64]) -> f64 {
    let m = mass.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let e = (1e140 * m).log2().round().clamp(-1000.0, 1000.0);
    2f64.powi(e as i32)
}

/// Runs two independent tasks, on two threads (`rayon::join`) if `parallel`.
fn fork(parallel: bool, a: impl FnOnce() + Send, b: impl FnOnce() + Send) {
    if parallel {
        rayon::join(a, b);
    } else {
        a();
        b();
    }
}

/// Integrated divergence of the normalised heat gradient, b_i += Σ_f A_f X_f·∇φ_i with
/// X = −∇u/|∇u|, over `faces` (positions in `u`, `b`) and their Gram data (see
/// [`HeatGeodesic`]). With d_i = u_i − u₀ and g_i = A∇φ_i: A∇u = d₁g₁ + d₂g₂, and
/// b_i += X·g_i (b₀ gets minus the other two) needs only the Gram matrix of g₁, g₂.
fn divergence(faces: &[[u32; 3]], gram: &[[f64; 3]], u: &[f64], b: &mut [f64]) {
    // |A∇u|² inside these bounds neither underflowed nor overflowed.
    const TINY: f64 = 1e-290;
    const HUGE: f64 = 1e290;
    for (f, g) in faces.iter().zip(gram) {
        let [a0, a1, a2] = f.map(|v| v as usize);
        let u0 = u[a0];
        let (mut d1, mut d2) = (u[a1] - u0, u[a2] - u0);
        let mut p1 = d1 * g[0] + d2 * g[1];
        let mut p2 = d1 * g[1] + d2 * g[2];
        let mut len2 = d1 * p1 + d2 * p2;
        if !(len2 > TINY && len2 < HUGE) {
            // Far from the source (u tiny): the direction from the rescaled differences.
            let m = d1.abs().max(d2.abs());
            if !(m > 0.0 && m.is_finite()) {
                continue; // flat: no direction
            }
            (d1, d2) = (d1 / m, d2 / m);
            p1 = d1 * g[0] + d2 * g[1];
            p2 = d1 * g[1] + d2 * g[2];
            len2 = d1 * p1 + d2 * p2;
            if !(len2 > 0.0) {
                continue;
            }
        }
        let inv = 1.0 / len2.sqrt();
        let (c1, c2) = (p1 * inv, p2 * inv);
        b[a0] += c1 + c2;
        b[a1] -= c1;
        b[a2] -= c2;
    }
}

/// The inverse of `fwd` if it is a permutation of `0..n`.
fn inverse_permutation(fwd: &[u32], n: usize) -> Option<Vec<u32>> {
    if fwd.len() != n {
        return None;
    }
    let mut inv = vec![u32::MAX; n];
    for (k, &v) in fwd.iter().enumerate() {
        let slot = inv.get_mut(v as usize)?;
        if *slot != u32::MAX {
            return None;
        }
        *slot = k as u32;
    }
    Some(inv)
}

/// The cotan Laplacian's lower triangle (CSC, original vertex order, diagonal first, rows
/// ascending), lumped mass and per-face gradient data of a surface.
struct Assembly {
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    /// L values (m⁰): diagonal Σ w, off-diagonal −w, w = ½(cot α + cot β) summed over faces.
    val: Vec<f64>,
    /// Lumped vertex mass (m²).
    mass: Vec<f64>,
    /// Per face: ¼[e₁·e₁, e₁·e₂, e₂·e₂] (m²), see [`HeatGeodesic`].
    gram: Vec<[f64; 3]>,
    /// Mean edge length (m).
    mean_edge: f64,
}

impl Assembly {
    /// Per face: geometry checks, mass, gradient data, three cotan half-edge weights; then the
    /// half-edges bucketed by their lower vertex and merged (no triplet sort).
    fn new(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self, GeodesicError> {
        let n = vertices.len();
        if n == 0 || triangles.is_empty() {
            return Err(GeodesicError::Empty);
        }
        let mut mass = vec![0.0; n];
        let mut gram = Vec::with_capacity(triangles.len());
        // (lower vertex, upper vertex, w) per face corner's opposite edge.
        let mut half: Vec<(u32, u32, f64)> = Vec::with_capacity(triangles.len() * 3);
        let mut edge_sum = 0.0;
        for (f, tri) in triangles.iter().enumerate() {
            if tri.iter().any(|&i| i as usize >= n) {
                return Err(GeodesicError::BadIndex {
                    triangle: f,
                    vertices: n,
                });
            }
            let x = tri.map(|i| vertices[i as usize]);
            // e[i]: edge opposite corner i, counter-clockwise.
            let e = [sub(x[2], x[1]), sub(x[0], x[2]), sub(x[1], x[0])];
            let nn = cross(e[2], sub(x[2], x[0]));
            let two_a = norm(nn);
            let scale_len = dot(e[0], e[0]) + dot(e[1], e[1]) + dot(e[2], e[2]);
            if !(two_a > 1e-12 * scale_len) {
                return Err(GeodesicError::Degenerate {
                    triangle: f,
                    area: 0.5 * two_a,
                });
            }
            edge_sum += norm(e[0]) + norm(e[1]) + norm(e[2]);
            gram.push([
                0.25 * dot(e[1], e[1]),
                0.25 * dot(e[1], e[2]),
                0.25 * dot(e[2], e[2]),
            ]);
            for &v in tri {
                mass[v as usize] += two_a / 6.0;
            }
            // Cotangent of corner i = (e_j · e_k)/(2A) with the two edges leaving corner i.
            for i in 0..3 {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                let w = -0.5 * dot(e[j], e[k]) / two_a;
                let (a, b) = (tri[j], tri[k]);
                half.push((a.min(b), a.max(b), w));
            }
        }
        let mean_edge = edge_sum / (3.0 * triangles.len() as f64);
        // Bucket the half-edges by lower vertex (column).
        let mut start = vec![0u32; n + 1];
        for h in &half {
            start[h.0 as usize + 1] += 1;
        }
        for c in 0..n {
            start[c + 1] += start[c];
        }
        let mut next = start.clone();
        let mut bucket = vec![(0u32, 0.0f64); half.len()];
        for &(lo, hi, w) in &half {
            bucket[next[lo as usize] as usize] = (hi, w);
            next[lo as usize] += 1;
        }
        // Per column: diagonal, then the merged rows ascending.
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(n + half.len());
        let mut val = Vec::with_capacity(n + half.len());
        let mut diag = vec![0.0; n];
        col_ptr.push(0u32);
        for c in 0..n {
            let seg = &mut bucket[start[c] as usize..start[c + 1] as usize];
            seg.sort_unstable_by_key(|&(r, _)| r);
            row_idx.push(c as u32);
            val.push(0.0); // the diagonal, set once every column has contributed
            for &(r, w) in seg.iter() {
                if *row_idx.last().expect("diagonal pushed") == r {
                    *val.last_mut().expect("diagonal pushed") -= w;
                } else {
                    row_idx.push(r);
                    val.push(-w);
                }
                diag[c] += w;
                diag[r as usize] += w;
            }
            col_ptr.push(row_idx.len() as u32);
        }
        for c in 0..n {
            val[col_ptr[c] as usize] = diag[c];
        }
        Ok(Assembly {
            col_ptr,
            row_idx,
            val,
            mass,
            gram,
            mean_edge,
        })
    }
}
