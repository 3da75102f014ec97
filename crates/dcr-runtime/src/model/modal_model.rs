//! [`ModalModel`]: a validated base, its surface BVH and the per-vertex data every query reuses.

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::TriMesh;

use super::{quadratic_triangle_weights, LoadError, SurfacePoint};
use crate::attenuation::{GeodesicError, GeodesicTable, HeatGeodesic};
use crate::format::ModesFile;
use crate::math::{add, cross, norm, normalize, sub};

/// An immutable modal model shared (via `Arc`) by every object instance that uses the same base.
///
/// Object frame = the base's frame (m). Mass-normalised modes: U has units m·kg^-1/2, so a
/// reduced impulse `r = Uᵀ f` is in kg^1/2·m/s and `q` in kg^1/2·m.
#[derive(Debug)]
pub struct ModalModel {
    base: ModesFile,
    omega: Vec<f64>,
    normals: Vec<[f64; 3]>,
    normal_rows: Vec<f64>,
    trimesh: TriMesh,
    bbox_diagonal: f64,
    mean_edge_length: f64,
    /// Second-order bases: per surface triangle, the mid-edge node (index into
    /// `base.quadratic`) of its edges (v₀,v₁), (v₁,v₂), (v₂,v₀). Empty for a linear base.
    tri_edges: Vec<[u32; 3]>,
    heat: OnceLock<Result<HeatGeodesic, GeodesicError>>,
    geodesic_table: OnceLock<GeodesicTable>,
}

impl ModalModel {
    /// Reads and validates a `.modes` file and builds the model.
    ///
    /// # Errors
    /// [`LoadError`] naming the file: unreadable, truncated, mismatched shapes, NaN, or a surface
    /// the BVH cannot be built from.
    pub fn load(path: &Path) -> Result<Arc<ModalModel>, LoadError> {
        let base = ModesFile::read(path)?;
        Self::build(base, path).map(Arc::new)
    }

    /// Builds a model from an in-memory base, validating it first (errors name `<memory>`).
    ///
    /// # Errors
    /// As [`ModalModel::load`].
    pub fn from_base(base: ModesFile) -> Result<ModalModel, LoadError> {
        Self::build(base, Path::new("<memory>"))
    }

