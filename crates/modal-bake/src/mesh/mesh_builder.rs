//! Shared back end of the readers: collects nodes and elements, then builds a [`TetMesh`] in
//! canonical form (nodes by ascending tag, nodes outside every tetrahedron dropped, 0-based).

use std::collections::BTreeMap;

use super::mesh_error::{Location, MeshError, MeshErrorKind};
use super::tet_mesh::TetMesh;

/// [`MeshErrorKind::NoTets`]'s fix when the file holds other volume elements.
pub(crate) const NO_TETS_OTHER_VOLUME: &str = "modal-bake bakes 4- and 10-node tetrahedra only; mesh the volume with tetrahedra of order 1 or 2 (gmsh: no `Recombine` in `Extrude`, `Mesh.RecombineAll = 0`, `Mesh.Recombine3DAll = 0`, `-order 1` or `-order 2`)";

/// [`MeshErrorKind::NoTets`]'s fix when the file holds no volume elements at all.
pub(crate) const NO_TETS_NO_VOLUME: &str = "modal-bake bakes a volume meshed with tetrahedra; mesh a volume (gmsh: a `Volume` in the geometry, `gmsh FILE.geo -3`), or give the closed surface as an .obj / .stl / .ply / .glb asset for modal-bake to mesh (a gmsh surface mesh: `gmsh FILE.msh -0 -format stl -o FILE.stl`)";

/// Nodes and elements as read, before canonicalisation. Element node references are indices
/// into the tag-sorted node table.
#[derive(Debug, Default)]
pub(crate) struct MeshBuilder {
    tags: Vec<u64>,
    coords: Vec<[f64; 3]>,
    /// `Some(first)` when the sorted tags are exactly `first, first+1, ...`.
    dense_first: Option<u64>,
    tets: Vec<(u64, [usize; 4])>,
    /// 10-node tetrahedra: 4 corners, then the mid-edge nodes in `TET10_EDGES` order.
    tets10: Vec<(u64, [usize; 10])>,
    triangles: Vec<[usize; 3]>,
    groups: BTreeMap<String, Vec<usize>>,
    /// Elements not built, per description: (what, count, whether they are volume elements).
    skipped: Vec<(String, u64, bool)>,
}

