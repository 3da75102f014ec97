//! P1 (4-node) and P2 (10-node, straight-sided) tetrahedron stiffness and mass assembly with a
//! deterministic summation order.
//!
//! P2 element matrices are integrated exactly: the stiffness integrand (products of linear
//! shape-function gradients, degree 2) with the symmetric 4-point rule (degree 2), the
//! consistent mass (products of quadratic shape functions, degree 4) in closed form from
//! ∫ L₀^a L₁^b L₂^c L₃^d dV = 6V a! b! c! d! / (a+b+c+d+3)! (`p2_mass_ref`). The lumped P2
//! mass is the HRZ diagonal (the consistent diagonal scaled to the element mass: corners
//! 6/216, mid-edge nodes 32/216 of ρV), because row-sum lumping gives corners negative mass.
//!
//! The sparsity pattern is built once from the node graph (two nodes are adjacent when they
//! share a tetrahedron). Column block `3a..3a+3` of node `a` is one contiguous slice of the value
//! array, so nodes are assembled in parallel (rayon) on disjoint slices, and inside a node the
//! element contributions are summed in ascending tetrahedron order. The result is therefore
//! bit-identical for any number of threads, and the stored matrices are bit-exactly symmetric
//! (entry `(r, c)` and `(c, r)` see the same products summed in the same order).

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use rayon::prelude::*;

use super::{DofMap, DofMapError, Material};
use crate::mesh::{TetMesh, TET10_EDGES};

/// Node adjacency and node → tetrahedron incidence of a mesh.
pub(crate) struct NodeGraph {
    /// `adj[adj_ptr[a]..adj_ptr[a+1]]`: sorted neighbours of node `a`, including `a` itself.
    pub adj_ptr: Vec<usize>,
    pub adj: Vec<usize>,
    /// `inc[inc_ptr[a]..inc_ptr[a+1]]`: `(tet, local vertex)` pairs of node `a`, ascending tet.
    pub inc_ptr: Vec<usize>,
    pub inc: Vec<(u32, u8)>,
}

/// Nodes per rayon task in the per-node loops: enough work per task that the per-task
/// scratch (one mark per mesh node) costs little.
const NODES_PER_TASK: usize = 256;

/// Marks of a per-node neighbour scatter: `UNMARKED` or the position in the node's list.
const UNMARKED: u32 = u32::MAX;

impl NodeGraph {
    pub fn new(mesh: &TetMesh) -> NodeGraph {
        let n = mesh.nodes.len();
        let npe = mesh.nodes_per_tet();
        let mut inc_ptr = vec![0usize; n + 1];
        for t in 0..mesh.tets.len() {
            for &v in &mesh.tet_nodes(t)[..npe] {
                inc_ptr[v + 1] += 1;
            }
        }
        for a in 0..n {
            inc_ptr[a + 1] += inc_ptr[a];
        }
        let mut fill = inc_ptr.clone();
        let mut inc = vec![(0u32, 0u8); inc_ptr[n]];
        for ti in 0..mesh.tets.len() {
            for (p, &v) in mesh.tet_nodes(ti)[..npe].iter().enumerate() {
                inc[fill[v]] = (ti as u32, p as u8);
                fill[v] += 1;
            }
        }
        // Each node's distinct neighbours through a mark array (each neighbour appears in
        // ~6 of the node's tetrahedra), so only the distinct ones are sorted.
        let lists: Vec<Vec<usize>> = (0..n)
            .into_par_iter()
            .with_min_len(NODES_PER_TASK)
            .map_init(
                || vec![false; n],
                |seen, a| {
                    let mut l: Vec<usize> = Vec::with_capacity(32);
                    seen[a] = true;
                    l.push(a);
                    for &(t, _) in &inc[inc_ptr[a]..inc_ptr[a + 1]] {
                        for &b in &mesh.tet_nodes(t as usize)[..npe] {
                            if !seen[b] {
                                seen[b] = true;
                                l.push(b);
                            }
                        }
                    }
                    for &b in &l {
                        seen[b] = false;
                    }
                    l.sort_unstable();
                    l
                },
            )
            .collect();
        let mut adj_ptr = Vec::with_capacity(n + 1);
        adj_ptr.push(0);
        let mut adj = Vec::with_capacity(lists.iter().map(Vec::len).sum());
        for l in &lists {
            adj.extend_from_slice(l);
            adj_ptr.push(adj.len());
        }
        NodeGraph {
            adj_ptr,
            adj,
            inc_ptr,
            inc,
        }
    }

