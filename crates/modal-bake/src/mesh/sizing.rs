//! The element size of a surface asset's tetrahedra: the default size, the curvature-driven
//! refinement that follows the asset's shape, and the equivalent uniform size used by the
//! size estimate before meshing.
//!
//! gmsh remeshes a surface at `--size` h. Where the surface curves, it makes elements no
//! larger than 2π·R/N (R the local radius of curvature; gmsh's `Mesh.MeshSizeFromCurvature`,
//! N elements per full turn), with
//!
//! N = [`CURVATURE_ELEMENTS`] · h₀ / h,   h₀ = [`default_size`] (1/20 of the diagonal),
//!
//! so every element size is proportional to h: halving `--size` halves the elements on flat
//! and curved parts alike (N = 6 at the default size, 12 at half of it), which keeps "the same
//! mesh at half the size" a real refinement. A uniform size rounds off ears, handles and
//! fillets at a coarse h and changes the shape; with curvature sizing the remeshed surface
//! keeps them, at far fewer elements than a uniform size fine enough to keep them.
//!
//! Thin walls ([`thickness_grid`]): elements much larger than a wall's thickness t make it far
//! too stiff in bending. Each triangle's shape diameter (a ray along its inward normal to the
//! opposite side, [`shape_diameters`]) gives a [`wall_size`] of [`WALL_SIZE_FACTOR`]·t, never
//! below h/[`MAX_WALL_REFINEMENT`] nor above h; spread onto a regular grid, it becomes gmsh's
//! `Structured` background field, which gmsh combines with h and the curvature sizes by
//! taking the smallest. The rule follows the wall, not h: a smaller h refines wherever it is
//! below 1.5·t. The grid is written once per run (a few MB at most, [`MAX_GRID_NODES`]);
//! hand-written because gmsh reads its own text format and nothing else is needed.

use super::surface::SurfaceMesh;

/// Elements per full turn (2π radians of curvature) at the default size.
pub const CURVATURE_ELEMENTS: f64 = 6.0;

/// Dihedral angle (radians) above which an edge is a feature line, not curvature: gmsh's
/// surface classification splits the surface into patches there (40°).
pub const FEATURE_ANGLE: f64 = 40.0 * std::f64::consts::PI / 180.0;

