//! The bake-time peak-transfer table: for a region R of surface vertices, the points of a
//! Lagrange interpolant on its triangles (vertices; edge midpoints for P2; two points per edge
//! and face centroids for P3), `T[i][j]` = peak over one step h of `|n_jᵀ u_j(t)|` at point j
//! after a unit inward-normal impulse (1 N·s along −n_i) at point i, summed over MANY modes
//! (Rayleigh damping of the base, exact impulse responses `g_l(t)` of `dcr_runtime::filter::ModeFilter`,
//! samples t = k·h/S, k = 1..S). A point's normal row is the barycentric blend of its vertices'.
//!
//! With `w_il = n_iᵀ U_il` (the runtime's area-weighted vertex normals) the response is
//! `−Σ_l w_il w_jl g_l(t)`, symmetric in (i, j) (reciprocity): only the upper triangle is
//! computed and stored, as f32, in the base ([`dcr_runtime::format::TransferTable`]); how it is
//! computed is in [`build_transfer_table`]'s module. The runtime looks it up with
//! `dcr_runtime::Method::Transfer`.
//!
//! The mode set is any base-shaped [`ModesFile`](dcr_runtime::format::ModesFile) holding many
//! modes (surface rows of U): from the dense all-mode eigensolve
//! ([`mode_set_dense`](crate::bake::mode_set_dense), small meshes) or a Lanczos bake with many
//! modes ([`mode_set_lanczos`](crate::bake::mode_set_lanczos)).

mod region;
mod table_builder;
mod table_plan;
mod transfer_params;

pub use region::{select_region, RegionBox};
pub use table_builder::{build_transfer_table, plan_transfer_table, CLUSTER_BYTES};
pub use table_plan::{OverBudget, TablePlan};
pub use transfer_params::{
    TableOrder, TransferError, TransferModes, TransferParams, TransferProgress,
    AUTO_CUBIC_MAX_POINTS, AUTO_LANCZOS_MODES, DEFAULT_OVERSAMPLE, DENSE_MAX_DOFS, UP_MIN_COS,
};
