//! [`FullOrderSystem`]: the full-order FEM system of a mesh (free dofs), its surface, and the
//! M-orthogonal projector that removes rigid-body motion from loads and measurements.

use faer::sparse::SparseColMat;
use faer::Mat;

use dcr_runtime::model::SurfacePoint;

use super::surface_map::SurfaceMap;
use super::{FullOrderError, SystemParams};
use crate::fem::{self, DofMap, Material};
use crate::mesh::{TetMesh, DEFAULT_DEGENERATE_REL_TOL};

/// A prepared full-order problem: K (N/m) and M (kg) on the free dofs, the dof map, the boundary
/// surface, and (free-free only) the six rigid-body modes made M-orthonormal.
#[derive(Clone, Debug)]
pub struct FullOrderSystem {
    /// The oriented mesh (m).
    pub mesh: TetMesh,
    /// Full ↔ free dof map (fixed nodes removed).
    pub map: DofMap,
    /// Stiffness on the free dofs (N/m), both triangles stored.
    pub k: SparseColMat<usize, f64>,
    /// Mass on the free dofs (kg), both triangles stored.
    pub m: SparseColMat<usize, f64>,
    /// Boundary surface for mapping points.
    pub surface: SurfaceMap,
    /// Rayleigh damping [α0 (1/s), α1 (s)].
    pub rayleigh: [f64; 2],
    /// Number of fixed nodes (0: free-free).
    pub fixed_nodes: usize,
    /// Free-free only: rigid modes R̃ (n_free × 6), R̃ᵀ M R̃ = I.
    rigid: Option<Mat<f64>>,
}

