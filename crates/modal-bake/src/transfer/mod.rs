//! The bake-time peak-transfer table (issue #5 item 3): for a region R of surface vertices and
//! the midpoints of its edges (the table's points), `T[i][j]` = peak over one step h of
//! `|n_jᵀ u_j(t)|` at point j after a unit inward-normal impulse (1 N·s along −n_i) at point i
//! (a midpoint's normal row is the average of its two vertices'), summed over MANY modes (Rayleigh damping of the base,
//! exact impulse responses `g_l(t)` of `dcr_runtime::ModeFilter`, samples t = k·h/S, k = 1..S).
//!
//! With `w_il = n_iᵀ U_il` (the runtime's area-weighted vertex normals) the response is
//! `−Σ_l w_il w_jl g_l(t)`, symmetric in (i, j) (reciprocity): only the upper triangle is
//! computed (one GEMM per source point: `Y = (G ∘ w_i) W_Rᵀ` against the region vertices, a
//! midpoint column being the average of two vertex columns; G the S × m table of g_l(kT))
//! and stored, as f32, in the base ([`dcr_runtime::format::TransferTable`]). The runtime looks
//! it up with `dcr_runtime::Method::Transfer`.
//!
//! The mode set is any base-shaped [`ModesFile`](dcr_runtime::format::ModesFile) holding many modes (surface rows of U): from the
//! dense all-mode eigensolve ([`mode_set_dense`], small meshes) or a Lanczos bake with many modes
//! ([`mode_set_lanczos`]).

mod region;
mod table_builder;

pub use region::{select_region, RegionBox};
pub use table_builder::{
    build_transfer_table, mode_set_dense, mode_set_from_dense, mode_set_lanczos, TransferError,
    TransferModes, TransferParams, TransferProgress, DEFAULT_OVERSAMPLE, DENSE_MAX_DOFS,
    UP_MIN_COS,
};
