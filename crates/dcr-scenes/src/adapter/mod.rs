//! The rapier ↔ distant-collision-response adapter (paper §4.5, Eq. 17–19).
//!
//! After each `PhysicsWorld::step`, for every elastic object: read the solver manifolds of
//! its contact pairs, split the contact points into new impacts and resting contacts,
//! express them in the object's frame, query [`dcr_runtime::DistantResponse`], and apply
//! the returned Δv at the resting contacts as impulses (effective mass, Eq. 17–18).
//! See docs/scenes.md for the one-step-lag choice.

mod contact_key;
mod dcr_adapter;
pub mod engine;

pub use contact_key::contact_key;
pub use dcr_adapter::{AdapterParams, DcrAdapter, ModelStats, ResponseEvent, StepStats};