/// The bounding-box diagonal of `bbox` (m).
pub fn diagonal(bbox: [[f64; 3]; 2]) -> f64 {
    (0..3)
        .map(|k| (bbox[1][k] - bbox[0][k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Default element size (m): 1/20 of the bounding-box diagonal.
pub fn default_size(bbox: [[f64; 3]; 2]) -> f64 {
    diagonal(bbox) / 20.0
}

/// Elements per full turn of curvature at element size `size` (m) for an asset whose
/// bounding-box diagonal is `diag` (m): N = 6 · (diag/20) / size, rounded, at least 1.
pub fn curvature_elements(size: f64, diag: f64) -> u32 {
    let n = CURVATURE_ELEMENTS * (diag / 20.0) / size;
    if n.is_finite() {
        n.round().clamp(1.0, 10_000.0) as u32
    } else {
        1
    }
}

/// The uniform element size (m) that puts as many triangles on `surface`'s area as the
/// curvature-driven sizes at `size` do, and with `thickness` the thickness-aware ones
/// ([`wall_size`]) too: the area-weighted mean of 1/s² over the triangles, as
/// (Σ A)/(Σ A/s²) = h_eq⁻² (for the size estimate before meshing; `size` itself when the
/// surface is flat and thick, or both are off).
///
/// The local radius of curvature at a triangle is estimated from its edges below
/// [`FEATURE_ANGLE`]: an edge whose adjacent triangles' normals differ by θ over the distance
/// d across the edge between their centroids curves with radius d/θ (a slight overestimate
/// of the curvature on slender triangles, 1.5/R on a cylinder of long strips). This sees the surface's curvature, not
/// the curvature of its feature lines (gmsh refines those too), so it underestimates on a
/// part with many small holes; the bake checks the real mesh against the budget again before
/// the factorization.
pub fn equivalent_size(surface: &SurfaceMesh, size: f64, curvature: bool, thickness: bool) -> f64 {
    let diameters = (thickness && !surface.triangles.is_empty()).then(|| shape_diameters(surface));
    equivalent_size_with(surface, size, curvature, diameters.as_deref())
}

/// [`equivalent_size`] with the triangles' wall thicknesses already measured
/// ([`shape_diameters`], m): `Some` for thickness-aware sizes, `None` without.
pub fn equivalent_size_with(
    surface: &SurfaceMesh,
    size: f64,
    curvature: bool,
    diameters: Option<&[Option<f64>]>,
) -> f64 {
    if !(curvature || diameters.is_some()) || !(size > 0.0) || surface.triangles.is_empty() {
        return size;
    }
    let local = local_sizes(surface, size, curvature, diameters);
    let (mut total, mut weighted) = (0.0, 0.0);
    for (t, s) in surface.triangles.iter().zip(&local) {
        let a = triangle_area(surface, *t);
        total += a;
        weighted += a / (s * s);
    }
    if weighted > 0.0 {
        (total / weighted).sqrt()
    } else {
        size
    }
}

/// The area (m²) of triangle `t` of `surface`.
fn triangle_area(surface: &SurfaceMesh, t: [usize; 3]) -> f64 {
    let [a, b, c] = t.map(|i| surface.vertices[i]);
    let cr = dcr_runtime::math::cross(dcr_runtime::math::sub(b, a), dcr_runtime::math::sub(c, a));
    0.5 * dcr_runtime::math::norm2(cr).sqrt()
}

/// Each triangle's element size (m) at `--size` `size`: its [`wall_size`] with the walls'
/// `diameters` (`size` without), and with `curvature` no more than 2π·R/N at its radius of
/// curvature R (N = [`curvature_elements`]); R as [`equivalent_size`] measures it, from the
/// edges below [`FEATURE_ANGLE`]. The sizes the size estimate assumes, and the field of
/// [`surface_size_grid`].
pub fn local_sizes(
    surface: &SurfaceMesh,
    size: f64,
    curvature: bool,
    diameters: Option<&[Option<f64>]>,
) -> Vec<f64> {
    let walls: Vec<f64> = match diameters {
        Some(d) => d.iter().map(|t| wall_size(*t, size)).collect(),
        None => vec![size; surface.triangles.len()],
    };
    if !curvature {
        return walls;
    }
    let n = f64::from(curvature_elements(size, diagonal(surface.bounding_box())));
    let v = &surface.vertices;
    let tri = &surface.triangles;
    let mut normal = Vec::with_capacity(tri.len());
    let mut area = Vec::with_capacity(tri.len());
    for t in tri {
        let [a, b, c] = t.map(|i| v[i]);
        let cr =
            dcr_runtime::math::cross(dcr_runtime::math::sub(b, a), dcr_runtime::math::sub(c, a));
        let len = dcr_runtime::math::norm2(cr).sqrt();
        area.push(0.5 * len);
        normal.push(if len > 0.0 {
            cr.map(|x| x / len)
        } else {
            [0.0; 3]
        });
    }
    // Edges (sorted vertex pair) with their triangles, sorted for a deterministic pairing.
    let mut edges: Vec<([usize; 2], usize)> = Vec::with_capacity(3 * tri.len());
    for (i, t) in tri.iter().enumerate() {
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            edges.push(([p.min(q), p.max(q)], i));
        }
    }
    edges.sort_unstable();
    let mut curvature_of = vec![0.0f64; tri.len()];
    for w in edges.chunk_by(|x, y| x.0 == y.0) {
        let [(_, a), (_, b)] = w else { continue };
        let (a, b) = (*a, *b);
        let cos = dcr_runtime::math::dot(normal[a], normal[b]).clamp(-1.0, 1.0);
        let theta = cos.acos();
        if !(theta > 0.0 && theta <= FEATURE_ANGLE) {
            continue;
        }
        // Distance across the edge between the two centroids: each lies 2·area/(3·|e|)
        // from the edge's line (the centroid distance itself also counts any offset along
        // the edge, large on slender triangles).
        let [p, q] = w[0].0;
        let e = dcr_runtime::math::norm2(dcr_runtime::math::sub(v[p], v[q])).sqrt();
        let d = if e > 0.0 {
            2.0 * (area[a] + area[b]) / (3.0 * e)
        } else {
            0.0
        };
        if d > 0.0 {
            let k = theta / d;
            curvature_of[a] = curvature_of[a].max(k);
            curvature_of[b] = curvature_of[b].max(k);
        }
    }
    walls
        .iter()
        .zip(&curvature_of)
        .map(|(wall, k)| {
            if *k > 0.0 {
                wall.min(std::f64::consts::TAU / (n * k))
            } else {
                *wall
            }
        })
        .collect()
}

/// Fraction of the surface area whose thickness [`thin_parts`] reports: the thinnest 5 %.
pub const THIN_AREA_FRACTION: f64 = 0.05;

/// The shape diameter of each triangle (m): the distance from its centroid along its inward
/// normal to the next triangle hit (a ray cast through parry's BVH); `None` where no ray hits
/// (a degenerate triangle, or a surface without a closed inside). Computed in parallel, the
/// result does not depend on the thread count.
pub fn shape_diameters(surface: &SurfaceMesh) -> Vec<Option<f64>> {
    use parry3d_f64::math::Vector;
    use parry3d_f64::query::{Ray, RayCast};
    use parry3d_f64::shape::TriMesh;
    use rayon::prelude::*;
    let v = &surface.vertices;
    let Ok(tm) = TriMesh::new(
        v.iter().map(|p| Vector::new(p[0], p[1], p[2])).collect(),
        surface
            .triangles
            .iter()
            .map(|t| t.map(|i| i as u32))
            .collect(),
    ) else {
        return vec![None; surface.triangles.len()];
    };
    // Inward is against the normal of an outward-oriented surface (positive volume).
    let inward = if surface.signed_volume() >= 0.0 {
        -1.0
    } else {
        1.0
    };
    let eps = 1e-9 * diagonal(surface.bounding_box());
    surface
        .triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| v[i]);
            let cr = dcr_runtime::math::cross(
                dcr_runtime::math::sub(b, a),
                dcr_runtime::math::sub(c, a),
            );
            let len = dcr_runtime::math::norm2(cr).sqrt();
            if !(len > 0.0) {
                return None;
            }
            let d = cr.map(|x| inward * x / len);
            let o = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0 + eps * d[k]);
            let ray = Ray::new(Vector::new(o[0], o[1], o[2]), Vector::new(d[0], d[1], d[2]));
            let toi = tm.cast_local_ray(&ray, f64::MAX, false)?;
            (toi > 0.0).then_some(toi + eps)
        })
        .collect()
}

