//! A point mapped onto the model's surface, and the surface conventions every mapper shares:
//! area-weighted vertex normals and the point at barycentric weights of a triangle. Below both
//! [`crate::model`] (which re-exports these items) and [`crate::attenuation`] (whose geodesics
//! start from a [`SurfacePoint`]), so neither depends on the other for them.

use crate::math::{add, cross, norm, normalize, scale, sub};

/// A point projected onto the surface triangle mesh of a [`crate::ModalModel`] (object frame, m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Index of the surface triangle (into `ModesFile::surface_triangles`).
    pub triangle: u32,
    /// Barycentric weights of the triangle's three vertices (in triangle order); sum to 1, ≥ 0.
    pub bary: [f64; 3],
    /// The projected point `Σ bary_i x_i` (m, object frame).
    pub point: [f64; 3],
    /// Outward unit normal: area-weighted vertex normals interpolated with `bary`, normalised.
    pub normal: [f64; 3],
    /// Distance from the query point to `point` (m).
    pub distance: f64,
}

/// Weights of the six nodes of a 6-node (quadratic) triangle at barycentric `bary` = (b₀, b₁,
/// b₂): corners `bᵢ(2bᵢ − 1)`, then the mid-edge nodes of edges (v₀,v₁), (v₁,v₂), (v₂,v₀):
/// `4b₀b₁`, `4b₁b₂`, `4b₂b₀`. They sum to 1 when the bᵢ do, and reproduce every quadratic
/// field exactly. Corner weights are negative inside the triangle (down to −1/8).
///
/// ```
/// let w = dcr_runtime::model::quadratic_triangle_weights([0.5, 0.5, 0.0]);
/// assert_eq!(w, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
/// ```
#[inline]
pub fn quadratic_triangle_weights(bary: [f64; 3]) -> [f64; 6] {
    let [b0, b1, b2] = bary;
    [
        b0 * (2.0 * b0 - 1.0),
        b1 * (2.0 * b1 - 1.0),
        b2 * (2.0 * b2 - 1.0),
        4.0 * b0 * b1,
        4.0 * b1 * b2,
        4.0 * b2 * b0,
    ]
}

/// Area-weighted outward unit vertex normals of a triangle surface (object frame): per vertex
/// the sum of its triangles' right-hand cross products (twice their areas times their unit
/// normals), normalised; zero for a vertex with no area around it.
pub fn area_weighted_normals(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut normals = vec![[0.0; 3]; vertices.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let x = vertices;
        let n = cross(sub(x[b], x[a]), sub(x[c], x[a]));
        for v in [a, b, c] {
            normals[v] = add(normals[v], n);
        }
    }
    for n in &mut normals {
        *n = normalize(*n);
    }
    normals
}

/// The [`SurfacePoint`] at barycentric `bary` of triangle `tri` of a surface (`vertices` in
/// m, `normals` from [`area_weighted_normals`]): the point `Σ bary_i x_i`, the normal
/// interpolated with `bary` and normalised (the face normal where that vanishes), and the
/// distance from `query` (m). What [`crate::ModalModel::surface_point`] returns for its base.
///
/// # Panics
/// If `tri` or one of its vertices is out of range.
pub fn surface_point_on(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    normals: &[[f64; 3]],
    tri: u32,
    bary: [f64; 3],
    query: [f64; 3],
) -> SurfacePoint {
    let vs = triangles[tri as usize].map(|i| i as usize);
    let x = vertices;
    let mut point = [0.0; 3];
    let mut n = [0.0; 3];
    for (i, &v) in vs.iter().enumerate() {
        point = add(point, scale(x[v], bary[i]));
        n = add(n, scale(normals[v], bary[i]));
    }
    let mut normal = normalize(n);
    if normal == [0.0; 3] {
        normal = normalize(cross(sub(x[vs[1]], x[vs[0]]), sub(x[vs[2]], x[vs[0]])));
    }
    SurfacePoint {
        triangle: tri,
        bary,
        point,
        normal,
        distance: norm(sub(query, point)),
    }
}
