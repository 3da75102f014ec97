//! `dcr-runtime`: distant collision response for rigid-body engines (paper §4.2–4.5).
//!
//! Load a baked `.modes` base once ([`mod@format`], [`ModalModel`]), share it between instances, and
//! per simulation step answer: "these impacts happened; which impulses go to which resting
//! contacts?" ([`DistantResponse`]).
//!
//! Pipeline, one module per stage:
//! [`model`] (validated base, vertex normals, surface BVH) → [`mapping`] (impacts and resting
//! contacts onto the surface, per-contact cache) → [`filter`] (exact modal IIR filters, Eq. 10)
//! or [`attenuation`] (spatial attenuation over heat-method geodesics, Eq. 14–16) →
//! [`response`] (peak displacement, Δv, Eq. 11–13, and impulses, Eq. 17–19).
//!
//! Frames and units: everything is in the base's object frame, SI units (m, s, N·s);
//! engine-boundary types are plain `[f64; 3]` data.

pub mod attenuation;
pub mod filter;
pub mod format;
pub mod mapping;
mod math;
pub mod model;
pub mod response;
pub mod testing;
pub mod world;

pub use attenuation::{
    AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind, GeodesicError, HeatGeodesic,
    HeatWorkspace,
};
pub use filter::{damping_ratio, samples_per_step, ModalBank, ModeFilter, Sampling};
pub use model::{LoadError, ModalModel, SurfacePoint};
pub use response::{
    effective_mass, peak_abs_projection, peak_abs_rows, response_impulse, ContactResponse,
    DistantResponse, ForceInput, Impact, Method, ParamsError, ResponseParams, RestingContact,
    ServedBy, StepInfo, TableFallback, TablePolicy, TableStatus, Variant,
};
pub use world::{
    BodyState, ClassifyParams, ContactReport, DcrWorld, ElasticHandle, ElasticObjectDesc,
    EnergyInfo, ImpulseEvent, ObjectStepInfo, Pose, WorldError, WorldParams, WorldStepInfo,
};
