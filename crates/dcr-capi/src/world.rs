//! [`DcrWorld`]: the engine-level API (elastic objects by handle, world-frame contact reports
//! in, impulse events out), over `dcr_runtime::DcrWorld`.

use std::mem::{align_of, offset_of, size_of};
use std::sync::Arc;

use dcr_runtime::world::{BaseSupport, ObjectTotals};
use dcr_runtime::{
    BodyState, ContactReport, DcrWorld as RtWorld, ElasticHandle, ElasticObjectDesc, ImpulseEvent,
    ObjectStepInfo, WorldStepInfo,
};

use crate::guard::guard;
use crate::ptr::{
    arg_mut, arg_ref, arg_slice, check_bools, check_bools_in_array, check_ptr, check_struct_size,
    write_out,
};
use crate::response::{
    read_params, response_info, served_by_code, step_info, DcrResponseInfo, DcrServedBy,
    DcrStepInfo, SERVED_BY_CODES,
};
use crate::status::{DcrStatus, Failure};
use crate::world_params::{DcrElasticHandle, DcrElasticObjectDesc, DcrPose, DcrWorldParams};

/// The elastic objects of a rigid-body world and their distant responses (opaque). Created by
/// `dcr_world_create`, released by `dcr_world_free`. Used by one thread at a time.
///
/// Per rigid-body step, once, after the engine's step: `dcr_world_set_pose` for each dynamic
/// elastic object, then `dcr_world_step` with the step's contact reports and body states;
/// apply each returned `DcrImpulseEvent` with the engine's apply-impulse-at-point. The rules
/// (impact vs resting classification, frames, Eq. 17–18 impulses with one Gauss–Seidel pass
/// per body, chains through dynamic objects, eviction in steps, energy bound) are those of the
/// Rust `dcr_runtime::DcrWorld`, documented in its rustdoc.
#[derive(Debug)]
pub struct DcrWorld {
    world: RtWorld,
    contacts: Vec<ContactReport>,
    bodies: Vec<BodyState>,
    events: Vec<DcrImpulseEvent>,
}

/// One contact point between two engine bodies after a rigid-body step (world frame). Report
/// every contact point of the step that involves an elastic object's body, zero-impulse
/// (predictive) points included.
///
/// Sign convention: `normal` points from `body1` toward `body2`; the step's contact impulse
/// acts on `body2` as `+impulse · normal` and on `body1` as `−impulse · normal`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrContactReport {
    /// Stable id of the contact point while the engine tracks it (e.g. a hash of the collider
    /// pair, sub-shapes and manifold point index).
    pub id: u64,
    /// Engine id of the first body.
    pub body1: u64,
    /// Engine id of the second body.
    pub body2: u64,
    /// The contact point on `body1`'s surface (m, world frame, after the step).
    pub point1: [f64; 3],
    /// The contact point on `body2`'s surface (m, world frame, after the step); engines with
    /// one point per contact pass it in both fields.
    pub point2: [f64; 3],
    /// Unit contact normal (world frame), from `body1` toward `body2`.
    pub normal: [f64; 3],
    /// Normal impulse the solver applied at this point during the step (N·s, ≥ 0); 0 for a
    /// predictive contact that did not touch.
    pub impulse: f64,
    /// The engine's own newness: true when this point carried no impulse at the engine's
    /// previous step (rapier: the solver contact's warm-start impulse is 0; Box2D: a
    /// begin-touch event). Read only under `DcrClassifyParams.engine_newness`; pass false
    /// otherwise.
    pub is_new: bool,
}

/// A dynamic or kinematic body after the step (world frame). Give one per body touching an
/// elastic object; an id absent from the list is immovable and at rest.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrBodyState {
    /// Engine id of the body (as in `DcrContactReport.body1`).
    pub id: u64,
    /// Inverse mass (1/kg); 0 for a kinematic or static body.
    pub inv_mass: f64,
    /// Inverse inertia tensor (1/(kg·m²), world frame), symmetric, row-major.
    pub inv_inertia: [[f64; 3]; 3],
    /// Centre of mass (m, world frame).
    pub center_of_mass: [f64; 3],
    /// Linear velocity of the centre of mass after the step (m/s, world frame).
    pub linvel: [f64; 3],
    /// Angular velocity after the step (rad/s, world frame).
    pub angvel: [f64; 3],
}

