//! gmsh MSH 4.1 binary writer for a [`TetMesh`]: what `modal-bake mesh` saves for a backend that
//! does not write gmsh files itself (fTetWild), and for meshes made second-order here.
//!
//! One volume entity (tag 1) in the physical group 3 "volume" (as the gmsh backend's files),
//! nodes tagged 1…N in mesh order, 4-node tetrahedra (type 4) or 10-node ones (type 11, gmsh's
//! node order: corners, then the mid-edge nodes of [`super::TET10_EDGES`]) tagged 1…T.
//! Coordinates are written as the exact doubles, so [`super::read_msh_bytes`] gives back the
//! mesh bit for bit (in its canonical order). The same mesh always gives the same bytes.

use super::TetMesh;

fn size(out: &mut Vec<u8>, v: usize) {
    out.extend_from_slice(&(v as u64).to_le_bytes());
}

fn int(out: &mut Vec<u8>, v: i32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn float(out: &mut Vec<u8>, v: f64) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// The mesh as MSH 4.1 binary bytes (little-endian, 8-byte sizes).
///
/// ```
/// use modal_bake::mesh::{msh41_bytes, read_msh_bytes, TetMesh};
/// let m = TetMesh::structured_box([1, 1, 1], [0.5, 0.25, 0.125]).to_quadratic();
/// let back = read_msh_bytes(&msh41_bytes(&m), "box.msh").unwrap();
/// assert!(back.is_quadratic());
/// assert_eq!(back.tets.len(), m.tets.len());
/// assert!((back.volume() - m.volume()).abs() < 1e-15);
/// ```
pub fn msh41_bytes(mesh: &TetMesh) -> Vec<u8> {
    let per = mesh.nodes_per_tet();
    let mut out = Vec::with_capacity(200 + 32 * mesh.nodes.len() + 8 * (per + 1) * mesh.tets.len());
    out.extend_from_slice(b"$MeshFormat\n4.1 1 8\n");
    int(&mut out, 1);
    out.extend_from_slice(b"\n$EndMeshFormat\n");
    out.extend_from_slice(b"$PhysicalNames\n1\n3 1 \"volume\"\n$EndPhysicalNames\n");
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if mesh.nodes.is_empty() {
        lo = [0.0; 3];
        hi = [0.0; 3];
    }
    out.extend_from_slice(b"$Entities\n");
    for n in [0, 0, 0, 1] {
        size(&mut out, n);
    }
    int(&mut out, 1);
    for v in lo.iter().chain(hi.iter()) {
        float(&mut out, *v);
    }
    size(&mut out, 1);
    int(&mut out, 1);
    size(&mut out, 0);
    out.extend_from_slice(b"\n$EndEntities\n$Nodes\n");
    let n = mesh.nodes.len();
    for v in [1, n, 1.min(n), n] {
        size(&mut out, v);
    }
    int(&mut out, 3);
    int(&mut out, 1);
    int(&mut out, 0);
    size(&mut out, n);
    for tag in 1..=n {
        size(&mut out, tag);
    }
    for p in &mesh.nodes {
        for &x in p {
            float(&mut out, x);
        }
    }
    out.extend_from_slice(b"\n$EndNodes\n$Elements\n");
    let t = mesh.tets.len();
    for v in [1, t, 1.min(t), t] {
        size(&mut out, v);
    }
    int(&mut out, 3);
    int(&mut out, 1);
    int(&mut out, if per == 10 { 11 } else { 4 });
    size(&mut out, t);
    for e in 0..t {
        size(&mut out, e + 1);
        for &v in &mesh.tet_nodes(e)[..per] {
            size(&mut out, v + 1);
        }
    }
    out.extend_from_slice(b"\n$EndElements\n");
    out
}
