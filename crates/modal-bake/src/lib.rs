//! `modal-bake`: a tetrahedral mesh in, a validated `.modes` base out (paper §4.1).
//!
//! Pipeline, one module per stage:
//! [`mesh`] (read MSH 2.2/4.1 and meshio JSON) → [`fem`] (assemble P1 stiffness K and mass M)
//! → [`eigen`] (shift-invert block Lanczos for K u = λ M u) → [`bake`] (boundary conditions,
//! rigid-mode exclusion, surface extraction, write through [`dcr_runtime::format`]).
//! [`truth`]: the full-order reference response (Newmark, sum over all modes) that bases are
//! measured against.

pub mod bake;
pub mod eigen;
pub mod export;
pub mod fem;
pub mod mesh;
pub mod signals;
pub mod transfer;
pub mod truth;
