//! The bake pipeline: mesh → oriented, validated mesh → K, M → boundary conditions →
//! lowest elastic modes → surface extraction → [`ModesFile`].
//!
//! One file per part: `params` ([`BakeParams`], what determines a result), `error`
//! ([`BakeError`]), `report` ([`BakeReport`], [`BakeStage`]), `hashing` ([`geometry_hash`]),
//! `prepare` (orientation, connectivity, fixed-node selection), `fixed_near` ([`FixedNear`]:
//! nodes near given points and triangles), `surface` (the surface a base stores, from
//! [`extract_surface`]), `mode_set` (the transfer table's many-mode sets: [`mode_set_dense`],
//! [`mode_set_lanczos`]), `estimate` ([`SizeEstimate`], [`Budget`]: size before work),
//! `plausibility` ([`unit_hint`], [`plausibility_warnings`]: unit mistakes named), `pipeline` ([`bake_mesh`], [`bake_file`]) and `staleness`
//! ([`base_status`], [`BaseStatus`]).

mod error;
mod estimate;
mod fixed_near;
mod fixed_nodes;
mod hashing;
mod mode_set;
mod params;
mod pipeline;
mod plausibility;
mod prepare;
mod report;
mod stale_detail;
mod staleness;
mod surface;

pub use dcr_runtime::format::{MaterialSi, ModesFile, ModesPrecision};

/// The boundary surface of a tetrahedral mesh (defined in [`crate::mesh`]).
pub use crate::mesh::extract_surface;
pub use error::BakeError;
pub use estimate::{
    format_bytes, format_count, format_seconds, group_digits, Budget, SizeEstimate,
    SurfaceMeasures, FEWEST_ELEMENTS, FTETWILD_ELEMENTS, FTETWILD_S_PER_TET,
};
pub use fixed_near::{FixedNear, DEFAULT_DISTANCE_FRACTION};
pub use fixed_nodes::{FixedNodes, FixedSelectors};
pub use hashing::{geometry_hash, round_16_digits};
pub use mode_set::{mode_set_dense, mode_set_from_dense, mode_set_lanczos};
pub use params::{BakeParams, FixedBelow, ModeRequest};
pub(crate) use pipeline::transfer_meta;
pub use pipeline::{
    bake_file, bake_mesh, MAX_RESIDUAL, OUTPUT_VERSION, RIGID_REL_TOL, TOOL_VERSION,
};
pub use plausibility::{
    plausibility_warnings, unit_hint, PLAUSIBLE_EXTENT_M, PLAUSIBLE_LOWEST_HZ, PLAUSIBLE_MASS_KG,
    PLAUSIBLE_WAVE_SPEED,
};
pub use report::{BakeReport, BakeStage, TransferReport};
pub use stale_detail::option_number;
pub use staleness::{
    base_status, is_mesh_up_to_date, is_up_to_date, mesh_base_status, same_mesh_base_status,
    BaseStatus,
};
