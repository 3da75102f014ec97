//! [`DcrResponse`]: one elastic object's per-step distant response (paper §4.2–4.5), object
//! frame: impacts and resting contacts in, per-contact Δv and peak displacement out.

use std::mem::{align_of, offset_of, size_of};
use std::sync::Arc;

use dcr_runtime::response::{
    ContactResponse, Impact, RestingContact, ServedBy, StepInfo, TableFallback, TableStatus,
};
use dcr_runtime::DistantResponse;

use crate::guard::guard;
use crate::model::DcrModel;
use crate::ptr::{arg_mut, arg_ref, arg_slice, check_len, check_ptr, write_out};
use crate::response_params::DcrResponseParams;
use crate::status::{DcrStatus, Failure};

/// One elastic object instance's distant response (opaque): its filters, contact cache and
/// output buffers. Created by `dcr_response_create`, released by `dcr_response_free`. Used by
/// one thread at a time.
#[derive(Debug)]
pub struct DcrResponse {
    pub(crate) response: DistantResponse,
    impacts: Vec<Impact>,
    resting: Vec<RestingContact>,
}

/// A new collision on the object this step (object frame).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrImpact {
    /// Contact point (m, object frame); mapped to the nearest surface point.
    pub point: [f64; 3],
    /// Unit direction in which the impulse acts ON THIS OBJECT (object frame); usually the
    /// inward normal, −normal.
    pub direction: [f64; 3],
    /// Impulse magnitude λ (N·s, ≥ 0); below `DcrResponseParams.impact_threshold` it is
    /// ignored.
    pub impulse: f64,
}

/// An existing (resting) contact of another body on the object (object frame).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrRestingContact {
    /// The caller's stable id of the contact (its mapping is cached under it).
    pub id: u64,
    /// Contact point (m, object frame).
    pub point: [f64; 3],
}

/// What served one contact's response (`DcrContactResponse.served_by`,
/// `DcrImpulseEvent.served_by`): one of `DCR_SERVED_BY_*`.
pub type DcrServedBy = u8;
/// The truncated modal base (Eq. 9–13).
pub const DCR_SERVED_BY_MODAL: DcrServedBy = 0;
/// Spatial attenuation (Eq. 14–16).
pub const DCR_SERVED_BY_ATTENUATION: DcrServedBy = 1;
/// The base's bake-time peak-transfer table.
pub const DCR_SERVED_BY_TRANSFER_TABLE: DcrServedBy = 2;
/// Not mapped to the surface (farther than the mapping distance): zero response.
pub const DCR_SERVED_BY_UNMAPPED: DcrServedBy = 3;

pub(crate) fn served_by_code(s: ServedBy) -> DcrServedBy {
    match s {
        ServedBy::Modal => DCR_SERVED_BY_MODAL,
        ServedBy::Attenuation => DCR_SERVED_BY_ATTENUATION,
        ServedBy::TransferTable => DCR_SERVED_BY_TRANSFER_TABLE,
        ServedBy::Unmapped => DCR_SERVED_BY_UNMAPPED,
    }
}

/// The distant response at one resting contact for the step (object frame).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrContactResponse {
    /// The resting contact's id.
    pub id: u64,
    /// Mapped surface point (m, object frame); the query point when not mapped.
    pub point: [f64; 3],
    /// Outward unit surface normal (object frame): the resting body is pushed along +normal.
    /// Zero when not mapped.
    pub normal: [f64; 3],
    /// Peak normal displacement over the step (m; Eq. 11 / 13, or Eq. 15 × s(r)).
    pub peak_displacement: f64,
    /// Velocity change along +normal (m/s; Eq. 12 / 13 / 16): `peak_displacement / h`. Turn
    /// it into an impulse with `dcr_effective_mass` and `dcr_response_impulse` (Eq. 17–18),
    /// after rotating `normal` to the world frame.
    pub delta_v: f64,
    /// Tangential velocity change (m/s, object frame, ⟂ normal): the lateral kick (§5.4); zero
    /// unless `DcrResponseParams.lateral_kick`.
    pub lateral_delta_v: [f64; 3],
    /// Which method produced the response, `DCR_SERVED_BY_*`.
    pub served_by: DcrServedBy,
    /// false: the contact is farther than the mapping distance from the surface (zero
    /// response).
    pub mapped: bool,
}