    fn incidences(&self, a: usize) -> &[(u32, u8)] {
        &self.inc[self.inc_ptr[a]..self.inc_ptr[a + 1]]
    }
}

/// The node-level pattern of the matrices restricted to the kept (free) nodes: the kept
/// nodes in ascending order and, for each, its kept neighbours (ascending). With no node
/// fixed it is the whole node graph.
struct KeptPattern {
    /// Mesh node of each kept node, ascending.
    kept: Vec<usize>,
    /// Kept index of each mesh node, `usize::MAX` when fixed.
    index: Vec<usize>,
    /// `nb[ptr[k]..ptr[k+1]]`: kept neighbours (mesh node indices, ascending) of kept node k.
    ptr: Vec<usize>,
    nb: Vec<usize>,
}

impl KeptPattern {
    /// `fixed`: strictly ascending mesh node indices, all `< n` (checked by [`DofMap::new`]).
    fn new(graph: &NodeGraph, fixed: &[usize]) -> KeptPattern {
        let n = graph.adj_ptr.len() - 1;
        let mut index = vec![0usize; n];
        for &v in fixed {
            index[v] = usize::MAX;
        }
        let mut kept = Vec::with_capacity(n - fixed.len());
        for (v, slot) in index.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = kept.len();
                kept.push(v);
            }
        }
        let mut ptr = Vec::with_capacity(kept.len() + 1);
        ptr.push(0);
        let mut nb = Vec::with_capacity(graph.adj.len());
        for &a in &kept {
            let all = &graph.adj[graph.adj_ptr[a]..graph.adj_ptr[a + 1]];
            nb.extend(all.iter().copied().filter(|&b| index[b] != usize::MAX));
            ptr.push(nb.len());
        }
        KeptPattern {
            kept,
            index,
            ptr,
            nb,
        }
    }

    fn neighbours(&self, k: usize) -> &[usize] {
        &self.nb[self.ptr[k]..self.ptr[k + 1]]
    }

    /// CSC pattern on the `3·kept` dofs (node-major). `full_blocks`: every node pair couples
    /// all 3×3 axis pairs (stiffness); otherwise only equal axes (consistent mass).
    fn dof_pattern(&self, full_blocks: bool) -> SymbolicSparseColMat<usize> {
        let n = self.kept.len();
        let per = if full_blocks { 3 } else { 1 };
        let mut col_ptr = Vec::with_capacity(3 * n + 1);
        let mut row_idx = Vec::with_capacity(3 * per * self.nb.len());
        col_ptr.push(0);
        for k in 0..n {
            for i in 0..3 {
                for &b in self.neighbours(k) {
                    let r = 3 * self.index[b];
                    if full_blocks {
                        row_idx.extend_from_slice(&[r, r + 1, r + 2]);
                    } else {
                        row_idx.push(r + i);
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        SymbolicSparseColMat::new_checked(3 * n, 3 * n, col_ptr, None, row_idx)
    }

    /// Splits `values` into the per-kept-node column-block slices (`len_per_neighbour`
    /// values per neighbour).
    fn node_slices<'a>(
        &self,
        values: &'a mut [f64],
        len_per_neighbour: usize,
    ) -> Vec<&'a mut [f64]> {
        let mut out = Vec::with_capacity(self.kept.len());
        let mut rest = values;
        for k in 0..self.kept.len() {
            let len = len_per_neighbour * (self.ptr[k + 1] - self.ptr[k]);
            let (head, tail) = rest.split_at_mut(len);
            out.push(head);
            rest = tail;
        }
        out
    }

    /// Runs `f(node, d, marks, out)` on every kept mesh node in parallel, with `d` its number
    /// of kept neighbours, `out` its column-block slice and `marks[b]` the position of `b` in
    /// its kept neighbour list (`UNMARKED` for a fixed node): an O(1) slot lookup instead of
    /// a search per element entry.
    fn for_each_node<F>(&self, slices: Vec<&mut [f64]>, f: F)
    where
        F: Fn(usize, usize, &[u32], &mut [f64]) + Sync,
    {
        let n = self.index.len();
        slices
            .into_par_iter()
            .enumerate()
            .with_min_len(NODES_PER_TASK)
            .for_each_init(
                || vec![UNMARKED; n],
                |marks, (k, out)| {
                    let nb = self.neighbours(k);
                    for (slot, &b) in nb.iter().enumerate() {
                        marks[b] = slot as u32;
                    }
                    f(self.kept[k], nb.len(), marks, out);
                    for &b in nb {
                        marks[b] = UNMARKED;
                    }
                },
            );
    }
}

/// Shape-function gradients (1/m) and |volume| (m³) of one tetrahedron; zero for a degenerate one.
fn element_geometry(mesh: &TetMesh, t: &[usize; 4]) -> ([[f64; 3]; 4], f64) {
    let x0 = mesh.nodes[t[0]];
    let e = |k: usize| {
        let x = mesh.nodes[t[k]];
        [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]]
    };
    let (e1, e2, e3) = (e(1), e(2), e(3));
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let c23 = cross(e2, e3);
    let det = e1[0] * c23[0] + e1[1] * c23[1] + e1[2] * c23[2];
    if det == 0.0 || !det.is_finite() {
        return ([[0.0; 3]; 4], 0.0);
    }
    // Rows of J⁻¹ for J = [e1 e2 e3] (columns): (e2×e3, e3×e1, e1×e2)/det.
    let c31 = cross(e3, e1);
    let c12 = cross(e1, e2);
    let inv = 1.0 / det;
    let g1 = [c23[0] * inv, c23[1] * inv, c23[2] * inv];
    let g2 = [c31[0] * inv, c31[1] * inv, c31[2] * inv];
    let g3 = [c12[0] * inv, c12[1] * inv, c12[2] * inv];
    let g0 = [
        -(g1[0] + g2[0] + g3[0]),
        -(g1[1] + g2[1] + g3[1]),
        -(g1[2] + g2[2] + g3[2]),
    ];
    ([g0, g1, g2, g3], det.abs() / 6.0)
}

