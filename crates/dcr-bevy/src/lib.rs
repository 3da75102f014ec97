//! `dcr-bevy`: the distant collision response (Distant Collision Response in Rigid Body
//! Simulations, CGF 2020) as a Bevy plugin over bevy_rapier3d.
//!
//! An entity with a bevy_rapier `RigidBody` (fixed or dynamic), its colliders and a
//! [`DcrElastic`] component (a handle to a baked `.modes` base, loaded by [`ModesLoader`]) is an
//! elastic object: an impact on it pushes the bodies resting elsewhere on it (paper §4). The
//! plugin runs `dcr-rapier`'s rapier3d (f32) adapter around bevy_rapier's step in
//! `FixedUpdate`:
//!
//! ```text
//! FixedUpdate: PhysicsSet::SyncBackend → DcrSet::BeforeStep → PhysicsSet::StepSimulation
//!              → DcrSet::AfterStep → PhysicsSet::Writeback
//! ```
//!
//! - [`DcrSet::BeforeStep`] adds the elastic objects whose base has loaded and whose rapier
//!   body exists ([`DcrObject`] on success, [`DcrElasticFailed`] with the reason otherwise);
//! - [`DcrSet::AfterStep`] checks that rapier made exactly one step of the world's `h` since
//!   [`DcrSet::BeforeStep`] (else it refuses and says why: [`DcrStatus`], [`DcrRefusal`]),
//!   reads the elastic objects' contacts, steps the world and applies its impulses to the
//!   rapier bodies **before bevy_rapier's writeback**, so the `Velocity` components receive
//!   them (an impulse applied after the writeback would be overwritten by the component at the
//!   next step), and writes one [`DcrResponse`] message per impulse.
//!
//! bevy_rapier3d 0.37 and `dcr_rapier::f32` wrap the same rapier3d (0.36): the plugin works on
//! bevy_rapier's own rapier sets. The world's counters are in [`DcrContext`]. See
//! docs/engine-integration.md ("Bevy") and `examples/dinner.rs`.

mod adapter;
mod dcr_elastic;
mod dcr_response;
mod dcr_status;
mod modes_asset;
mod plugin;
mod systems;

pub use adapter::DcrContext;
pub use dcr_elastic::{DcrElastic, DcrElasticFailed, DcrObject};
pub use dcr_response::DcrResponse;
pub use dcr_status::{DcrRefusal, DcrStatus};
pub use modes_asset::{ModesAsset, ModesLoader, ModesLoaderError};
pub use plugin::{DcrPlugin, DcrPluginError, DcrSet};

pub use dcr_rapier;
