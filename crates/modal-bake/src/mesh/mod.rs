//! Mesh input: gmsh MSH 2.2 (also 2.0, 2.1) and 4.1 (ASCII and binary) and meshio-style JSON,
//! read into a canonical [`TetMesh`]: nodes by ascending tag (JSON: point order), nodes outside
//! every tetrahedron dropped, 0-based indices, tetrahedra and triangles sorted by node indices with
//! exact repeats removed. Two files holding the same nodes (same tags, bit-identical
//! positions) and elements give equal meshes, whatever their format or element order.
//!
//! Caveat: gmsh writes ASCII MSH coordinates with `%.16g`, which does not round-trip every
//! `f64`; an ASCII and a binary file of one gmsh mesh can differ by 1 ulp per coordinate
//! (the geometry hash, [`crate::bake::geometry_hash`], rounds to 16 digits and sees them as one).
//!
//! Supported: 4- and 10-node tetrahedra (volume), 3- and 6-node triangles (informational) and
//! physical groups of any dimension (as node sets, for boundary conditions). Other volume
//! elements (hexahedra, prisms, pyramids, tetrahedra of higher order) beside tetrahedra are
//! refused, other elements (points, lines, quadrangles) skipped with a note in
//! [`TetMesh::notes`]. MSH 1 and 4.0, an ANSYS Fluent `.msh` and unknown formats are refused
//! with the command that converts them. How an element type is dispatched
//! is in the `msh` and `json` module docs: one table of node counts per format, one function
//! that files each element by type.
//!
//! Hostile input: files are read only when they are regular files (a device or FIFO is refused
//! before it is opened), and no more than their size; declared counts are checked against the
//! bytes left before allocating; repeated or misplaced sections, non-positive tags, short or
//! long ASCII records and tetrahedra listed twice in different node orders are refused with
//! their line, byte offset or element ids. Every error is a [`MeshError`] naming the file.

mod asset;
mod asset_key;
mod boundary;
mod cursor;
mod distance;
pub mod ftetwild;
pub mod gmsh;
mod json;
mod mesh_builder;
mod mesh_error;
pub mod mesher;
mod msh;
mod msh_writer;
mod pieces;
mod selection;
pub mod sizing;
pub mod surface;
mod tet_mesh;
mod validate;
pub mod work;

use std::path::Path;

pub use asset::mesh_asset;
pub use asset_key::{surface_sha256, AssetKey, BUILD_HASH};
pub use boundary::extract_surface;
pub use distance::{surface_distance, SurfaceDistance};
pub use mesh_error::{Location, MeshError, MeshErrorKind};
pub use mesher::{
    choose_backend, mesh_surface, AssetError, Backend, MeshParams, MeshReport, MeshedAsset,
    MesherChoice,
};
pub use msh_writer::msh41_bytes;
pub(crate) use pieces::list_pieces;
pub use pieces::{four_digits, MeshPiece};
pub use selection::{is_json, Units, VolumeSelection};
pub(crate) use tet_mesh::tet_faces;
pub use tet_mesh::{signed_volume, TetMesh, TET10_EDGES};
pub use validate::{DEFAULT_DEGENERATE_REL_TOL, DEFAULT_STRAIGHT_REL_TOL, STRAIGHT_DIAGONAL_TOL};

/// Reads a whole regular file, at most as many bytes as its size when opened. A directory,
/// device, FIFO or socket is refused before it is opened for reading (a FIFO would block, a
/// device like `/dev/zero` never ends).
fn read_file(path: &Path) -> Result<(Vec<u8>, String), MeshError> {
    use dcr_runtime::format::{open_regular_file, OpenError};
    use std::io::Read;
    let name = path.display().to_string();
    let error = |kind| MeshError::new(&name, Location::None, kind);
    let (file, len) = open_regular_file(path).map_err(|e| match e {
        OpenError::NotRegular(what) => error(MeshErrorKind::NotARegularFile(what)),
        OpenError::Io(e) => error(MeshErrorKind::Io(e.to_string())),
    })?;
    let mut data = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.take(len)
        .read_to_end(&mut data)
        .map_err(|e| error(MeshErrorKind::Io(e.to_string())))?;
    Ok((data, name))
}

/// Reads a mesh file (positions in m), choosing the format from its content (`$MeshFormat`
/// → MSH, `{` → JSON) or else its extension (`.msh`, `.json`).
///
/// # Errors
/// A [`MeshError`] naming the file and the line, byte offset or element at fault.
///
/// ```no_run
/// let mesh = modal_bake::mesh::read_mesh("data/meshes/cube_v41.msh".as_ref()).unwrap();
/// assert!(mesh.groups.contains_key("bottom"));
/// ```
pub fn read_mesh(path: &Path) -> Result<TetMesh, MeshError> {
    let (data, name) = read_file(path)?;
    read_mesh_bytes(&data, &name)
}