/// Why a transfer-table response fell back to the modal method in a step
/// (`DcrStepInfo.table_fallback`): one of `DCR_TABLE_FALLBACK_*`.
pub type DcrTableFallback = u32;
/// The table served every contact, or was not requested.
pub const DCR_TABLE_FALLBACK_NONE: DcrTableFallback = 0;
/// The table does not apply to this response at all (see `DcrResponseInfo.table_status`).
pub const DCR_TABLE_FALLBACK_UNAVAILABLE: DcrTableFallback = 1;
/// The step had a force input (the table holds impulse responses only).
pub const DCR_TABLE_FALLBACK_FORCES: DcrTableFallback = 2;
/// An applied impact lies outside the table's region: every contact was modal.
pub const DCR_TABLE_FALLBACK_IMPACT_OUTSIDE_REGION: DcrTableFallback = 3;
/// Some resting contacts lie outside the table's region: those were modal.
pub const DCR_TABLE_FALLBACK_CONTACTS_OUTSIDE_REGION: DcrTableFallback = 4;

/// Counters of a response's last step (`dcr_response_step_info`, `DcrObjectStepInfo`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrStepInfo {
    /// Impacts applied (impulse ≥ threshold, mapped).
    pub impacts_applied: u32,
    /// Impacts ignored: impulse below the threshold or not finite.
    pub impacts_below_threshold: u32,
    /// Impacts ignored: farther than the mapping distance from the surface.
    pub impacts_unmapped: u32,
    /// Resting contacts mapped (or re-mapped) this step: cache misses.
    pub contacts_mapped_now: u32,
    /// Resting contacts beyond the mapping distance (zero response).
    pub contacts_unmapped: u32,
    /// Heat-method distance fields computed this step (attenuation cache misses).
    pub distance_fields_computed: u32,
    /// Resting contacts served by the transfer table.
    pub contacts_by_table: u32,
    /// Resting contacts a transfer-table response served with the modal method instead.
    pub contacts_table_fallback: u32,
    /// Why, `DCR_TABLE_FALLBACK_*`.
    pub table_fallback: DcrTableFallback,
    /// The filter bank was asleep (carry-over): no work, zero output.
    pub asleep: bool,
}

pub(crate) fn step_info(s: &StepInfo) -> DcrStepInfo {
    DcrStepInfo {
        impacts_applied: s.impacts_applied,
        impacts_below_threshold: s.impacts_below_threshold,
        impacts_unmapped: s.impacts_unmapped,
        contacts_mapped_now: s.contacts_mapped_now,
        contacts_unmapped: s.contacts_unmapped,
        distance_fields_computed: s.distance_fields_computed,
        contacts_by_table: s.contacts_by_table,
        contacts_table_fallback: s.contacts_table_fallback,
        table_fallback: match s.table_fallback {
            None => DCR_TABLE_FALLBACK_NONE,
            Some(TableFallback::Unavailable) => DCR_TABLE_FALLBACK_UNAVAILABLE,
            Some(TableFallback::Forces) => DCR_TABLE_FALLBACK_FORCES,
            Some(TableFallback::ImpactOutsideRegion) => DCR_TABLE_FALLBACK_IMPACT_OUTSIDE_REGION,
            Some(TableFallback::ContactsOutsideRegion) => {
                DCR_TABLE_FALLBACK_CONTACTS_OUTSIDE_REGION
            }
        },
        asleep: s.asleep,
    }
}

/// Whether a response's transfer table is in use, and if not why
/// (`DcrResponseInfo.table_status`): one of `DCR_TABLE_STATUS_*`.
pub type DcrTableStatus = u32;
/// The table serves the steps (contacts and impacts inside its region).
pub const DCR_TABLE_STATUS_ACTIVE: DcrTableStatus = 0;
/// The method is not `DCR_METHOD_TRANSFER`.
pub const DCR_TABLE_STATUS_NOT_REQUESTED: DcrTableStatus = 1;
/// The base has no transfer table: the modal method serves.
pub const DCR_TABLE_STATUS_NO_TABLE: DcrTableStatus = 2;
/// The table was baked for another rigid-body step h.
pub const DCR_TABLE_STATUS_STEP_MISMATCH: DcrTableStatus = 3;
/// The table was baked with other Rayleigh damping.
pub const DCR_TABLE_STATUS_DAMPING_MISMATCH: DcrTableStatus = 4;
/// `carry_over` is on; the table assumes filters at rest at each step's start.
pub const DCR_TABLE_STATUS_CARRY_OVER: DcrTableStatus = 5;

