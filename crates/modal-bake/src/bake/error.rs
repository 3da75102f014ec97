//! [`BakeError`]: why a bake failed, naming the file and what failed.

use super::MAX_RESIDUAL;
use crate::eigen::EigenError;
use crate::fem::MaterialError;
use crate::mesh::MeshError;
use dcr_runtime::format::FormatError;

/// How to bake one piece of a mesh of several, by the kind of file `file` names.
fn piece_hint(file: &str) -> &'static str {
    let ext = std::path::Path::new(file)
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("msh") => "--piece N bakes piece N alone; --object NAME bakes the tetrahedra of one 3-D physical group (in gmsh, a `Physical Volume` per piece)",
        Some("json") => "--piece N bakes piece N alone",
        Some("stl" | "ply") => "an STL or PLY file names no objects: save each piece as its own file, or as one named object each of an OBJ or glTF and bake them one at a time with --object NAME",
        _ => "a glTF or OBJ asset's named objects one at a time: --object NAME, `modal-bake mesh ASSET --dry-run` lists them; pieces of one object: make each its own object or file",
    }
}

/// Why a bake failed. Every variant names what and where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BakeError {
    /// The mesh could not be read or is invalid (file, line or element in the message).
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Material parameters out of range.
    #[error("invalid material: {0}")]
    Material(#[from] MaterialError),
    /// Inconsistent bake parameters.
    #[error("invalid bake parameters: {0}")]
    Params(String),
    /// The mesh has several disconnected pieces.
    #[error(
        "{file}: the mesh has {pieces} disconnected pieces, largest first: {list}; bake each piece as its own object ({})",
        piece_hint(file)
    )]
    Disconnected {
        /// Mesh file.
        file: String,
        /// Number of connected pieces.
        pieces: usize,
        /// The pieces, largest first: number, tetrahedra, volume (m³), bounding box (m).
        list: String,
    },
    /// A free-free object did not show exactly six rigid-body modes.
    #[error("{file}: expected 6 rigid-body modes for a free-free object, found {found} eigenvalues with |λ| ≤ {tol:.3e} rad²/s² (a mechanism, or a near-singular mesh)")]
    RigidModes {
        /// Mesh file.
        file: String,
        /// Near-zero eigenvalues found.
        found: usize,
        /// Threshold used (rad²/s²).
        tol: f64,
    },
    /// The eigensolver failed or did not converge; nothing is written.
    #[error("{file}: {error}")]
    Eigen {
        /// Mesh file.
        file: String,
        /// What the solver reported.
        error: EigenError,
    },
    /// Modes whose residual exceeds [`MAX_RESIDUAL`](super::MAX_RESIDUAL); nothing is written.
    #[error("{file}: mode {mode} did not converge (relative residual {residual:.3e} > {MAX_RESIDUAL:.0e}); refusing to write the base")]
    NotConverged {
        /// Mesh file.
        file: String,
        /// 0-based elastic mode index.
        mode: usize,
        /// Its relative residual.
        residual: f64,
    },
    /// Writing or reading the `.modes` file failed.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The peak-transfer table ([`BakeParams::transfer`](super::BakeParams::transfer)) could not be built; nothing is written.
    #[error("{file}: {error}")]
    Transfer {
        /// Mesh file.
        file: String,
        /// What failed.
        error: Box<crate::transfer::TransferError>,
    },
    /// The many-mode Lanczos bake for the transfer table's modes failed; nothing is written.
    #[error("{file}: transfer table modes: {error}")]
    TransferModes {
        /// Mesh file.
        file: String,
        /// Why that bake failed.
        error: Box<BakeError>,
    },
}

impl BakeError {
    /// Whether this is a transfer table refused before its build for an estimate over its
    /// budget ([`TransferError::OverBudget`](crate::transfer::TransferError::OverBudget)).
    pub fn is_table_over_budget(&self) -> bool {
        matches!(self, BakeError::Transfer { error, .. }
            if matches!(**error, crate::transfer::TransferError::OverBudget(_)))
    }
}

#[cfg(test)]
mod tests {
    use super::BakeError;

    // Expectation: the refusal of a mesh of several pieces offers what works for its kind of
    // file: --piece for volume meshes, --object for assets with named objects, and for an STL
    // or PLY (no names) a file or named object per piece, never an option the file cannot use.
    #[test]
    fn a_mesh_of_several_pieces_is_told_what_works_for_its_file() {
        let text = |file: &str| {
            BakeError::Disconnected {
                file: file.into(),
                pieces: 2,
                list: "piece 1: …; piece 2: …".into(),
            }
            .to_string()
        };
        assert!(text("a.msh").contains("--piece N bakes piece N alone; --object NAME"));
        assert!(text("a.JSON").contains("--piece N") && !text("a.json").contains("--object"));
        for asset in ["a.stl", "a.PLY"] {
            let t = text(asset);
            assert!(
                t.contains("names no objects") && !t.contains("--piece"),
                "{t}"
            );
        }
        for asset in ["a.obj", "a.glb", "a.gltf"] {
            let t = text(asset);
            assert!(t.contains("--object NAME") && !t.contains("--piece"), "{t}");
        }
    }
}
