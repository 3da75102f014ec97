//! A point mapped onto the model's surface.

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