/// Set-up facts of a response (`dcr_response_info`, `dcr_world_object_response_info`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrResponseInfo {
    /// Filter samples per rigid-body step S = ⌈h / T⌉.
    pub samples_per_step: usize,
    /// Effective filter period h / S (s).
    pub substep: f64,
    /// Mapping distance in use (m).
    pub max_map_distance: f64,
    /// Whether the transfer table serves, `DCR_TABLE_STATUS_*`.
    pub table_status: DcrTableStatus,
    /// Resting contacts currently cached.
    pub cached_contacts: usize,
}

pub(crate) fn response_info(r: &DistantResponse) -> DcrResponseInfo {
    DcrResponseInfo {
        samples_per_step: r.samples_per_step(),
        substep: r.substep(),
        max_map_distance: r.max_map_distance(),
        table_status: match r.table_status() {
            TableStatus::Active => DCR_TABLE_STATUS_ACTIVE,
            TableStatus::NotRequested => DCR_TABLE_STATUS_NOT_REQUESTED,
            TableStatus::NoTable => DCR_TABLE_STATUS_NO_TABLE,
            TableStatus::StepMismatch { .. } => DCR_TABLE_STATUS_STEP_MISMATCH,
            TableStatus::DampingMismatch { .. } => DCR_TABLE_STATUS_DAMPING_MISMATCH,
            TableStatus::CarryOver => DCR_TABLE_STATUS_CARRY_OVER,
        },
        cached_contacts: r.cached_contacts(),
    }
}

fn contact_response(c: &ContactResponse) -> DcrContactResponse {
    DcrContactResponse {
        id: c.id,
        point: c.point,
        normal: c.normal,
        peak_displacement: c.peak_displacement,
        delta_v: c.delta_v,
        lateral_delta_v: c.lateral_delta_v,
        served_by: served_by_code(c.served_by),
        mapped: c.mapped,
    }
}

/// `DcrImpact` has `Impact`'s layout: impacts pass to the runtime without a copy.
const IMPACT_ZERO_COPY: bool = size_of::<Impact>() == size_of::<DcrImpact>()
    && align_of::<Impact>() == align_of::<DcrImpact>()
    && offset_of!(Impact, point) == offset_of!(DcrImpact, point)
    && offset_of!(Impact, direction) == offset_of!(DcrImpact, direction)
    && offset_of!(Impact, impulse) == offset_of!(DcrImpact, impulse);

/// `DcrRestingContact` has `RestingContact`'s layout.
const RESTING_ZERO_COPY: bool = size_of::<RestingContact>() == size_of::<DcrRestingContact>()
    && align_of::<RestingContact>() == align_of::<DcrRestingContact>()
    && offset_of!(RestingContact, id) == offset_of!(DcrRestingContact, id)
    && offset_of!(RestingContact, point) == offset_of!(DcrRestingContact, point);

/// `ContactResponse` has `DcrContactResponse`'s layout (and `ServedBy`'s discriminants are the
/// `DCR_SERVED_BY_*` codes): responses are copied out as whole structs, without conversion.
const RESPONSE_ZERO_COPY: bool = size_of::<ContactResponse>() == size_of::<DcrContactResponse>()
    && align_of::<ContactResponse>() == align_of::<DcrContactResponse>()
    && offset_of!(ContactResponse, id) == offset_of!(DcrContactResponse, id)
    && offset_of!(ContactResponse, point) == offset_of!(DcrContactResponse, point)
    && offset_of!(ContactResponse, normal) == offset_of!(DcrContactResponse, normal)
    && offset_of!(ContactResponse, peak_displacement)
        == offset_of!(DcrContactResponse, peak_displacement)
    && offset_of!(ContactResponse, delta_v) == offset_of!(DcrContactResponse, delta_v)
    && offset_of!(ContactResponse, lateral_delta_v)
        == offset_of!(DcrContactResponse, lateral_delta_v)
    && offset_of!(ContactResponse, served_by) == offset_of!(DcrContactResponse, served_by)
    && offset_of!(ContactResponse, mapped) == offset_of!(DcrContactResponse, mapped)
    && SERVED_BY_CODES;

