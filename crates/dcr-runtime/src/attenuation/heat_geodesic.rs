//! [`HeatGeodesic`]: geodesic distances on a triangle surface by the heat method
//! (Crane, Weischedel & Wardetzky 2013), factor once, query many.
//!
//! Set-up: cotan Laplacian L (positive semi-definite, `L_ij = −½(cot α_ij + cot β_ij)`), lumped
//! vertex mass M (⅓ of the incident triangle areas), t = (mean edge length)²; ε = 1e-8/t
//! (scale-free regularisation of the closed-surface null space). L is assembled straight into a
//! sorted symmetric adjacency (no triplet sort); one AMD ordering (faer) and one symbolic
//! analysis (elimination tree, row patterns of the factor) serve both operators, whose numeric
//! Cholesky factors of (M + tL) and (L + εM) are computed together in one up-looking pass
//! (same pattern, so every index load feeds both factors).
//! Everything is kept in the permuted vertex order (triangles are renumbered once), so a query
//! never permutes until the final gather.
//! Per source: heat solve (M + tL) u = δ (the forward substitution skips the zero part of the
//! sparse right-hand side), X = −∇u/|∇u| per face from precomputed per-face A_f∇φ_i, integrated
//! divergence b_i = Σ_f A_f X_f·∇φ_i, Poisson solve (L + εM) φ = b, shift so the source is at 0.
//! The triangular solves are hand-written CSC loops (u32 indices, reciprocal diagonals).
//! No boundary-condition averaging (open surfaces get the natural Neumann condition).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

use crate::math::{cross, dot, norm, scale, sub};
use crate::model::SurfacePoint;

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
    /// The sparse Cholesky factorisation failed (e.g. a vertex used by no triangle).
    #[error("sparse Cholesky failed: {0}")]
    Factorization(String),
}

const NONE: u32 = u32::MAX;

/// Reusable scratch for [`HeatGeodesic`] queries, so repeated queries do not allocate.
pub struct HeatWorkspace {
    /// Heat solution (permuted order).
    u: Vec<f64>,
    /// Divergence / distance before the final gather (permuted order).
    b: Vec<f64>,
}

impl std::fmt::Debug for HeatWorkspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeatWorkspace")
            .field("vertices", &self.u.len())
            .finish()
    }
}

/// One face in permuted vertex numbering with A_f ∇φ_i of its three corners (m).
#[derive(Clone, Copy)]
struct Face {
    tri: [u32; 3],
    ga: [[f64; 3]; 3],
}

/// Lower Cholesky factor without its diagonal (CSC, rows sorted) plus reciprocal diagonal.
struct Factor {
    vals: Vec<f64>,
    rdiag: Vec<f64>,
}

/// Heat-method geodesic distances (m) on a fixed triangle surface: factor once, many sources.
pub struct HeatGeodesic {
    n: usize,
    /// Per face, in permuted numbering.
    faces: Vec<Face>,
    /// `perm_inv[v]`: position of original vertex v in the factor order.
    perm_inv: Vec<u32>,
    /// Strictly-lower pattern of the shared factor (CSC) as contiguous row runs: column j's
    /// runs are `runs[run_ptr[j]..run_ptr[j + 1]]`, each `[first value position, first row]`;
    /// a run ends where the next one starts (the last at `col_end[j]`).
    /// Columns with short runs have none listed and use the indexed pattern instead.
    run_ptr: Vec<u32>,
    runs: Vec<[u32; 2]>,
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    heat: Factor,
    poisson: Factor,
    mean_edge: f64,
}

impl std::fmt::Debug for HeatGeodesic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeatGeodesic")
            .field("vertices", &self.n)
            .field("triangles", &self.faces.len())
            .field("mean_edge", &self.mean_edge)
            .finish()
    }
}

fn fact_err(msg: impl Into<String>) -> GeodesicError {
    GeodesicError::Factorization(msg.into())
}

