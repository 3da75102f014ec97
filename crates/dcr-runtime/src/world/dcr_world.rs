//! [`DcrWorld`]: the elastic objects of a rigid-body world and their per-step responses.

mod chains;
mod classify;
mod energy_bound;
mod impulse_pass;
mod lateral_kick;

use std::collections::HashMap;

use self::classify::{ContactAge, Source};
use self::impulse_pass::{Touched, Tracked};
use super::{
    BaseSupport, BodyState, ContactReport, ElasticHandle, ElasticObjectDesc, EnergyInfo,
    ImpulseEvent, ObjectStepInfo, ObjectTotals, Pose, WorldError, WorldParams, WorldStepInfo,
};
use crate::mapping::BuildIdHasher;
use crate::response::{
    prepared_vec, DistantResponse, Impact, RestingContact, ServedBy, PREPARED_CONTACTS,
};

/// Objects whose contacts the world's per-step buffers are sized for at set-up (beyond them
/// the buffers grow on first sight, as before), so that set-up memory stays bounded.
const PREPARED_OBJECTS: usize = 8;

/// One elastic object.
#[derive(Debug)]
struct Object {
    /// Its handle (slot and generation).
    handle: ElasticHandle,
    /// Whether it takes part in the steps ([`DcrWorld::set_enabled`]).
    enabled: bool,
    /// World step from which it is disabled (for [`ObjectTotals::disabled_steps`]).
    disabled_since: u64,
    /// World step from which it takes part (added, or enabled again): the contacts it first
    /// sees in the `settle_steps` steps from here are its resting set, not impacts.
    active_since: u64,
    support: BaseSupport,
    totals: ObjectTotals,
    body: u64,
    dynamic: bool,
    gain: f64,
    pose: Pose,
    rot: [[f64; 3]; 3],
    threshold: f64,
    response: DistantResponse,
    /// World step of the last response call.
    last_called: Option<u64>,
    /// This step's impacts (object frame): engine impacts first, then chained ones.
    impacts: Vec<Impact>,
    resting: Vec<RestingContact>,
    sources: Vec<Source>,
    /// Chain depth of this step's chained impacts (0: none).
    depth: u32,
    info: ObjectStepInfo,
}

/// A slot of the handle table: its generation and the object's index in `objects`
/// (`u32::MAX`: free).
#[derive(Clone, Copy, Debug)]
struct Slot {
    generation: u32,
    dense: u32,
}

