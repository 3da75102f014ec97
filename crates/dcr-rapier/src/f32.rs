//! dcr for **rapier3d** (f32, what bevy_rapier uses): [`DcrRapier`] and [`DcrSolverHooks`]
//! over `rapier3d`.
//!
//! The same source as [`crate::f64`], built against `rapier3d` with [`Real`] = `f32`. The
//! world API works in `f64`; contact data is widened on the way in and impulses rounded to
//! `f32` on the way out.

pub use rapier3d as rapier;

/// rapier's scalar in this module (`f32`).
pub type Real = f32;

/// A rapier scalar as `f64` (exact).
#[inline]
fn to_f64(x: Real) -> f64 {
    f64::from(x)
}

/// An `f64` as a rapier scalar (rounded to nearest).
#[inline]
fn from_f64(x: f64) -> Real {
    x as f32
}

#[path = "backend/mod.rs"]
mod backend;

pub use backend::*;