impl HeatGeodesic {
    /// Builds and factors the operators for a surface (vertices in m, any consistent orientation).
    ///
    /// # Errors
    /// [`GeodesicError`] for an empty surface, bad indices, degenerate triangles, or a failed
    /// factorisation (e.g. unused vertices).
    pub fn new(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self, GeodesicError> {
        let n = vertices.len();
        if n == 0 || triangles.is_empty() {
            return Err(GeodesicError::Empty);
        }
        if n >= NONE as usize || triangles.len() * 6 >= NONE as usize {
            return Err(fact_err("surface too large for 32-bit indices"));
        }
        // --- Geometry: per-face gradients, lumped mass, half-cotangent edge weights. ---
        let mut mass = vec![0.0; n];
        let mut faces = Vec::with_capacity(triangles.len());
        // Directed adjacency counts (each face edge once per direction).
        let mut cnt = vec![0u32; n + 1];
        let mut cot_w = Vec::with_capacity(triangles.len());
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
            let unit = scale(nn, 1.0 / two_a);
            faces.push(Face {
                tri: *tri,
                ga: [0, 1, 2].map(|i| scale(cross(unit, e[i]), 0.5)),
            });
            for &v in tri {
                mass[v as usize] += two_a / 6.0;
                cnt[v as usize] += 2;
            }
            // Cotangent of corner i = (e_j · e_k)/(2A) with the two edges leaving corner i;
            // w = ½ cot weights edge (tri[j], tri[k]) opposite corner i.
            cot_w.push([0, 1, 2].map(|i| {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                -0.5 * dot(e[j], e[k]) / two_a
            }));
        }
        let mean_edge = edge_sum / (3.0 * triangles.len() as f64);
        let t = mean_edge * mean_edge;
        let eps = 1e-8 / t;

        // --- Symmetric adjacency (CSR == CSC), sorted, duplicates merged; w_ij ≥ edge weight. ---
        let mut ptr = vec![0u32; n + 1];
        for v in 0..n {
            ptr[v + 1] = ptr[v] + cnt[v];
        }
        let mut fill = ptr[..n].to_vec();
        let total = ptr[n] as usize;
        let mut adj = vec![0u32; total];
        let mut wts = vec![0.0f64; total];
        for (tri, w) in triangles.iter().zip(&cot_w) {
            for i in 0..3 {
                let (a, b) = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
                for (p, q) in [(a, b), (b, a)] {
                    let s = fill[p as usize] as usize;
                    adj[s] = q;
                    wts[s] = w[i];
                    fill[p as usize] += 1;
                }
            }
        }
        drop(cot_w);
        // Per row: insertion sort by column, merge duplicates, compact in place.
        let mut diag = vec![0.0f64; n];
        let mut out_ptr = vec![0u32; n + 1];
        let mut w_pos = 0usize;
        for v in 0..n {
            let (lo, hi) = (ptr[v] as usize, ptr[v + 1] as usize);
            for i in lo + 1..hi {
                let (c, x) = (adj[i], wts[i]);
                let mut j = i;
                while j > lo && adj[j - 1] > c {
                    adj[j] = adj[j - 1];
                    wts[j] = wts[j - 1];
                    j -= 1;
                }
                adj[j] = c;
                wts[j] = x;
            }
            let start = w_pos;
            let mut dsum = 0.0;
            for i in lo..hi {
                dsum += wts[i];
                if w_pos > start && adj[w_pos - 1] == adj[i] {
                    wts[w_pos - 1] += wts[i];
                } else {
                    adj[w_pos] = adj[i];
                    wts[w_pos] = wts[i];
                    w_pos += 1;
                }
            }
            diag[v] = dsum;
            out_ptr[v + 1] = w_pos as u32;
        }
        adj.truncate(w_pos);
        wts.truncate(w_pos);
        let ptr = out_ptr;

        // --- AMD ordering on the strictly-upper pattern (prefix of each sorted column). ---
        let mut up_ptr = vec![0u32; n + 1];
        let mut up_idx = Vec::with_capacity(w_pos / 2);
        for v in 0..n {
            let row = &adj[ptr[v] as usize..ptr[v + 1] as usize];
            up_idx.extend(row.iter().copied().take_while(|&c| (c as usize) < v));
            up_ptr[v + 1] = up_idx.len() as u32;
        }
        let mut perm = vec![0u32; n];
        let mut perm_inv = vec![0u32; n];
        {
            let upper = SymbolicSparseColMatRef::new_checked(n, n, &up_ptr, None, &up_idx);
            let mut buf = MemBuffer::new(amd::order_scratch::<u32>(n, up_idx.len()));
            amd::order(
                &mut perm,
                &mut perm_inv,
                upper,
                Default::default(),
                MemStack::new(&mut buf),
            )
            .map_err(|e| fact_err(format!("AMD ordering: {e:?}")))?;
        }
        drop(up_idx);
        drop(up_ptr);

        // --- Permuted symmetric matrix C = P A Pᵀ: strictly-upper part of each column. ---
        // cu_ptr/cu_idx/cu_w: column k holds (i < k, −w) entries.
        let mut cu_ptr = vec![0u32; n + 1];
        let mut cu_idx = Vec::with_capacity(w_pos / 2);
        let mut cu_w = Vec::with_capacity(w_pos / 2);
        for k in 0..n {
            let v = perm[k] as usize;
            for p in ptr[v] as usize..ptr[v + 1] as usize {
                let i = perm_inv[adj[p] as usize];
                if (i as usize) < k {
                    cu_idx.push(i);
                    cu_w.push(wts[p]);
                }
            }
            cu_ptr[k + 1] = cu_idx.len() as u32;
        }
        drop(adj);
        drop(wts);

        // --- Symbolic: elimination tree, then row patterns of L (ereach), topological order. ---
        let mut parent = vec![NONE; n];
        {
            let mut ancestor = vec![NONE; n];
            for k in 0..n {
                for &i0 in &cu_idx[cu_ptr[k] as usize..cu_ptr[k + 1] as usize] {
                    let mut i = i0;
                    while i != NONE && (i as usize) < k {
                        let next = ancestor[i as usize];
                        ancestor[i as usize] = k as u32;
                        if next == NONE {
                            parent[i as usize] = k as u32;
                        }
                        i = next;
                    }
                }
            }
        }
        let mut flag = vec![NONE; n];
        let mut stack = vec![0u32; n];
        let mut rp_ptr = vec![0u32; n + 1];
        let mut rp: Vec<u32> = Vec::with_capacity(24 * n);
        let mut col_cnt = vec![0u32; n];
        for k in 0..n {
            flag[k] = k as u32;
            let base = rp.len();
            for &i0 in &cu_idx[cu_ptr[k] as usize..cu_ptr[k + 1] as usize] {
                let mut len = 0;
                let mut i = i0;
                while flag[i as usize] != k as u32 {
                    stack[len] = i;
                    len += 1;
                    flag[i as usize] = k as u32;
                    i = parent[i as usize];
                }
                // Path pushed bottom-up; prepend reversed so the whole list stays topological
                // when read back to front.
                rp.extend(stack[..len].iter().rev());
            }
            // rp[base..] holds paths each root-first; reversing the whole segment gives a
            // topological (descendants first) order.
            rp[base..].reverse();
            for &j in &rp[base..] {
                col_cnt[j as usize] += 1;
            }
            rp_ptr[k + 1] = rp.len() as u32;
        }
        let lnz = rp.len();
        let mut col_ptr = vec![0u32; n + 1];
        for j in 0..n {
            col_ptr[j + 1] = col_ptr[j] + col_cnt[j];
        }
        let mut row_idx = vec![0u32; lnz];
        {
            let mut next: Vec<u32> = col_ptr[..n].to_vec();
            for k in 0..n {
                for &j in &rp[rp_ptr[k] as usize..rp_ptr[k + 1] as usize] {
                    row_idx[next[j as usize] as usize] = k as u32;
                    next[j as usize] += 1;
                }
            }
        }

        // Contiguous row runs of every column: `runs[run_ptr[j]..run_ptr[j + 1]]` are the
        // positions where a run starts (rows consecutive within a run), so the updates on
        // separator columns become dense slice loops without index loads.
        let mut run_ptr = vec![0u32; n + 1];
        let mut runs: Vec<u32> = Vec::with_capacity(lnz / 4);
        let mut run_rows: Vec<[u32; 2]> = Vec::with_capacity(lnz / 4);
        for j in 0..n {
            let (lo, hi) = (col_ptr[j] as usize, col_ptr[j + 1] as usize);
            for p in lo..hi {
                if p == lo || row_idx[p] != row_idx[p - 1] + 1 {
                    runs.push(p as u32);
                    run_rows.push([p as u32, row_idx[p]]);
                }
            }
            run_ptr[j + 1] = runs.len() as u32;
        }
        // Solve-side runs: only for columns whose runs average ≥ 4 rows.
        let mut srun_ptr = vec![0u32; n + 1];
        let mut sruns: Vec<[u32; 2]> = Vec::new();
        for j in 0..n {
            let (a, b) = (run_ptr[j] as usize, run_ptr[j + 1] as usize);
            let len = (col_ptr[j + 1] - col_ptr[j]) as usize;
            if b > a && len >= 4 * (b - a) {
                sruns.extend_from_slice(&run_rows[a..b]);
            }
            srun_ptr[j + 1] = sruns.len() as u32;
        }
        drop(run_rows);

        // --- Numeric: both factors in one up-looking pass, values paired [heat, poisson]. ---
        let mut lx = vec![[0.0f64; 2]; lnz];
        let mut rd = vec![[0.0f64; 2]; n];
        let mut x = vec![[0.0f64; 2]; n];
        let mut next: Vec<u32> = col_ptr[..n].to_vec();
        for k in 0..n {
            for p in cu_ptr[k] as usize..cu_ptr[k + 1] as usize {
                let a = -cu_w[p];
                x[cu_idx[p] as usize] = [t * a, a];
            }
            let v = perm[k] as usize;
            let mut d = [t * diag[v] + mass[v], diag[v] + eps * mass[v]];
            for &i in &rp[rp_ptr[k] as usize..rp_ptr[k + 1] as usize] {
                let i = i as usize;
                let r = rd[i];
                let xi = x[i];
                let l = [xi[0] * r[0], xi[1] * r[1]];
                x[i] = [0.0; 2];
                let hi = next[i] as usize;
                let rr = &runs[run_ptr[i] as usize..run_ptr[i + 1] as usize];
                for (q, &start) in rr.iter().enumerate() {
                    let start = start as usize;
                    if start >= hi {
                        break;
                    }
                    let end = rr.get(q + 1).map_or(hi, |&e| (e as usize).min(hi));
                    let r0 = row_idx[start] as usize;
                    let xs = &mut x[r0..r0 + (end - start)];
                    for (xr, val) in xs.iter_mut().zip(&lx[start..end]) {
                        xr[0] -= val[0] * l[0];
                        xr[1] -= val[1] * l[1];
                    }
                }
                d[0] -= l[0] * l[0];
                d[1] -= l[1] * l[1];
                lx[hi] = l;
                next[i] += 1;
            }
            if !(d[0] > 0.0 && d[1] > 0.0) {
                return Err(fact_err(format!(
                    "matrix not positive definite at column {k} (vertex {v})"
                )));
            }
            rd[k] = [1.0 / d[0].sqrt(), 1.0 / d[1].sqrt()];
        }
        let split = |c: usize| Factor {
            vals: lx.iter().map(|p| p[c]).collect(),
            rdiag: rd.iter().map(|p| p[c]).collect(),
        };
        let (heat, poisson) = (split(0), split(1));
        for f in &mut faces {
            f.tri = f.tri.map(|v| perm_inv[v as usize]);
        }
        Ok(HeatGeodesic {
            n,
            faces,
            perm_inv,
            run_ptr: srun_ptr,
            runs: sruns,
            col_ptr,
            row_idx,
            heat,
            poisson,
            mean_edge,
        })
    }

