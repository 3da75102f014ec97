//! Connected pieces of a [`TetMesh`]: which tetrahedra hold together, and one piece kept alone.
//!
//! Two tetrahedra are in one piece when they share a node (a corner, or a mid-edge node of a
//! second-order mesh): union–find over the nodes, near-linear in the mesh size. Pieces are
//! numbered from 1, **largest volume first** (volumes compared at six significant digits);
//! equal volumes keep the order of their first tetrahedron in the canonical mesh, so a piece's
//! number depends only on the file's content.
//!
//! A mesh for baking is one piece. A file of several (gmsh volumes that do not touch, a scene
//! exported as one mesh) is baked one piece at a time: [`TetMesh::keep_piece`] gives the mesh
//! of one piece in canonical form, the same mesh (bit for bit) as a file holding that piece
//! alone with the same node tags would give.

use super::mesh_error::{Location, MeshError, MeshErrorKind};
use super::tet_mesh::{signed_volume, TetMesh};
use crate::bake::group_digits;

/// At most this many pieces are listed in a message; the rest are counted.
const LISTED: usize = 8;

/// One connected piece of a [`TetMesh`], as [`TetMesh::pieces`] lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshPiece {
    /// Its number: 1-based, largest volume first.
    pub number: usize,
    /// How many tetrahedra it holds.
    pub tets: usize,
    /// Its volume (m³): the sum of its tetrahedra's |signed volume| (corners).
    pub volume: f64,
    /// Its axis-aligned bounding box (m, object frame), `[min, max]`, over its nodes.
    pub bbox: [[f64; 3]; 2],
    /// The union–find root naming it inside [`TetMesh::piece_labels`].
    label: usize,
}

impl std::fmt::Display for MeshPiece {
    /// `piece 2: 1,234 tetrahedra, 1.25e-4 m³, from (0, 0, 0) to (0.05, 0.05, 0.05) m`: four
    /// significant digits; a coordinate within a millionth of the piece's diagonal of 0 is 0.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [lo, hi] = self.bbox;
        let zero = 1e-6 * (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let p = |x: [f64; 3]| {
            let c = x.map(|c| four_digits(if c.abs() < zero { 0.0 } else { c }));
            format!("({}, {}, {})", c[0], c[1], c[2])
        };
        write!(
            f,
            "piece {}: {} {}, {} m³, from {} to {} m",
            self.number,
            group_digits(self.tets),
            if self.tets == 1 {
                "tetrahedron"
            } else {
                "tetrahedra"
            },
            four_digits(self.volume),
            p(lo),
            p(hi)
        )
    }
}

/// `x` with four significant digits, without trailing zeros: `0.05`, `1`, `-1.25e-5`, `1.235e4`
/// (plain between 1e-3 and 1e4, else in e-notation); `-0` prints as `0`.
///
/// ```
/// use modal_bake::mesh::four_digits;
/// assert_eq!(four_digits(0.050001), "0.05");
/// assert_eq!(four_digits(-1.23456e-5), "-1.235e-5");
/// assert_eq!(four_digits(-0.0), "0");
/// assert_eq!(four_digits(12_346.0), "1.235e4");
/// ```
pub fn four_digits(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{}", if x == 0.0 { 0.0 } else { x });
    }
    let rounded: f64 = format!("{x:.3e}").parse().unwrap_or(x);
    if (1e-3..1e4).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// `pieces` as one line: each piece, up to [`LISTED`], then how many more.
pub(crate) fn list_pieces(pieces: &[MeshPiece]) -> String {
    let mut parts: Vec<String> = pieces.iter().take(LISTED).map(|p| p.to_string()).collect();
    if pieces.len() > LISTED {
        parts.push(format!("and {} smaller", pieces.len() - LISTED));
    }
    parts.join("; ")
}

impl TetMesh {
    /// The piece label of every tetrahedron (the union–find root of its first corner; the
    /// same label for tetrahedra that share a node, directly or through others).
    fn piece_labels(&self) -> Vec<usize> {
        fn find(parent: &mut [usize], mut v: usize) -> usize {
            while parent[v] != v {
                parent[v] = parent[parent[v]];
                v = parent[v];
            }
            v
        }
        let mut parent: Vec<usize> = (0..self.nodes.len()).collect();
        for (i, t) in self.tets.iter().enumerate() {
            let mid = self.mid_edges.get(i).map_or(&[][..], |e| &e[..]);
            let r0 = find(&mut parent, t[0]);
            for &v in t[1..].iter().chain(mid) {
                let r = find(&mut parent, v);
                if r != r0 {
                    parent[r] = r0;
                }
            }
        }
        self.tets.iter().map(|t| find(&mut parent, t[0])).collect()
    }

    /// Number of connected pieces of the tetrahedra (two tetrahedra are connected when they
    /// share a node). Nodes in no tetrahedron are not counted. A mesh for baking has exactly 1.
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// assert_eq!(TetMesh::structured_box([2, 1, 1], [1.0, 1.0, 1.0]).connected_components(), 1);
    /// ```
    pub fn connected_components(&self) -> usize {
        let mut labels = self.piece_labels();
        labels.sort_unstable();
        labels.dedup();
        labels.len()
    }

