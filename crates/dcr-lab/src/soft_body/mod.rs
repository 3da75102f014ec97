//! The alternative a game developer would try first: make the elastic object a rapier FEM soft
//! body (`rapier3d_f64` with its `fem` feature: `SoftBodySolver::Fem`, implicit Euler
//! `(M + h D + h² K) Δv = b` per substep, two-way coupled with the rigid bodies through rapier's
//! own solver) instead of a rigid body with dcr's distant response — and what that costs and
//! shows, side by side with dcr on the same scene.
//!
//! - [`tet_soft_body()`]: a soft body from the baker's tetrahedral mesh, material, fixed groups and
//!   Rayleigh damping;
//! - [`run_soft_scene`]: a scene run with its elastic objects as soft bodies, the rest of the
//!   world as `dcr-scenes run` builds it, the same outcome figures;
//! - [`run_side`], [`sweep_substeps`], [`render_markdown`]: the comparison rows (rapier-FEM at
//!   increasing substeps, dcr with 20 modes and with the ★ table, no response), each an
//!   ensemble of runs with the projectile moved 0.1 mm ([`EnsembleParams`]: the outcomes are
//!   chaotic, so a row reports their mean ± standard deviation and the sweep converges within
//!   the ensemble's noise), and their table (`dcr-lab soft-body compare`,
//!   `scripts/soft_body_compare.sh`, docs/benchmarks.md).

mod peak_rss;
mod side_by_side;
mod side_report;
mod soft_scene;
mod tet_soft_body;

pub use peak_rss::peak_rss_bytes;
pub use side_by_side::{
    outcome_change, run_side, sweep_substeps, with_projectiles_advanced, with_transfer_region,
    within_noise, EnsembleParams, SideMethod, SideRow, SweepEnd, SweepParams,
};
pub use side_report::{render_markdown, SceneComparison};
pub use soft_scene::{run_soft_scene, SoftObjectInfo, SoftRunReport, SoftSceneParams};
pub use tet_soft_body::{tet_soft_body, tet_soft_body_from_file, TetSoftBody, TetSoftBodyDesc};
