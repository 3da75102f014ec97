//! The surface a base stores: the boundary faces of the tetrahedral mesh
//! ([`extract_surface`]) in surface-vertex indices, their positions, the heat geodesic's
//! elimination order and, for second-order meshes, the mid-edge nodes.

use crate::mesh::{extract_surface, TetMesh};
use dcr_runtime::format::QuadraticSurface;

/// The boundary surface of a mesh as the bake stores it.
pub(super) struct Surface {
    /// Sorted volume-node indices of the surface vertices.
    pub(super) nodes: Vec<usize>,
    /// Their positions (m).
    pub(super) positions: Vec<[f64; 3]>,
    /// Outward triangles in surface-vertex indices.
    pub(super) triangles: Vec<[u32; 3]>,
    /// The heat geodesic's elimination order, so loading skips AMD and factors less fill.
    /// A surface the heat method cannot factor (degenerate triangles) simply stores none; the
    /// runtime reports the problem if the heat method is used.
    pub(super) order: Option<Vec<u32>>,
    /// Second-order meshes: the surface edges (surface-vertex pairs, sorted) and the volume
    /// node of each one's mid-edge node. Empty for a linear mesh.
    pub(super) edges: Vec<[u32; 2]>,
    pub(super) edge_nodes: Vec<usize>,
}

impl Surface {
    /// `mid_table`: [`TetMesh::edge_mid_nodes`] (empty for a linear mesh).
    pub(super) fn of(mesh: &TetMesh, mid_table: &[([usize; 2], usize)]) -> Surface {
        let (nodes, tris) = extract_surface(mesh);
        let mut local = vec![u32::MAX; mesh.nodes.len()];
        for (i, &v) in nodes.iter().enumerate() {
            local[v] = i as u32;
        }
        let triangles: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|v| local[v])).collect();
        let positions: Vec<[f64; 3]> = nodes.iter().map(|&v| mesh.nodes[v]).collect();
        let order = crate::ordering::plan_surface_order(&positions, &triangles).ok();
        let (mut edges, mut edge_nodes) = (Vec::new(), Vec::new());
        if mesh.is_quadratic() {
            edges = QuadraticSurface::edges_of(&triangles);
            // Every surface edge is a tet edge, so the look-up succeeds on a mesh that passed
            // `edge_mid_nodes`; `usize::MAX` would fail the base's validation, not panic.
            edge_nodes = edges
                .iter()
                .map(|&[a, b]| {
                    let key = [nodes[a as usize], nodes[b as usize]];
                    mid_table
                        .binary_search_by(|x| x.0.cmp(&key))
                        .map_or(usize::MAX, |i| mid_table[i].1)
                })
                .collect();
        }
        Surface {
            nodes,
            positions,
            triangles,
            order,
            edges,
            edge_nodes,
        }
    }
}
