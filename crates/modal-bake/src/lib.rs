//! `modal-bake`: a tetrahedral mesh in, a validated `.modes` base out (paper §4.1).
//!
//! Pipeline, one module per stage:
//! [`mesh`] (read MSH 2.2/4.1 and meshio JSON) → [`fem`] (assemble P1 stiffness K and mass M)
//! → [`eigen`] (shift-invert block Lanczos for K u = λ M u) → [`bake`] (boundary conditions,
//! rigid-mode exclusion, surface extraction, write through [`dcr_runtime::format`]).
//! [`transfer`]: the optional bake-time peak-transfer table. [`full_order`]: the full-order
//! reference kernel (Newmark, sum over every mode) that tables and bases are measured against;
//! the `dcr-lab` crate builds its evaluation tools on it.

pub mod args;
pub mod bake;
pub mod eigen;
pub mod export;
pub mod fem;
pub mod full_order;
pub mod mesh;
pub mod ordering;
pub mod signals;
pub mod target_error;
pub mod transfer;

// The unit tests' program draws METIS's random numbers from the same generator as the tools
// (`ordering::c_rand`), so their orders are the tools' on every platform.
#[cfg(test)]
c_rand_symbols!();
