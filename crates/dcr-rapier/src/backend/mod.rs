//! The rapier adapter, written once and compiled once per precision (`crate::f32`,
//! `crate::f64`): each parent module names its rapier crate `rapier`, its scalar `Real` and the
//! two conversions to and from the world API's `f64`.
//!
//! - [`DcrRapier`] reads rapier's contacts after `step()` into the world API's plain data
//!   (world frame, stable contact ids, this step's normal impulses), reads the touching bodies'
//!   inverse mass, world inverse inertia, centre of mass and velocities, runs
//!   [`dcr_runtime::DcrWorld::step`], and applies the returned impulse events — after the step
//!   (Eq. 17–18, [`ApplyMode::AfterStep`]) or through the solver of the next step
//!   ([`ApplyMode::InSolver`] with [`DcrSolverHooks`]).
//! - [`contact_id`], [`body_id`], [`body_handle`]: rapier handles ↔ the world's `u64` ids.

use super::{from_f64, rapier, to_f64};

mod apply_mode;
mod body_reader;
mod contact_id;
mod contact_reader;
mod dcr_rapier;
mod solver_hooks;
mod step_gate;

pub use apply_mode::ApplyMode;
pub use contact_id::{body_handle, body_id, collider_pair_key, contact_id, NO_BODY};
pub use dcr_rapier::{AdapterError, AdapterParams, AdapterStepInfo, DcrRapier};
pub use solver_hooks::DcrSolverHooks;
pub use step_gate::StepGate;

/// A rapier vector as the world API's `[f64; 3]`.
#[inline]
fn arr(v: rapier::math::Vector) -> [f64; 3] {
    [to_f64(v.x), to_f64(v.y), to_f64(v.z)]
}

/// A world API `[f64; 3]` as a rapier vector.
#[inline]
fn vector(a: [f64; 3]) -> rapier::math::Vector {
    rapier::math::Vector::new(from_f64(a[0]), from_f64(a[1]), from_f64(a[2]))
}