/// An impulse to apply to a body at a world point after the step (paper §4.5, Eq. 17–18).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrImpulseEvent {
    /// Engine id of the body receiving the impulse.
    pub body: u64,
    /// Application point (m, world frame): the contact point on the receiving body.
    pub point: [f64; 3],
    /// Impulse (N·s, world frame): along `normal`, plus a tangential part with the lateral
    /// kick.
    pub impulse: [f64; 3],
    /// Unit outward normal of the elastic object at the contact (world frame).
    pub normal: [f64; 3],
    /// Velocity change the impulse gives the body at `point` along `normal` (m/s).
    pub delta_v: f64,
    /// The resting contact's id (`DcrContactReport.id`).
    pub contact: u64,
    /// The elastic object whose response this is.
    pub object: DcrElasticHandle,
    /// Which method computed the response, `DCR_SERVED_BY_*`.
    pub served_by: DcrServedBy,
    /// Whether the object's response this step was driven (in part) by chained impacts.
    pub chained: bool,
}

/// `DcrContactReport` has `ContactReport`'s layout: reports pass without a copy.
const REPORT_ZERO_COPY: bool = size_of::<ContactReport>() == size_of::<DcrContactReport>()
    && align_of::<ContactReport>() == align_of::<DcrContactReport>()
    && offset_of!(ContactReport, id) == offset_of!(DcrContactReport, id)
    && offset_of!(ContactReport, body1) == offset_of!(DcrContactReport, body1)
    && offset_of!(ContactReport, body2) == offset_of!(DcrContactReport, body2)
    && offset_of!(ContactReport, point1) == offset_of!(DcrContactReport, point1)
    && offset_of!(ContactReport, point2) == offset_of!(DcrContactReport, point2)
    && offset_of!(ContactReport, normal) == offset_of!(DcrContactReport, normal)
    && offset_of!(ContactReport, impulse) == offset_of!(DcrContactReport, impulse)
    && offset_of!(ContactReport, is_new) == offset_of!(DcrContactReport, is_new);

/// `DcrBodyState` has `BodyState`'s layout.
const BODY_ZERO_COPY: bool = size_of::<BodyState>() == size_of::<DcrBodyState>()
    && align_of::<BodyState>() == align_of::<DcrBodyState>()
    && offset_of!(BodyState, id) == offset_of!(DcrBodyState, id)
    && offset_of!(BodyState, inv_mass) == offset_of!(DcrBodyState, inv_mass)
    && offset_of!(BodyState, inv_inertia) == offset_of!(DcrBodyState, inv_inertia)
    && offset_of!(BodyState, center_of_mass) == offset_of!(DcrBodyState, center_of_mass)
    && offset_of!(BodyState, linvel) == offset_of!(DcrBodyState, linvel)
    && offset_of!(BodyState, angvel) == offset_of!(DcrBodyState, angvel);

/// `ImpulseEvent` has `DcrImpulseEvent`'s layout (the handle is its `u32` index, `ServedBy`'s
/// discriminants are the `DCR_SERVED_BY_*` codes): `dcr_world_step` lends the runtime's own
/// event buffer.
const EVENT_ZERO_COPY: bool = size_of::<ImpulseEvent>() == size_of::<DcrImpulseEvent>()
    && align_of::<ImpulseEvent>() == align_of::<DcrImpulseEvent>()
    && offset_of!(ImpulseEvent, body) == offset_of!(DcrImpulseEvent, body)
    && offset_of!(ImpulseEvent, point) == offset_of!(DcrImpulseEvent, point)
    && offset_of!(ImpulseEvent, impulse) == offset_of!(DcrImpulseEvent, impulse)
    && offset_of!(ImpulseEvent, normal) == offset_of!(DcrImpulseEvent, normal)
    && offset_of!(ImpulseEvent, delta_v) == offset_of!(DcrImpulseEvent, delta_v)
    && offset_of!(ImpulseEvent, contact) == offset_of!(DcrImpulseEvent, contact)
    && offset_of!(ImpulseEvent, object) == offset_of!(DcrImpulseEvent, object)
    && offset_of!(ImpulseEvent, served_by) == offset_of!(DcrImpulseEvent, served_by)
    && offset_of!(ImpulseEvent, chained) == offset_of!(DcrImpulseEvent, chained)
    // An 8-byte handle holding one u64 (index and generation).
    && size_of::<ElasticHandle>() == size_of::<DcrElasticHandle>()
    && SERVED_BY_CODES;

/// Whether the world's per-step structs convert without copies: (contact reports, body
/// states, impulse events). See `zero_copy_layouts`.
pub fn world_zero_copy_layouts() -> (bool, bool, bool) {
    (REPORT_ZERO_COPY, BODY_ZERO_COPY, EVENT_ZERO_COPY)
}