/// The symmetric 4-point rule on a tetrahedron (degree 2): point q has barycentric coordinate
/// `P2_QA` at corner q and `P2_QB` at the other three, weight V/4.
const P2_QA: f64 = 0.585_410_196_624_968_5; // (5 + 3√5)/20
const P2_QB: f64 = 0.138_196_601_125_010_5; // (5 − √5)/20

/// Gradients (1/m) of the ten P2 shape functions at the four points of the 4-point rule, from
/// the barycentric gradients `g` of the corners: corner i, N = Lᵢ(2Lᵢ − 1), ∇N = (4Lᵢ − 1)∇Lᵢ;
/// mid-edge node of edge (a, b) ([`TET10_EDGES`]), N = 4 L_a L_b, ∇N = 4(L_b ∇L_a + L_a ∇L_b).
fn p2_gradients(g: &[[f64; 3]; 4]) -> [[[f64; 3]; 10]; 4] {
    let mut out = [[[0.0; 3]; 10]; 4];
    for (q, at) in out.iter_mut().enumerate() {
        let l = |i: usize| if i == q { P2_QA } else { P2_QB };
        for i in 0..4 {
            let c = 4.0 * l(i) - 1.0;
            at[i] = g[i].map(|x| c * x);
        }
        for (e, &[a, b]) in TET10_EDGES.iter().enumerate() {
            at[4 + e] = [0, 1, 2].map(|c| 4.0 * (l(b) * g[a][c] + l(a) * g[b][c]));
        }
    }
    out
}

/// `420/V ∫ N_a N_b dV` of the P2 tetrahedron (local nodes: corners 0–3, then the mid-edge
/// nodes of [`TET10_EDGES`]): corner–corner 6 (same) or 1; corner–edge −4 (the corner is on the
/// edge) or −6; edge–edge 32 (same), 16 (sharing a corner) or 8 (opposite). Rows sum to
/// 420/V ∫ N_a: −21 (corners) and 84 (mid-edge nodes).
pub(crate) fn p2_mass_ref(a: usize, b: usize) -> f64 {
    let (a, b) = (a.min(b), a.max(b));
    match (a < 4, b < 4) {
        (true, true) => {
            if a == b {
                6.0
            } else {
                1.0
            }
        }
        (true, false) => {
            if TET10_EDGES[b - 4].contains(&a) {
                -4.0
            } else {
                -6.0
            }
        }
        _ => {
            let (ea, eb) = (TET10_EDGES[a - 4], TET10_EDGES[b - 4]);
            if a == b {
                32.0
            } else if ea.iter().any(|c| eb.contains(c)) {
                16.0
            } else {
                8.0
            }
        }
    }
}

