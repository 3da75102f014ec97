//! Whether a base is up to date ([`BaseStatus`]): compared with what a bake would write by
//! content hashes of the geometry and the parameters, the tool's output version and the
//! transfer table's recorded parameters — never by file times.

use std::path::Path;

use super::pipeline::transfer_meta;
use super::prepare::prepare;
use super::stale_detail;
use super::{BakeError, BakeParams, OUTPUT_VERSION};
use crate::mesh::TetMesh;
use dcr_runtime::format::ModesFile;

/// Whether `modes` is an up-to-date base of `mesh_path` baked with `params`: it exists, reads,
/// its stored geometry and parameter hashes equal those of this mesh and these parameters, it
/// holds the heat-geodesic `surface_order` a bake would store, and its peak-transfer table
/// matches [`BakeParams::transfer`] (see [`base_status`]).
///
/// `Ok(false)` when the base is missing, unreadable or stale.
///
/// # Errors
/// A [`BakeError`] when the mesh itself cannot be read or prepared (what `check` exits 2 on).
pub fn is_up_to_date(
    mesh_path: &Path,
    params: &BakeParams,
    modes: &Path,
) -> Result<bool, BakeError> {
    Ok(base_status(mesh_path, params, modes)? == BaseStatus::UpToDate)
}

/// Whether a base is up to date, and if not why (what `modal-bake check --json` reports);
/// each stale reason carries one line naming what differs, by the options that change it
/// ([`BaseStatus::detail`]).
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum BaseStatus {
    /// The base holds what a bake of this mesh with these options would write.
    UpToDate,
    /// No file at the base's path.
    Missing,
    /// The file does not read as a valid base (the reader's message).
    Unreadable(String),
    /// Written by a `modal-bake` whose output differs ([`OUTPUT_VERSION`]), or without what
    /// this one stores (the heat-geodesic order).
    ToolChanged(String),
    /// The mesh's geometry or fixed set differs ([`geometry_hash`](super::geometry_hash)).
    GeometryChanged(String),
    /// The bake parameters differ ([`BakeParams::hash`]).
    ParametersChanged(String),
    /// The peak-transfer table is missing, unwanted or built with other parameters.
    TransferTableChanged(String),
}

impl BaseStatus {
    /// The reason as one word (`up_to_date`, `missing`, `unreadable`, `tool_changed`,
    /// `geometry_changed`, `parameters_changed`, `transfer_table_changed`).
    pub fn reason(&self) -> &'static str {
        match self {
            BaseStatus::UpToDate => "up_to_date",
            BaseStatus::Missing => "missing",
            BaseStatus::Unreadable(_) => "unreadable",
            BaseStatus::ToolChanged(_) => "tool_changed",
            BaseStatus::GeometryChanged(_) => "geometry_changed",
            BaseStatus::ParametersChanged(_) => "parameters_changed",
            BaseStatus::TransferTableChanged(_) => "transfer_table_changed",
        }
    }

    /// What differs, in one line (`--modes/--max-freq: 10 modes in the base, 12 modes asked`),
    /// or why the base is unreadable; `None` when up to date or missing.
    pub fn detail(&self) -> Option<&str> {
        match self {
            BaseStatus::UpToDate | BaseStatus::Missing => None,
            BaseStatus::Unreadable(d)
            | BaseStatus::ToolChanged(d)
            | BaseStatus::GeometryChanged(d)
            | BaseStatus::ParametersChanged(d)
            | BaseStatus::TransferTableChanged(d) => Some(d),
        }
    }
}

/// Compares the base at `modes` with what a bake of `mesh_path` with `params` would write: by
/// content hashes of the parsed geometry and of the parameters, the [`OUTPUT_VERSION`] of the
/// tool that wrote it, and the recorded transfer-table parameters — never by file times. A
/// base is stale when it has a table and none is asked for, has none and one is asked for, or
/// its table was built with other parameters (step h, modes, region, up direction,
/// oversampling, order).
///
/// # Errors
/// A [`BakeError`] when the mesh itself cannot be read or prepared, or the parameters are
/// invalid (what `check` exits 2 on).
pub fn base_status(
    mesh_path: &Path,
    params: &BakeParams,
    modes: &Path,
) -> Result<BaseStatus, BakeError> {
    let file = mesh_path.display().to_string();
    check_options(params, &file)?;
    let mesh = crate::mesh::read_mesh(mesh_path)?;
    mesh_base_status(mesh, &file, params, modes)
}

/// Checks the bake and transfer-table parameters (what `check` exits 2 on before any mesh work).
fn check_options(params: &BakeParams, file: &str) -> Result<(), BakeError> {
    params.check()?;
    if let Some(tp) = &params.transfer {
        tp.check().map_err(|error| BakeError::Transfer {
            file: file.to_string(),
            error: Box::new(error),
        })?;
    }
    Ok(())
}