/// `ServedBy` is one byte holding the `DCR_SERVED_BY_*` code of each method.
pub(crate) const SERVED_BY_CODES: bool = size_of::<ServedBy>() == size_of::<DcrServedBy>()
    && ServedBy::Modal as DcrServedBy == DCR_SERVED_BY_MODAL
    && ServedBy::Attenuation as DcrServedBy == DCR_SERVED_BY_ATTENUATION
    && ServedBy::TransferTable as DcrServedBy == DCR_SERVED_BY_TRANSFER_TABLE
    && ServedBy::Unmapped as DcrServedBy == DCR_SERVED_BY_UNMAPPED;

/// Whether the per-step conversions are copies-free: (impacts, resting contacts, responses).
/// The tests assert all three on the CI toolchain; a `false` is still correct (field-by-field
/// conversion), only slower.
pub fn zero_copy_layouts() -> (bool, bool, bool) {
    (IMPACT_ZERO_COPY, RESTING_ZERO_COPY, RESPONSE_ZERO_COPY)
}

/// Sets up a response of `model` with `params` (filters, and for attenuation the local
/// amplitudes and distance solver). On success `*out` receives a new response (free it with
/// `dcr_response_free`); on failure `*out` is set to NULL.
///
/// # Errors
/// `DCR_STATUS_INVALID_ARGUMENT` for a parameter out of range (the message names the field and
/// its value), an unknown code, a wrong `struct_size`, or a transfer table refused by
/// `DCR_TABLE_POLICY_REFUSE` (the message says why); `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `model` must be NULL or a live handle; `params` NULL or a valid `DcrResponseParams`; `out`
/// NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_create(
    model: *const DcrModel,
    params: *const DcrResponseParams,
    out: *mut *mut DcrResponse,
) -> DcrStatus {
    guard("dcr_response_create", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, std::ptr::null_mut(), "out")? };
        // SAFETY: caller contract (NULL is checked).
        let model = unsafe { &arg_ref(model, "model")?.model };
        // SAFETY: caller contract (NULL is checked); the struct size is checked first.
        let params = unsafe { read_params(params, "params")? };
        let response = DistantResponse::new(Arc::clone(model), params)
            .map_err(|e| Failure::invalid(e.to_string()))?;
        let handle = Box::into_raw(Box::new(DcrResponse {
            response,
            impacts: Vec::new(),
            resting: Vec::new(),
        }));
        // SAFETY: `out` was checked above.
        unsafe { out.write(handle) };
        Ok(())
    })
}

/// Reads a `DcrResponseParams`, checking `struct_size` before the rest.
///
/// # Safety
/// `p` must be NULL or point to a readable `DcrResponseParams` (its `struct_size` first).
pub(crate) unsafe fn read_params(
    p: *const DcrResponseParams,
    name: &str,
) -> Result<dcr_runtime::ResponseParams, Failure> {
    check_ptr(p, name)?;
    // SAFETY: non-null and aligned; `struct_size` is the first field (offset 0) of the repr(C)
    // struct, so reading a u32 there never reads past a caller's struct of another layout.
    let size = unsafe { p.cast::<u32>().read() };
    crate::ptr::check_struct_size::<DcrResponseParams>(size, name, "DcrResponseParams")?;
    let bools = [
        (
            offset_of!(DcrResponseParams, override_rayleigh),
            "override_rayleigh",
        ),
        (offset_of!(DcrResponseParams, carry_over), "carry_over"),
        (offset_of!(DcrResponseParams, lateral_kick), "lateral_kick"),
        (
            offset_of!(DcrResponseParams, attenuation)
                + offset_of!(crate::DcrAttenuationParams, parallel_heat),
            "attenuation.parallel_heat",
        ),
    ];
    // SAFETY: the caller's struct has this library's size, so every offset is inside it.
    unsafe { crate::ptr::check_bools(p, &bools, name)? };
    // SAFETY: the caller's struct has this library's size and valid bools; the rest is plain
    // data, and `runtime_params` reads `amplitude_vertices` under the documented contract.
    unsafe { (*p).runtime_params(name) }
}