/// The elastic objects of a rigid-body world and their distant collision responses (paper
/// §4.2–4.5), driven by plain world-frame contact data from any engine.
///
/// Set up once: [`DcrWorld::new`] with [`WorldParams`], then [`DcrWorld::add_object`] per
/// elastic object ([`ElasticObjectDesc`]: a shared [`crate::ModalModel`], its
/// [`crate::ResponseParams`], the engine body carrying it, static or dynamic, a gain). After
/// every rigid-body step, once: [`DcrWorld::set_pose`] for the dynamic objects, then
/// [`DcrWorld::step`] with the step's contact reports and the states of the bodies that touch
/// elastic objects; apply the returned [`ImpulseEvent`]s with the engine's
/// `apply_impulse_at_point`. A step does not allocate after warm-up and never fails.
///
/// # Impacts and resting contacts
/// Every contact report that touches an elastic object's body is classified, per object
/// ([`crate::world::ClassifyParams`]); the rules suit engines that create contacts before they carry
/// an impulse (predictive contacts):
/// - a contact id's *age* counts world steps since it appeared or last had zero impulse; an id
///   absent for `new_after_missing_steps` steps or more is new again when it returns (a
///   bounce), and so is one that touched with zero impulse (a body lifted within the engine's
///   prediction distance that lands again);
/// - an **impact** on the object is a contact with age ≤ `fresh_steps` that has not been an
///   impact on that object since, whose impulse is > 0 and ≥ the object's
///   `impact_threshold` (N·s). A zero-impulse (predictive) contact is never an impact and
///   stays fresh, so it fires when its impulse arrives; the contacts that appeared in the
///   first `settle_steps` steps (the initial resting set) do not fire until they lift off —
///   counted per object from the step it was added or enabled again, so bodies already
///   resting on an object added or re-enabled mid-run are not impacts;
/// - a **resting contact** is any other contact whose other body is dynamic
///   ([`BodyState::is_dynamic`]) with impulse > 0: it may receive a response.
///
/// Ages live in a hash table whose entries are dropped once their id has been absent long
/// enough to count as new, so its size is bounded by the contacts alive in a few steps and it
/// stops growing after warm-up. Engines that know which points are new themselves (and
/// callers that report only some steps, passing the others with [`DcrWorld::advance`]) use
/// [`crate::world::ClassifyParams::engine_newness`] instead: an impact is a report with
/// [`ContactReport::is_new`] and impulse > 0 and ≥ the threshold, after the settle window, and
/// no table is kept. Under either rule an impact must also have closed at least at
/// [`crate::world::ClassifyParams::min_approach_speed`] (default 0): engines that re-create the
/// points of sliding contacts set it so that the new points of a resting weight are not
/// impacts.
///
/// # Frames
/// Contacts arrive in the world frame; the response works in the object frame of the base.
/// With the object's pose `x_w = R x_o + t` the world converts impact points `Rᵀ(p − t)` and
/// directions `Rᵀd`, resting-contact points the same way, and the response's outward normals
/// back `n_w = R n_o`. Impacts use the point on the elastic object's surface; impulses are
/// applied at the point on the receiving body's surface.
///
/// # Impulses (Eq. 17–18) and one Gauss–Seidel pass per body
/// A resting contact's response asks for a normal velocity change `Δv` (m/s) at the contact;
/// the world issues `j = m_eff (g Δv − a) n` with the gain g, the effective mass of the body at
/// the point along n (Eq. 17, [`crate::response::effective_mass`]) and `a` the normal velocity change the
/// impulses already issued to that body this step, by any object, produce at that point (a body
/// resting on two objects hit at once moves as the larger push asks, not their sum; tracked from the
/// body's inverse mass and world inverse inertia, so the engine is not re-read); nothing when
/// `g Δv ≤ a`. A plate on four contacts that all ask for Δv thus gets Δv, not four times it —
/// one Gauss–Seidel pass, in contact-report order.
///
/// Under [`crate::Launch::SustainedPeak`] (carried-over filters) `Δv` is a target: `a` also
/// counts the body's own normal velocity at the point relative to the object's (from the
/// [`BodyState`]s), only contacts that carried an impulse this step (touching) receive it, and
/// it is asked for on every step the object's filters ring, not only on steps with impacts.
///
/// # Lateral kick
/// With [`crate::ResponseParams::lateral_kick`] on an object, its responses also carry the
/// tangential velocity change of §5.4 ([`crate::response::ContactResponse::lateral_delta_v`], rotated to
/// the world); after the normal part the world adds `m_eff,t (g |Δv_t| − a_t) t̂` along its
/// direction t̂ by the same Gauss–Seidel rule, so the event's impulse gets a tangential part.
///
/// # Chains through dynamic elastic objects
/// An impulse issued to the body of a dynamic elastic object becomes an impact on that object
/// in the same step (point and direction in its frame, magnitude |j|), so a hit floor pushes a
/// fridge that pushes the plant on it. Objects are processed in a fixed order — static objects
/// first, then dynamic ones, each group in the order added — and a chain only goes forward in
/// it, at most [`WorldParams::max_chain_depth`] links: a chain always terminates and every
/// object's response runs at most once per step (add a dynamic object after the one it rests
/// on). Impulses that cannot chain are still issued and counted in
/// [`WorldStepInfo::chains_dropped`].
///
/// # Eviction
/// A response runs only on steps with impacts (or while carry-over filters ring), but its
/// contact cache counts world steps: resting contacts unseen for more than
/// [`crate::ResponseParams::evict_after_steps`] world steps are evicted.
///
/// # Energy bound
/// With `η = WorldParams::energy_eta`, per object and step the kinetic energy its responses
/// inject, `E_in = Σ_bodies (P·V + ½ PᵀM⁻¹P)` (P the body's summed linear and angular impulse
/// from this object, V its velocity before them, M⁻¹ from its inverse mass and world inverse
/// inertia — exact for rigid bodies), is at most `η (D + R)`: D the energy the step's impacts
/// on the object dissipated, R the kinetic energy chained impulses gave its body. When over,
/// all the object's impulses are scaled by the largest s ∈ [0, 1] with
/// `s A + s² B ≤ η (D + R)` (E_in is quadratic in s; closed form). Under
/// [`crate::Launch::SustainedPeak`] the budget is `η (D + R + E_modal)`, E_modal the object's
/// modal energy at the step's end (J): the ringing the props draw on after the impact. The
/// energy the object's impulses then inject (after any scaling, when positive) is drained from
/// its carried filters ([`crate::DistantResponse::drain`]: every mode's state scaled alike,
/// the filters at rest once it reaches E_modal), so the ringing pays for what it lifts.
///
/// D is estimated per impact from post-step data only: with λ the impact's normal impulse,
/// `u⁺` the relative normal velocity of the two bodies at the contact after the step
/// (separating > 0) and `k = k₁ + k₂` the pair's inverse effective mass along the normal
/// (`kᵢ = mᵢ⁻¹ + (rᵢ × n)ᵀ Iᵢ⁻¹ (rᵢ × n)`, 0 for a body without state),
/// `D = max(0, ½ k λ² − λ u⁺)`. This is the exact kinetic energy an impulse λ removes from two
/// rigid bodies that leave with relative velocity u⁺ (their approach speed was u⁺ − kλ): ½ m u⁻²
/// for a plastic impact (u⁺ = 0), 0 for a perfectly elastic one, whatever restitution model the
/// engine uses and without its pre-step velocities. Gravity and other contacts acting during
/// the step make it an estimate. An impact between two elastic objects shares its D equally.
///
/// A chain passes on at most η of what it received, so over a chain of depth k the energy
/// injected is at most (η + … + η^(k+1))·D.
///
/// ```
/// use std::sync::Arc;
/// use dcr_runtime::{testing, BodyState, ContactReport, DcrWorld, ElasticObjectDesc, ModalModel,
///     Pose, WorldParams};
///
/// let model = Arc::new(ModalModel::from_base(testing::plate_base())?);
/// let mut world = DcrWorld::new(WorldParams {
///     energy_eta: None,
///     gravity: [0.0; 3], // no support compensation: this example lifts nothing off
///     ..Default::default()
/// })?;
/// // The plate (engine body 1) stands upright: its +z normal points along world +x.
/// let mut desc = ElasticObjectDesc::new(model, 1);
/// desc.pose = Pose::from_axis_angle([0.0, 1.0, 0.0], std::f64::consts::FRAC_PI_2, [2.0, 0.0, 0.0]);
/// let plate = world.add_object(desc)?;
/// // A 1 kg box (body 7) leaning on it; its contact settles during the first steps.
/// let mut boxy = BodyState::fixed(7);
/// boxy.inv_mass = 1.0;
/// let pose = world.pose(plate);
/// let on_plate = |x: [f64; 3]| pose.transform_point(x);
/// let rest = ContactReport { id: 70, body1: 1, body2: 7, point1: on_plate([0.9, 0.5, 0.0]),
///     point2: on_plate([0.9, 0.5, 0.0]), normal: [1.0, 0.0, 0.0], impulse: 0.01,
///     is_new: false };
/// for _ in 0..5 {
///     assert!(world.step(&[rest], &[boxy]).is_empty());
/// }
/// // A ball (body 9) hits the plate's middle with 2 N·s.
/// let hit = ContactReport { id: 90, body1: 9, body2: 1, point1: on_plate([0.5, 0.3, 0.0]),
///     point2: on_plate([0.5, 0.3, 0.0]), normal: [-1.0, 0.0, 0.0], impulse: 2.0,
///     is_new: false };
/// let events = world.step(&[rest, hit], &[boxy]);
/// assert_eq!(events.len(), 1);
/// assert_eq!(events[0].body, 7);
/// assert!(events[0].impulse[0] > 0.0); // pushed away from the plate: world +x
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct DcrWorld {
    params: WorldParams,
    /// The objects, densely packed (removal swaps the last into the hole).
    objects: Vec<Object>,
    /// Handle table: slot index → generation and position in `objects`.
    slots: Vec<Slot>,
    /// Free slots (reused last-in first-out).
    free: Vec<u32>,
    /// Whether the last rigid-body step was passed with [`DcrWorld::advance`] (the per-step
    /// counters then read as zeros).
    quiet: bool,
    /// Processing order (indices into `objects`): static, then dynamic, each in order added.
    order: Vec<u32>,
    /// Position of each object in `order`.
    rank: Vec<u32>,
    /// Engine body id of each object (index = object), scanned when there are few objects.
    object_bodies: Vec<u64>,
    /// Whether any object is dynamic (else no impulse can chain and no chain budget is kept).
    any_dynamic: bool,
    by_body: HashMap<u64, u32, BuildIdHasher>,
    ages: HashMap<u64, ContactAge, BuildIdHasher>,
    /// This step's `bodies` index by id.
    body_index: HashMap<u64, u32, BuildIdHasher>,
    /// The ids `body_index` was built for, in order (rebuilt only when they change).
    body_ids: Vec<u64>,
    tracked: Vec<Tracked>,
    touched: Vec<Touched>,
    events: Vec<ImpulseEvent>,
    /// (contact id, world step) of the events of the last two steps (`recently_pushed`).
    pushed: Vec<(u64, u64)>,
    /// Chained impacts produced by the current object: (target object, impact, depth).
    handed: Vec<(u32, Impact, u32)>,
    step: u64,
    /// Step at or after which the age table is next purged of dead ids.
    next_purge: u64,
    info: WorldStepInfo,
}

