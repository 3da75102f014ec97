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
