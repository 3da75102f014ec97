//! [`HeatGeodesic`]: geodesic distances on a triangle surface by the heat method
//! (Crane, Weischedel & Wardetzky 2013), factor once, query many.
//!
//! Set-up: cotan Laplacian L (positive semi-definite, `L_ij = −½(cot α_ij + cot β_ij)`), lumped
//! vertex mass M (⅓ of the incident triangle areas), t = (mean edge length)²; one symbolic
//! sparse Cholesky (faer, AMD ordering) shared by the two numeric factors of (M + tL) and
//! (L + εM), ε = 1e-8/t (scale-free regularisation of the closed-surface null space).
//! Per source: heat solve (M + tL) u = δ, X = −∇u/|∇u| per face, integrated divergence
//! b_i = Σ_f A_f X_f·∇φ_i, Poisson solve (L + εM) φ = b, shift so the source is at 0.
//! No boundary-condition averaging (open surfaces get the natural Neumann condition).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Par, Side};

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

/// Simplicial factors: measured faster to solve than supernodal ones on ~5k-vertex surfaces.
const SUPERNODAL: SupernodalThreshold = SupernodalThreshold::FORCE_SIMPLICIAL;

struct Factor {
    values: Vec<f64>,
}

/// Reusable scratch for [`HeatGeodesic`] queries, so repeated queries do not allocate.
pub struct HeatWorkspace {
    u: Vec<f64>,
    /// Right-hand side / solution in the factor's (permuted) order.
    x: Vec<f64>,
}

impl std::fmt::Debug for HeatWorkspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeatWorkspace")
            .field("vertices", &self.u.len())
            .finish()
    }
}