fn event(e: &ImpulseEvent) -> DcrImpulseEvent {
    DcrImpulseEvent {
        body: e.body,
        point: e.point,
        impulse: e.impulse,
        normal: e.normal,
        delta_v: e.delta_v,
        contact: e.contact,
        object: e.object.to_bits(),
        served_by: served_by_code(e.served_by),
        chained: e.chained,
    }
}

/// Counters of a world's last step, all objects (`dcr_world_step_info`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrWorldStepInfo {
    /// Index of the step (0 for the first call).
    pub step: u64,
    /// Contact reports that involve an elastic object's body.
    pub contacts: u32,
    /// Impacts classified from the reports (one per object side).
    pub impacts: u32,
    /// Chained impacts: impulses of the step given to a dynamic elastic object's body.
    pub chained_impacts: u32,
    /// Resting contacts (a dynamic body on an elastic object, impulse > 0).
    pub resting: u32,
    /// Elastic objects whose response ran.
    pub queries: u32,
    /// Impulse events issued.
    pub events: u32,
    /// Impulses to a dynamic elastic object that could not chain (still issued).
    pub chains_dropped: u32,
    /// Objects whose responses the energy bound scaled down.
    pub energy_limited: u32,
    /// Kinetic energy the responses gave the receiving bodies (J).
    pub injected: f64,
    /// Energy the step's impacts dissipated (J, an estimate from post-step data).
    pub dissipated: f64,
}

/// The energy account of one elastic object (J): the last step's values and sums since it was
/// added.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrEnergyInfo {
    /// Energy the step's engine impacts on the object dissipated (J, ≥ 0).
    pub dissipated: f64,
    /// Kinetic energy chained impulses gave the object's body this step (J, ≥ 0).
    pub received: f64,
    /// Kinetic energy the object's responses would have given without the bound (J).
    pub requested: f64,
    /// Kinetic energy the object's responses gave the receiving bodies (J, after scaling).
    pub injected: f64,
    /// The uniform scale the bound applied to the object's impulses (1: not limited).
    pub scale: f64,
    /// Σ `dissipated` since the object was added (J).
    pub total_dissipated: f64,
    /// Σ `received` since the object was added (J).
    pub total_received: f64,
    /// Σ `injected` since the object was added (J).
    pub total_injected: f64,
}

/// What a world's last step did for one elastic object (`dcr_world_object_info`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrObjectStepInfo {
    /// Engine impacts on the object.
    pub impacts: u32,
    /// Chained impacts on the object.
    pub chained_impacts: u32,
    /// Resting contacts on the object.
    pub resting: u32,
    /// Impulse events the object's response issued.
    pub events: u32,
    /// Whether the object's response ran this step.
    pub queried: bool,
    /// Wall time of the object's response call this step (ns; 0 when it did not run). For
    /// profiling; results never depend on it.
    pub response_time_ns: u64,
    /// The response's own counters (zeros when it did not run).
    pub response: DcrStepInfo,
    /// The energy account.
    pub energy: DcrEnergyInfo,
}

fn world_step_info(i: &WorldStepInfo) -> DcrWorldStepInfo {
    DcrWorldStepInfo {
        step: i.step,
        contacts: i.contacts,
        impacts: i.impacts,
        chained_impacts: i.chained_impacts,
        resting: i.resting,
        queries: i.queries,
        events: i.events,
        chains_dropped: i.chains_dropped,
        energy_limited: i.energy_limited,
        injected: i.injected,
        dissipated: i.dissipated,
    }
}

fn object_step_info(i: &ObjectStepInfo) -> DcrObjectStepInfo {
    let e = &i.energy;
    DcrObjectStepInfo {
        impacts: i.impacts,
        chained_impacts: i.chained_impacts,
        resting: i.resting,
        events: i.events,
        queried: i.queried,
        response_time_ns: i.response_time_ns,
        response: step_info(&i.response),
        energy: DcrEnergyInfo {
            dissipated: e.dissipated,
            received: e.received,
            requested: e.requested,
            injected: e.injected,
            scale: e.scale,
            total_dissipated: e.total_dissipated,
            total_received: e.total_received,
            total_injected: e.total_injected,
        },
    }
}

/// The world's handle for `handle`, or `DCR_STATUS_INVALID_HANDLE` (removed or never issued).
fn handle_of(world: &RtWorld, handle: DcrElasticHandle) -> Result<ElasticHandle, Failure> {
    let h = ElasticHandle::from_bits(handle);
    if world.contains(h) {
        Ok(h)
    } else {
        Err(Failure::new(
            DcrStatus::InvalidHandle,
            format!(
                "elastic object {handle} (slot {}, generation {}) does not exist: removed, or \
                 not from this world (it has {} objects)",
                h.index(),
                h.generation(),
                world.num_objects()
            ),
        ))
    }
}