/// The thickness (m) of the asset's thinnest parts: the area-weighted
/// [`THIN_AREA_FRACTION`] quantile of the [`shape_diameters`]. `None` for a surface without
/// a closed inside (no ray hits). A 2 mm wall of a 130 mm part gives 2 mm; a sphere its
/// diameter.
///
/// Elements much larger than a wall's thickness make it too stiff in bending, 10-node ones
/// less so; the `mesh` command warns when the size is above twice this thickness.
pub fn thin_parts(surface: &SurfaceMesh) -> Option<f64> {
    thin_parts_from(surface, &shape_diameters(surface))
}

/// [`thin_parts`] from the surface's [`shape_diameters`] already computed.
pub fn thin_parts_from(surface: &SurfaceMesh, diameters: &[Option<f64>]) -> Option<f64> {
    let v = &surface.vertices;
    let mut hits: Vec<(f64, f64)> = surface
        .triangles
        .iter()
        .zip(diameters)
        .filter_map(|(t, d)| {
            let [a, b, c] = t.map(|i| v[i]);
            let cr = dcr_runtime::math::cross(
                dcr_runtime::math::sub(b, a),
                dcr_runtime::math::sub(c, a),
            );
            Some(((*d)?, 0.5 * dcr_runtime::math::norm2(cr).sqrt()))
        })
        .collect();
    if hits.is_empty() {
        return None;
    }
    hits.sort_by(|x, y| x.0.total_cmp(&y.0));
    let total: f64 = hits.iter().map(|h| h.1).sum();
    let mut acc = 0.0;
    for (t, a) in &hits {
        acc += a;
        if acc >= THIN_AREA_FRACTION * total {
            return Some(*t);
        }
    }
    hits.last().map(|h| h.0)
}