/// Releases a response (NULL is a no-op).
///
/// # Safety
/// `response` must be NULL or a handle from `dcr_response_create` not freed before.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_free(response: *mut DcrResponse) {
    if response.is_null() {
        return;
    }
    let _ = std::panic::catch_unwind(|| {
        // SAFETY: a live handle from Box::into_raw (caller contract), freed once.
        drop(unsafe { Box::from_raw(response) });
    });
}

/// One rigid-body step of the response (paper §4.2–4.5): the step's new `impacts` and the
/// current `resting` contacts in (object frame), one `DcrContactResponse` per resting contact
/// out, in the same order, into the caller's `out` array of `out_capacity` entries.
///
/// `*out_count` receives `num_resting` (the required capacity) whatever the outcome. Call once
/// per rigid-body step (skipped steps: `dcr_response_skip_steps`); impacts below the
/// threshold or unmapped are counted in `dcr_response_step_info` and ignored. Does not
/// allocate after warm-up (buffers grow on first sight of more contacts).
///
/// # Errors
/// `DCR_STATUS_BUFFER_TOO_SMALL` when `out_capacity` < `num_resting`: the step did not run (no
/// state changed); call again with a large enough `out`. `DCR_STATUS_NULL_POINTER` for a NULL
/// `response` or `out_count`, or a NULL array with a non-zero count;
/// `DCR_STATUS_INVALID_ARGUMENT` for a misaligned array.
///
/// # Safety
/// `response` must be NULL or a live handle not used by another thread during the call;
/// `impacts` / `resting` must point to `num_impacts` / `num_resting` readable elements (may be
/// NULL when the count is 0); `out` must point to `out_capacity` writable elements;
/// `out_count` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_step(
    response: *mut DcrResponse,
    impacts: *const DcrImpact,
    num_impacts: usize,
    resting: *const DcrRestingContact,
    num_resting: usize,
    out: *mut DcrContactResponse,
    out_capacity: usize,
    out_count: *mut usize,
) -> DcrStatus {
    guard("dcr_response_step", || {
        // SAFETY: caller contract (NULL is checked).
        let r = unsafe { arg_mut(response, "response")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out_count, num_resting, "out_count")? };
        if out_capacity < num_resting {
            return Err(Failure::new(
                DcrStatus::BufferTooSmall,
                format!(
                    "`out_capacity` is {out_capacity} but the step has {num_resting} resting \
                     contacts (one response each); the step did not run"
                ),
            ));
        }
        // SAFETY: caller contract (counts, NULL and alignment checked).
        let impacts = unsafe { arg_slice(impacts, num_impacts, "impacts")? };
        // SAFETY: as above.
        let resting = unsafe { arg_slice(resting, num_resting, "resting")? };
        if num_resting > 0 {
            check_ptr(out, "out")?;
            check_len::<DcrContactResponse>(num_resting, "out")?;
        }
        let DcrResponse {
            response,
            impacts: impact_buf,
            resting: resting_buf,
        } = r;
        let impacts: &[Impact] = if IMPACT_ZERO_COPY {
            // SAFETY: DcrImpact and Impact have the same size, alignment and field offsets,
            // with fields of the same types (checked at compile time), all valid for any bits.
            unsafe { std::slice::from_raw_parts(impacts.as_ptr().cast(), impacts.len()) }
        } else {
            impact_buf.clear();
            impact_buf.extend(impacts.iter().map(|i| Impact {
                point: i.point,
                direction: i.direction,
                impulse: i.impulse,
            }));
            impact_buf
        };
        let resting: &[RestingContact] = if RESTING_ZERO_COPY {
            // SAFETY: as above, for DcrRestingContact and RestingContact.
            unsafe { std::slice::from_raw_parts(resting.as_ptr().cast(), resting.len()) }
        } else {
            resting_buf.clear();
            resting_buf.extend(resting.iter().map(|c| RestingContact {
                id: c.id,
                point: c.point,
            }));
            resting_buf
        };
        let results = response.step(impacts, resting);
        if RESPONSE_ZERO_COPY && !results.is_empty() {
            // SAFETY: `out` holds out_capacity ≥ num_resting = results.len() > 0 writable
            // elements (checked non-null and aligned above); ContactResponse has
            // DcrContactResponse's size, alignment and field offsets, fields of the same
            // layout, and ServedBy's discriminants are the DCR_SERVED_BY_* codes (checked at
            // compile time), so the bytes are valid DcrContactResponse values.
            unsafe {
                std::ptr::copy_nonoverlapping(
                    results.as_ptr(),
                    out.cast::<ContactResponse>(),
                    results.len(),
                )
            };
        } else {
            for (k, c) in results.iter().enumerate() {
                // SAFETY: `out` is non-null, aligned and holds out_capacity ≥ num_resting =
                // results.len() writable elements (checked above).
                unsafe { out.add(k).write(contact_response(c)) };
            }
        }
        Ok(())
    })
}