/// Running totals of one elastic object since it was added (`dcr_world_object_totals`), apart
/// from the per-step counters of `DcrObjectStepInfo`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DcrObjectTotals {
    /// Engine impacts on the object.
    pub impacts: u64,
    /// Chained impacts on the object.
    pub chained_impacts: u64,
    /// Steps on which the object's response ran.
    pub queries: u64,
    /// Impulse events the object's response issued.
    pub events: u64,
    /// Resting contacts farther than `max_map_distance` from the base's surface (no response):
    /// a contact in another frame than the base's, or far from its mesh.
    pub contacts_unmapped: u64,
    /// Impacts farther than `max_map_distance` from the surface (ignored).
    pub impacts_unmapped: u64,
    /// Resting contacts a transfer-table response served with the modal method instead.
    pub contacts_table_fallback: u64,
    /// Steps the object spent disabled.
    pub disabled_steps: u64,
}

/// How an object's base is held compared with its body (`dcr_world_object_base_support`).
pub type DcrBaseSupport = u32;
/// A static body with fixed nodes, or a dynamic body with a free-floating base.
pub const DCR_BASE_SUPPORT_CONSISTENT: DcrBaseSupport = 0;
/// A dynamic body with a base baked with fixed nodes: right for an object standing on what
/// holds those nodes (a table on a floor), wrong for one in flight.
pub const DCR_BASE_SUPPORT_DYNAMIC_BODY_FIXED_BASE: DcrBaseSupport = 1;
/// A static body with a free-floating base: where the object is held, its response is that of
/// a floating object (bake with fixed nodes at its supports).
pub const DCR_BASE_SUPPORT_STATIC_BODY_FREE_BASE: DcrBaseSupport = 2;

fn object_totals(t: &ObjectTotals) -> DcrObjectTotals {
    DcrObjectTotals {
        impacts: t.impacts,
        chained_impacts: t.chained_impacts,
        queries: t.queries,
        events: t.events,
        contacts_unmapped: t.contacts_unmapped,
        impacts_unmapped: t.impacts_unmapped,
        contacts_table_fallback: t.contacts_table_fallback,
        disabled_steps: t.disabled_steps,
    }
}

/// Creates an empty world. On success `*out` receives it (free with `dcr_world_free`); on
/// failure `*out` is set to NULL.
///
/// # Errors
/// `DCR_STATUS_INVALID_ARGUMENT` for a non-positive or non-finite h, `energy_eta` outside
/// [0, 1] with the bound on, or a wrong `struct_size`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `params` must be NULL or a valid `DcrWorldParams`; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_create(
    params: *const DcrWorldParams,
    out: *mut *mut DcrWorld,
) -> DcrStatus {
    guard("dcr_world_create", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, std::ptr::null_mut(), "out")? };
        check_ptr(params, "params")?;
        // SAFETY: non-null, aligned; `struct_size` is at offset 0 of the repr(C) struct.
        let size = unsafe { params.cast::<u32>().read() };
        check_struct_size::<DcrWorldParams>(size, "params", "DcrWorldParams")?;
        let bools = [
            (offset_of!(DcrWorldParams, energy_bound), "energy_bound"),
            (
                offset_of!(DcrWorldParams, classify)
                    + offset_of!(crate::DcrClassifyParams, engine_newness),
                "classify.engine_newness",
            ),
        ];
        // SAFETY: the caller's struct has this library's size, so every offset is inside it.
        unsafe { check_bools(params, &bools, "params")? };
        // SAFETY: this library's size, valid bools, the rest plain data.
        let p = unsafe { (*params).runtime_params("params")? };
        let world = RtWorld::new(p).map_err(|e| Failure::invalid(e.to_string()))?;
        let handle = Box::into_raw(Box::new(DcrWorld {
            world,
            contacts: Vec::new(),
            bodies: Vec::new(),
            events: Vec::new(),
        }));
        // SAFETY: `out` was checked above.
        unsafe { out.write(handle) };
        Ok(())
    })
}

/// Releases a world and its objects' responses (NULL is a no-op). Event arrays returned by
/// `dcr_world_step` become invalid.
///
/// # Safety
/// `world` must be NULL or a handle from `dcr_world_create` not freed before.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_free(world: *mut DcrWorld) {
    if world.is_null() {
        return;
    }
    let _ = std::panic::catch_unwind(|| {
        // SAFETY: a live handle from Box::into_raw (caller contract), freed once.
        drop(unsafe { Box::from_raw(world) });
    });
}

