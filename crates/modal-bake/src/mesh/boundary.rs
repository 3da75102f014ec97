//! The boundary surface of a tetrahedral mesh: the faces of exactly one tetrahedron, oriented
//! outward, sorted (deterministic).

use super::{tet_faces, TetMesh};

/// Bits per node index in the packed face keys of [`extract_surface`] (3 × 21 ≤ 64).
const PACK_BITS: u32 = 21;

/// Boundary faces of a tetrahedral mesh, oriented outward, as (sorted surface-vertex list of
/// volume nodes, triangles in volume-node indices). Deterministic: faces are sorted.
pub fn extract_surface(mesh: &TetMesh) -> (Vec<usize>, Vec<[usize; 3]>) {
    let packable = mesh.nodes.len() <= 1 << PACK_BITS && mesh.tets.len() < 1 << 30;
    let tris = if packable {
        boundary_faces_packed(&mesh.tets)
    } else {
        boundary_faces(&mesh.tets)
    };
    let mut verts: Vec<usize> = tris.iter().flatten().copied().collect();
    verts.sort_unstable();
    verts.dedup();
    (verts, tris)
}

/// A face rotated so its smallest index comes first (canonical, orientation kept).
fn canonical_face(f: [usize; 3]) -> [usize; 3] {
    let r = (0..3).min_by_key(|&k| f[k]).unwrap_or(0);
    [f[r], f[(r + 1) % 3], f[(r + 2) % 3]]
}

/// The faces that belong to exactly one tet, canonical, in the order of their sorted node
/// triples.
fn boundary_faces(tets: &[[usize; 4]]) -> Vec<[usize; 3]> {
    let mut faces: Vec<([usize; 3], [usize; 3])> = Vec::with_capacity(tets.len() * 4);
    for &tet in tets {
        for f in tet_faces(tet) {
            let mut key = f;
            key.sort_unstable();
            faces.push((key, f));
        }
    }
    faces.sort_unstable_by_key(|x| x.0);
    let mut tris = Vec::new();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        if j - i == 1 {
            tris.push(canonical_face(faces[i].1));
        }
        i = j;
    }
    tris
}

/// [`boundary_faces`] for node indices below 2^[`PACK_BITS`] and fewer than 2^30 tets: the
/// sorted node triple packed into one u64 (same order as the triples) beside the face's
/// number: 16-byte elements sort about twice as fast as the 48-byte (triple, face)
/// pairs (docs/benchmarks.md, "Design measurements"). Same result.
fn boundary_faces_packed(tets: &[[usize; 4]]) -> Vec<[usize; 3]> {
    let mut faces: Vec<(u64, u32)> = Vec::with_capacity(tets.len() * 4);
    for (t, &tet) in tets.iter().enumerate() {
        for (k, mut key) in tet_faces(tet).into_iter().enumerate() {
            key.sort_unstable();
            let packed = ((key[0] as u64) << (2 * PACK_BITS))
                | ((key[1] as u64) << PACK_BITS)
                | key[2] as u64;
            faces.push((packed, (4 * t + k) as u32));
        }
    }
    faces.sort_unstable();
    let same = |j: usize, key: u64| faces.get(j).is_some_and(|&(other, _)| other == key);
    let mut tris = Vec::new();
    for (i, &(key, id)) in faces.iter().enumerate() {
        if !same(i + 1, key) && (i == 0 || !same(i - 1, key)) {
            let id = id as usize;
            tris.push(canonical_face(tet_faces(tets[id / 4])[id % 4]));
        }
    }
    tris
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The packed-key boundary faces equal the general ones (same faces, same order), on a
    /// structured box and on the same box with its tets listed in reverse.
    #[test]
    fn packed_boundary_faces_equal_the_general_ones() {
        let mesh = TetMesh::structured_box([7, 3, 4], [1.0, 0.5, 0.5]);
        let mut tets = mesh.tets.clone();
        let general = boundary_faces(&tets);
        assert_eq!(general.len(), 2 * 2 * (7 * 3 + 7 * 4 + 3 * 4));
        assert_eq!(boundary_faces_packed(&tets), general);
        tets.reverse();
        assert_eq!(boundary_faces_packed(&tets), boundary_faces(&tets));
        assert_eq!(boundary_faces(&tets), general);
    }
}
