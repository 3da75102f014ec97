//! A surface asset to a tetrahedral mesh: read ([`super::surface`]), scale to metres, check
//! that it bounds a solid, tetrahedralize with gmsh ([`super::gmsh`]).

use std::path::Path;

use super::gmsh::{self, GmshError, GmshOutput, GmshParams};
use super::surface::{self, SurfaceError, SurfaceInfo};

/// Why an asset could not be meshed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AssetError {
    /// The surface is unreadable or does not bound a solid (position in m in the message).
    #[error(transparent)]
    Surface(#[from] SurfaceError),
    /// gmsh is missing or failed.
    #[error(transparent)]
    Gmsh(#[from] GmshError),
}

/// Reads the surface asset `path`, multiplies its coordinates by `to_metres` (1 for an asset
/// in m, 0.001 for mm, ...), checks it and tetrahedralizes it.
///
/// # Errors
/// [`AssetError`] naming the file: the first open edge, non-manifold vertex or inconsistent
/// orientation with its position (m), or a gmsh failure (missing gmsh: how to install it).
pub fn mesh_asset(
    path: &Path,
    to_metres: f64,
    params: &GmshParams,
) -> Result<(GmshOutput, SurfaceInfo), AssetError> {
    let file = path.display().to_string();
    let mut s = surface::read_surface(path)?;
    if to_metres != 1.0 {
        s.scale(to_metres);
    }
    let info = s.check_closed(&file)?;
    let out = gmsh::tetrahedralize(&s, params, &file)?;
    Ok((out, info))
}
