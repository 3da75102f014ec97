//! `dcr-rapier`: the distant collision response (Distant Collision Response in Rigid Body
//! Simulations, CGF 2020) for rapier apps, as a thin translation of rapier's contacts into
//! [`dcr_runtime::DcrWorld`]'s plain data and of its impulse events back into rapier.
//!
//! Two backends, built side by side from one source tree (cargo features `f32` and `f64`, both
//! on by default):
//! - [`mod@f32`] for `rapier3d` (f32, what bevy_rapier uses);
//! - [`mod@f64`] for `rapier3d-f64`.
//!
//! Each offers [`f64::DcrRapier`] (read contacts after the step, step the world, apply its
//! events), the two application paths of the paper (§3 and §4.5, [`f64::ApplyMode`]: explicit
//! impulses after the step, Eq. 17–18, the default; or a replay through the next step's contact
//! solver with [`f64::DcrSolverHooks`]) and the id conversions. The world API types are
//! re-exported here. See docs/engine-integration.md for a step-by-step integration into a
//! rapier or bevy_rapier app.

// `f32` and `f64` each compile the one backend source tree (`src/backend/`) against their
// own rapier crate: the module is loaded twice on purpose.
#![allow(clippy::duplicate_mod)]

#[cfg(feature = "f32")]
pub mod f32;
#[cfg(feature = "f64")]
pub mod f64;

/// docs/engine-integration.md, compiled: its Rust snippets run as this crate's doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/engine-integration.md")]
pub struct EngineIntegrationGuide;

pub use dcr_runtime;
pub use dcr_runtime::{
    BodyState, ContactReport, DcrWorld, ElasticHandle, ElasticObjectDesc, ImpulseEvent, ModalModel,
    Pose, ResponseParams, WorldError, WorldParams,
};
