//! A surface asset to a tetrahedral mesh: read ([`super::surface`]), scale to metres, then the
//! meshing chain of [`super::mesher`] (range checks, inspection, gmsh or fTetWild, distance).

use std::path::Path;

use super::mesher::{mesh_surface, AssetError, MeshParams, MeshedAsset};
use super::surface;

/// Reads the surface asset `path` (its object `params.object`, or all of it), multiplies its coordinates by `to_metres` (1 for an asset
/// in m, 0.001 for mm, ...) and meshes it ([`mesh_surface`]); `progress` receives a line per
/// stage.
///
/// # Errors
/// [`AssetError`] naming the file: unreadable, out of range, gmsh forced on a defective surface
/// (the defect with its position, m), a backend failure (missing: how to install it).
pub fn mesh_asset(
    path: &Path,
    to_metres: f64,
    params: &MeshParams,
    progress: &dyn Fn(&str),
) -> Result<MeshedAsset, AssetError> {
    let file = path.display().to_string();
    let mut s = surface::read_surface_object(path, params.object.as_deref())?;
    if to_metres != 1.0 {
        s.scale(to_metres);
    }
    mesh_surface(&s, params, &file, progress)
}
