//! The in-memory tetrahedral mesh every reader produces and every later stage consumes.
//!
//! Readers (MSH 2.2 / 4.1, meshio JSON) build a [`TetMesh`] in *canonical form*:
//! nodes ordered by ascending file node tag, nodes not referenced by any tetrahedron dropped,
//! every index 0-based. Canonical form is what makes every input form of one geometry give a
//! byte-identical base.

use std::collections::BTreeMap;

/// A linear (4-node) tetrahedral mesh with its boundary triangles and named node groups.
///
/// Positions are in metres, in the object's local frame.
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
}

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

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

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