/// Heat-method geodesic distances (m) on a fixed triangle surface: factor once, many sources.
pub struct HeatGeodesic {
    n: usize,
    triangles: Vec<[u32; 3]>,
    /// Per face: A_f ∇φ_i for its three corners (m), i.e. N × e_i / 2.
    grad_area: Vec<[[f64; 3]; 3]>,
    symbolic: SymbolicCholesky<usize>,
    heat: Factor,
    poisson: Factor,
    /// Pattern of the simplicial factor L (CSC, diagonal first in each column), as u32.
    l_col_ptr: Vec<u32>,
    l_row_idx: Vec<u32>,
    /// Fill-reducing permutation: factor row i is vertex `perm[i]`.
    perm: Vec<u32>,
    mean_edge: f64,
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
    /// Builds and factors the operators for a surface (vertices in m, any consistent orientation).
    ///
    /// # Errors
    /// [`GeodesicError`] for an empty surface, bad indices, degenerate triangles, or a failed
    /// factorisation (e.g. unused vertices).
    pub fn new(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self, GeodesicError> {
        Self::with_threshold(vertices, triangles, SUPERNODAL)
    }

    pub(crate) fn with_threshold(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        threshold: SupernodalThreshold,
    ) -> Result<Self, GeodesicError> {
        let n = vertices.len();
        if n == 0 || triangles.is_empty() {
            return Err(GeodesicError::Empty);
        }
        let mut mass = vec![0.0; n];
        let mut grad_area = Vec::with_capacity(triangles.len());
        let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(triangles.len() * 9 + n);
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
            grad_area.push([0, 1, 2].map(|i| scale(cross(unit, e[i]), 0.5)));
            for &v in tri {
                mass[v as usize] += two_a / 6.0;
            }
            // Cotangent of corner i = (e_j · e_k)/(2A) with the two edges leaving corner i.
            for i in 0..3 {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                let cot = -dot(e[j], e[k]) / two_a;
                let w = 0.5 * cot;
                let (a, b) = (tri[j] as usize, tri[k] as usize);
                trip.push(Triplet::new(a.max(b), a.min(b), -w));
                trip.push(Triplet::new(a, a, w));
                trip.push(Triplet::new(b, b, w));
            }
        }
        let mean_edge = edge_sum / (3.0 * triangles.len() as f64);
        let t = mean_edge * mean_edge;
        let eps = 1e-8 / t;
        // L (lower triangle) once; both operators share its pattern and differ on the diagonal.
        for i in 0..n {
            trip.push(Triplet::new(i, i, 0.0));
        }
        let lap = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip)
            .map_err(|e| GeodesicError::Factorization(format!("{e:?}")))?;
        let diag: Vec<usize> = {
            let (col_ptr, row_idx) = (lap.symbolic().col_ptr(), lap.symbolic().row_idx());
            (0..n)
                .map(|j| {
                    (col_ptr[j]..col_ptr[j + 1])
                        .find(|&k| row_idx[k] == j)
                        .expect("diagonal present")
                })
                .collect()
        };
        let with_diag = |a: f64, b: f64| {
            let mut mat = lap.clone();
            let vals = mat.val_mut();
            vals.iter_mut().for_each(|x| *x *= a);
            for (i, &k) in diag.iter().enumerate() {
                vals[k] += b * mass[i];
            }
            mat
        };
        let heat_mat = with_diag(t, 1.0);
        let poisson_mat = with_diag(1.0, eps);
        let symbolic = factorize_symbolic_cholesky(
            heat_mat.symbolic(),
            Side::Lower,
            Default::default(),
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: threshold,
                ..Default::default()
            },
        )
        .map_err(|e| GeodesicError::Factorization(format!("{e:?}")))?;
        let par = Par::Seq;
        // The two numeric factorisations are independent: run them on two threads.
        let numeric = |a: &SparseColMat<usize, f64>| -> Result<Factor, GeodesicError> {
            let mut buf = MemBuffer::new(
                symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
            );
            let mut values = vec![0.0; symbolic.len_val()];
            symbolic
                .factorize_numeric_llt::<f64>(
                    &mut values,
                    a.as_ref(),
                    Side::Lower,
                    Default::default(),
                    par,
                    MemStack::new(&mut buf),
                    Default::default(),
                )
                .map_err(|e| GeodesicError::Factorization(format!("{e:?}")))?;
            Ok(Factor { values })
        };
        let (heat, poisson) = std::thread::scope(|scope| {
            let h = scope.spawn(|| numeric(&heat_mat));
            let p = numeric(&poisson_mat);
            (h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)), p)
        });
        let (heat, poisson) = (heat?, poisson?);
        let SymbolicCholeskyRaw::Simplicial(simp) = symbolic.raw() else {
            return Err(GeodesicError::Factorization(
                "expected a simplicial factor".into(),
            ));
        };
        let to_u32 = |x: &[usize]| -> Vec<u32> { x.iter().map(|&i| i as u32).collect() };
        let (l_col_ptr, l_row_idx) = (to_u32(simp.col_ptr()), to_u32(simp.row_idx()));
        let perm = match symbolic.perm() {
            Some(p) => to_u32(p.arrays().0),
            None => (0..n as u32).collect(),
        };
        Ok(HeatGeodesic {
            n,
            triangles: triangles.to_vec(),
            grad_area,
            symbolic,
            heat,
            poisson,
            l_col_ptr,
            l_row_idx,
            perm,
            mean_edge,
        })
    }

    /// Stored values of the Cholesky factor (fill), for diagnostics.
    pub fn factor_len(&self) -> usize {
        self.symbolic.len_val()
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
            x: vec![0.0; self.n],
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

    /// Core: heat from a weighted vertex source, normalised gradient, divergence, Poisson, shift.
    fn distances_with(&self, source: &[(usize, f64)], out: &mut [f64], ws: &mut HeatWorkspace) {
        assert_eq!(out.len(), self.n);
        let u = &mut ws.u;
        u.iter_mut().for_each(|x| *x = 0.0);
        for &(v, w) in source {
            u[v] += w;
        }
        self.solve(&self.heat, u, &mut ws.x);
        out.iter_mut().for_each(|x| *x = 0.0);
        for (f, tri) in self.triangles.iter().enumerate() {
            let ga = &self.grad_area[f];
            let mut grad = [0.0; 3];
            for i in 0..3 {
                let ui = u[tri[i] as usize];
                for k in 0..3 {
                    grad[k] += ui * ga[i][k];
                }
            }
            // grad = A ∇u; X = −∇u/|∇u| (direction only, so the A scale drops out).
            let len = norm(grad);
            if !(len > 0.0) {
                continue;
            }
            let x = scale(grad, -1.0 / len);
            for i in 0..3 {
                out[tri[i] as usize] += dot(x, ga[i]);
            }
        }
        self.solve(&self.poisson, out, &mut ws.x);
        let shift: f64 = source.iter().map(|&(v, w)| w * out[v]).sum();
        for d in out.iter_mut() {
            *d = (*d - shift).max(0.0);
        }
    }

    /// `rhs ← A⁻¹ rhs` through the permuted simplicial factor (Pᵀ A P = L Lᵀ).
    ///
    /// Hand-written rather than faer's `LltRef::solve_in_place_with_conj` (which this replaced)
    /// for two reasons measured on ~5k-vertex surfaces: the forward sweep skips columns whose
    /// entry is still zero, so the heat solve's three-vertex source only walks its elimination
    /// tree ancestors; and u32 indices with one flat loop per column halve the index traffic.
    /// Column axpy forward, row dot backward (summed in four partial sums, so results differ from
    /// faer's in the last bits).
    fn solve(&self, factor: &Factor, rhs: &mut [f64], x: &mut [f64]) {
        let (cp, ri, l) = (&self.l_col_ptr, &self.l_row_idx, &factor.values);
        for (xi, &p) in x.iter_mut().zip(&self.perm) {
            *xi = rhs[p as usize];
        }
        // L y = P b, column by column (diagonal first in each column).
        for j in 0..self.n {
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
        // would be bound by add latency (≈ 23 entries per column here).
        for j in (0..self.n).rev() {
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
        for (xi, &p) in x.iter().zip(&self.perm) {
            rhs[p as usize] = *xi;
        }
    }

    /// faer's solve on the same factor (the implementation [`HeatGeodesic::solve`] replaced),
    /// for tests and the timing probe: `which` 0 = heat, 1 = Poisson.
    #[cfg(test)]
    pub(crate) fn solve_faer(&self, which: usize, rhs: &mut [f64]) {
        use faer::sparse::linalg::cholesky::LltRef;
        let factor = if which == 0 {
            &self.heat
        } else {
            &self.poisson
        };
        let mut buf = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        LltRef::<usize, f64>::new(&self.symbolic, &factor.values).solve_in_place_with_conj(
            faer::Conj::No,
            faer::MatMut::from_column_major_slice_mut(rhs, self.n, 1),
            Par::Seq,
            MemStack::new(&mut buf),
        );
    }

    /// [`HeatGeodesic::solve`] by index, for tests: `which` 0 = heat, 1 = Poisson.
    #[cfg(test)]
    pub(crate) fn solve_own(&self, which: usize, rhs: &mut [f64], x: &mut [f64]) {
        let factor = if which == 0 {
            &self.heat
        } else {
            &self.poisson
        };
        self.solve(factor, rhs, x);
    }
}
