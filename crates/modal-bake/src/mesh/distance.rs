//! Distance between a surface asset and the boundary of the tetrahedral mesh made from it: the
//! two one-sided Hausdorff distances, sampled.
//!
//! d(A→M) = max over points a of A of the distance from a to the surface M, and d(M→A) the
//! same the other way; the Hausdorff distance is the larger. Each surface is sampled at its
//! vertices and on a barycentric grid in every triangle with spacing at most h = diag/200
//! (diag: the asset's bounding-box diagonal; h grows when that would exceed
//! [`MAX_SAMPLES`] points per side), so a one-sided distance is exact to within about h/2 for
//! the sampled side. Distances to a surface are exact point projections onto its triangles
//! (parry's `TriMesh` with its BVH).

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::TriMesh;
use rayon::prelude::*;

use super::surface::SurfaceMesh;
use super::TetMesh;

/// Most sample points per surface.
pub const MAX_SAMPLES: usize = 400_000;

/// The sampled distances between an asset and a mesh boundary (m).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SurfaceDistance {
    /// Largest distance from a point of the asset to the mesh boundary (m).
    pub asset_to_mesh_m: f64,
    /// Where on the asset that distance is reached (m).
    pub asset_to_mesh_at: [f64; 3],
    /// Largest distance from a point of the mesh boundary to the asset (m).
    pub mesh_to_asset_m: f64,
    /// Where on the mesh boundary that distance is reached (m).
    pub mesh_to_asset_at: [f64; 3],
    /// The Hausdorff distance: the larger of the two (m).
    pub hausdorff_m: f64,
    /// `hausdorff_m` over the asset's bounding-box diagonal.
    pub relative: f64,
    /// The sample spacing used (m).
    pub spacing_m: f64,
    /// Points sampled on the asset and on the mesh boundary.
    pub samples: [usize; 2],
}

/// Points on the triangles: a barycentric grid of spacing at most `h` (corners excluded) and
/// each centroid.
fn sample(vertices: &[[f64; 3]], triangles: &[[usize; 3]], h: f64) -> Vec<[f64; 3]> {
    let mut pts: Vec<[f64; 3]> = Vec::new();
    for t in triangles {
        let [a, b, c] = t.map(|v| vertices[v]);
        let len = |p: [f64; 3], q: [f64; 3]| {
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let longest = len(a, b).max(len(b, c)).max(len(c, a));
        let n = ((longest / h).ceil() as usize).clamp(1, 1000);
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let w = 1.0 - u - v;
                if (i == 0 && j == 0) || (i == n) || (j == n) {
                    continue; // corners are the vertices
                }
                pts.push([
                    w * a[0] + u * b[0] + v * c[0],
                    w * a[1] + u * b[1] + v * c[1],
                    w * a[2] + u * b[2] + v * c[2],
                ]);
            }
        }
        pts.push([
            (a[0] + b[0] + c[0]) / 3.0,
            (a[1] + b[1] + c[1]) / 3.0,
            (a[2] + b[2] + c[2]) / 3.0,
        ]);
    }
    pts
}

/// Points a grid of spacing `h` puts on the triangles (an estimate, for choosing `h`).
fn count_samples(vertices: &[[f64; 3]], triangles: &[[usize; 3]], h: f64) -> f64 {
    let area: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| vertices[v]);
            let n = dcr_runtime::math::cross(
                dcr_runtime::math::sub(b, a),
                dcr_runtime::math::sub(c, a),
            );
            0.5 * dcr_runtime::math::norm2(n).sqrt()
        })
        .sum();
    vertices.len() as f64 + 2.0 * triangles.len() as f64 + 2.0 * area / (h * h)
}

fn trimesh(vertices: &[[f64; 3]], triangles: &[[usize; 3]]) -> Option<TriMesh> {
    let v = vertices
        .iter()
        .map(|p| Vector::new(p[0], p[1], p[2]))
        .collect();
    let t = triangles.iter().map(|t| t.map(|i| i as u32)).collect();
    TriMesh::new(v, t).ok()
}

/// The largest distance from `points` to `target`, and where (the first point reaching it).
fn one_side(points: &[[f64; 3]], target: &TriMesh) -> (f64, [f64; 3]) {
    let (d, i) = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let q = Vector::new(p[0], p[1], p[2]);
            let proj = target.project_local_point(q, false);
            ((proj.point - q).length(), i)
        })
        .reduce(
            || (0.0, usize::MAX),
            |a, b| {
                if b.0 > a.0 || (b.0 == a.0 && b.1 < a.1) {
                    b
                } else {
                    a
                }
            },
        );
    (d, points.get(i).copied().unwrap_or([0.0; 3]))
}

/// The sampled distances between `asset` and the boundary of `mesh` (both in m, one frame);
/// deterministic (the same inputs give the same numbers with any thread count).
///
/// ```
/// use modal_bake::mesh::{surface_distance, surface::SurfaceMesh, TetMesh};
/// let mesh = TetMesh::structured_box([2, 2, 2], [1.0, 1.0, 1.0]);
/// // The asset: the box's top face lifted by 1 cm.
/// let asset = SurfaceMesh {
///     vertices: vec![[0.0, 0.0, 1.01], [1.0, 0.0, 1.01], [1.0, 1.0, 1.01], [0.0, 1.0, 1.01]],
///     triangles: vec![[0, 1, 2], [0, 2, 3]],
/// };
/// let d = surface_distance(&asset, &mesh);
/// assert!((d.asset_to_mesh_m - 0.01).abs() < 1e-12);
/// assert!(d.mesh_to_asset_m > 1.0); // the box's bottom is far from the asset
/// ```
pub fn surface_distance(asset: &SurfaceMesh, mesh: &TetMesh) -> SurfaceDistance {
    let (_, boundary) = super::extract_surface(mesh);
    let bbox = asset.bounding_box();
    let diag = (0..3)
        .map(|k| (bbox[1][k] - bbox[0][k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let mut h = diag / 200.0;
    let most = count_samples(&asset.vertices, &asset.triangles, h).max(count_samples(
        &mesh.nodes,
        &boundary,
        h,
    ));
    if most > MAX_SAMPLES as f64 {
        h *= (most / MAX_SAMPLES as f64).sqrt();
    }
    let (Some(asset_tm), Some(mesh_tm)) = (
        trimesh(&asset.vertices, &asset.triangles),
        trimesh(&mesh.nodes, &boundary),
    ) else {
        return SurfaceDistance::default();
    };
    let mut a_pts = asset.vertices.clone();
    a_pts.extend(sample(&asset.vertices, &asset.triangles, h));
    // The boundary's own nodes (mesh.nodes also holds interior ones), then its grid points.
    let mut used = vec![false; mesh.nodes.len()];
    for t in &boundary {
        for &v in t {
            used[v] = true;
        }
    }
    let mut m_pts: Vec<[f64; 3]> = mesh
        .nodes
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(p, _)| *p)
        .collect();
    m_pts.extend(sample(&mesh.nodes, &boundary, h));
    let (am, am_at) = one_side(&a_pts, &mesh_tm);
    let (ma, ma_at) = one_side(&m_pts, &asset_tm);
    let hausdorff = am.max(ma);
    SurfaceDistance {
        asset_to_mesh_m: am,
        asset_to_mesh_at: am_at,
        mesh_to_asset_m: ma,
        mesh_to_asset_at: ma_at,
        hausdorff_m: hausdorff,
        relative: if diag > 0.0 { hausdorff / diag } else { 0.0 },
        spacing_m: h,
        samples: [a_pts.len(), m_pts.len()],
    }
}