/// Assembles the linear-elastic stiffness matrix K (N/m), `3n × 3n`, node-major dofs
/// (`3·node + axis`), both triangles stored, rows sorted in every column: P1 for a linear
/// mesh, P2 (4-point rule, exact on straight-sided elements) for a second-order one.
///
/// Element matrix: K_ab^{ij} = V (λ ∂_i N_a ∂_j N_b + μ ∂_j N_a ∂_i N_b + μ δ_ij ∇N_a·∇N_b), with
/// the Lamé parameters of `mat` and V = |signed volume|, so either orientation gives the same
/// matrix. Degenerate (zero-volume) tetrahedra contribute nothing; the bake rejects them
/// earlier. The material is assumed validated ([`Material::validate`]).
///
/// Deterministic: bit-identical for any rayon thread count, and bit-exactly symmetric.
///
/// ```
/// use modal_bake::{fem::{assemble_stiffness, Material}, mesh::TetMesh};
/// let mesh = TetMesh::structured_box([2, 1, 1], [2.0, 1.0, 1.0]);
/// let k = assemble_stiffness(&mesh, &Material::new(1e9, 0.3, 1000.0).unwrap());
/// assert_eq!(k.nrows(), mesh.dofs());
/// ```
pub fn assemble_stiffness(mesh: &TetMesh, mat: &Material) -> SparseColMat<usize, f64> {
    let graph = NodeGraph::new(mesh);
    let pattern = KeptPattern::new(&graph, &[]);
    stiffness(mesh, mat, &graph, &pattern, &geometries(mesh))
}

/// Shape-function gradients and volumes of every tetrahedron ([`element_geometry`]).
fn geometries(mesh: &TetMesh) -> Vec<([[f64; 3]; 4], f64)> {
    mesh.tets
        .par_iter()
        .map(|t| element_geometry(mesh, t))
        .collect()
}

/// K on the kept nodes of `pattern`.
fn stiffness(
    mesh: &TetMesh,
    mat: &Material,
    graph: &NodeGraph,
    pattern: &KeptPattern,
    geo: &[([[f64; 3]; 4], f64)],
) -> SparseColMat<usize, f64> {
    let (lam, mu) = mat.lame();
    let sym = pattern.dof_pattern(true);
    let mut values = vec![0.0f64; sym.row_idx().len()];
    let slices = pattern.node_slices(&mut values, 9);
    if mesh.is_quadratic() {
        pattern.for_each_node(slices, |a, d, marks, out| {
            for &(t, p) in graph.incidences(a) {
                let (g, v) = &geo[t as usize];
                if *v == 0.0 {
                    continue;
                }
                let grads = p2_gradients(g);
                let w = 0.25 * v;
                let p = p as usize;
                for (q, &b) in mesh.tet_nodes(t as usize).iter().enumerate() {
                    let k = marks[b];
                    if k == UNMARKED {
                        continue; // a fixed node: its rows are not stored
                    }
                    let k = k as usize;
                    // s = Σ_qp ∇N_a ∇N_bᵀ over the 4 points: the (a,b) and (b,a) blocks see
                    // the same products (commuted) in the same order, so K stays bit-exactly
                    // symmetric.
                    let mut s = [[0.0f64; 3]; 3];
                    let mut dot = 0.0;
                    for gq in &grads {
                        let (ga, gb) = (gq[p], gq[q]);
                        for i in 0..3 {
                            for j in 0..3 {
                                s[i][j] += ga[i] * gb[j];
                            }
                        }
                        dot += ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
                    }
                    for i in 0..3 {
                        let col = &mut out[3 * d * i + 3 * k..3 * d * i + 3 * k + 3];
                        for j in 0..3 {
                            let mut e = lam * s[i][j] + mu * s[j][i];
                            if i == j {
                                e += mu * dot;
                            }
                            col[j] += w * e;
                        }
                    }
                }
            }
        });
        return SparseColMat::new(sym, values);
    }
    pattern.for_each_node(slices, |a, d, marks, out| {
        for &(t, p) in graph.incidences(a) {
            let (g, v) = &geo[t as usize];
            if *v == 0.0 {
                continue;
            }
            let ga = g[p as usize];
            let tet = &mesh.tets[t as usize];
            for (q, &b) in tet.iter().enumerate() {
                let k = marks[b];
                if k == UNMARKED {
                    continue; // a fixed node: its rows are not stored
                }
                let k = k as usize;
                let gb = g[q];
                let dot = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
                // Entry (row 3b+j, col 3a+i), written so that (a,i)↔(b,j) swaps factors of
                // commutative products only: bit-exact symmetry.
                for i in 0..3 {
                    let col = &mut out[3 * d * i + 3 * k..3 * d * i + 3 * k + 3];
                    for j in 0..3 {
                        let mut s = lam * (ga[i] * gb[j]) + mu * (ga[j] * gb[i]);
                        if i == j {
                            s += mu * dot;
                        }
                        col[j] += v * s;
                    }
                }
            }
        }
    });
    SparseColMat::new(sym, values)
}