    fn build(base: ModesFile, path: &Path) -> Result<ModalModel, LoadError> {
        base.validate(path)?;
        let invalid = |detail: String| LoadError::Invalid {
            path: PathBuf::from(path),
            detail,
        };
        let ns = base.num_surface_vertices();
        let m = base.num_modes();
        let omega: Vec<f64> = base.eigenvalues.iter().map(|l| l.sqrt()).collect();
        let x = &base.surface_vertices;
        let mut normals = vec![[0.0; 3]; ns];
        let mut edge_sum = 0.0;
        for t in &base.surface_triangles {
            let [a, b, c] = t.map(|i| i as usize);
            let n = cross(sub(x[b], x[a]), sub(x[c], x[a]));
            for v in [a, b, c] {
                normals[v] = add(normals[v], n);
            }
            edge_sum += norm(sub(x[b], x[a])) + norm(sub(x[c], x[b])) + norm(sub(x[a], x[c]));
        }
        let mean_edge_length = edge_sum / (3.0 * base.surface_triangles.len() as f64);
        for n in &mut normals {
            *n = normalize(*n);
        }
        let mut normal_rows = vec![0.0; ns * m];
        for v in 0..ns {
            let n = normals[v];
            for axis in 0..3 {
                let row = &base.modes[(v * 3 + axis) * m..(v * 3 + axis + 1) * m];
                for (o, u) in normal_rows[v * m..(v + 1) * m].iter_mut().zip(row) {
                    *o += n[axis] * u;
                }
            }
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in x {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let bbox_diagonal = norm(sub(hi, lo));
        let verts: Vec<Vector> = x.iter().map(|p| Vector::new(p[0], p[1], p[2])).collect();
        let trimesh = TriMesh::new(verts, base.surface_triangles.clone())
            .map_err(|e| invalid(format!("surface BVH: {e:?}")))?;
        if trimesh.num_triangles() != base.surface_triangles.len() {
            return Err(invalid("the BVH dropped surface triangles".into()));
        }
        let tri_edges = match &base.quadratic {
            Some(q) => q.triangle_edges(&base.surface_triangles).map_err(invalid)?,
            None => Vec::new(),
        };
        Ok(ModalModel {
            base,
            omega,
            normals,
            normal_rows,
            trimesh,
            bbox_diagonal,
            mean_edge_length,
            tri_edges,
            heat: OnceLock::new(),
            geodesic_table: OnceLock::new(),
        })
    }

    /// The validated base this model was built from.
    pub fn base(&self) -> &ModesFile {
        &self.base
    }

    /// Number of modes m.
    pub fn num_modes(&self) -> usize {
        self.omega.len()
    }

    /// Number of surface vertices ns.
    pub fn num_vertices(&self) -> usize {
        self.normals.len()
    }

    /// Undamped angular frequencies ω_j = √λ_j (rad/s), ascending.
    pub fn omega(&self) -> &[f64] {
        &self.omega
    }

    /// Area-weighted outward unit vertex normals (object frame), one per surface vertex
    /// (`[0, 0, 0]` for a vertex no triangle uses).
    pub fn vertex_normals(&self) -> &[[f64; 3]] {
        &self.normals
    }

    /// Row-major (ns, m) table of `n_vᵀ U_v` (m·kg^-1/2): normal displacement of vertex v per unit
    /// modal coordinate (paper Eq. 11 rows).
    pub fn normal_mode_rows(&self) -> &[f64] {
        &self.normal_rows
    }

    /// Diagonal of the surface's axis-aligned bounding box (m).
    pub fn bounding_box_diagonal(&self) -> f64 {
        self.bbox_diagonal
    }

    /// Mean surface edge length (m).
    pub fn mean_edge_length(&self) -> f64 {
        self.mean_edge_length
    }

    /// The three vertex indices of surface triangle `t`.
    pub fn triangle(&self, t: u32) -> [usize; 3] {
        self.base.surface_triangles[t as usize].map(|i| i as usize)
    }

    /// A per-vertex field (one value per surface vertex, any unit) read at a surface point:
    /// linear in its triangle, Σ bary_i · field\[v_i\].
    pub fn interpolate(&self, field: &[f64], sp: &SurfacePoint) -> f64 {
        let vs = self.triangle(sp.triangle);
        (0..3).map(|i| sp.bary[i] * field[vs[i]]).sum()
    }

    /// Projects `p` (object frame, m) onto the surface with the BVH; `None` if the surface is
    /// farther than `max_distance` (m). Never snaps a far point.
    pub fn project(&self, p: [f64; 3], max_distance: f64) -> Option<SurfacePoint> {
        if !(p.iter().all(|x| x.is_finite()) && max_distance >= 0.0) {
            return None;
        }
        let q = Vector::new(p[0], p[1], p[2]);
        let (_, (tri, loc)) = self
            .trimesh
            .project_local_point_and_get_location_with_max_dist(q, false, max_distance)?;
        let mut bary = loc.barycentric_coordinates()?;
        for b in &mut bary {
            *b = b.clamp(0.0, 1.0);
        }
        let s = bary[0] + bary[1] + bary[2];
        if !(s > 0.0) {
            return None;
        }
        bary = bary.map(|b| b / s);
        let sp = self.surface_point(tri, bary, p);
        (sp.distance <= max_distance).then_some(sp)
    }

    /// Builds the [`SurfacePoint`] at barycentric `bary` of triangle `tri`; `distance` is measured
    /// from `query` (m).
    pub fn surface_point(&self, tri: u32, bary: [f64; 3], query: [f64; 3]) -> SurfacePoint {
        let b = &self.base;
        super::surface_point_on(
            &b.surface_vertices,
            &b.surface_triangles,
            &self.normals,
            tri,
            bary,
            query,
        )
    }

    /// Whether the base is second-order (modes interpolated quadratically on 6-node triangles).
    pub fn is_quadratic(&self) -> bool {
        self.base.quadratic.is_some()
    }

    /// Reduced impulse `r += Uᵀ H (d·λ)` (paper Eq. 9) of an impulse `lambda` (N·s) along unit
    /// `direction` (object frame) applied at `sp`; `r` has length m. H holds the shape
    /// functions at `sp`: the barycentric weights (linear base) or the six
    /// [`quadratic_triangle_weights`] (second-order base).
    pub fn add_reduced_impulse(
        &self,
        sp: &SurfacePoint,
        direction: [f64; 3],
        lambda: f64,
        r: &mut [f64],
    ) {
        let m = self.num_modes();
        let mut add_node = |rows: &[f64], node: usize, weight: f64| {
            for axis in 0..3 {
                let c = weight * direction[axis] * lambda;
                if c != 0.0 {
                    let row = &rows[(node * 3 + axis) * m..(node * 3 + axis + 1) * m];
                    for (o, u) in r.iter_mut().zip(row) {
                        *o += c * u;
                    }
                }
            }
        };
        let corners = self.triangle(sp.triangle);
        match &self.base.quadratic {
            None => {
                for (i, v) in corners.into_iter().enumerate() {
                    add_node(&self.base.modes, v, sp.bary[i]);
                }
            }
            Some(q) => {
                let w = quadratic_triangle_weights(sp.bary);
                for (i, v) in corners.into_iter().enumerate() {
                    add_node(&self.base.modes, v, w[i]);
                }
                let edges = self.tri_edges[sp.triangle as usize];
                for (k, e) in edges.into_iter().enumerate() {
                    add_node(&q.modes, e as usize, w[3 + k]);
                }
            }
        }
    }

    /// Contact row `w = nᵀ Σ_i N_i U_i` (m·kg^-1/2, length m) at `sp` with its interpolated
    /// normal (N_i: barycentric weights, or the quadratic shape functions of a second-order
    /// base): `w·q` is the normal displacement of the contact point.
    pub fn contact_row(&self, sp: &SurfacePoint, w: &mut [f64]) {
        w.iter_mut().for_each(|x| *x = 0.0);
        self.add_reduced_impulse(sp, sp.normal, 1.0, w);
    }

    /// The heat-method geodesic solver of this surface, factored on first use (under the
    /// base's stored `surface_order`, else AMD) and shared by every instance using the model.
    ///
    /// # Errors
    /// The [`GeodesicError`] from building it (e.g. degenerate triangles, unused vertices).
    pub fn heat_geodesic(&self) -> Result<&HeatGeodesic, &GeodesicError> {
        self.heat
            .get_or_init(|| {
                HeatGeodesic::with_ordering(
                    &self.base.surface_vertices,
                    &self.base.surface_triangles,
                    self.base.surface_order.as_deref(),
                )
            })
            .as_ref()
    }

    /// All-pairs heat-method distances over the surface's vertices, computed on first use
    /// (ns solves) and shared by every instance using the model.
    ///
    /// # Errors
    /// As [`ModalModel::heat_geodesic`]; a surface of more than
    /// [`GeodesicTable::MAX_VERTICES`] vertices is refused by the caller before this.
    pub fn geodesic_table(&self) -> Result<&GeodesicTable, &GeodesicError> {
        let heat = self.heat_geodesic()?;
        Ok(self
            .geodesic_table
            .get_or_init(|| GeodesicTable::build(heat)))
    }
}