    /// The mesh's connected pieces, largest volume first (see the module doc): their number,
    /// tetrahedra, volume (m³) and bounding box (m).
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// let p = TetMesh::structured_box([2, 1, 1], [2.0, 1.0, 1.0]).pieces();
    /// assert_eq!((p.len(), p[0].tets), (1, 12));
    /// assert!((p[0].volume - 2.0).abs() < 1e-12);
    /// ```
    pub fn pieces(&self) -> Vec<MeshPiece> {
        self.pieces_of(&self.piece_labels())
    }

    fn pieces_of(&self, labels: &[usize]) -> Vec<MeshPiece> {
        // Index of each label's piece in first-seen order.
        let mut slot = vec![usize::MAX; self.nodes.len()];
        let mut pieces: Vec<MeshPiece> = Vec::new();
        for (t, &label) in self.tets.iter().zip(labels) {
            if slot[label] == usize::MAX {
                slot[label] = pieces.len();
                pieces.push(MeshPiece {
                    number: 0,
                    tets: 0,
                    volume: 0.0,
                    bbox: [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]],
                    label,
                });
            }
            let p = &mut pieces[slot[label]];
            let x = t.map(|v| self.nodes[v]);
            p.tets += 1;
            p.volume += signed_volume(x[0], x[1], x[2], x[3]).abs();
            for c in x {
                for k in 0..3 {
                    p.bbox[0][k] = p.bbox[0][k].min(c[k]);
                    p.bbox[1][k] = p.bbox[1][k].max(c[k]);
                }
            }
        }
        // Volumes compared at six significant digits (one geometry meshed twice sums its
        // tetrahedra in another order); the sort is stable: equal volumes keep first-seen order.
        // (Volumes are ≥ 0, where the bits of an f64 order as its value.)
        pieces.sort_by_cached_key(|p| {
            let v: f64 = format!("{:.5e}", p.volume).parse().unwrap_or(p.volume);
            std::cmp::Reverse(v.to_bits())
        });
        for (i, p) in pieces.iter_mut().enumerate() {
            p.number = i + 1;
        }
        pieces
    }

    /// The mesh of piece `number` alone (1-based, largest volume first, as [`TetMesh::pieces`]
    /// numbers them), in canonical form: its tetrahedra, element ids and mid-edge nodes in the
    /// order they had, its nodes in the order they had, the file's triangles whose nodes are
    /// all in it, its node groups restricted to it (a group left empty is dropped), and a note
    /// saying which piece was kept.
    ///
    /// # Errors
    /// [`MeshErrorKind::NoSuchPiece`] (listing the pieces) when the mesh has no piece `number`.
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// let a = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]);
    /// let mut two = a.clone();
    /// let n = two.nodes.len();
    /// two.nodes.extend(a.nodes.iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
    /// two.tets.extend(a.tets.iter().map(|t| t.map(|v| v + n)));
    /// two.tet_ids.clear();
    /// assert_eq!(two.connected_components(), 2);
    /// let first = two.keep_piece(1).unwrap();
    /// assert_eq!((first.nodes.len(), first.tets.len()), (8, 6));
    /// assert!(two.keep_piece(3).is_err());
    /// ```
    pub fn keep_piece(&self, number: usize) -> Result<TetMesh, MeshError> {
        let labels = self.piece_labels();
        let pieces = self.pieces_of(&labels);
        let Some(piece) = number.checked_sub(1).and_then(|i| pieces.get(i)) else {
            return Err(MeshError::new(
                "",
                Location::None,
                MeshErrorKind::NoSuchPiece {
                    asked: number,
                    count: pieces.len(),
                    list: list_pieces(&pieces),
                },
            ));
        };
        let kept: Vec<usize> = (0..self.tets.len())
            .filter(|&t| labels[t] == piece.label)
            .collect();
        let mut used = vec![false; self.nodes.len()];
        for &t in &kept {
            let mid = self.mid_edges.get(t).map_or(&[][..], |e| &e[..]);
            for &v in self.tets[t].iter().chain(mid) {
                used[v] = true;
            }
        }
        // New index of each kept node, in the order the nodes had; usize::MAX elsewhere.
        let mut index = vec![usize::MAX; self.nodes.len()];
        let mut nodes = Vec::new();
        for (v, _) in used.iter().enumerate().filter(|u| *u.1) {
            index[v] = nodes.len();
            nodes.push(self.nodes[v]);
        }
        let map = |v: usize| index[v];
        let triangles = self
            .triangles
            .iter()
            .filter(|f| f.iter().all(|&v| index[v] != usize::MAX))
            .map(|f| f.map(map))
            .collect();
        let groups = self
            .groups
            .iter()
            .filter_map(|(name, members)| {
                let kept: Vec<usize> = members
                    .iter()
                    .filter(|&&v| index[v] != usize::MAX)
                    .map(|&v| index[v])
                    .collect();
                (!kept.is_empty()).then(|| (name.clone(), kept))
            })
            .collect();
        let mut notes = self.notes.clone();
        notes.push(format!(
            "kept {piece} (one of {} connected pieces)",
            pieces.len()
        ));
        Ok(TetMesh {
            nodes,
            tets: kept.iter().map(|&t| self.tets[t].map(map)).collect(),
            tet_ids: if self.tet_ids.len() == self.tets.len() {
                kept.iter().map(|&t| self.tet_ids[t]).collect()
            } else {
                Vec::new()
            },
            triangles,
            groups,
            notes,
            mid_edges: if self.mid_edges.len() == self.tets.len() {
                kept.iter().map(|&t| self.mid_edges[t].map(map)).collect()
            } else {
                Vec::new()
            },
        })
    }
}
