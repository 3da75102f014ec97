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
/// curvature-driven sizes at `size` do (for the size estimate before meshing; `size` itself
/// when the surface is flat or `curvature` is off).
///
/// The local radius of curvature at a triangle is estimated from its edges below
/// [`FEATURE_ANGLE`]: an edge whose adjacent triangles' normals differ by θ over the distance
/// d across the edge between their centroids curves with radius d/θ (a slight overestimate
/// of the curvature on slender triangles, 1.5/R on a cylinder of long strips). This sees the surface's curvature, not
/// the curvature of its feature lines (gmsh refines those too), so it underestimates on a
/// part with many small holes; the bake checks the real mesh against the budget again before
/// the factorization.
pub fn equivalent_size(surface: &SurfaceMesh, size: f64, curvature: bool) -> f64 {
    if !curvature || !(size > 0.0) || surface.triangles.is_empty() {
        return size;
    }
    let n = f64::from(curvature_elements(size, diagonal(surface.bounding_box())));
    let v = &surface.vertices;
    let tri = &surface.triangles;
    let mut normal = Vec::with_capacity(tri.len());
    let mut centroid = Vec::with_capacity(tri.len());
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
        centroid.push([0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0));
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
    let (mut total, mut weighted) = (0.0, 0.0);
    for (a, k) in area.iter().zip(&curvature_of) {
        let local = if *k > 0.0 {
            size.min(std::f64::consts::TAU / (n * k))
        } else {
            size
        };
        total += a;
        weighted += a / (local * local);
    }
    if weighted > 0.0 {
        (total / weighted).sqrt()
    } else {
        size
    }
}

/// Fraction of the surface area whose thickness [`thin_parts`] reports: the thinnest 5 %.
pub const THIN_AREA_FRACTION: f64 = 0.05;

/// The thickness (m) of the asset's thinnest parts: the area-weighted
/// [`THIN_AREA_FRACTION`] quantile of the shape diameter, the distance from each triangle's
/// centroid along its inward normal to the next triangle hit (a ray cast through parry's
/// BVH). `None` for a surface without a closed inside (no ray hits). A 2 mm wall of a
/// 130 mm part gives 2 mm; a sphere its diameter.
///
/// Elements much larger than a wall's thickness make it too stiff in bending, 10-node ones
/// less so; the `mesh` command warns when the size is above twice this thickness.
pub fn thin_parts(surface: &SurfaceMesh) -> Option<f64> {
    use parry3d_f64::math::Vector;
    use parry3d_f64::query::{Ray, RayCast};
    use parry3d_f64::shape::TriMesh;
    use rayon::prelude::*;
    let v = &surface.vertices;
    let tm = TriMesh::new(
        v.iter().map(|p| Vector::new(p[0], p[1], p[2])).collect(),
        surface
            .triangles
            .iter()
            .map(|t| t.map(|i| i as u32))
            .collect(),
    )
    .ok()?;
    // Inward is against the normal of an outward-oriented surface (positive volume).
    let inward = if surface.signed_volume() >= 0.0 {
        -1.0
    } else {
        1.0
    };
    let eps = 1e-9 * diagonal(surface.bounding_box());
    let mut hits: Vec<(f64, f64)> = surface
        .triangles
        .par_iter()
        .filter_map(|t| {
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
            (toi > 0.0).then_some((toi + eps, 0.5 * len))
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