/// Counts `steps` rigid-body steps that passed without a `dcr_response_step` call: cache
/// eviction (`evict_after_steps`) is counted in steps, not calls. A caller that queries only
/// on steps with impacts reports the steps in between here.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` when `response` is NULL.
///
/// # Safety
/// `response` must be NULL or a live handle not used by another thread during the call.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_skip_steps(
    response: *mut DcrResponse,
    steps: u64,
) -> DcrStatus {
    guard("dcr_response_skip_steps", || {
        // SAFETY: caller contract (NULL is checked).
        let r = unsafe { arg_mut(response, "response")? };
        r.response.skip_steps(steps);
        Ok(())
    })
}

/// `*out` = whether the response must run this step even without impacts (carry-over filters
/// still ringing); always false in the default restart-every-step mode.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `response` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_needs_step(
    response: *const DcrResponse,
    out: *mut bool,
) -> DcrStatus {
    guard("dcr_response_needs_step", || {
        // SAFETY: caller contract (NULL is checked).
        let r = unsafe { arg_ref(response, "response")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, r.response.needs_step(), "out") }
    })
}

/// Fills `out` with the counters of the response's last step.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `response` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_step_info(
    response: *const DcrResponse,
    out: *mut DcrStepInfo,
) -> DcrStatus {
    guard("dcr_response_step_info", || {
        // SAFETY: caller contract (NULL is checked).
        let r = unsafe { arg_ref(response, "response")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, step_info(&r.response.last_step_info()), "out") }
    })
}

/// Fills `out` with the response's set-up facts: samples per step, filter period, mapping
/// distance, transfer-table status, cached contacts.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `response` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_info(
    response: *const DcrResponse,
    out: *mut DcrResponseInfo,
) -> DcrStatus {
    guard("dcr_response_info", || {
        // SAFETY: caller contract (NULL is checked).
        let r = unsafe { arg_ref(response, "response")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, response_info(&r.response), "out") }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The whole-struct copy of the fast path and the field conversion of the fallback give the
    /// same C values, for every method code.
    #[test]
    fn copying_a_response_equals_converting_it() {
        assert!(
            zero_copy_layouts().2,
            "the fast path is off on this toolchain"
        );
        for (k, served_by) in [
            ServedBy::Modal,
            ServedBy::Attenuation,
            ServedBy::TransferTable,
            ServedBy::Unmapped,
        ]
        .into_iter()
        .enumerate()
        {
            let c = ContactResponse {
                id: 40 + k as u64,
                point: [1.0, 2.0, 3.0],
                normal: [0.0, 0.6, 0.8],
                peak_displacement: 1e-6 * k as f64,
                delta_v: 1e-4 * k as f64,
                mapped: k != 3,
                lateral_delta_v: [4.0, 5.0, 6.0],
                served_by,
            };
            // SAFETY: same layout (asserted above), as in `dcr_response_step`.
            let copied = unsafe { std::ptr::read((&c as *const ContactResponse).cast()) };
            assert_eq!(contact_response(&c), copied);
        }
    }
}