/// Assembles the mass matrix M (kg), `3n × 3n`, node-major dofs, both triangles stored.
///
/// P1, `lumped == false`: consistent mass, ρV/20·(1+δ_ab) between nodes a, b of a
/// tetrahedron, per axis (no coupling between axes). `lumped == true`: diagonal, ρV/4 per node
/// and axis. P2: consistent ρV/420 × (6, 1; −4, −6; 32, 16, 8) between corners, corner and
/// mid-edge node, and mid-edge nodes (exact; see the module docs), or its HRZ diagonal when
/// lumped.
/// Either way 1ᵀ M_axis 1 = ρ·(total volume). Deterministic like [`assemble_stiffness`].
///
/// ```
/// use modal_bake::{fem::{assemble_mass, Material}, mesh::TetMesh};
/// let mesh = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]);
/// let m = assemble_mass(&mesh, &Material::new(1e9, 0.3, 1000.0).unwrap(), true);
/// let total: f64 = m.val().iter().sum();
/// assert!((total - 3.0 * 1000.0).abs() < 1e-9);
/// ```
pub fn assemble_mass(mesh: &TetMesh, mat: &Material, lumped: bool) -> SparseColMat<usize, f64> {
    let graph = NodeGraph::new(mesh);
    let pattern = KeptPattern::new(&graph, &[]);
    mass(mesh, mat, lumped, &graph, &pattern, &geometries(mesh))
}

/// M on the kept nodes of `pattern`.
fn mass(
    mesh: &TetMesh,
    mat: &Material,
    lumped: bool,
    graph: &NodeGraph,
    pattern: &KeptPattern,
    geo: &[([[f64; 3]; 4], f64)],
) -> SparseColMat<usize, f64> {
    let rho = mat.density;
    let quadratic = mesh.is_quadratic();
    if lumped {
        let n = pattern.kept.len();
        let mut values = vec![0.0f64; 3 * n];
        values.par_chunks_mut(3).enumerate().for_each(|(k, out)| {
            let mut m = 0.0;
            for &(t, p) in graph.incidences(pattern.kept[k]) {
                m += if quadratic {
                    // HRZ: the consistent diagonal (6 or 32 per 420) scaled to ρV.
                    rho * geo[t as usize].1 * p2_mass_ref(p as usize, p as usize) / 216.0
                } else {
                    rho * geo[t as usize].1 / 4.0
                };
            }
            out.fill(m);
        });
        let sym = SymbolicSparseColMat::new_checked(
            3 * n,
            3 * n,
            (0..=3 * n).collect(),
            None,
            (0..3 * n).collect(),
        );
        return SparseColMat::new(sym, values);
    }
    let sym = pattern.dof_pattern(false);
    let mut values = vec![0.0f64; sym.row_idx().len()];
    let slices = pattern.node_slices(&mut values, 3);
    if quadratic {
        pattern.for_each_node(slices, |a, d, marks, out| {
            for &(t, p) in graph.incidences(a) {
                let rv = rho * geo[t as usize].1 / 420.0;
                for (q, &b) in mesh.tet_nodes(t as usize).iter().enumerate() {
                    let k = marks[b];
                    if k == UNMARKED {
                        continue; // a fixed node: its rows are not stored
                    }
                    let w = rv * p2_mass_ref(p as usize, q);
                    for i in 0..3 {
                        out[d * i + k as usize] += w;
                    }
                }
            }
        });
        return SparseColMat::new(sym, values);
    }
    pattern.for_each_node(slices, |a, d, marks, out| {
        for &(t, _) in graph.incidences(a) {
            let m = rho * geo[t as usize].1 / 20.0;
            for &b in &mesh.tets[t as usize] {
                let k = marks[b];
                if k == UNMARKED {
                    continue; // a fixed node: its rows are not stored
                }
                let k = k as usize;
                let w = if b == a { 2.0 * m } else { m };
                for i in 0..3 {
                    out[d * i + k] += w;
                }
            }
        }
    });
    SparseColMat::new(sym, values)
}