/// Adds an elastic object built from `desc` (its model, response parameters, engine body,
/// static or dynamic, gain, pose). `*out` receives its handle (a free slot of a removed object
/// with that slot's next generation, else a new slot: k for the k-th object while nothing is
/// removed). Add a dynamic object after the one it rests on (chains only go forward). How the
/// base is held against the body is checked (`dcr_world_object_base_support`).
///
/// # Errors
/// `DCR_STATUS_INVALID_ARGUMENT` for a response parameter out of range, a negative or
/// non-finite gain, a pose translation that is not finite or beyond `DCR_MAX_TRANSLATION`, a
/// body that already carries an object, a transfer table refused by its policy, or a wrong
/// `struct_size` (the message says which); `DCR_STATUS_NULL_POINTER` for a NULL argument or
/// `desc->model`.
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread during the call; `desc`
/// NULL or a valid `DcrElasticObjectDesc` whose `model` is NULL or a live model handle; `out`
/// NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_add_object(
    world: *mut DcrWorld,
    desc: *const DcrElasticObjectDesc,
    out: *mut DcrElasticHandle,
) -> DcrStatus {
    guard("dcr_world_add_object", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        check_ptr(out, "out")?;
        check_ptr(desc, "desc")?;
        // SAFETY: non-null, aligned; `struct_size` is at offset 0 of the repr(C) struct.
        let size = unsafe { desc.cast::<u32>().read() };
        check_struct_size::<DcrElasticObjectDesc>(size, "desc", "DcrElasticObjectDesc")?;
        let bools = [(offset_of!(DcrElasticObjectDesc, dynamic), "dynamic")];
        // SAFETY: the caller's struct has this library's size, so the offset is inside it.
        unsafe { check_bools(desc, &bools, "desc")? };
        // SAFETY: a field pointer inside the caller's struct (no reference is created);
        // `read_params` checks its size and bools before reading it.
        let response =
            unsafe { read_params(std::ptr::addr_of!((*desc).response), "desc.response")? };
        // SAFETY: this library's size, valid bools (checked above and by read_params), the
        // rest plain data.
        let d = unsafe { &*desc };
        // SAFETY: `desc->model` is NULL or a live handle (caller contract; NULL is checked).
        let model = unsafe { &arg_ref(d.model, "desc.model")?.model };
        let mut rd = ElasticObjectDesc::new(Arc::clone(model), d.body);
        rd.response = response;
        rd.dynamic = d.dynamic;
        rd.gain = d.gain;
        rd.pose = d.pose.checked("desc.pose")?;
        let h = w
            .world
            .add_object(rd)
            .map_err(|e| Failure::invalid(e.to_string()))?;
        // SAFETY: `out` was checked above.
        unsafe { out.write(h.to_bits()) };
        Ok(())
    })
}

/// Sets a dynamic object's pose (object frame → world) for the coming `dcr_world_step`: its
/// body's pose after the rigid-body step.
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE` for a removed handle or one not from this world;
/// `DCR_STATUS_INVALID_ARGUMENT` for a translation component that is not finite or beyond
/// `DCR_MAX_TRANSLATION` (the pose is unchanged); `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread; `pose` NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_set_pose(
    world: *mut DcrWorld,
    object: DcrElasticHandle,
    pose: *const DcrPose,
) -> DcrStatus {
    guard("dcr_world_set_pose", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        // SAFETY: caller contract (NULL is checked).
        let pose = unsafe { *arg_ref(pose, "pose")? };
        let h = handle_of(&w.world, object)?;
        w.world.set_pose(h, pose.checked("pose")?);
        Ok(())
    })
}

/// Writes an object's current pose (object frame → world) to `out`.
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_get_pose(
    world: *const DcrWorld,
    object: DcrElasticHandle,
    out: *mut DcrPose,
) -> DcrStatus {
    guard("dcr_world_get_pose", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        let h = handle_of(&w.world, object)?;
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, w.world.pose(h).into(), "out") }
    })
}

