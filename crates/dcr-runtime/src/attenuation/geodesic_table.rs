//! [`GeodesicTable`]: heat-method geodesic distances between every pair of surface vertices,
//! computed once per model, so an attenuation query needs no heat solve.
//!
//! Row a holds the distances of the heat method (Crane et al. 2013) from a unit source at
//! vertex a to every vertex. Between two surface points (triangles (a₀, a₁, a₂) and
//! (b₀, b₁, b₂), barycentric weights β and γ) the distance is read bilinearly,
//! `r = Σ_i Σ_j β_i γ_j D[a_i][b_j]` (source side first: the resting contact, as the per-contact
//! fields of [`crate::attenuation::DistanceKind::Heat`] are). At vertices this is the heat
//! distance itself; inside triangles it differs from the field of a point source by the
//! interpolation error, O(edge length) within a triangle of the source and small farther away.
//!
//! Cost: ns solves at set-up (the rows in parallel on the rayon pool, bit-identical for any
//! thread count: each row is one independent solve) and ns² × 4 bytes (f32, the heat method's
//! own error is far larger than f32 rounding); refused above
//! [`GeodesicTable::MAX_VERTICES`] surface vertices.

use rayon::prelude::*;

use super::HeatGeodesic;
use crate::surface_point::SurfacePoint;

/// All-pairs heat-method distances over a surface's vertices (m).
#[derive(Debug)]
pub struct GeodesicTable {
    n: usize,
    /// Row-major ns × ns: `d[a * n + b]` = distance from a source at a to vertex b.
    d: Vec<f32>,
}

impl GeodesicTable {
    /// Largest surface handled: 8192 vertices (256 MiB).
    pub const MAX_VERTICES: usize = 8192;

    /// Solves the heat method from every vertex of `heat`'s surface.
    ///
    /// # Panics
    /// If the surface has more than [`GeodesicTable::MAX_VERTICES`] vertices (callers check).
    pub fn build(heat: &HeatGeodesic) -> GeodesicTable {
        let n = heat.num_vertices();
        assert!(
            n <= Self::MAX_VERTICES,
            "{n} vertices exceed the table limit"
        );
        let mut d = vec![0.0f32; n * n];
        d.par_chunks_mut(n).enumerate().for_each_init(
            || (heat.workspace(), vec![0.0f64; n]),
            |(ws, row), (a, out)| {
                heat.distances_from_vertex_with(a, row, ws);
                for (o, &x) in out.iter_mut().zip(row.iter()) {
                    *o = x as f32;
                }
            },
        );
        GeodesicTable { n, d }
    }

    /// Number of surface vertices.
    pub fn num_vertices(&self) -> usize {
        self.n
    }

    /// Bytes held by the table.
    pub fn size_bytes(&self) -> usize {
        self.d.len() * std::mem::size_of::<f32>()
    }

    /// Distance (m) from vertex `a` (the source) to vertex `b`.
    pub fn vertex_distance(&self, a: usize, b: usize) -> f64 {
        f64::from(self.d[a * self.n + b])
    }

    /// Distance (m) from surface point `src` (corners `src_tri`) to `dst` (corners `dst_tri`),
    /// bilinear in both points' barycentric weights.
    pub fn distance(
        &self,
        src: &SurfacePoint,
        src_tri: [usize; 3],
        dst: &SurfacePoint,
        dst_tri: [usize; 3],
    ) -> f64 {
        let mut r = 0.0;
        for (i, &a) in src_tri.iter().enumerate() {
            let row = &self.d[a * self.n..(a + 1) * self.n];
            let inner: f64 = (0..3)
                .map(|j| dst.bary[j] * f64::from(row[dst_tri[j]]))
                .sum();
            r += src.bary[i] * inner;
        }
        r
    }
}