impl FullOrderSystem {
    /// Orients and checks `mesh`, fixes the nodes `params`' selectors pick (groups, half-spaces,
    /// boxes: [`SystemParams::fixed_selectors`]), assembles K and M.
    ///
    /// # Errors
    /// [`FullOrderError`] on an invalid material, a degenerate or disconnected mesh, an unknown
    /// group, a selector that fixes no node, collinear fixed nodes or every node fixed.
    pub fn new(
        mut mesh: TetMesh,
        params: &SystemParams,
        file: &str,
    ) -> Result<Self, FullOrderError> {
        let mat = Material::new(
            params.material.youngs,
            params.material.poisson,
            params.material.density,
        )
        .map_err(|e| FullOrderError::Params(format!("invalid material: {e}")))?;
        if !params.rayleigh.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(FullOrderError::Params(format!(
                "Rayleigh coefficients [α0, α1] must be finite and ≥ 0, got {:?}",
                params.rayleigh
            )));
        }
        let name_file = |mut e: crate::mesh::MeshError| {
            if e.file.is_empty() {
                e.file = file.to_string();
            }
            FullOrderError::Mesh(e)
        };
        if mesh.tets.is_empty() {
            return Err(FullOrderError::Params(format!(
                "{file}: the mesh has no tetrahedra"
            )));
        }
        if mesh.is_quadratic() {
            return Err(FullOrderError::Params(format!(
                "{file}: the full-order reference supports 4-node tetrahedra only (its surface map is linear); use a linear mesh"
            )));
        }
        mesh.orient_tets(DEFAULT_DEGENERATE_REL_TOL)
            .map_err(name_file)?;
        let pieces = mesh.pieces();
        if pieces.len() != 1 {
            // The bake's refusal: the pieces, largest first, and what selects one.
            return Err(FullOrderError::Params(
                crate::bake::BakeError::Disconnected {
                    file: file.to_string(),
                    pieces: pieces.len(),
                    list: crate::mesh::list_pieces(&pieces),
                }
                .to_string(),
            ));
        }
        let fixed = params
            .fixed_selectors()
            .resolve(&mesh, file)
            .map_err(|e| match e {
                crate::bake::BakeError::Mesh(e) => FullOrderError::Mesh(e),
                crate::bake::BakeError::Params(msg) => FullOrderError::Params(msg),
                other => FullOrderError::Params(other.to_string()),
            })?
            .nodes;
        let (map, k, m) = fem::assemble_clamped(&mesh, &mat, params.lumped, &fixed)
            .map_err(|e| FullOrderError::Params(format!("{file}: {e}")))?;
        let rigid = if fixed.is_empty() {
            Some(m_orthonormal(&m, fem::rigid_body_modes(&mesh)))
        } else {
            None
        };
        let surface = SurfaceMap::new(&mesh);
        Ok(FullOrderSystem {
            mesh,
            map,
            k,
            m,
            surface,
            rayleigh: params.rayleigh,
            fixed_nodes: fixed.len(),
            rigid,
        })
    }

    /// Number of free dofs.
    pub fn n(&self) -> usize {
        self.map.n_free()
    }

    /// Whether the object is free-free (rigid motion is projected out).
    pub fn free_free(&self) -> bool {
        self.rigid.is_some()
    }

    /// Nodal impulse vector (N·s, free dofs) of an impulse `impulse` (N·s) along unit `direction`
    /// at `sp`, spread to the triangle's three nodes with the barycentric weights (paper Eq. 9,
    /// `H_cᵀ n λ`). Free-free: the rigid-body part is removed (see [`FullOrderSystem::remove_rigid`]).
    pub fn load_vector(&self, sp: &SurfacePoint, direction: [f64; 3], impulse: f64) -> Vec<f64> {
        let mut f = vec![0.0; self.n()];
        self.scatter(sp, direction, impulse, &mut f);
        self.remove_rigid(&mut f);
        f
    }

    /// Measurement row w (free dofs): `wᵀu` is the displacement (m) of `sp` along its
    /// interpolated normal, `nᵀ Σ_i b_i u_i` (paper Eq. 11). Free-free: rigid part removed, so
    /// `wᵀu` measures the elastic displacement only.
    pub fn contact_row(&self, sp: &SurfacePoint) -> Vec<f64> {
        let mut w = vec![0.0; self.n()];
        self.scatter(sp, sp.normal, 1.0, &mut w);
        self.remove_rigid(&mut w);
        w
    }

    fn scatter(&self, sp: &SurfacePoint, d: [f64; 3], s: f64, out: &mut [f64]) {
        for (i, v) in self
            .surface
            .triangle_nodes(sp.triangle)
            .into_iter()
            .enumerate()
        {
            for (axis, da) in d.iter().enumerate() {
                if let Some(j) = self.map.free_index(3 * v + axis) {
                    out[j] += sp.bary[i] * da * s;
                }
            }
        }
    }

    /// Free-free: the rigid modes R̃ (n_free × 6, m·kg^-1/2), R̃ᵀ M R̃ = I; `None` when clamped.
    pub fn rigid_modes(&self) -> Option<&Mat<f64>> {
        self.rigid.as_ref()
    }

    /// Free-free: `x ← x − M R̃ (R̃ᵀ x)` for a dual vector x (a load, or a measurement row).
    ///
    /// For a load f this removes exactly the part that drives rigid motion (R̃ᵀ f_e = 0); for a
    /// row w it makes `w_eᵀ u = wᵀ(u − R̃ R̃ᵀ M u)`, the displacement minus its M-orthogonal
    /// projection on the rigid modes. Rigid modes span an invariant subspace of
    /// M ü + (α0 M + α1 K) u̇ + K u (K R = 0), so the elastic part evolves on its own and equals
    /// the sum over every elastic mode, which is what a baked base truncates. Clamped: no-op.
    pub fn remove_rigid(&self, x: &mut [f64]) {
        let Some(r) = &self.rigid else { return };
        let n = self.n();
        let mut c = [0.0; 6];
        for (j, cj) in c.iter_mut().enumerate() {
            *cj = (0..n).map(|i| r[(i, j)] * x[i]).sum();
        }
        let mut rc = vec![0.0; n];
        for i in 0..n {
            rc[i] = (0..6).map(|j| r[(i, j)] * c[j]).sum();
        }
        let mut mrc = vec![0.0; n];
        spmv(&self.m, &rc, &mut mrc);
        for (xi, y) in x.iter_mut().zip(&mrc) {
            *xi -= y;
        }
    }
}

/// `y = A x` for a sparse matrix stored by columns with both triangles (any square matrix).
pub(crate) fn spmv(a: &SparseColMat<usize, f64>, x: &[f64], y: &mut [f64]) {
    let (ptr, rows, vals) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    y.iter_mut().for_each(|v| *v = 0.0);
    for (j, &xj) in x.iter().enumerate() {
        if xj == 0.0 {
            continue;
        }
        for p in ptr[j]..ptr[j + 1] {
            y[rows[p]] += vals[p] * xj;
        }
    }
}

/// Columns of `r` made M-orthonormal by modified Gram–Schmidt in the M inner product (twice).
fn m_orthonormal(m: &SparseColMat<usize, f64>, mut r: Mat<f64>) -> Mat<f64> {
    let n = r.nrows();
    let mut mv = vec![0.0; n];
    for j in 0..r.ncols() {
        for _pass in 0..2 {
            for i in 0..j {
                let col_i: Vec<f64> = (0..n).map(|k| r[(k, i)]).collect();
                spmv(m, &col_i, &mut mv);
                let c: f64 = (0..n).map(|k| mv[k] * r[(k, j)]).sum();
                for k in 0..n {
                    r[(k, j)] -= c * col_i[k];
                }
            }
        }
        let col: Vec<f64> = (0..n).map(|k| r[(k, j)]).collect();
        spmv(m, &col, &mut mv);
        let nrm = mv.iter().zip(&col).map(|(a, b)| a * b).sum::<f64>().sqrt();
        for k in 0..n {
            r[(k, j)] /= nrm;
        }
    }
    r
}