/// One rigid-body step: classifies the step's `contacts` (world frame), runs the responses of
/// the objects with impacts, and sets `*events` / `*num_events` to the impulses to apply.
///
/// `bodies`: the state after the step of every dynamic or kinematic body that touches an
/// elastic object (unique ids). The event array is owned by the world and valid until the next
/// `dcr_world_step` or `dcr_world_free` on it (NULL when there are none). Does not allocate
/// after warm-up.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL `world`, `events` or `num_events`, or a NULL array
/// with a non-zero count; `DCR_STATUS_INVALID_ARGUMENT` for a misaligned array. The step does
/// not run then (`*events` = NULL, `*num_events` = 0 when they are non-NULL).
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread during the call;
/// `contacts` / `bodies` must point to `num_contacts` / `num_bodies` readable elements (may be
/// NULL when the count is 0); `events` / `num_events` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_step(
    world: *mut DcrWorld,
    contacts: *const DcrContactReport,
    num_contacts: usize,
    bodies: *const DcrBodyState,
    num_bodies: usize,
    events: *mut *const DcrImpulseEvent,
    num_events: *mut usize,
) -> DcrStatus {
    guard("dcr_world_step", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(events, std::ptr::null(), "events")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(num_events, 0, "num_events")? };
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        if num_contacts > 0 {
            check_ptr(contacts, "contacts")?;
            crate::ptr::check_len::<DcrContactReport>(num_contacts, "contacts")?;
            let bools = [(offset_of!(DcrContactReport, is_new), "is_new")];
            // SAFETY: `num_contacts` readable reports (caller contract; NULL, alignment and
            // size checked); only raw bytes are read.
            unsafe { check_bools_in_array(contacts, num_contacts, &bools, "contacts")? };
        }
        // SAFETY: caller contract (counts, NULL and alignment checked; bools valid).
        let contacts = unsafe { arg_slice(contacts, num_contacts, "contacts")? };
        // SAFETY: as above.
        let bodies = unsafe { arg_slice(bodies, num_bodies, "bodies")? };
        let DcrWorld {
            world: rw,
            contacts: contact_buf,
            bodies: body_buf,
            events: event_buf,
        } = w;
        let contacts: &[ContactReport] = if REPORT_ZERO_COPY {
            // SAFETY: DcrContactReport and ContactReport have the same size, alignment and
            // field offsets with fields of the same types (checked at compile time); the C
            // `bool` holds 0 or 1 as Rust's does.
            unsafe { std::slice::from_raw_parts(contacts.as_ptr().cast(), contacts.len()) }
        } else {
            contact_buf.clear();
            contact_buf.extend(contacts.iter().map(|c| ContactReport {
                id: c.id,
                body1: c.body1,
                body2: c.body2,
                point1: c.point1,
                point2: c.point2,
                normal: c.normal,
                impulse: c.impulse,
                is_new: c.is_new,
            }));
            contact_buf
        };
        let bodies: &[BodyState] = if BODY_ZERO_COPY {
            // SAFETY: as above, for DcrBodyState and BodyState (all fields f64 / u64).
            unsafe { std::slice::from_raw_parts(bodies.as_ptr().cast(), bodies.len()) }
        } else {
            body_buf.clear();
            body_buf.extend(bodies.iter().map(|b| BodyState {
                id: b.id,
                inv_mass: b.inv_mass,
                inv_inertia: b.inv_inertia,
                center_of_mass: b.center_of_mass,
                linvel: b.linvel,
                angvel: b.angvel,
            }));
            body_buf
        };
        let out = rw.step(contacts, bodies);
        if !EVENT_ZERO_COPY {
            event_buf.clear();
            event_buf.extend(out.iter().map(event));
        }
        publish(w, events, num_events);
        Ok(())
    })
}

/// Writes the world's event array to the caller's out-parameters (checked non-null before).
fn publish(w: &DcrWorld, events: *mut *const DcrImpulseEvent, num_events: *mut usize) {
    let (p, n): (*const DcrImpulseEvent, usize) = if EVENT_ZERO_COPY {
        // The runtime's own buffer, valid until its next step: ImpulseEvent has
        // DcrImpulseEvent's layout (checked at compile time).
        let e = w.world.events();
        (e.as_ptr().cast(), e.len())
    } else {
        (w.events.as_ptr(), w.events.len())
    };
    let p = if n == 0 { std::ptr::null() } else { p };
    // SAFETY: both pointers were checked non-null and aligned by the caller of `publish`
    // (write_out), and are valid for writes per the C caller's contract.
    unsafe {
        events.write(p);
        num_events.write(n);
    }
}

/// Counts `steps` rigid-body steps that passed without `dcr_world_step` (quiet steps: no
/// contact to report and `dcr_world_needs_step` false). Step counts (settle window, ages,
/// cache eviction) stay in engine steps. O(1), no allocation; the event array becomes empty.
/// Callers that skip steps should classify with `DcrClassifyParams.engine_newness`.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` when `world` is NULL.
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread during the call.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_advance(world: *mut DcrWorld, steps: u64) -> DcrStatus {
    guard("dcr_world_advance", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        w.world.advance(steps);
        w.events.clear();
        Ok(())
    })
}

