//! The world-level engine contract: elastic objects by handle, world-frame contact reports in,
//! impulse events out (paper §4.2–4.5, Eq. 17–18), for any rigid-body engine.
//!
//! [`DcrWorld`] owns what every integration would otherwise re-write: telling impacts from
//! resting contacts, converting frames, turning velocity changes into impulses with one
//! Gauss–Seidel pass per body, chaining responses through dynamic elastic objects in the same
//! step, counting cache eviction in steps, and bounding the injected energy. Its boundary is
//! plain data (`[f64; 3]`, `u64` ids, slices; the per-step types are `#[repr(C)]`), so any
//! engine's math types convert cheaply.
//! See [`DcrWorld`] for the rules and their reasons.

mod base_support;
mod body_state;
mod contact_report;
mod dcr_world;
mod elastic_handle;
mod elastic_object_desc;
mod impulse_event;
mod pose;
mod world_error;
mod world_info;
mod world_params;

pub use base_support::BaseSupport;
pub use body_state::BodyState;
pub use contact_report::ContactReport;
pub use dcr_world::DcrWorld;
pub use elastic_handle::ElasticHandle;
pub use elastic_object_desc::ElasticObjectDesc;
pub use impulse_event::ImpulseEvent;
pub use pose::Pose;
pub use world_error::WorldError;
pub use world_info::{EnergyInfo, ObjectStepInfo, ObjectTotals, WorldStepInfo};
pub use world_params::{ClassifyParams, WorldParams};