impl MeshBuilder {
    /// Sets the node table from `(tag, position)` pairs in any order.
    ///
    /// # Errors
    /// The first duplicated tag.
    pub fn set_nodes(&mut self, mut nodes: Vec<(u64, [f64; 3])>) -> Result<(), MeshErrorKind> {
        nodes.sort_by_key(|n| n.0);
        if let Some(w) = nodes.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(MeshErrorKind::DuplicateNode { node: w[0].0 });
        }
        self.tags = nodes.iter().map(|n| n.0).collect();
        self.coords = nodes.iter().map(|n| n.1).collect();
        self.dense_first = match (self.tags.first(), self.tags.last()) {
            (Some(&first), Some(&last))
                if (last - first).checked_add(1) == Some(self.tags.len() as u64) =>
            {
                Some(first)
            }
            _ => None,
        };
        Ok(())
    }

    /// Index of node `tag` in the sorted table.
    pub fn node_index(&self, tag: u64) -> Option<usize> {
        match self.dense_first {
            Some(first) => {
                let i = tag.checked_sub(first)?;
                (i < self.tags.len() as u64).then_some(i as usize)
            }
            None => self.tags.binary_search(&tag).ok(),
        }
    }

    /// Adds a tetrahedron with element id `id` (node table indices).
    pub fn push_tet(&mut self, id: u64, nodes: [usize; 4]) {
        self.tets.push((id, nodes));
    }

    /// Adds a 10-node tetrahedron with element id `id` (node table indices, gmsh order: 4
    /// corners, then the mid-edge nodes of edges (0,1), (1,2), (2,0), (3,0), (3,2), (3,1)).
    pub fn push_tet10(&mut self, id: u64, nodes: [usize; 10]) {
        self.tets10.push((id, nodes));
    }

    /// Adds a triangle (node table indices).
    pub fn push_triangle(&mut self, nodes: [usize; 3]) {
        self.triangles.push(nodes);
    }

    /// Adds node table indices to group `name` (created if new).
    pub fn add_to_group(&mut self, name: &str, nodes: &[usize]) {
        match self.groups.get_mut(name) {
            Some(g) => g.extend_from_slice(nodes),
            None => {
                self.groups.insert(name.to_string(), nodes.to_vec());
            }
        }
    }

    /// Counts `n` skipped elements described by `what` (one note per distinct `what`);
    /// `volume`: they are 3-D elements (hexahedra, prisms, pyramids, higher-order
    /// tetrahedra), which [`MeshBuilder::finish`] refuses rather than leave part of the object
    /// out.
    pub fn skip(&mut self, what: &str, n: u64, volume: bool) {
        match self.skipped.iter_mut().find(|s| s.0 == what) {
            Some(s) => s.1 += n,
            None => self.skipped.push((what.to_string(), n, volume)),
        }
    }

    /// What was read besides tetrahedra, for an error: "726 triangles, 70 elements of gmsh
    /// type 1 (2-node line)"; only the volume elements when `volume_only`.
    fn found(&self, volume_only: bool) -> String {
        use crate::bake::group_digits;
        let mut parts = Vec::new();
        if !volume_only && !self.triangles.is_empty() {
            let n = self.triangles.len();
            let plural = if n == 1 { "" } else { "s" };
            parts.push(format!("{} triangle{plural}", group_digits(n)));
        }
        for (what, n, volume) in &self.skipped {
            if *volume || !volume_only {
                parts.push(format!("{} {what}", group_digits(*n as usize)));
            }
        }
        if parts.is_empty() {
            "no elements".into()
        } else {
            parts.join(", ")
        }
    }

    /// Builds the canonical [`TetMesh`].
    ///
    /// Tetrahedra are ordered by their node indices (lexicographically, ties by element id)
    /// and exact repeats (same nodes in the same order, as MSH 2.2 writes for an element of two
    /// physical groups) removed, keeping the smallest element id; triangles likewise sorted and
    /// deduplicated. Element order in the file therefore does not matter.
    ///
    /// # Errors
    /// [`MeshErrorKind::NoTets`] when there is no tetrahedron;
    /// [`MeshErrorKind::OtherVolumeElements`] when other volume elements were skipped;
    /// [`MeshErrorKind::DuplicateTet`] (at the later element) when two tetrahedra have the
    /// same nodes in different orders: one would count twice.
    pub fn finish(mut self, file: &str) -> Result<TetMesh, MeshError> {
        if self.tets.is_empty() && self.tets10.is_empty() {
            let found = self.found(false);
            let how = if self.skipped.iter().any(|s| s.2) {
                NO_TETS_OTHER_VOLUME
            } else {
                NO_TETS_NO_VOLUME
            };
            return Err(MeshError::new(
                file,
                Location::None,
                MeshErrorKind::NoTets { found, how },
            ));
        }
        if self.skipped.iter().any(|s| s.2) {
            let found = self.found(true);
            return Err(MeshError::new(
                file,
                Location::None,
                MeshErrorKind::OtherVolumeElements { found },
            ));
        }
        if !self.tets.is_empty() && !self.tets10.is_empty() {
            return Err(MeshError::new(
                file,
                Location::None,
                MeshErrorKind::MixedOrder {
                    linear: self.tets.len(),
                    quadratic: self.tets10.len(),
                },
            ));
        }
        let quadratic = !self.tets10.is_empty();
        let corners: Vec<(u64, [usize; 4])> = self
            .tets10
            .iter()
            .map(|&(id, t)| (id, [t[0], t[1], t[2], t[3]]))
            .collect();
        let dup = if quadratic {
            same_nodes_reordered(&corners)
        } else {
            same_nodes_reordered(&self.tets)
        };
        if let Some((first, second)) = dup {
            return Err(MeshError::new(
                file,
                Location::Element(second),
                MeshErrorKind::DuplicateTet { first, second },
            ));
        }
        let mut notes = Vec::new();
        for (what, n, _) in &self.skipped {
            notes.push(format!("skipped {n} {what}"));
        }
        // Canonical element order: by node indices (which follow node tags), so the order in
        // which a file lists its elements does not matter; ties by element id.
        self.tets.sort_unstable_by_key(|&(id, t)| (t, id));
        self.tets10.sort_unstable_by_key(|&(id, t)| (t, id));
        let before = self.tets.len() + self.tets10.len();
        self.tets.dedup_by_key(|t| t.1);
        self.tets10.dedup_by_key(|t| t.1);
        if self.tets.len() + self.tets10.len() < before {
            notes.push(format!(
                "removed {} duplicated tetrahedra (same nodes in the same order)",
                before - self.tets.len() - self.tets10.len()
            ));
        }
        self.triangles.sort_unstable();
        self.triangles.dedup();

        const UNUSED: usize = usize::MAX;
        let mut new_index = vec![UNUSED; self.tags.len()];
        for (_, t) in &self.tets {
            for &v in t {
                new_index[v] = 0;
            }
        }
        for (_, t) in &self.tets10 {
            for &v in t {
                new_index[v] = 0;
            }
        }
        let mut nodes = Vec::with_capacity(self.tags.len());
        for (v, slot) in new_index.iter_mut().enumerate() {
            if *slot != UNUSED {
                *slot = nodes.len();
                nodes.push(self.coords[v]);
            }
        }
        let dropped = self.tags.len() - nodes.len();
        if dropped > 0 {
            notes.push(format!(
                "dropped {dropped} nodes not referenced by any tetrahedron"
            ));
        }
        let (tets, tet_ids, mid_edges) = if quadratic {
            let corner = |t: &[usize; 10]| [t[0], t[1], t[2], t[3]].map(|v| new_index[v]);
            let mid = |t: &[usize; 10]| [t[4], t[5], t[6], t[7], t[8], t[9]].map(|v| new_index[v]);
            (
                self.tets10.iter().map(|(_, t)| corner(t)).collect(),
                self.tets10.iter().map(|(id, _)| *id).collect(),
                self.tets10.iter().map(|(_, t)| mid(t)).collect(),
            )
        } else {
            (
                self.tets
                    .iter()
                    .map(|(_, t)| t.map(|v| new_index[v]))
                    .collect(),
                self.tets.iter().map(|(id, _)| *id).collect(),
                Vec::new(),
            )
        };

        let mut triangles = Vec::with_capacity(self.triangles.len());
        for tri in &self.triangles {
            if tri.iter().all(|&v| new_index[v] != UNUSED) {
                triangles.push(tri.map(|v| new_index[v]));
            }
        }
        if triangles.len() < self.triangles.len() {
            notes.push(format!(
                "dropped {} triangles with nodes outside the tetrahedra",
                self.triangles.len() - triangles.len()
            ));
        }

        let mut groups = BTreeMap::new();
        for (name, members) in self.groups {
            let mut set: Vec<usize> = members
                .into_iter()
                .map(|v| new_index[v])
                .filter(|&v| v != UNUSED)
                .collect();
            set.sort_unstable();
            set.dedup();
            if set.is_empty() {
                notes.push(format!(
                    "group {name:?} has no node on the tetrahedral mesh"
                ));
            }
            groups.insert(name, set);
        }

        Ok(TetMesh {
            nodes,
            tets,
            tet_ids,
            triangles,
            groups,
            notes,
            mid_edges,
        })
    }
}

/// The ids (smaller first) of two tetrahedra with the same node set in different orders, if
/// any (exact repeats are the same element listed twice and are not reported). Sorted node
/// sets are packed into one `u128` (node indices < 2^32, as any mesh that fits in memory has)
/// to sort fast.
fn same_nodes_reordered(tets: &[(u64, [usize; 4])]) -> Option<(u64, u64)> {
    let mut keys: Vec<(u128, usize)> = tets
        .iter()
        .enumerate()
        .map(|(i, (_, t))| {
            let mut k = *t;
            k.sort_unstable();
            let packed = k
                .iter()
                .fold(0u128, |acc, &v| (acc << 32) | (v as u32 as u128));
            (packed, i)
        })
        .collect();
    keys.sort_unstable();
    keys.windows(2).find_map(|w| {
        let (a, b) = (&tets[w[0].1], &tets[w[1].1]);
        // Equal packed keys are equal sets when every index fits in 32 bits.
        let same_set = w[0].0 == w[1].0 && {
            let (mut x, mut y) = (a.1, b.1);
            x.sort_unstable();
            y.sort_unstable();
            x == y
        };
        (same_set && a.1 != b.1).then(|| (a.0.min(b.0), a.0.max(b.0)))
    })
}
