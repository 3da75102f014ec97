//! The many-mode sets a transfer table ([`crate::transfer`]) is built from: the dense all-mode
//! eigensolve (small meshes) or a Lanczos bake with many modes, as base-shaped
//! [`ModesFile`]s. They live with the bake because the second one is a bake.

use dcr_runtime::format::ModesFile;

use super::{bake_mesh, BakeError, BakeParams, ModeRequest};
use crate::full_order::{FullOrderSystem, ModalAll, SystemParams};
use crate::mesh::TetMesh;
use crate::transfer::{TransferError, TransferModes, DENSE_MAX_DOFS};

/// A base-shaped mode set (surface rows of U) of the lowest `modes` dense eigenpairs, in the
/// layout of `template` (a base baked from the same mesh and options: same surface order).
///
/// # Errors
/// [`TransferError::FullOrder`] when the system cannot be built or the dense eigensolve fails
/// (including more than [`DENSE_MAX_DOFS`] free dofs).
pub fn mode_set_dense(
    template: &ModesFile,
    mesh: &TetMesh,
    params: &BakeParams,
    modes: TransferModes,
    file: &str,
) -> Result<ModesFile, TransferError> {
    let tp = SystemParams::of_bake(params);
    let sys = FullOrderSystem::new(mesh.clone(), &tp, file)?;
    let ma = ModalAll::new(&sys, DENSE_MAX_DOFS)?;
    let m = match modes {
        TransferModes::All | TransferModes::Auto => ma.eigenvalues.len(),
        TransferModes::Count(n) => n.min(ma.eigenvalues.len()),
    };
    Ok(mode_set_from_dense(template, &sys, &ma, m))
}

/// The lowest `m` eigenpairs of a dense all-mode solve `ma` of `sys` as a base-shaped mode set
/// in the layout of `template` (surface rows of U; fixed dofs zero; no table).
pub fn mode_set_from_dense(
    template: &ModesFile,
    sys: &FullOrderSystem,
    ma: &ModalAll,
    m: usize,
) -> ModesFile {
    let mut b = template.clone();
    let mut rows = Vec::with_capacity(b.surface_to_volume.len() * 3 * m);
    for &v in &b.surface_to_volume {
        for ax in 0..3 {
            match sys.map.free_index(3 * v as usize + ax) {
                Some(i) => rows.extend((0..m).map(|j| ma.vectors[(i, j)])),
                None => rows.extend(std::iter::repeat_n(0.0, m)),
            }
        }
    }
    b.modes = rows;
    b.eigenvalues = ma.eigenvalues[..m].to_vec();
    b.residuals = vec![0.0; m];
    b.transfer = None;
    b
}

/// A mode set of the lowest `n` modes from a Lanczos bake of `mesh` with `params`.
///
/// # Errors
/// [`BakeError::TransferModes`] when that bake fails (e.g. the eigensolver does not converge).
pub fn mode_set_lanczos(
    mesh: &TetMesh,
    params: &BakeParams,
    n: usize,
    file: &str,
) -> Result<ModesFile, BakeError> {
    let p = BakeParams {
        modes: ModeRequest::Count(n),
        transfer: None,
        ..params.clone()
    };
    bake_mesh(mesh.clone(), &p, file, &mut |_| {})
        .map(|(b, _)| b)
        .map_err(|e| BakeError::TransferModes {
            file: file.to_string(),
            error: Box::new(e),
        })
}