/// Largest element size, in wall thicknesses, of thickness-aware sizing: in a wall of
/// thickness t the elements are at most 1.5·t. The largest factor that brings gmsh's
/// thin-walled tutorial part within about 2 % of its refined reference inside the default
/// budget (docs/artist-guide.md, § Thin walls).
pub const WALL_SIZE_FACTOR: f64 = 1.5;

/// Thickness-aware sizing never makes elements smaller than `size` / 4: a hair-thin feature
/// does not refine the whole mesh (it is reported as thin instead).
pub const MAX_WALL_REFINEMENT: f64 = 4.0;

/// Most grid nodes of a [`SizeGrid`] (a file of a few tens of MB at most for gmsh to read).
pub const MAX_GRID_NODES: usize = 2_000_000;

/// The thickness-aware size of a triangle whose shape diameter is `t` (m) at `--size` `size`
/// (m): min(size, max([`WALL_SIZE_FACTOR`]·t, size/[`MAX_WALL_REFINEMENT`])); `size` where
/// no thickness was measured.
pub fn wall_size(t: Option<f64>, size: f64) -> f64 {
    match t {
        Some(t) if t.is_finite() && t > 0.0 => (WALL_SIZE_FACTOR * t)
            .max(size / MAX_WALL_REFINEMENT)
            .min(size),
        _ => size,
    }
}

/// A scalar field of element sizes (m) on a regular grid over the asset's bounding box, for
/// gmsh's `Structured` mesh-size field (trilinear interpolation between grid nodes).
#[derive(Clone, Debug, PartialEq)]
pub struct SizeGrid {
    /// Position of node (0, 0, 0) (m).
    pub origin: [f64; 3],
    /// Node spacing along x, y, z (m).
    pub spacing: [f64; 3],
    /// Nodes along x, y, z (each at least 2).
    pub dims: [usize; 3],
    /// Sizes (m), z fastest, then y, then x: node (i, j, k) at `(i·dims[1] + j)·dims[2] + k`.
    pub values: Vec<f64>,
    /// Fraction of the surface area whose own size (wall thickness, or curvature) is finer than
    /// the size.
    pub refined_area_fraction: f64,
    /// The smallest size on the grid (m).
    pub smallest_m: f64,
}

impl SizeGrid {
    /// The file gmsh's `Structured` field reads with `TextFormat = 1`: origin, spacing,
    /// dimensions, then the values (shortest round-trip decimals).
    pub fn to_gmsh_text(&self) -> String {
        use std::fmt::Write;
        let mut s = String::with_capacity(12 * self.values.len() + 128);
        let [o, d] = [self.origin, self.spacing];
        let _ = writeln!(s, "{:?} {:?} {:?}", o[0], o[1], o[2]);
        let _ = writeln!(s, "{:?} {:?} {:?}", d[0], d[1], d[2]);
        let _ = writeln!(s, "{} {} {}", self.dims[0], self.dims[1], self.dims[2]);
        for row in self.values.chunks(self.dims[2]) {
            for (k, x) in row.iter().enumerate() {
                if k > 0 {
                    s.push(' ');
                }
                let _ = write!(s, "{x:?}");
            }
            s.push('\n');
        }
        s
    }
}

/// Thickness-aware element sizes for `surface` at `--size` `size` (m): each triangle's
/// [`wall_size`] from its [`shape_diameters`], spread onto a grid (every node within one grid
/// diagonal of a triangle takes the smallest such size; other nodes `size`) so that the
/// elements inside a thin wall, and on both its faces, are no larger than
/// [`WALL_SIZE_FACTOR`] times its thickness. `None` when no part is thinner than
/// size/[`WALL_SIZE_FACTOR`] (the field would change nothing).
///
/// The grid spacing is half the smallest wall size, coarsened until the grid has at most
/// [`MAX_GRID_NODES`] nodes.
pub fn thickness_grid(surface: &SurfaceMesh, size: f64) -> Option<SizeGrid> {
    thickness_grid_from(surface, &shape_diameters(surface), size)
}

