//! The response engine the adapter talks to: `dcr_runtime`'s public surface, re-exported
//! in one place so the rest of the crate names one module.

pub use dcr_runtime::{
    effective_mass, response_impulse, AmplitudeKind, AttenuationLaw, AttenuationParams,
    ContactResponse, DistanceKind, DistantResponse, Impact, Method, ModalModel, ResponseParams,
    RestingContact,
};