/// As [`is_up_to_date`] for a mesh already in memory (e.g. one gmsh made from a
/// surface asset); `file` names it in messages.
///
/// # Errors
/// As [`is_up_to_date`].
pub fn is_mesh_up_to_date(
    mesh: TetMesh,
    file: &str,
    params: &BakeParams,
    modes: &Path,
) -> Result<bool, BakeError> {
    Ok(mesh_base_status(mesh, file, params, modes)? == BaseStatus::UpToDate)
}

/// As [`base_status`] for a mesh already in memory; `file` names it in messages.
///
/// # Errors
/// As [`base_status`].
pub fn mesh_base_status(
    mesh: TetMesh,
    file: &str,
    params: &BakeParams,
    modes: &Path,
) -> Result<BaseStatus, BakeError> {
    check_options(params, file)?;
    let prepared = prepare(mesh, params, file)?;
    let base = match read_base(modes) {
        Ok(base) => base,
        Err(status) => return Ok(status),
    };
    compare(&base, params, Some(&prepared))
}

/// As [`base_status`] for `base` (already read) and the mesh it was baked from, known to be
/// the same without reading it (a surface asset whose bytes, meshing options, meshers and
/// build are those recorded: [`AssetKey`](crate::mesh::AssetKey)): the tool, parameters and
/// table are compared, the geometry is taken as the base's, and the table's mode count is
/// resolved with the base's free dofs; `file` names the mesh in messages.
///
/// # Errors
/// Invalid parameters (what `check` exits 2 on).
pub fn same_mesh_base_status(
    file: &str,
    params: &BakeParams,
    base: &ModesFile,
) -> Result<BaseStatus, BakeError> {
    check_options(params, file)?;
    compare(base, params, None)
}

/// The base at `modes`, or its status when it is missing or unreadable.
fn read_base(modes: &Path) -> Result<ModesFile, BaseStatus> {
    if std::fs::symlink_metadata(modes).is_err() {
        return Err(BaseStatus::Missing);
    }
    ModesFile::read(modes).map_err(|e| BaseStatus::Unreadable(e.to_string()))
}

/// `base` against a bake with `params` of `prepared` (`None`: of the base's own mesh).
fn compare(
    base: &ModesFile,
    params: &BakeParams,
    prepared: Option<&super::prepare::Prepared>,
) -> Result<BaseStatus, BakeError> {
    let version_matches =
        base.meta.bake_params.get("output_version") == Some(&serde_json::json!(OUTPUT_VERSION));
    // A base without the stored heat-geodesic order (baked before it existed, or written
    // elsewhere) is stale when this tool would store one.
    let order_matches = base.surface_order.is_some()
        || crate::ordering::plan_surface_order(&base.surface_vertices, &base.surface_triangles)
            .is_err();
    if !version_matches || !order_matches {
        return Ok(BaseStatus::ToolChanged(stale_detail::tool_difference(
            base,
            version_matches,
        )));
    }
    if let Some(prepared) = prepared {
        if base.meta.source_hash != prepared.hash {
            return Ok(BaseStatus::GeometryChanged(
                stale_detail::geometry_difference(base, prepared),
            ));
        }
    }
    if base.meta.params_hash != params.hash() {
        return Ok(BaseStatus::ParametersChanged(
            stale_detail::with_target_choice(
                base,
                stale_detail::parameter_difference(base, params),
            ),
        ));
    }
    // The bake records the table's mode count resolved for the mesh (`auto` → `all` or a
    // Lanczos count), so compare with the same resolution.
    let free_dofs = match prepared {
        Some(p) => 3 * (p.mesh.nodes.len() - p.fixed.len()),
        None => {
            3 * base
                .meta
                .volume_nodes
                .saturating_sub(base.fixed_nodes.len())
        }
    };
    let expected = params.transfer.as_ref().map(|tp| {
        let resolved = crate::transfer::TransferParams {
            modes: tp.modes.resolve(free_dofs),
            ..tp.clone()
        };
        transfer_meta(&resolved, params)
    });
    let table_matches = match &expected {
        None => base.transfer.is_none(),
        Some(e) => base.transfer.is_some() && base.meta.bake_params.get("transfer") == Some(e),
    };
    if !table_matches {
        return Ok(BaseStatus::TransferTableChanged(
            stale_detail::with_target_choice(
                base,
                stale_detail::transfer_difference(base, expected.as_ref()),
            ),
        ));
    }
    Ok(BaseStatus::UpToDate)
}