/// [`read_mesh`] on bytes in memory; `name` (a file name) is used for format detection by
/// extension and in error messages.
///
/// # Errors
/// As [`read_mesh`].
pub fn read_mesh_bytes(data: &[u8], name: &str) -> Result<TetMesh, MeshError> {
    let lower = name.to_ascii_lowercase();
    match data.iter().find(|b| !b.is_ascii_whitespace()) {
        Some(b'$') => msh::parse_msh(data, name),
        Some(b'{') => json::parse_json(data, name),
        Some(b'(') if lower.ends_with(".msh") => Err(MeshError::new(
            name,
            Location::None,
            MeshErrorKind::FluentMsh,
        )),
        _ => {
            if lower.ends_with(".msh") {
                msh::parse_msh(data, name)
            } else if lower.ends_with(".json") {
                json::parse_json(data, name)
            } else {
                Err(MeshError::new(
                    name,
                    Location::None,
                    MeshErrorKind::UnknownFormat,
                ))
            }
        }
    }
}

/// Reads a gmsh MSH 2.2 or 4.1 file, ASCII or binary (either endianness; 4.1 `size_t` of 4
/// or 8 bytes). Positions in m. Tetrahedron ids are the element tags.
///
/// # Errors
/// A [`MeshError`] with a line (ASCII) or byte offset (binary).
///
/// ```
/// let msh = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n\
///             0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n\
///             1 1 2 3 4\n$EndElements\n";
/// let m = modal_bake::mesh::read_msh_bytes(msh, "tet.msh").unwrap();
/// assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
/// ```
pub fn read_msh(path: &Path) -> Result<TetMesh, MeshError> {
    let (data, name) = read_file(path)?;
    read_msh_bytes(&data, &name)
}

/// [`read_msh`] keeping only the tetrahedra of one object: the 3-D physical group `object`
/// (its name, or its number when it has none) — one piece of a file of several volumes.
/// Nodes outside its tetrahedra are dropped (a note), node groups keep their nodes in it.
///
/// # Errors
/// As [`read_msh`], and [`MeshErrorKind::UnknownObject`] (listing the file's 3-D physical
/// groups) when no tetrahedron belongs to `object`.
pub fn read_msh_object(path: &Path, object: &str) -> Result<TetMesh, MeshError> {
    let (data, name) = read_file(path)?;
    msh::parse_msh_object(&data, &name, Some(object))
}

/// [`read_msh_object`] on bytes in memory; `name` is used in error messages.
///
/// # Errors
/// As [`read_msh_object`].
pub fn read_msh_object_bytes(data: &[u8], name: &str, object: &str) -> Result<TetMesh, MeshError> {
    msh::parse_msh_object(data, name, Some(object))
}

/// [`read_msh`] on bytes in memory; `name` is used in error messages.
///
/// # Errors
/// As [`read_msh`].
pub fn read_msh_bytes(data: &[u8], name: &str) -> Result<TetMesh, MeshError> {
    msh::parse_msh(data, name)
}

/// Reads a meshio-style JSON mesh (`points` in m, `cells` blocks of 0-based indices, groups
/// from `cell_sets` or `cell_data["gmsh:physical"]` + `field_data`). Tetrahedron ids are the
/// 1-based positions across `tetra` blocks.
///
/// # Errors
/// A [`MeshError`] with a JSON path (shape/type errors) or line (syntax errors).
///
/// ```
/// let json = br#"{"points": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]],
///                 "cells": [{"type": "tetra", "data": [[0,1,2,3]]}],
///                 "cell_sets": {"volume": [[0]]}}"#;
/// let m = modal_bake::mesh::read_json_bytes(json, "tet.json").unwrap();
/// assert_eq!(m.groups["volume"], vec![0, 1, 2, 3]);
/// ```
pub fn read_json(path: &Path) -> Result<TetMesh, MeshError> {
    let (data, name) = read_file(path)?;
    read_json_bytes(&data, &name)
}

/// [`read_json`] on bytes in memory; `name` is used in error messages.
///
/// # Errors
/// As [`read_json`].
pub fn read_json_bytes(data: &[u8], name: &str) -> Result<TetMesh, MeshError> {
    json::parse_json(data, name)
}
