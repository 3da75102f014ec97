//! A mesh made ready for baking: tetrahedra oriented and checked, connectivity checked, the
//! fixed-node set selected (groups, half-spaces, boxes, nodes near given points) and the geometry hashed.

use super::{geometry_hash, BakeError, BakeParams, FixedNodes};
use crate::mesh::{MeshError, TetMesh, DEFAULT_DEGENERATE_REL_TOL, DEFAULT_STRAIGHT_REL_TOL};

/// A mesh prepared for baking: oriented, checked, with its fixed-node set and hash.
pub(super) struct Prepared {
    pub(super) mesh: TetMesh,
    pub(super) fixed: Vec<usize>,
    /// What each selector fixed: (description, nodes), in the order groups, below, boxes.
    pub(super) fixed_by: Vec<(String, usize)>,
    /// Second-order meshes: each edge (sorted corner pair) with its mid-edge node, sorted.
    pub(super) mid_table: Vec<([usize; 2], usize)>,
    pub(super) reoriented: usize,
    pub(super) hash: String,
}

pub(super) fn prepare(
    mut mesh: TetMesh,
    params: &BakeParams,
    file: &str,
) -> Result<Prepared, BakeError> {
    let name_file = |mut e: MeshError| {
        if e.file.is_empty() {
            e.file = file.to_string();
        }
        e
    };
    if mesh.tets.is_empty() {
        return Err(BakeError::Params(format!(
            "{file}: the mesh has no tetrahedra"
        )));
    }
    mesh.check_extent().map_err(name_file)?;
    let reoriented = mesh
        .orient_tets(DEFAULT_DEGENERATE_REL_TOL)
        .map_err(name_file)?;
    mesh.check_straight(DEFAULT_STRAIGHT_REL_TOL)
        .map_err(name_file)?;
    let mid_table = mesh.edge_mid_nodes().map_err(name_file)?;
    mesh.check_overlaps().map_err(name_file)?;
    let pieces = mesh.pieces();
    if pieces.len() != 1 {
        return Err(BakeError::Disconnected {
            file: file.to_string(),
            pieces: pieces.len(),
            list: crate::mesh::list_pieces(&pieces),
        });
    }
    let FixedNodes {
        nodes: fixed,
        by: fixed_by,
    } = params
        .fixed_selectors()
        .resolve_with(&mesh, &mid_table, file)?;
    let hash = geometry_hash(&mesh, &fixed);
    Ok(Prepared {
        mesh,
        fixed,
        fixed_by,
        mid_table,
        reoriented,
        hash,
    })
}