/// `*out` = whether the next step must call `dcr_world_step` even with nothing to report (an
/// object's carry-over filters still ring); false with the default parameters.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_needs_step(world: *const DcrWorld, out: *mut bool) -> DcrStatus {
    guard("dcr_world_needs_step", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, w.world.needs_step(), "out") }
    })
}

/// Sets `*events` / `*num_events` to the last step's impulse events again (same array and
/// lifetime as returned by `dcr_world_step`; NULL and 0 before the first step).
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `world` must be NULL or a live handle; `events` / `num_events` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_events(
    world: *const DcrWorld,
    events: *mut *const DcrImpulseEvent,
    num_events: *mut usize,
) -> DcrStatus {
    guard("dcr_world_events", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(events, std::ptr::null(), "events")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(num_events, 0, "num_events")? };
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        publish(w, events, num_events);
        Ok(())
    })
}

/// Fills `out` with the counters of the world's last step.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_step_info(
    world: *const DcrWorld,
    out: *mut DcrWorldStepInfo,
) -> DcrStatus {
    guard("dcr_world_step_info", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, world_step_info(&w.world.step_info()), "out") }
    })
}

/// Fills `out` with what the last step did for one object (counters, the response's step
/// info, energy account).
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_object_info(
    world: *const DcrWorld,
    object: DcrElasticHandle,
    out: *mut DcrObjectStepInfo,
) -> DcrStatus {
    guard("dcr_world_object_info", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        let h = handle_of(&w.world, object)?;
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, object_step_info(&w.world.object_info(h)), "out") }
    })
}

/// Fills `out` with the set-up facts of one object's response (samples per step, mapping
/// distance, transfer-table status, cached contacts).
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_object_response_info(
    world: *const DcrWorld,
    object: DcrElasticHandle,
    out: *mut DcrResponseInfo,
) -> DcrStatus {
    guard("dcr_world_object_response_info", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        let h = handle_of(&w.world, object)?;
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, response_info(w.world.response(h)), "out") }
    })
}

/// Removes an elastic object: its response and counters are dropped, its body may carry
/// another object, and `object` becomes stale (every call with it returns
/// `DCR_STATUS_INVALID_HANDLE`, even after its slot is reused). Event arrays already returned
/// keep their values until the next step. Not a per-step call (it re-indexes the objects).
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE` for an already removed or foreign handle;
/// `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread during the call.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_remove_object(
    world: *mut DcrWorld,
    object: DcrElasticHandle,
) -> DcrStatus {
    guard("dcr_world_remove_object", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        let h = handle_of(&w.world, object)?;
        w.world
            .remove_object(h)
            .map_err(|e| Failure::new(DcrStatus::InvalidHandle, e.to_string()))
    })
}

/// Enables (`enabled` true) or disables an object from the next step on. A disabled object's
/// contacts are ignored, it issues no events, impulses on its body do not chain into it, and
/// its filters restart at rest when it is enabled again; its handle and settings are kept.
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread during the call.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_set_object_enabled(
    world: *mut DcrWorld,
    object: DcrElasticHandle,
    enabled: bool,
) -> DcrStatus {
    guard("dcr_world_set_object_enabled", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        let h = handle_of(&w.world, object)?;
        w.world
            .set_enabled(h, enabled)
            .map_err(|e| Failure::invalid(e.to_string()))
    })
}

/// Sets an object's gain (dimensionless, ≥ 0: the scale of the velocity changes its responses
/// ask for) from the next step on.
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE`; `DCR_STATUS_INVALID_ARGUMENT` for a negative or non-finite
/// gain (the old one is kept); `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread during the call.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_set_object_gain(
    world: *mut DcrWorld,
    object: DcrElasticHandle,
    gain: f64,
) -> DcrStatus {
    guard("dcr_world_set_object_gain", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        let h = handle_of(&w.world, object)?;
        w.world
            .set_gain(h, gain)
            .map_err(|e| Failure::invalid(e.to_string()))
    })
}

/// Sets an object's impact threshold (N·s, ≥ 0: smaller impacts are ignored) from the next
/// step on, for the classification and the response.
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE`; `DCR_STATUS_INVALID_ARGUMENT` for a negative or non-finite
/// threshold (the old one is kept); `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread during the call.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_set_object_threshold(
    world: *mut DcrWorld,
    object: DcrElasticHandle,
    threshold: f64,
) -> DcrStatus {
    guard("dcr_world_set_object_threshold", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        let h = handle_of(&w.world, object)?;
        w.world
            .set_impact_threshold(h, threshold)
            .map_err(|e| Failure::invalid(e.to_string()))
    })
}