    /// Stored values of the Cholesky factor (fill, diagonal included), for diagnostics.
    pub fn factor_len(&self) -> usize {
        self.heat.vals.len() + self.n
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
            u: vec![0.0; self.n],
            b: vec![0.0; self.n],
        }
    }

    /// Distances (m) from vertex `v` to every vertex, written to `out` (length ns).
    ///
    /// # Panics
    /// If `v` ≥ ns or `out.len()` ≠ ns.
    pub fn distances_from_vertex(&self, v: usize, out: &mut [f64]) {
        assert!(v < self.n, "vertex {v} out of range");
        let mut ws = self.workspace();
        self.distances_with(&[(self.perm_inv[v] as usize, 1.0)], out, &mut ws);
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
        let tri = self.faces[sp.triangle as usize].tri;
        let src = [0, 1, 2].map(|i| (tri[i] as usize, sp.bary[i]));
        self.distances_with(&src, out, ws);
    }

    /// Core (source in permuted numbering): heat, normalised gradient, divergence, Poisson,
    /// shift, gather back to the caller's vertex order.
    fn distances_with(&self, source: &[(usize, f64)], out: &mut [f64], ws: &mut HeatWorkspace) {
        assert_eq!(out.len(), self.n);
        let (u, b) = (&mut ws.u[..self.n], &mut ws.b[..self.n]);
        u.iter_mut().for_each(|x| *x = 0.0);
        for &(v, w) in source {
            u[v] += w;
        }
        self.forward(&self.heat, u, true);
        self.backward(&self.heat, u);
        b.iter_mut().for_each(|x| *x = 0.0);
        for f in &self.faces {
            let [i0, i1, i2] = f.tri.map(|i| i as usize);
            let (u0, u1, u2) = (u[i0], u[i1], u[i2]);
            let ga = &f.ga;
            let g = [0, 1, 2].map(|k| u0 * ga[0][k] + u1 * ga[1][k] + u2 * ga[2][k]);
            // g = A ∇u; X = −∇u/|∇u| (direction only, so the A scale drops out).
            let len2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
            if !(len2 > 0.0) {
                continue;
            }
            let s = -1.0 / len2.sqrt();
            let x = [g[0] * s, g[1] * s, g[2] * s];
            b[i0] += dot(x, ga[0]);
            b[i1] += dot(x, ga[1]);
            b[i2] += dot(x, ga[2]);
        }
        self.forward(&self.poisson, b, false);
        self.backward(&self.poisson, b);
        let shift: f64 = source.iter().map(|&(v, w)| w * b[v]).sum();
        for (o, &p) in out.iter_mut().zip(&self.perm_inv) {
            *o = (b[p as usize] - shift).max(0.0);
        }
    }

    /// Runs of column j: (value range, first row).
    #[inline(always)]
    fn col_runs(&self, j: usize) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        let rr = &self.runs[self.run_ptr[j] as usize..self.run_ptr[j + 1] as usize];
        let end = self.col_ptr[j + 1] as usize;
        rr.iter().enumerate().map(move |(q, r)| {
            let e = rr.get(q + 1).map_or(end, |n| n[0] as usize);
            (r[0] as usize, e, r[1] as usize)
        })
    }

    /// L y = x in place (`sparse`: skip columns whose value is exactly zero).
    #[inline]
    fn forward(&self, f: &Factor, x: &mut [f64], sparse: bool) {
        let lv = &f.vals[..];
        for j in 0..self.n {
            let xj = x[j] * f.rdiag[j];
            x[j] = xj;
            if sparse && xj == 0.0 {
                continue;
            }
            if self.run_ptr[j] == self.run_ptr[j + 1] {
                let (lo, hi) = (self.col_ptr[j] as usize, self.col_ptr[j + 1] as usize);
                for (&r, &l) in self.row_idx[lo..hi].iter().zip(&lv[lo..hi]) {
                    x[r as usize] -= l * xj;
                }
                continue;
            }
            for (lo, hi, r0) in self.col_runs(j) {
                let xs = &mut x[r0..r0 + (hi - lo)];
                for (xr, &l) in xs.iter_mut().zip(&lv[lo..hi]) {
                    *xr -= l * xj;
                }
            }
        }
    }

    /// Lᵀ y = x in place (dot products over the column runs, four partial sums).
    #[inline]
    fn backward(&self, f: &Factor, x: &mut [f64]) {
        let lv = &f.vals[..];
        for j in (0..self.n).rev() {
            let mut s = [0.0f64; 4];
            if self.run_ptr[j] == self.run_ptr[j + 1] {
                let (lo, hi) = (self.col_ptr[j] as usize, self.col_ptr[j + 1] as usize);
                let (ri, lv) = (&self.row_idx[lo..hi], &lv[lo..hi]);
                let mut ic = ri.chunks_exact(4);
                let mut lc = lv.chunks_exact(4);
                for (i4, l4) in (&mut ic).zip(&mut lc) {
                    for q in 0..4 {
                        s[q] += l4[q] * x[i4[q] as usize];
                    }
                }
                for (&r, &l) in ic.remainder().iter().zip(lc.remainder()) {
                    s[0] += l * x[r as usize];
                }
                x[j] = (x[j] - ((s[0] + s[1]) + (s[2] + s[3]))) * f.rdiag[j];
                continue;
            }
            for (lo, hi, r0) in self.col_runs(j) {
                let (l, xs) = (&lv[lo..hi], &x[r0..r0 + (hi - lo)]);
                let mut lc = l.chunks_exact(4);
                let mut xc = xs.chunks_exact(4);
                for (l4, x4) in (&mut lc).zip(&mut xc) {
                    for q in 0..4 {
                        s[q] += l4[q] * x4[q];
                    }
                }
                for (&a, &b) in lc.remainder().iter().zip(xc.remainder()) {
                    s[0] += a * b;
                }
            }
            x[j] = (x[j] - ((s[0] + s[1]) + (s[2] + s[3]))) * f.rdiag[j];
        }
    }
}