/// [`thickness_grid`] from the surface's [`shape_diameters`] already computed.
pub fn thickness_grid_from(
    surface: &SurfaceMesh,
    diameters: &[Option<f64>],
    size: f64,
) -> Option<SizeGrid> {
    let sizes: Vec<f64> = diameters.iter().map(|t| wall_size(*t, size)).collect();
    surface_size_grid(surface, &sizes, size)
}

/// A grid of the triangles' own element sizes `sizes` (m, one per triangle, at most `size`),
/// spread as [`thickness_grid`] spreads the wall sizes: every node within one grid diagonal
/// of a triangle takes the smallest such size, other nodes `size`. `None` when no triangle is
/// finer than `size` (the field would change nothing) or `size` is not a positive number.
///
/// The grid spacing is half the smallest size, coarsened until the grid has at most
/// [`MAX_GRID_NODES`] nodes.
pub fn surface_size_grid(surface: &SurfaceMesh, sizes: &[f64], size: f64) -> Option<SizeGrid> {
    use parry3d_f64::math::Vector;
    use parry3d_f64::query::PointQuery;
    use parry3d_f64::shape::Triangle;
    if !(size.is_finite() && size > 0.0) {
        return None;
    }
    let v = &surface.vertices;
    let smallest = sizes.iter().copied().fold(size, f64::min);
    if !(smallest < size) {
        return None;
    }
    let (mut refined, mut total) = (0.0, 0.0);
    for (t, s) in surface.triangles.iter().zip(sizes) {
        let [a, b, c] = t.map(|i| v[i]);
        let cr =
            dcr_runtime::math::cross(dcr_runtime::math::sub(b, a), dcr_runtime::math::sub(c, a));
        let area = 0.5 * dcr_runtime::math::norm2(cr).sqrt();
        total += area;
        if *s < size {
            refined += area;
        }
    }
    let [lo, hi] = surface.bounding_box();
    let ext = [0, 1, 2].map(|k| (hi[k] - lo[k]).max(0.0));
    let mut g = 0.5 * smallest;
    let nodes_at = |g: f64| -> [usize; 3] { ext.map(|e| (e / g).ceil() as usize + 3) };
    while nodes_at(g).iter().product::<usize>() > MAX_GRID_NODES {
        g *= 1.25;
    }
    let dims = nodes_at(g);
    let origin = [0, 1, 2].map(|k| lo[k] - g);
    let mut values = vec![size; dims.iter().product()];
    let reach = g * 3f64.sqrt();
    for (t, s) in surface.triangles.iter().zip(sizes) {
        if !(*s < size) {
            continue;
        }
        let [a, b, c] = t.map(|i| v[i]);
        let tri = Triangle::new(
            Vector::new(a[0], a[1], a[2]),
            Vector::new(b[0], b[1], b[2]),
            Vector::new(c[0], c[1], c[2]),
        );
        let range = |k: usize| {
            let lo_k = a[k].min(b[k]).min(c[k]) - reach;
            let hi_k = a[k].max(b[k]).max(c[k]) + reach;
            let i0 = ((lo_k - origin[k]) / g).floor().max(0.0) as usize;
            let i1 = (((hi_k - origin[k]) / g).ceil().max(0.0) as usize).min(dims[k] - 1);
            i0..=i1
        };
        for i in range(0) {
            for j in range(1) {
                for k in range(2) {
                    let at = (i * dims[1] + j) * dims[2] + k;
                    if values[at] <= *s {
                        continue;
                    }
                    let p = Vector::new(
                        origin[0] + i as f64 * g,
                        origin[1] + j as f64 * g,
                        origin[2] + k as f64 * g,
                    );
                    if tri.distance_to_local_point(p, true) <= reach {
                        values[at] = *s;
                    }
                }
            }
        }
    }
    Some(SizeGrid {
        origin,
        spacing: [g; 3],
        dims,
        values,
        refined_area_fraction: if total > 0.0 { refined / total } else { 0.0 },
        smallest_m: smallest,
    })
}