fn invalid(field: &'static str, detail: String) -> WorldError {
    WorldError::Params { field, detail }
}

impl DcrWorld {
    /// An empty world.
    ///
    /// # Errors
    /// [`WorldError::Params`] for a non-positive or non-finite `h`, an unset (the default) or
    /// non-finite gravity, or `energy_eta` outside [0, 1].
    pub fn new(params: WorldParams) -> Result<DcrWorld, WorldError> {
        if !(params.h.is_finite() && params.h > 0.0) {
            return Err(invalid(
                "h",
                format!("{} s (must be finite and > 0)", params.h),
            ));
        }
        if params.gravity_unset() {
            return Err(invalid(
                "gravity",
                "is not set: give the engine's gravity (m/s², world frame), e.g. [0, -9.81, 0] \
                 for a y-up engine (WorldParams::with_gravity), or [0, 0, 0] for no support \
                 compensation (a body a response lifts off then loses g·h of its push)"
                    .into(),
            ));
        }
        if !params.gravity.iter().all(|g| g.is_finite()) {
            return Err(invalid(
                "gravity",
                format!("{:?} m/s² (must be finite)", params.gravity),
            ));
        }
        let v = params.classify.min_approach_speed;
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(
                "classify.min_approach_speed",
                format!("{v} m/s (must be finite and ≥ 0)"),
            ));
        }
        if let Some(eta) = params.energy_eta {
            if !(0.0..=1.0).contains(&eta) {
                return Err(invalid("energy_eta", format!("{eta} (must be in [0, 1])")));
            }
        }
        Ok(DcrWorld {
            params,
            objects: Vec::new(),
            slots: Vec::new(),
            free: Vec::new(),
            quiet: false,
            order: Vec::new(),
            rank: Vec::new(),
            object_bodies: Vec::new(),
            any_dynamic: false,
            by_body: HashMap::default(),
            ages: HashMap::default(),
            body_index: HashMap::default(),
            body_ids: Vec::new(),
            tracked: Vec::new(),
            touched: Vec::new(),
            events: Vec::new(),
            handed: Vec::new(),
            pushed: Vec::new(),
            step: 0,
            next_purge: 0,
            info: WorldStepInfo::default(),
        })
    }

    /// Adds an elastic object; its response uses the world's `h`. Its handle takes a free slot
    /// (the most recently freed) with that slot's current generation, or a new slot.
    ///
    /// Checks how the base is held against the body ([`BaseSupport`]): a dynamic body with a
    /// base baked with fixed nodes, or a static body with a free-floating base, is logged as a
    /// warning (`log` crate, target `dcr_runtime::world`) and readable with
    /// [`DcrWorld::base_support`]; neither is refused.
    ///
    /// # Errors
    /// [`WorldError::DuplicateBody`] if another object is on the same body,
    /// [`WorldError::Object`] for a negative or non-finite gain, [`WorldError::Response`] if
    /// the response cannot be set up ([`DistantResponse::new`]), e.g. a transfer table refused
    /// under [`crate::response::TablePolicy::Refuse`].
    pub fn add_object(&mut self, desc: ElasticObjectDesc) -> Result<ElasticHandle, WorldError> {
        if let Some(&existing) = self.by_body.get(&desc.body) {
            return Err(WorldError::DuplicateBody {
                body: desc.body,
                existing: self.objects[existing as usize].handle.index(),
            });
        }
        if !(desc.gain.is_finite() && desc.gain >= 0.0) {
            return Err(WorldError::Object {
                body: desc.body,
                field: "gain",
                detail: format!("{} (must be finite and ≥ 0)", desc.gain),
            });
        }
        let mut rp = desc.response;
        rp.h = self.params.h;
        let threshold = rp.impact_threshold;
        let response =
            DistantResponse::new(desc.model, rp).map_err(|source| WorldError::Response {
                body: desc.body,
                source,
            })?;
        let fixed_nodes = response.model().base().fixed_nodes.len();
        let support = match (desc.dynamic, fixed_nodes) {
            (true, n) if n > 0 => BaseSupport::DynamicBodyFixedBase { fixed_nodes: n },
            (false, 0) => BaseSupport::StaticBodyFreeBase,
            _ => BaseSupport::Consistent,
        };
        match support {
            BaseSupport::DynamicBodyFixedBase { fixed_nodes } => log::warn!(
                target: "dcr_runtime::world",
                "elastic object on body {}: the body is dynamic but its base was baked with \
                 {fixed_nodes} fixed nodes; its modes assume those nodes held (right for a \
                 table standing on a floor, wrong for an object in flight: bake a free-floating \
                 base, without --fixed, for that)",
                desc.body
            ),
            BaseSupport::StaticBodyFreeBase => log::warn!(
                target: "dcr_runtime::world",
                "elastic object on body {}: the body is static but its base is free-floating \
                 (baked without fixed nodes); where the object is held (feet on the ground) its \
                 response is that of a floating object: bake with --fixed for its supports",
                desc.body
            ),
            BaseSupport::Consistent => {}
        }
        let slot = match self.free.pop() {
            Some(i) => i,
            None => {
                self.slots.push(Slot {
                    generation: 0,
                    dense: u32::MAX,
                });
                (self.slots.len() - 1) as u32
            }
        };
        let handle = ElasticHandle::from_raw_parts(slot, self.slots[slot as usize].generation);
        self.objects.push(Object {
            handle,
            enabled: true,
            disabled_since: 0,
            active_since: self.step,
            support,
            totals: ObjectTotals::default(),
            body: desc.body,
            dynamic: desc.dynamic,
            gain: desc.gain,
            pose: desc.pose,
            rot: desc.pose.rotation_matrix(),
            threshold,
            response,
            last_called: None,
            impacts: prepared_vec(
                PREPARED_CONTACTS,
                Impact {
                    point: [0.0; 3],
                    direction: [0.0; 3],
                    impulse: 0.0,
                },
            ),
            resting: prepared_vec(
                PREPARED_CONTACTS,
                RestingContact {
                    id: 0,
                    point: [0.0; 3],
                },
            ),
            sources: prepared_vec(
                PREPARED_CONTACTS,
                Source {
                    body: 0,
                    point: [0.0; 3],
                    touching: false,
                },
            ),
            depth: 0,
            info: ObjectStepInfo::default(),
        });
        self.reindex();
        self.prepare_buffers();
        Ok(handle)
    }

    /// Sizes the per-step buffers for [`PREPARED_CONTACTS`] resting contacts (and as many
    /// bodies) per object, for at most [`PREPARED_OBJECTS`] objects, and writes them once:
    /// set-up, not the first world steps, pays their allocation and first touch.
    fn prepare_buffers(&mut self) {
        let n = PREPARED_CONTACTS * self.objects.len().min(PREPARED_OBJECTS);
        let event = ImpulseEvent {
            body: 0,
            point: [0.0; 3],
            impulse: [0.0; 3],
            normal: [0.0; 3],
            delta_v: 0.0,
            contact: 0,
            object: ElasticHandle::from_raw_parts(0, 0),
            served_by: ServedBy::Modal,
            chained: false,
        };
        let impact = Impact {
            point: [0.0; 3],
            direction: [0.0; 3],
            impulse: 0.0,
        };
        self.body_index
            .reserve(n.saturating_sub(self.body_index.len()));
        prepare(&mut self.body_ids, n, 0);
        prepare(&mut self.tracked, n, Tracked::UNTOUCHED);
        prepare(&mut self.touched, n, Touched::default());
        // An event per contact and a support event per body.
        prepare(&mut self.events, 2 * n, event);
        prepare(&mut self.pushed, 2 * n, (0, 0));
        prepare(&mut self.handed, n, (0, impact, 0));
    }

    /// Rebuilds everything indexed by position in `objects` (set-up and removal only).
    fn reindex(&mut self) {
        self.by_body.clear();
        self.object_bodies.clear();
        self.any_dynamic = false;
        for (i, o) in self.objects.iter().enumerate() {
            self.by_body.insert(o.body, i as u32);
            self.object_bodies.push(o.body);
            self.any_dynamic |= o.dynamic;
            self.slots[o.handle.index() as usize].dense = i as u32;
        }
        let n = self.objects.len() as u32;
        let objects = &self.objects;
        self.order = (0..n)
            .filter(|&o| !objects[o as usize].dynamic)
            .chain((0..n).filter(|&o| objects[o as usize].dynamic))
            .collect();
        self.rank = vec![0; self.objects.len()];
        for (r, &o) in self.order.iter().enumerate() {
            self.rank[o as usize] = r as u32;
        }
    }

    /// Position in `objects` of the object `handle` names.
    ///
    /// # Errors
    /// [`WorldError::StaleHandle`] for a removed object or a handle not from this world.
    fn resolve(&self, handle: ElasticHandle) -> Result<usize, WorldError> {
        let Some(slot) = self.slots.get(handle.index() as usize) else {
            return Err(WorldError::StaleHandle {
                handle,
                why: "no such slot in this world",
            });
        };
        if slot.generation != handle.generation() || slot.dense == u32::MAX {
            return Err(WorldError::StaleHandle {
                handle,
                why: "the object was removed",
            });
        }
        Ok(slot.dense as usize)
    }

    /// [`DcrWorld::resolve`] for the accessors that panic.
    #[track_caller]
    fn dense(&self, handle: ElasticHandle) -> usize {
        match self.resolve(handle) {
            Ok(o) => o,
            Err(e) => panic!("{e}"),
        }
    }

    /// Whether `handle` names an object of this world (not removed).
    pub fn contains(&self, handle: ElasticHandle) -> bool {
        self.resolve(handle).is_ok()
    }

    /// The handles of the world's objects (in storage order, which removal changes).
    pub fn handles(&self) -> impl Iterator<Item = ElasticHandle> + '_ {
        self.objects.iter().map(|o| o.handle)
    }

    /// Removes an elastic object: its response, cached contacts and counters are dropped, its
    /// body is free to carry another object, and `handle` (and every copy of it) becomes
    /// stale: every call with it fails, even after its slot is reused by a later
    /// [`DcrWorld::add_object`] (with the next generation). Impulse events already returned
    /// keep their values. Set-up-time call (it re-indexes the objects; the step after it does
    /// not allocate).
    ///
    /// # Errors
    /// [`WorldError::StaleHandle`] when `handle` was already removed or is not from this world.
    pub fn remove_object(&mut self, handle: ElasticHandle) -> Result<(), WorldError> {
        let o = self.resolve(handle)?;
        self.objects.swap_remove(o);
        let slot = &mut self.slots[handle.index() as usize];
        slot.generation = slot.generation.wrapping_add(1);
        slot.dense = u32::MAX;
        self.free.push(handle.index());
        self.reindex();
        Ok(())
    }

    /// Enables or disables an object from the next step on. A disabled object is as if absent
    /// from the steps: its contacts are neither classified nor answered, impulses on its body
    /// do not chain into it, it issues no events, and its filters are returned to rest (a
    /// re-enabled object starts quiet). Its handle, pose, parameters and totals are kept. Under
    /// the ages rule, the contacts a re-enabled object first sees in its first `settle_steps`
    /// steps are its resting set (bodies that rested on it while it was off), not impacts.
    /// O(1), no allocation.
    ///
    /// # Errors
    /// [`WorldError::StaleHandle`].
    pub fn set_enabled(&mut self, handle: ElasticHandle, enabled: bool) -> Result<(), WorldError> {
        let o = self.resolve(handle)?;
        let step = self.step;
        let obj = &mut self.objects[o];
        if obj.enabled == enabled {
            return Ok(());
        }
        if enabled {
            obj.totals.disabled_steps += step - obj.disabled_since;
            obj.active_since = step;
        } else {
            obj.disabled_since = step;
            obj.response.reset();
        }
        obj.enabled = enabled;
        Ok(())
    }

    /// Whether the object takes part in the steps ([`DcrWorld::set_enabled`]).
    ///
    /// # Panics
    /// If `handle` is stale or not from this world.
    pub fn is_enabled(&self, handle: ElasticHandle) -> bool {
        self.objects[self.dense(handle)].enabled
    }

    /// Sets the object's gain (dimensionless, ≥ 0; [`ElasticObjectDesc::gain`]) from the next
    /// step on. O(1), no allocation.
    ///
    /// # Errors
    /// [`WorldError::StaleHandle`]; [`WorldError::Object`] for a negative or non-finite gain
    /// (the old one is kept).
    pub fn set_gain(&mut self, handle: ElasticHandle, gain: f64) -> Result<(), WorldError> {
        let o = self.resolve(handle)?;
        if !(gain.is_finite() && gain >= 0.0) {
            return Err(WorldError::Object {
                body: self.objects[o].body,
                field: "gain",
                detail: format!("{gain} (must be finite and ≥ 0)"),
            });
        }
        self.objects[o].gain = gain;
        Ok(())
    }

    /// The object's gain.
    ///
    /// # Panics
    /// If `handle` is stale or not from this world.
    pub fn gain(&self, handle: ElasticHandle) -> f64 {
        self.objects[self.dense(handle)].gain
    }

    /// Sets the object's impact threshold (N·s, ≥ 0; [`crate::ResponseParams::impact_threshold`]):
    /// both the impact classification and the response use it from the next step on. O(1), no
    /// allocation.
    ///
    /// # Errors
    /// [`WorldError::StaleHandle`]; [`WorldError::Response`] for a negative or non-finite
    /// threshold (the old one is kept).
    pub fn set_impact_threshold(
        &mut self,
        handle: ElasticHandle,
        threshold: f64,
    ) -> Result<(), WorldError> {
        let o = self.resolve(handle)?;
        let obj = &mut self.objects[o];
        obj.response
            .set_impact_threshold(threshold)
            .map_err(|source| WorldError::Response {
                body: obj.body,
                source,
            })?;
        obj.threshold = threshold;
        Ok(())
    }

    /// The object's impact threshold (N·s).
    ///
    /// # Panics
    /// If `handle` is stale or not from this world.
    pub fn impact_threshold(&self, handle: ElasticHandle) -> f64 {
        self.objects[self.dense(handle)].threshold
    }

    /// How the object's base is held compared with its body (checked at
    /// [`DcrWorld::add_object`]).
    ///
    /// # Panics
    /// If `handle` is stale or not from this world.
    pub fn base_support(&self, handle: ElasticHandle) -> BaseSupport {
        self.objects[self.dense(handle)].support
    }

    /// Changes the rigid-body step h (s) of the world and every object: each response is
    /// rebuilt for the new h — the modal filters' exact impulse-invariant coefficients (Eq. 10)
    /// and samples per step re-derived, a transfer table (baked for one h) re-checked under
    /// its [`crate::response::TablePolicy`] (refused, or served by the modal method and counted in
    /// [`crate::response::StepInfo::contacts_table_fallback`]). Filters restart at rest and resting
    /// contacts are mapped again on their next step. Costs a set-up per object (an
    /// attenuation response refactors its heat-method operators): call it when the engine's
    /// step changes, not every step. Nothing changes when `h` is the current one.
    ///
    /// # Errors
    /// [`WorldError::Params`] for a non-positive or non-finite h; [`WorldError::Response`]
    /// when an object's response cannot be set up for it (e.g. a table refused under
    /// [`crate::response::TablePolicy::Refuse`]). The world is unchanged then.
    pub fn set_h(&mut self, h: f64) -> Result<(), WorldError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(invalid("h", format!("{h} s (must be finite and > 0)")));
        }
        if h == self.params.h {
            return Ok(());
        }
        let mut rebuilt = Vec::with_capacity(self.objects.len());
        for o in &self.objects {
            let mut rp = o.response.params().clone();
            rp.h = h;
            let r = DistantResponse::new(o.response.model().clone(), rp).map_err(|source| {
                WorldError::Response {
                    body: o.body,
                    source,
                }
            })?;
            rebuilt.push(r);
        }
        for (o, r) in self.objects.iter_mut().zip(rebuilt) {
            o.response = r;
        }
        self.params.h = h;
        Ok(())
    }

    /// Sets an object's pose (object frame → world) for the coming [`DcrWorld::step`]: the
    /// body's pose after the rigid-body step. Static objects keep the pose they were added with.
    ///
    /// # Panics
    /// If `handle` is stale or not from this world (see [`DcrWorld::contains`]).
    pub fn set_pose(&mut self, handle: ElasticHandle, pose: Pose) {
        let o = self.dense(handle);
        let o = &mut self.objects[o];
        o.pose = pose;
        o.rot = pose.rotation_matrix();
    }

    /// The object's current pose.
    ///
    /// # Panics
    /// If `handle` is stale or not from this world (see [`DcrWorld::contains`]).
    pub fn pose(&self, handle: ElasticHandle) -> Pose {
        self.objects[self.dense(handle)].pose
    }

    /// Sets the gravity of the support compensation ([`WorldParams::gravity`], m/s², world
    /// frame; zero: none). O(1).
    ///
    /// # Errors
    /// [`WorldError::Params`] for a non-finite component (the old value is kept).
    pub fn set_gravity(&mut self, gravity: [f64; 3]) -> Result<(), WorldError> {
        if !gravity.iter().all(|g| g.is_finite()) {
            return Err(invalid(
                "gravity",
                format!("{gravity:?} m/s² (must be finite)"),
            ));
        }
        self.params.gravity = gravity;
        Ok(())
    }

    /// The parameters the world was built with (with `h` and `gravity` as last set).
    pub fn params(&self) -> &WorldParams {
        &self.params
    }

    /// Number of elastic objects (removed ones not counted).
    pub fn num_objects(&self) -> usize {
        self.objects.len()
    }

    /// The object on engine body `body`, if any.
    pub fn object_of_body(&self, body: u64) -> Option<ElasticHandle> {
        self.by_body
            .get(&body)
            .map(|&o| self.objects[o as usize].handle)
    }

    /// Engine body id of an object.
    ///
    /// # Panics
    /// If `handle` is stale or not from this world (see [`DcrWorld::contains`]).
    pub fn body_of(&self, handle: ElasticHandle) -> u64 {
        self.objects[self.dense(handle)].body
    }

    /// An object's response (its method, transfer-table status, cached contacts, …).
    ///
    /// # Panics
    /// If `handle` is stale or not from this world (see [`DcrWorld::contains`]).
    pub fn response(&self, handle: ElasticHandle) -> &DistantResponse {
        &self.objects[self.dense(handle)].response
    }

    /// What the last rigid-body step did, all objects (zeros but the step index after
    /// [`DcrWorld::advance`]).
    pub fn step_info(&self) -> WorldStepInfo {
        if self.quiet {
            WorldStepInfo {
                step: self.step.saturating_sub(1),
                ..Default::default()
            }
        } else {
            self.info
        }
    }

    /// What the last step did for one object (counters, the response's [`crate::response::StepInfo`],
    /// energy account).
    ///
    /// # Panics
    /// If `handle` is stale or not from this world (see [`DcrWorld::contains`]).
    pub fn object_info(&self, handle: ElasticHandle) -> ObjectStepInfo {
        let info = self.objects[self.dense(handle)].info;
        if self.quiet {
            let e = info.energy;
            ObjectStepInfo {
                energy: EnergyInfo {
                    scale: 1.0,
                    total_dissipated: e.total_dissipated,
                    total_received: e.total_received,
                    total_injected: e.total_injected,
                    ..Default::default()
                },
                ..Default::default()
            }
        } else {
            info
        }
    }

    /// Running totals of one object since it was added (impacts, queries, events, unmapped
    /// contacts, table fallbacks, disabled steps).
    ///
    /// # Panics
    /// If `handle` is stale or not from this world (see [`DcrWorld::contains`]).
    pub fn object_totals(&self, handle: ElasticHandle) -> ObjectTotals {
        let o = &self.objects[self.dense(handle)];
        let mut t = o.totals;
        if !o.enabled {
            t.disabled_steps += self.step - o.disabled_since;
        }
        t
    }

    /// The last step's impulse events (as returned by [`DcrWorld::step`]).
    pub fn events(&self) -> &[ImpulseEvent] {
        &self.events
    }

    /// Counts `steps` rigid-body steps that passed without [`DcrWorld::step`] (quiet steps: no
    /// contact to report, nothing ringing — see [`DcrWorld::needs_step`]). Step counts (settle
    /// window, ages, cache eviction) stay in engine steps. O(1), no allocation; clears the
    /// event buffer; [`DcrWorld::step_info`] and [`DcrWorld::object_info`] then read as zeros
    /// (a quiet step did nothing), so summing them per step counts each event once. Callers that skip steps should classify with
    /// [`crate::world::ClassifyParams::engine_newness`]: ages count a contact unseen for a while as new.
    pub fn advance(&mut self, steps: u64) {
        self.step += steps;
        self.events.clear();
        self.quiet = steps > 0 || self.quiet;
    }

    /// Whether the next step must call [`DcrWorld::step`] even without impacts to report: an
    /// object's carry-over filters still ring. `false` with the default parameters.
    pub fn needs_step(&self) -> bool {
        self.objects
            .iter()
            .any(|o| o.enabled && o.response.needs_step())
    }

    /// One rigid-body step: classifies `contacts` (world frame, see [`ContactReport`] for the
    /// sign convention), runs the responses of the objects with impacts, and returns the
    /// impulses to apply, valid until the next call. `bodies`: the state after the step of
    /// every dynamic or kinematic body that touches an elastic object (ids unique; others are
    /// treated as immovable and at rest). Set the dynamic objects' poses first
    /// ([`DcrWorld::set_pose`]). Does not allocate after warm-up.
    pub fn step(&mut self, contacts: &[ContactReport], bodies: &[BodyState]) -> &[ImpulseEvent] {
        let step = self.step;
        self.begin_step(bodies);
        // §4.5: the step's contacts split into impacts and resting contacts per object.
        self.classify(contacts, bodies);
        // Static objects first, then dynamic ones: a chain only goes forward in this order.
        for k in 0..self.order.len() {
            let o = self.order[k] as usize;
            if !self.is_due(o) {
                continue;
            }
            let first_event = self.events.len();
            // Eq. 9–16, then Eq. 17–18: the response to the object's impacts, a Δv per resting
            // contact, issued as impulses on the resting bodies (one Gauss–Seidel pass).
            self.respond(o, bodies);
            // E_in ≤ η (D + R): the object's impulses scaled down when they inject more.
            self.bound_energy(o, bodies, first_event);
            // Impulses on dynamic elastic objects later in the order become their impacts.
            self.hand_on_chains(o, first_event);
        }
        self.end_step(step);
        &self.events
    }

    /// Resets the per-step state: counters, events, the bodies' index (rebuilt only when the
    /// body list changes) and tracked velocity changes, each object's impacts and contacts.
    fn begin_step(&mut self, bodies: &[BodyState]) {
        let step = self.step;
        self.step += 1;
        self.quiet = false;
        self.info = WorldStepInfo {
            step,
            ..Default::default()
        };
        self.events.clear();
        // The body list usually repeats step after step: rebuild the index only on change.
        if self.body_ids.len() != bodies.len()
            || self.body_ids.iter().zip(bodies).any(|(&id, b)| id != b.id)
        {
            self.body_index.clear();
            self.body_ids.clear();
            for (i, b) in bodies.iter().enumerate() {
                self.body_index.insert(b.id, i as u32);
                self.body_ids.push(b.id);
            }
        }
        self.tracked.clear();
        self.tracked.resize(bodies.len(), Tracked::UNTOUCHED);
        for o in &mut self.objects {
            o.impacts.clear();
            o.resting.clear();
            o.sources.clear();
            o.depth = 0;
            let e = o.info.energy;
            o.info = ObjectStepInfo {
                energy: EnergyInfo {
                    scale: 1.0,
                    total_dissipated: e.total_dissipated,
                    total_received: e.total_received,
                    total_injected: e.total_injected,
                    ..Default::default()
                },
                ..Default::default()
            };
        }
    }

    /// Adds the step's counters to the objects' totals and the world's energy sums, records
    /// the events for classification and purges the age table.
    fn end_step(&mut self, step: u64) {
        for o in &mut self.objects {
            let t = &mut o.totals;
            let i = &o.info;
            t.impacts += u64::from(i.impacts);
            t.chained_impacts += u64::from(i.chained_impacts);
            t.queries += u64::from(i.queried);
            t.events += u64::from(i.events);
            t.contacts_unmapped += u64::from(i.response.contacts_unmapped);
            t.impacts_unmapped += u64::from(i.response.impacts_unmapped);
            t.contacts_table_fallback += u64::from(i.response.contacts_table_fallback);
            let e = &mut o.info.energy;
            e.total_dissipated += e.dissipated;
            e.total_received += e.received;
            e.total_injected += e.injected;
            self.info.injected += e.injected;
            self.info.dissipated += e.dissipated;
        }
        self.info.events = self.events.len() as u32;
        self.remember_pushed(step);
        self.purge_ages(step);
    }

    /// The object on engine body `body` (a scan of a few ids, else the hash table).
    #[inline]
    fn object_at(&self, body: u64) -> Option<u32> {
        if self.object_bodies.len() <= 8 {
            self.object_bodies
                .iter()
                .position(|&b| b == body)
                .map(|o| o as u32)
        } else {
            self.by_body.get(&body).copied()
        }
    }

    /// The enabled object on engine body `body`.
    #[inline]
    fn enabled_at(&self, body: u64) -> Option<u32> {
        self.object_at(body)
            .filter(|&o| self.objects[o as usize].enabled)
    }
}

/// Grows `v`'s capacity to at least `n` elements and writes the spare room once with `fill`
/// (set-up only; the contents are unchanged).
fn prepare<T: Clone>(v: &mut Vec<T>, n: usize, fill: T) {
    if v.capacity() < n {
        let len = v.len();
        v.reserve(n - len);
        v.resize(n, fill);
        v.truncate(len);
    }
}
