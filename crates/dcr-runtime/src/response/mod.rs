//! The per-object distant response (paper §4.2–4.5): impacts in, per-resting-contact peak normal
//! displacement and velocity change out (Eq. 9–13 modal, Eq. 14–16 attenuation), and the
//! impulse conversion of Eq. 17–19.

mod attenuation_response;
mod contact_response;
mod contact_set;
mod distant_response;
mod effective_mass;
mod force_input;
mod impact;
mod impulse_table;
mod lateral_kick;
mod modal_response;
mod peak_kernel;
mod response_params;
mod resting_contact;
mod step_ctx;
mod step_info;
mod transfer_response;

pub use contact_response::{ContactResponse, ServedBy};
pub(crate) use contact_set::ContactSet;
pub use distant_response::DistantResponse;
pub use effective_mass::{effective_mass, inverse_effective_mass, response_impulse};
pub use force_input::ForceInput;
pub use impact::Impact;
#[cfg(feature = "bench-internals")]
pub use peak_kernel::{peak_abs_projection, peak_abs_rows};
pub use response_params::{
    Launch, Method, ParamsError, ResponseParams, TablePolicy, TableStatus, Variant,
};
pub use resting_contact::RestingContact;
pub use step_info::{StepInfo, TableFallback};

/// Resting contacts per object that the buffers of a response ([`DistantResponse::new`]) and
/// of the world's objects are sized for at set-up: the first steps with up to this many
/// contacts neither allocate nor touch fresh memory; more grow the buffers on first sight (a
/// step does not allocate after that warm-up).
pub const PREPARED_CONTACTS: usize = 64;

/// An empty vector with room for `n` elements whose memory has been written once (with
/// `fill`): set-up pays the allocation and the first touch of its pages, not the first step.
pub(crate) fn prepared_vec<T: Clone>(n: usize, fill: T) -> Vec<T> {
    let mut v = Vec::with_capacity(n);
    v.resize(n, fill);
    v.clear();
    v
}

// The knobs of the attenuation method and of filter sampling, beside the other response
// settings (their home modules define them).
pub use crate::attenuation::{AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind};
pub use crate::filter::Sampling;

#[cfg(test)]
mod tests;
