//! Which part of a volume mesh file is the object, and in which unit it is written
//! ([`VolumeSelection`]): the one reading of `--object`, `--units`, `--piece` and
//! `--straighten` that `bake`, `check`, `info` and the lab's reference tools share, so that a
//! reference is computed on exactly the mesh a base was baked from.

use std::path::Path;

use super::{read_mesh, read_msh_object, Location, MeshError, MeshErrorKind, TetMesh};

/// Length unit of a mesh's or surface asset's coordinates (`--units`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Units {
    /// Metres (Blender's default export).
    #[default]
    M,
    /// Centimetres.
    Cm,
    /// Millimetres (most CAD exports).
    Mm,
    /// Inches.
    In,
}

impl Units {
    /// Metres per unit.
    pub fn to_metres(self) -> f64 {
        match self {
            Units::M => 1.0,
            Units::Cm => 0.01,
            Units::Mm => 0.001,
            Units::In => 0.0254,
        }
    }

    /// The coordinate `x` (in this unit) in metres. Centimetres and millimetres divide by 100
    /// and 1000 (one correctly rounded operation, so a coordinate exactly representable in
    /// the unit, such as a whole number of millimetres, gives the same bits as the metre value
    /// written in decimal); inches multiply by 0.0254.
    pub fn to_metres_of(self, x: f64) -> f64 {
        match self {
            Units::M => x,
            Units::Cm => x / 100.0,
            Units::Mm => x / 1000.0,
            Units::In => x * 0.0254,
        }
    }

    /// The option's spelling (`m`, `cm`, `mm`, `in`).
    pub fn name(self) -> &'static str {
        match self {
            Units::M => "m",
            Units::Cm => "cm",
            Units::Mm => "mm",
            Units::In => "in",
        }
    }
}

/// How a volume mesh file (gmsh `.msh`, meshio `.json`) is read into the object's mesh, applied
/// in this order: the physical volume `object` (`.msh` only), coordinates scaled from `units`
/// into metres, the connected `piece` (numbered from 1, largest volume first), and with
/// `straighten` every mid-edge node moved to its edge's midpoint. The default reads the whole
/// file in metres.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VolumeSelection {
    /// The 3-D physical group (name, or number when it has none) of a `.msh` file.
    pub object: Option<String>,
    /// The unit of the file's coordinates.
    pub units: Units,
    /// The connected piece (≥ 1, largest volume first).
    pub piece: Option<u64>,
    /// Move mid-edge nodes of a second-order mesh to their edges' midpoints (a note records
    /// the largest move).
    pub straighten: bool,
}

impl VolumeSelection {
    /// Reads `path` and selects the object (see [`VolumeSelection`]).
    ///
    /// # Errors
    /// The reader's [`MeshError`]s; [`MeshErrorKind::ObjectOfJson`] for an `object` of a
    /// meshio JSON file (which has no physical volumes), [`MeshErrorKind::UnknownObject`] and
    /// [`MeshErrorKind::NoSuchPiece`] listing what the file has.
    pub fn read(&self, path: &Path) -> Result<TetMesh, MeshError> {
        let name = path.display().to_string();
        let mut mesh = match &self.object {
            None => read_mesh(path)?,
            Some(_) if is_json(path) => {
                return Err(MeshError::new(
                    name,
                    Location::None,
                    MeshErrorKind::ObjectOfJson,
                ))
            }
            Some(object) => read_msh_object(path, object)?,
        };
        if self.units != Units::M {
            for p in &mut mesh.nodes {
                for c in p.iter_mut() {
                    *c = self.units.to_metres_of(*c);
                }
            }
        }
        if let Some(n) = self.piece {
            mesh = mesh
                .keep_piece(usize::try_from(n).unwrap_or(usize::MAX))
                .map_err(|mut e| {
                    e.file.clone_from(&name);
                    e
                })?;
        }
        if self.straighten {
            let note = if mesh.is_quadratic() {
                let (moved, relative) = mesh.straighten();
                format!(
                    "--straighten: every mid-edge node at its edge's midpoint; the largest move {moved:.3e} m ({:.3} % of its edge)",
                    100.0 * relative
                )
            } else {
                "--straighten: a linear mesh, nothing to move".to_string()
            };
            mesh.notes.push(note);
        }
        Ok(mesh)
    }
}

/// Whether `path` names a meshio-style `.json` mesh (by its extension).
pub fn is_json(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}
