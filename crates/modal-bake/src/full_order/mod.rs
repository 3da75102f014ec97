//! The full-order reference kernel: the exact linear response of a meshed object to an impulse,
//! on every dof of the mesh (paper Eq. 5, M ü + D u̇ + K u = f, D = α0 M + α1 K).
//!
//! This is what truncated bases and transfer tables are measured against — by the baker itself
//! (the transfer table's dense mode set, the accuracy target of a bake) and by the `dcr-lab`
//! crate (the `truth` and `fit-attenuation` tools, the accuracy report), which drive this kernel
//! rather than a copy of it.
//!
//! - [`FullOrderSystem`]: K (N/m) and M (kg) on the free dofs, the boundary surface
//!   ([`SurfaceMap`]), load vectors (Eq. 9, `H_cᵀ n λ`) and normal-displacement rows (Eq. 11),
//!   and the M-orthogonal projector that removes rigid-body motion of free-free objects.
//! - [`newmark_peaks`]: implicit Newmark average acceleration (β = ¼, γ = ½), one sparse
//!   Cholesky of K_eff and one back-solve per step; exact impulse initial state.
//! - [`ModalAll`]: dense generalized eigensolve of every mode (small meshes) and the exact damped
//!   impulse response of each mode in every damping regime (ξ < 1, = 1, > 1).
//! - [`converged_peaks`]: either solver with its step halved until the peaks change by less
//!   than a tolerance (0.5 % by default), reporting the step reached and the estimated error.

mod convergence;
mod full_order_system;
mod modal_all;
mod newmark;
mod surface_map;

pub use convergence::{
    converged_peaks, ConvergedPeaks, PeakSolver, PeakWindow, RefineParams, RefineProgress,
    Refinement,
};
pub use full_order_system::FullOrderSystem;
pub use modal_all::{ModalAll, ModalInput};
pub use newmark::{newmark_peaks, newmark_peaks_multi, newmark_run, NewmarkInfo};
pub use surface_map::SurfaceMap;

pub use dcr_runtime::format::MaterialSi;

use crate::mesh::MeshError;

/// The object a full-order system is built for (SI units).
#[derive(Clone, Debug, PartialEq)]
pub struct SystemParams {
    /// Isotropic material (E in Pa, ν, ρ in kg/m³). Default: 1.1 GPa, 0.3, 770 (as a bake).
    pub material: MaterialSi,
    /// Names of physical groups whose nodes are fixed (empty, with the other selectors empty:
    /// free-free).
    pub fixed: Vec<String>,
    /// Fix every node whose coordinate `axis` is ≤ `value` (m, mesh frame); a bake's
    /// `fixed_below`. Default none.
    pub fixed_below: Vec<crate::bake::FixedBelow>,
    /// Fix every node inside an axis-aligned box `[x0, y0, z0, x1, y1, z1]` (m, mesh frame,
    /// bounds included); a bake's `fixed_boxes`. Default none.
    pub fixed_boxes: Vec<[f64; 6]>,
    /// Fix every node near given points and triangles (m, mesh frame); a bake's `fixed_near`.
    /// Default none.
    pub fixed_near: Vec<crate::bake::FixedNear>,
    /// Rayleigh damping [α0 (1/s), α1 (s)]. Default (10, 1e-7), as a bake.
    pub rayleigh: [f64; 2],
    /// Lumped (diagonal) mass instead of consistent mass. Default false.
    pub lumped: bool,
}

impl Default for SystemParams {
    fn default() -> Self {
        SystemParams {
            material: MaterialSi {
                youngs: 1.1e9,
                poisson: 0.3,
                density: 770.0,
            },
            fixed: Vec::new(),
            fixed_below: Vec::new(),
            fixed_boxes: Vec::new(),
            fixed_near: Vec::new(),
            rayleigh: [10.0, 1e-7],
            lumped: false,
        }
    }
}

impl SystemParams {
    /// The object a bake with `params` describes: its material, every fixed-node selector,
    /// Rayleigh damping and mass lumping (the full-order system of that bake's base).
    pub fn of_bake(params: &crate::bake::BakeParams) -> SystemParams {
        SystemParams {
            material: params.material,
            fixed: params.fixed.clone(),
            fixed_below: params.fixed_below.clone(),
            fixed_boxes: params.fixed_boxes.clone(),
            fixed_near: params.fixed_near.clone(),
            rayleigh: params.rayleigh,
            lumped: params.lumped,
        }
    }

    /// The bake of this object keeping `modes` (every other bake parameter at its default):
    /// the inverse of [`SystemParams::of_bake`].
    pub fn bake_params(&self, modes: crate::bake::ModeRequest) -> crate::bake::BakeParams {
        crate::bake::BakeParams {
            material: self.material,
            modes,
            fixed: self.fixed.clone(),
            fixed_below: self.fixed_below.clone(),
            fixed_boxes: self.fixed_boxes.clone(),
            fixed_near: self.fixed_near.clone(),
            rayleigh: self.rayleigh,
            lumped: self.lumped,
            ..Default::default()
        }
    }

    /// The fixed-node selectors (`fixed`, `fixed_below`, `fixed_boxes`, `fixed_near`),
    /// borrowed: the same selection as a bake with these parameters.
    pub fn fixed_selectors(&self) -> crate::bake::FixedSelectors<'_> {
        crate::bake::FixedSelectors {
            groups: &self.fixed,
            below: &self.fixed_below,
            boxes: &self.fixed_boxes,
            near: &self.fixed_near,
        }
    }
}

/// Why a full-order system or solve failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FullOrderError {
    /// The mesh could not be read or is invalid.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Invalid parameters or inputs (the message names which).
    #[error("{0}")]
    Params(String),
    /// A sparse Cholesky factorization failed.
    #[error("factorization failed: {0}")]
    Factorization(String),
    /// The dense eigensolve failed.
    #[error("dense all-mode eigensolve failed: {0}")]
    Eigen(String),
    /// Too many dofs for the dense all-mode solve.
    #[error("the dense all-mode eigensolve needs {dofs} free dofs, above the limit {max} (use the Newmark method)")]
    TooLarge {
        /// Free dofs.
        dofs: usize,
        /// Limit.
        max: usize,
    },
}
