//! dcr for **rapier3d-f64**: [`DcrRapier`] and [`DcrSolverHooks`] over `rapier3d_f64`.
//!
//! The same source as [`crate::f32`], built against `rapier3d_f64` with [`Real`] = `f64`.

pub use rapier3d_f64 as rapier;

/// rapier's scalar in this module (`f64`).
pub type Real = f64;

/// A rapier scalar as `f64` (exact).
#[inline]
fn to_f64(x: Real) -> f64 {
    x
}

/// An `f64` as a rapier scalar (exact).
#[inline]
fn from_f64(x: f64) -> Real {
    x
}

#[path = "backend/mod.rs"]
mod backend;

pub use backend::*;
