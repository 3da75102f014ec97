//! [`StepCtx`]: what every method's step reads and writes — the model, the parameters, the
//! step's mapped resting contacts, the counters and the output buffer.

use super::{ContactResponse, ContactSet, ResponseParams, RestingContact, ServedBy, StepInfo};
use crate::model::{ModalModel, SurfacePoint};

/// One step's shared state, lent by [`super::DistantResponse`] to the method serving it.
pub(crate) struct StepCtx<'a> {
    pub model: &'a ModalModel,
    pub params: &'a ResponseParams,
    /// Mapping distance in use (m).
    pub max_map: f64,
    /// The step's resting contacts, mapped (slot per contact, in call order).
    pub contacts: &'a ContactSet,
    /// The response's step index (steps, for caches).
    pub step: u64,
    pub info: &'a mut StepInfo,
    /// One response per resting contact, in call order (the method fills it).
    pub out: &'a mut Vec<ContactResponse>,
}

impl StepCtx<'_> {
    /// Whether an impact of `impulse` (N·s) is applied: finite, > 0 and ≥ the threshold.
    pub fn applies(&self, impulse: f64) -> bool {
        impulse.is_finite() && impulse > 0.0 && impulse >= self.params.impact_threshold
    }

    /// Whether an impact of `impulse` (N·s) is applied: finite, > 0 and ≥ the threshold;
    /// counts it in `impacts_below_threshold` otherwise.
    pub fn accept(&mut self, impulse: f64) -> bool {
        let ok = self.applies(impulse);
        if !ok {
            self.info.impacts_below_threshold += 1;
        }
        ok
    }
}

/// The response of a mapped contact: peak normal displacement `d` (m) over the step `h` (s),
/// Δv = d/h (Eq. 12), at the contact's surface point and normal (object frame).
pub(crate) fn mapped_response(
    rc: &RestingContact,
    sp: &SurfacePoint,
    d: f64,
    h: f64,
    served_by: ServedBy,
) -> ContactResponse {
    ContactResponse {
        id: rc.id,
        point: sp.point,
        normal: sp.normal,
        peak_displacement: d,
        delta_v: d / h,
        lateral_delta_v: [0.0; 3],
        mapped: true,
        served_by,
    }
}

/// The zero response of a contact farther than the mapping distance.
pub(crate) fn unmapped_response(rc: &RestingContact) -> ContactResponse {
    ContactResponse {
        id: rc.id,
        point: rc.point,
        normal: [0.0; 3],
        peak_displacement: 0.0,
        delta_v: 0.0,
        lateral_delta_v: [0.0; 3],
        mapped: false,
        served_by: ServedBy::Unmapped,
    }
}
