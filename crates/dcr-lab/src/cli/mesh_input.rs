//! The mesh a reference tool reads: a volume mesh file and the options that select the
//! object in it, as `modal-bake bake` reads them (`--units`, `--object`, `--piece`;
//! [`modal_bake::mesh::VolumeSelection`]), so that a reference is computed on exactly the
//! tetrahedra a base was baked from. (No `--straighten`: the full-order reference takes
//! 4-node tetrahedra only.)

use std::path::Path;

use clap::Args;
use modal_bake::mesh::surface::is_surface_asset;
use modal_bake::mesh::{TetMesh, Units, VolumeSelection};

/// How the mesh file is read (the bake's options of the same names).
#[derive(Args, Clone, Debug)]
pub struct MeshInput {
    /// Unit of the mesh's coordinates; they are scaled into metres when read, so every other
    /// length option (--impact, --contact, --fixed-below, --fixed-box) is in metres — give
    /// the bake's --units.
    #[arg(long, value_enum, default_value_t = Units::M)]
    pub units: Units,
    /// gmsh .msh: only this 3-D physical group (its name, or its number when it has none), as
    /// `modal-bake bake --object` [default: the whole file].
    #[arg(long, value_name = "NAME")]
    pub object: Option<String>,
    /// Only connected piece N (numbered from 1, largest volume first; after --object), as
    /// `modal-bake bake --piece` [default: the whole mesh, which must be one piece].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub piece: Option<u64>,
}

impl MeshInput {
    /// The mesh of `path` with these options, its readers' notes printed on stderr; `command`
    /// (`truth`, `fit-attenuation`) names the subcommand in the advice for a surface asset.
    ///
    /// # Errors
    /// A surface asset (with the `modal-bake mesh` command that makes its bake's mesh), and
    /// the readers' errors naming the file and place.
    pub fn read(&self, path: &Path, command: &str) -> anyhow::Result<TetMesh> {
        if is_surface_asset(path) {
            let msh = path.with_extension("msh");
            anyhow::bail!(
                "{}: a surface asset; dcr-lab {command} works on a mesh of 4-node tetrahedra: mesh the asset as the bake did, `modal-bake mesh {} -o {} --order 1` with the bake's --units, --object, --mesher and --size (a base baked with --transfer-h or --order 1 was baked from exactly these tetrahedra), then `dcr-lab {command} {}`",
                path.display(),
                path.display(),
                msh.display(),
                msh.display()
            );
        }
        let selection = VolumeSelection {
            object: self.object.clone(),
            units: self.units,
            piece: self.piece,
            straighten: false,
        };
        let mesh = selection.read(path)?;
        for note in &mesh.notes {
            eprintln!("note: {}: {note}", path.display());
        }
        Ok(mesh)
    }
}