/// K (N/m) and M (kg) of `mesh` restricted to the free dofs left by clamping
/// `fixed_nodes` (strictly ascending), with their [`DofMap`]: bit for bit
/// `reduce_fixed(&assemble_stiffness(..), &assemble_mass(..), fixed_nodes)`, without
/// assembling the full matrices (one node graph and one pass over the element geometry for
/// both, and no entries in fixed rows or columns).
///
/// # Errors
/// [`DofMapError`] if the node list is invalid for the mesh.
///
/// ```
/// use modal_bake::{fem::{assemble_clamped, Material}, mesh::TetMesh};
/// let mesh = TetMesh::structured_box([2, 1, 1], [2.0, 1.0, 1.0]);
/// let mat = Material::new(1e9, 0.3, 1000.0).unwrap();
/// let (map, k, m) = assemble_clamped(&mesh, &mat, false, &mesh.groups["xmin"]).unwrap();
/// assert_eq!((k.nrows(), m.nrows()), (map.n_free(), map.n_free()));
/// ```
#[allow(clippy::type_complexity)]
pub fn assemble_clamped(
    mesh: &TetMesh,
    mat: &Material,
    lumped: bool,
    fixed_nodes: &[usize],
) -> Result<(DofMap, SparseColMat<usize, f64>, SparseColMat<usize, f64>), DofMapError> {
    let map = DofMap::new(mesh.nodes.len(), fixed_nodes)?;
    let graph = NodeGraph::new(mesh);
    let pattern = KeptPattern::new(&graph, fixed_nodes);
    let geo = geometries(mesh);
    let k = stiffness(mesh, mat, &graph, &pattern, &geo);
    let m = mass(mesh, mat, lumped, &graph, &pattern, &geo);
    Ok((map, k, m))
}

/// The six rigid-body motions of `mesh` as columns of a `3n × 6` matrix (m per unit
/// amplitude): translations along x, y, z, then infinitesimal rotations (rad) about the x, y, z
/// axes through the volume centroid. Not normalised; K annihilates every column.
///
/// ```
/// use modal_bake::{fem::rigid_body_modes, mesh::TetMesh};
/// let mesh = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]);
/// let r = rigid_body_modes(&mesh);
/// assert_eq!((r.nrows(), r.ncols()), (24, 6));
/// ```
pub fn rigid_body_modes(mesh: &TetMesh) -> faer::Mat<f64> {
    let mut c = [0.0f64; 3];
    let mut vol = 0.0;
    for t in &mesh.tets {
        let v = element_geometry(mesh, t).1;
        vol += v;
        for (k, ck) in c.iter_mut().enumerate() {
            *ck += v * 0.25 * t.iter().map(|&a| mesh.nodes[a][k]).sum::<f64>();
        }
    }
    if vol > 0.0 {
        c.iter_mut().for_each(|x| *x /= vol);
    }
    let n = mesh.nodes.len();
    let mut r = faer::Mat::<f64>::zeros(3 * n, 6);
    for (a, x) in mesh.nodes.iter().enumerate() {
        let d = [x[0] - c[0], x[1] - c[1], x[2] - c[2]];
        for k in 0..3 {
            r[(3 * a + k, k)] = 1.0;
        }
        // e_x × d = (0, −dz, dy); e_y × d = (dz, 0, −dx); e_z × d = (−dy, dx, 0).
        r[(3 * a + 1, 3)] = -d[2];
        r[(3 * a + 2, 3)] = d[1];
        r[(3 * a, 4)] = d[2];
        r[(3 * a + 2, 4)] = -d[0];
        r[(3 * a, 5)] = -d[1];
        r[(3 * a + 1, 5)] = d[0];
    }
    r
}