/// Changes the world's rigid-body step h (s) when the engine's step changes: every object's
/// response is rebuilt for it (the filters' exact coefficients re-derived; a transfer table
/// baked for another h refused or replaced by the modal method by its policy). Not a per-step
/// call: compare the engine's step with the world's h and call it on change.
///
/// # Errors
/// `DCR_STATUS_INVALID_ARGUMENT` for a non-positive or non-finite h, or when a response cannot
/// serve it (a transfer table under `DCR_TABLE_POLICY_REFUSE`); the world is unchanged then.
/// `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle not used by another thread during the call.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_set_h(world: *mut DcrWorld, h: f64) -> DcrStatus {
    guard("dcr_world_set_h", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_mut(world, "world")? };
        w.world
            .set_h(h)
            .map_err(|e| Failure::invalid(e.to_string()))
    })
}

/// `*out` = the world's rigid-body step h (s).
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_h(world: *const DcrWorld, out: *mut f64) -> DcrStatus {
    guard("dcr_world_h", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, w.world.params().h, "out") }
    })
}

/// Fills `out` with an object's running totals since it was added (impacts, queries, events,
/// unmapped contacts, table fallbacks, disabled steps).
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_object_totals(
    world: *const DcrWorld,
    object: DcrElasticHandle,
    out: *mut DcrObjectTotals,
) -> DcrStatus {
    guard("dcr_world_object_totals", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        let h = handle_of(&w.world, object)?;
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, object_totals(&w.world.object_totals(h)), "out") }
    })
}

/// `*out` = how an object's base is held compared with its body, `DCR_BASE_SUPPORT_*` (checked
/// at `dcr_world_add_object`; not refused either way).
///
/// # Errors
/// `DCR_STATUS_INVALID_HANDLE`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_object_base_support(
    world: *const DcrWorld,
    object: DcrElasticHandle,
    out: *mut DcrBaseSupport,
) -> DcrStatus {
    guard("dcr_world_object_base_support", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        let h = handle_of(&w.world, object)?;
        let code = match w.world.base_support(h) {
            BaseSupport::Consistent => DCR_BASE_SUPPORT_CONSISTENT,
            BaseSupport::DynamicBodyFixedBase { .. } => DCR_BASE_SUPPORT_DYNAMIC_BODY_FIXED_BASE,
            BaseSupport::StaticBodyFreeBase => DCR_BASE_SUPPORT_STATIC_BODY_FREE_BASE,
        };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, code, "out") }
    })
}

/// `*out` = the number of elastic objects in the world.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_num_objects(
    world: *const DcrWorld,
    out: *mut usize,
) -> DcrStatus {
    guard("dcr_world_num_objects", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, w.world.num_objects(), "out") }
    })
}

/// `*out` = the elastic object carried by engine body `body`.
///
/// # Errors
/// `DCR_STATUS_NOT_FOUND` when the body carries none; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `world` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_object_of_body(
    world: *const DcrWorld,
    body: u64,
    out: *mut DcrElasticHandle,
) -> DcrStatus {
    guard("dcr_world_object_of_body", || {
        // SAFETY: caller contract (NULL is checked).
        let w = unsafe { arg_ref(world, "world")? };
        check_ptr(out, "out")?;
        let h = w.world.object_of_body(body).ok_or_else(|| {
            Failure::new(
                DcrStatus::NotFound,
                format!("body {body} carries no elastic object"),
            )
        })?;
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, h.to_bits(), "out") }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use dcr_runtime::response::ServedBy;

    /// Lending the runtime's event and reading it as a `DcrImpulseEvent` gives the values the
    /// field conversion gives.
    #[test]
    fn lending_an_event_equals_converting_it() {
        assert!(
            world_zero_copy_layouts().2,
            "the fast path is off on this toolchain"
        );
        for (k, served_by) in [ServedBy::Modal, ServedBy::TransferTable]
            .into_iter()
            .enumerate()
        {
            let e = ImpulseEvent {
                body: 7,
                point: [1.0, 2.0, 3.0],
                impulse: [0.1, 0.2, 0.3],
                normal: [0.0, 0.0, 1.0],
                delta_v: 0.5,
                object: ElasticHandle::from_index(3 + k as u32),
                served_by,
                contact: 99,
                chained: k == 1,
            };
            // SAFETY: same layout (asserted above), as in `publish`.
            let lent = unsafe { std::ptr::read((&e as *const ImpulseEvent).cast()) };
            assert_eq!(event(&e), lent);
        }
    }
}
