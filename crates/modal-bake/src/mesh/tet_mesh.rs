//! The in-memory tetrahedral mesh every reader produces and every later stage consumes.
//!
//! Readers (MSH 2.2 / 4.1, meshio JSON) build a [`TetMesh`] in *canonical form*:
//! nodes ordered by ascending file node tag, nodes not referenced by any tetrahedron dropped,
//! every index 0-based. Canonical form is what makes every input form of one geometry give a
//! byte-identical base.

use std::collections::BTreeMap;

/// A tetrahedral mesh, linear (4-node) or second-order (10-node), with its boundary triangles
/// and named node groups.
///
/// Positions are in metres, in the object's local frame. A second-order mesh keeps its corner
/// connectivity in [`TetMesh::tets`] and the mid-edge nodes of each tetrahedron in
/// [`TetMesh::mid_edges`] (local edge order [`TET10_EDGES`], gmsh's for its 10-node
/// tetrahedron); only straight-sided elements (mid-edge nodes at the edge midpoints) are
/// accepted by [`TetMesh::check_straight`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetMesh {
    /// Node positions (m, object frame), canonical order (ascending file node tag).
    pub nodes: Vec<[f64; 3]>,
    /// Tetrahedra as 0-based node indices into [`TetMesh::nodes`].
    pub tets: Vec<[usize; 4]>,
    /// The file's element tag (or 1-based position for JSON) of each tetrahedron, for messages.
    pub tet_ids: Vec<u64>,
    /// Triangles read from the file (0-based node indices); informational, the surface is
    /// recomputed from the tetrahedra.
    pub triangles: Vec<[usize; 3]>,
    /// Named physical groups → sorted, deduplicated 0-based node indices.
    pub groups: BTreeMap<String, Vec<usize>>,
    /// Human-readable notes from reading (skipped element types, dropped nodes, ...).
    pub notes: Vec<String>,
    /// Second-order meshes: the mid-edge node of each tetrahedron's local edge
    /// `TET10_EDGES[k]` at `mid_edges[t][k]` (0-based node indices). Empty for a linear mesh;
    /// otherwise exactly one entry per tetrahedron.
    pub mid_edges: Vec<[usize; 6]>,
}

/// The local corner pairs of a tetrahedron's six edges, in the order of the mid-edge nodes
/// 5–10 of gmsh's 10-node tetrahedron (element type 11): (0,1), (1,2), (2,0), (3,0), (3,2),
/// (3,1), written here with the smaller corner first.
pub const TET10_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [2, 3], [1, 3]];

/// Signed volume (m³) of the tetrahedron `a b c d`, `(b−a)×(c−a)·(d−a)/6`: positive when `d`
/// lies on the side of triangle `a b c` its right-hand normal points to.
pub fn signed_volume(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    let u = sub(b, a);
    let v = sub(c, a);
    let w = sub(d, a);
    dot(cross(u, v), w) / 6.0
}

/// The faces of a positively oriented tetrahedron (a, b, c, d), each ordered so that its
/// right-hand normal points out of the tetrahedron.
pub(crate) fn tet_faces([a, b, c, d]: [usize; 4]) -> [[usize; 3]; 4] {
    [[a, c, b], [a, b, d], [a, d, c], [b, c, d]]
}

pub(crate) use dcr_runtime::math::{cross, dot, sub};

impl TetMesh {
    /// This mesh as meshio-style JSON that [`crate::mesh::read_mesh`] reads back: `points`
    /// (m), a `tetra` block, a `vertex` block of the nodes of `group`, and `cell_sets` naming
    /// that block `set_name` (benches and tests write their meshes this way).
    ///
    /// # Panics
    /// If the mesh has no group `group`.
    pub fn to_meshio_json(&self, group: &str, set_name: &str) -> serde_json::Value {
        let nodes = &self.groups[group];
        serde_json::json!({
            "points": self.nodes,
            "cells": [
                {"type": "tetra", "data": self.tets},
                {"type": "vertex", "data": nodes.iter().map(|&i| [i]).collect::<Vec<_>>()},
            ],
            "cell_sets": {set_name: [[], (0..nodes.len()).collect::<Vec<_>>()]},
        })
    }

