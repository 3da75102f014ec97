//! [`SurfaceMap`]: brute-force closest point on the extracted boundary surface, with the same
//! conventions as `dcr_runtime::ModalModel` (triangle indices of [`crate::mesh::extract_surface`],
//! barycentric weights in triangle order, area-weighted vertex normals interpolated with the
//! weights and normalised).

use dcr_runtime::model::{area_weighted_normals, surface_point_on, SurfacePoint};

use crate::mesh::extract_surface;
use crate::mesh::TetMesh;
use dcr_runtime::math::{add, dot, norm2, scale, sub};

/// The boundary surface of a tetrahedral mesh, for mapping points onto it (object frame, m).
#[derive(Clone, Debug)]
pub struct SurfaceMap {
    /// Surface vertex → volume node index (ascending).
    pub surface_to_volume: Vec<usize>,
    /// Surface vertex positions (m).
    pub vertices: Vec<[f64; 3]>,
    /// Outward triangles in surface-vertex indices (the order of a baked base).
    pub triangles: Vec<[u32; 3]>,
    /// Area-weighted outward unit vertex normals.
    pub normals: Vec<[f64; 3]>,
}

impl SurfaceMap {
    /// The surface of `mesh` (tetrahedra positively oriented, as after `orient_tets`).
    pub fn new(mesh: &TetMesh) -> SurfaceMap {
        let (surf, tris) = extract_surface(mesh);
        let mut local = vec![u32::MAX; mesh.nodes.len()];
        for (i, &v) in surf.iter().enumerate() {
            local[v] = i as u32;
        }
        let vertices: Vec<[f64; 3]> = surf.iter().map(|&v| mesh.nodes[v]).collect();
        let triangles: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|v| local[v])).collect();
        let normals = area_weighted_normals(&vertices, &triangles);
        SurfaceMap {
            surface_to_volume: surf,
            vertices,
            triangles,
            normals,
        }
    }

    /// The closest surface point to `p` (m) over every triangle (first triangle on ties), or
    /// `None` for a non-finite query or an empty surface.
    pub fn project(&self, p: [f64; 3]) -> Option<SurfacePoint> {
        if !p.iter().all(|x| x.is_finite()) {
            return None;
        }
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for (t, tri) in self.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| self.vertices[i as usize]);
            let (q, bary) = closest_point_triangle(p, a, b, c);
            let d2 = norm2(sub(p, q));
            if best.is_none_or(|(bd, _, _)| d2 < bd) {
                best = Some((d2, t as u32, bary));
            }
        }
        best.map(|(_, t, bary)| self.surface_point(t, bary, p))
    }

    /// The [`SurfacePoint`] at `bary` of triangle `tri`, `distance` measured from `query` (m).
    pub fn surface_point(&self, tri: u32, bary: [f64; 3], query: [f64; 3]) -> SurfacePoint {
        surface_point_on(
            &self.vertices,
            &self.triangles,
            &self.normals,
            tri,
            bary,
            query,
        )
    }

    /// Diagonal of the surface's axis-aligned bounding box (m).
    pub fn bounding_box_diagonal(&self) -> f64 {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &self.vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        norm2(sub(hi, lo)).sqrt()
    }

    /// Volume nodes of triangle `tri` (triangle order).
    pub fn triangle_nodes(&self, tri: u32) -> [usize; 3] {
        self.triangles[tri as usize].map(|i| self.surface_to_volume[i as usize])
    }
}

/// Closest point of triangle `a b c` to `p` and its barycentric weights (Ericson, Real-Time
/// Collision Detection §5.1.5), weights clamped ≥ 0 and renormalised to sum to 1.
pub(crate) fn closest_point_triangle(
    p: [f64; 3],
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    let bary = if d1 <= 0.0 && d2 <= 0.0 {
        [1.0, 0.0, 0.0]
    } else {
        let bp = sub(p, b);
        let d3 = dot(ab, bp);
        let d4 = dot(ac, bp);
        let cp = sub(p, c);
        let d5 = dot(ab, cp);
        let d6 = dot(ac, cp);
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            [0.0, 1.0, 0.0]
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            let v = d1 / (d1 - d3);
            [1.0 - v, v, 0.0]
        } else if d6 >= 0.0 && d5 <= d6 {
            [0.0, 0.0, 1.0]
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            let w = d2 / (d2 - d6);
            [1.0 - w, 0.0, w]
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            [0.0, 1.0 - w, w]
        } else {
            let denom = va + vb + vc;
            if denom > 0.0 {
                [va / denom, vb / denom, vc / denom]
            } else {
                [1.0 / 3.0; 3]
            }
        }
    };
    let mut bary = bary.map(|x: f64| {
        if x.is_finite() {
            x.clamp(0.0, 1.0)
        } else {
            0.0
        }
    });
    let s = bary[0] + bary[1] + bary[2];
    bary = if s > 0.0 {
        bary.map(|x| x / s)
    } else {
        [1.0, 0.0, 0.0]
    };
    let q = add(add(scale(a, bary[0]), scale(b, bary[1])), scale(c, bary[2]));
    (q, bary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let (q, w) = closest_point_triangle([0.2, 0.3, 5.0], a, b, c);
        assert!((q[0] - 0.2).abs() < 1e-15 && (q[1] - 0.3).abs() < 1e-15 && q[2] == 0.0);
        assert!((w[0] - 0.5).abs() < 1e-15);
        let (q, w) = closest_point_triangle([2.0, -1.0, 0.0], a, b, c);
        assert_eq!((q, w), ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
        let (q, _) = closest_point_triangle([1.0, 1.0, 0.0], a, b, c);
        assert!((q[0] - 0.5).abs() < 1e-15 && (q[1] - 0.5).abs() < 1e-15);
    }

    #[test]
    fn box_surface_normals_point_outward() {
        let mesh = TetMesh::structured_box([2, 2, 2], [1.0, 1.0, 1.0]);
        let s = SurfaceMap::new(&mesh);
        let sp = s.project([0.5, 0.5, 1.3]).unwrap();
        assert!((sp.normal[2] - 1.0).abs() < 1e-12, "{:?}", sp.normal);
        assert!((sp.point[2] - 1.0).abs() < 1e-15);
        assert!((sp.distance - 0.3).abs() < 1e-12);
        assert!((sp.bary.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
}