    /// A structured box `[0,lx]×[0,ly]×[0,lz]` (m) split into `nx×ny×nz` hexahedra, each cut into
    /// six positively oriented tetrahedra (Kuhn subdivision, conforming across faces).
    ///
    /// Named groups: `xmin`, `xmax`, `ymin`, `ymax`, `zmin`, `zmax` (the nodes on each face).
    /// Used by tests and benchmarks that need meshes without gmsh.
    ///
    /// # Panics
    /// If any of `nx, ny, nz` is zero.
    pub fn structured_box(n: [usize; 3], l: [f64; 3]) -> TetMesh {
        let [nx, ny, nz] = n;
        assert!(
            nx > 0 && ny > 0 && nz > 0,
            "structured_box needs at least one cell per axis"
        );
        let id = |i: usize, j: usize, k: usize| i + (nx + 1) * (j + (ny + 1) * k);
        let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    nodes.push([
                        l[0] * i as f64 / nx as f64,
                        l[1] * j as f64 / ny as f64,
                        l[2] * k as f64 / nz as f64,
                    ]);
                }
            }
        }
        // Kuhn subdivision: the six tets along the main diagonal v0 → v7, one per permutation
        // of the axes.
        const PERMS: [[usize; 3]; 6] = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        let mut tets = Vec::with_capacity(6 * nx * ny * nz);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    for p in PERMS {
                        let mut c = [i, j, k];
                        let mut t = [id(c[0], c[1], c[2]); 4];
                        for (s, &axis) in p.iter().enumerate() {
                            c[axis] += 1;
                            t[s + 1] = id(c[0], c[1], c[2]);
                        }
                        let v = signed_volume(nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]);
                        if v < 0.0 {
                            t.swap(2, 3);
                        }
                        tets.push(t);
                    }
                }
            }
        }
        let mut groups = BTreeMap::new();
        for (axis, lo, hi) in [
            (0, "xmin", "xmax"),
            (1, "ymin", "ymax"),
            (2, "zmin", "zmax"),
        ] {
            let lo_set: Vec<usize> = (0..nodes.len())
                .filter(|&v| nodes[v][axis] == 0.0)
                .collect();
            let hi_set: Vec<usize> = (0..nodes.len())
                .filter(|&v| nodes[v][axis] == l[axis])
                .collect();
            groups.insert(lo.to_string(), lo_set);
            groups.insert(hi.to_string(), hi_set);
        }
        let tet_ids = (1..=tets.len() as u64).collect();
        TetMesh {
            nodes,
            tets,
            tet_ids,
            triangles: Vec::new(),
            groups,
            notes: Vec::new(),
            mid_edges: Vec::new(),
        }
    }

    /// Whether the mesh is second-order (10-node tetrahedra, [`TetMesh::mid_edges`] set).
    pub fn is_quadratic(&self) -> bool {
        !self.mid_edges.is_empty()
    }

    /// Nodes per element: 4 (linear) or 10 (second-order).
    pub fn nodes_per_tet(&self) -> usize {
        if self.is_quadratic() {
            10
        } else {
            4
        }
    }

    /// The nodes of tetrahedron `t`: its 4 corners, then (second-order meshes) its 6 mid-edge
    /// nodes in [`TET10_EDGES`] order. Only the first [`TetMesh::nodes_per_tet`] entries are
    /// nodes; the rest (linear meshes) are `usize::MAX`.
    pub fn tet_nodes(&self, t: usize) -> [usize; 10] {
        let mut out = [usize::MAX; 10];
        out[..4].copy_from_slice(&self.tets[t]);
        if let Some(e) = self.mid_edges.get(t) {
            out[4..].copy_from_slice(e);
        }
        out
    }

    /// The second-order version of a linear mesh: a mid-edge node at the midpoint of every
    /// edge (m), appended after the corner nodes in the order of the sorted corner pairs.
    /// Groups gain the mid-edge nodes of edges whose two corners are both in the group. A
    /// mesh that is already second-order is returned unchanged.
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// let p1 = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]);
    /// let p2 = p1.to_quadratic();
    /// assert_eq!(p2.nodes.len(), 8 + 19); // 12 box edges, 6 face diagonals, 1 main diagonal
    /// assert!(p2.is_quadratic());
    /// ```
    pub fn to_quadratic(&self) -> TetMesh {
        if self.is_quadratic() {
            return self.clone();
        }
        let mut edges: Vec<[usize; 2]> = Vec::with_capacity(self.tets.len() * 6);
        for t in &self.tets {
            for [a, b] in TET10_EDGES {
                let (p, q) = (t[a].min(t[b]), t[a].max(t[b]));
                edges.push([p, q]);
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let n0 = self.nodes.len();
        let mut nodes = self.nodes.clone();
        nodes.extend(edges.iter().map(|&[a, b]| {
            let (x, y) = (self.nodes[a], self.nodes[b]);
            [
                0.5 * (x[0] + y[0]),
                0.5 * (x[1] + y[1]),
                0.5 * (x[2] + y[2]),
            ]
        }));
        let node_of = |a: usize, b: usize| {
            let key = [a.min(b), a.max(b)];
            n0 + edges.binary_search(&key).expect("every tet edge is listed")
        };
        let mid_edges = self
            .tets
            .iter()
            .map(|t| TET10_EDGES.map(|[a, b]| node_of(t[a], t[b])))
            .collect();
        let mut groups = self.groups.clone();
        for set in groups.values_mut() {
            let mut member = vec![false; n0];
            for &v in set.iter() {
                member[v] = true;
            }
            set.extend(
                edges
                    .iter()
                    .enumerate()
                    .filter(|(_, &[a, b])| member[a] && member[b])
                    .map(|(i, _)| n0 + i),
            );
        }
        TetMesh {
            nodes,
            tets: self.tets.clone(),
            tet_ids: self.tet_ids.clone(),
            triangles: self.triangles.clone(),
            groups,
            notes: self.notes.clone(),
            mid_edges,
        }
    }

    /// Total volume (m³) as the sum of absolute tetrahedron volumes.
    pub fn volume(&self) -> f64 {
        self.tets
            .iter()
            .map(|t| {
                signed_volume(
                    self.nodes[t[0]],
                    self.nodes[t[1]],
                    self.nodes[t[2]],
                    self.nodes[t[3]],
                )
                .abs()
            })
            .sum()
    }

    /// Number of displacement degrees of freedom (3 per node).
    pub fn dofs(&self) -> usize {
        3 * self.nodes.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn structured_box_volume_and_orientation() {
        let m = TetMesh::structured_box([3, 2, 4], [1.5, 0.5, 2.0]);
        assert_eq!(m.nodes.len(), 4 * 3 * 5);
        assert_eq!(m.tets.len(), 6 * 24);
        for t in &m.tets {
            let v = signed_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]);
            assert!(v > 0.0);
        }
        assert!((m.volume() - 1.5).abs() < 1e-12);
        assert_eq!(m.groups["xmin"].len(), 3 * 5);
    }
}
