//! [`DcrRapier`]: a [`DcrWorld`] driven by a rapier world.

use std::sync::atomic::{AtomicBool, Ordering};

use dcr_runtime::math::{add, dot, norm, scale, sub};
use dcr_runtime::response::{inverse_effective_mass, PREPARED_CONTACTS};
use dcr_runtime::{
    BodyState, ContactReport, DcrWorld, ElasticHandle, ElasticObjectDesc, ImpulseEvent, Pose,
    WorldError, WorldParams,
};

use super::body_reader::body_state;
use super::contact_id::{body_handle, body_id, collider_pair_key, NO_BODY};
use super::contact_reader::{read_pair, scan_pair, LoadMemory, ReportSource};
use super::rapier::math::Vector;
use super::rapier::prelude::{
    ActiveHooks, ColliderGraphIndex, ColliderHandle, ColliderSet, NarrowPhase, PhysicsWorld,
    RigidBody, RigidBodyHandle, RigidBodySet,
};
use super::solver_hooks::{DcrSolverHooks, PairMark};
use super::{arr, to_f64, vector, ApplyMode, StepGate};

/// Settings of a [`DcrRapier`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AdapterParams {
    /// How the responses reach the bodies. Default [`ApplyMode::AfterStep`].
    pub apply: ApplyMode,
    /// Leave rapier's contact recycling on for the elastic objects' colliders (rapier skips
    /// contact generation for a pair whose bodies barely moved and reuses its contacts).
    /// `false` sets `ActiveHooks::MODIFY_SOLVER_CONTACTS` on them, which rapier treats as "never
    /// recycle" (`geometry/narrow_phase/pair_update.rs`); [`ApplyMode::InSolver`] always does, as
    /// its hook must see every step. Default `true`.
    pub contact_recycling: bool,
    /// On which steps the contacts are read in full and the world stepped. Default
    /// [`StepGate::ImpactSteps`].
    pub gate: StepGate,
}

impl Default for AdapterParams {
    fn default() -> Self {
        AdapterParams {
            apply: ApplyMode::AfterStep,
            contact_recycling: true,
            gate: StepGate::ImpactSteps,
        }
    }
}

/// What the last [`DcrRapier::after_step`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AdapterStepInfo {
    /// Index of the rapier step just read (0 for the first).
    pub step: u64,
    /// Contact reports passed to the world (solver contacts involving an elastic object).
    pub reports: u32,
    /// Body states passed to the world (dynamic bodies touching an elastic object).
    pub bodies: u32,
    /// Whether the contacts were read in full and the world stepped (always under
    /// [`StepGate::EveryStep`]; see [`StepGate::ImpactSteps`]).
    pub world_stepped: bool,
    /// Impulse events the world returned.
    pub events: u32,
    /// [`ApplyMode::InSolver`]: collider pairs whose contacts replay responses in the next step.
    pub marked_pairs: u32,
    /// [`ApplyMode::InSolver`]: marked pairs of the step just taken that rapier never showed the
    /// hook (the bodies parted before the solve); their responses were applied after the step
    /// instead, as [`ApplyMode::AfterStep`] does.
    pub replay_missed: u32,
    /// Whether the world stepped with an h other than rapier's dt because re-deriving the
    /// responses for dt was refused (a transfer table under `TablePolicy::Refuse`; logged once
    /// per dt as an error). See [`DcrRapier::sync_timestep`].
    pub h_mismatch: bool,
}

/// Errors of [`DcrRapier::add_object`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AdapterError {
    /// The body handle is not in the body set.
    #[error("rigid body {index}:{generation} is not in the body set")]
    NoBody {
        /// Arena index of the handle.
        index: u32,
        /// Generation of the handle.
        generation: u32,
    },
    /// The body has no collider: nothing could ever touch the elastic object.
    #[error("rigid body {index}:{generation} has no collider attached")]
    NoColliders {
        /// Arena index of the handle.
        index: u32,
        /// Generation of the handle.
        generation: u32,
    },
    /// The world refused the object, the handle or the value.
    #[error(transparent)]
    World(#[from] WorldError),
}

/// One elastic object: its world handle and rapier body.
#[derive(Clone, Copy, Debug)]
struct ObjectSlot {
    handle: ElasticHandle,
    body: RigidBodyHandle,
    dynamic: bool,
    /// Impact threshold (N·s).
    threshold: f64,
    /// Whether the object takes part in the steps.
    enabled: bool,
    /// Whether its unmapped contacts were reported (once per object).
    warned_unmapped: bool,
}

impl ObjectSlot {
    /// The threshold the impact-step gate uses: infinite while disabled (its points are still
    /// recorded, so enabling it does not make its resting contacts look new).
    #[inline]
    fn gate_threshold(&self) -> f64 {
        if self.enabled {
            self.threshold
        } else {
            f64::INFINITY
        }
    }
}

/// A response replayed through the solver ([`ApplyMode::InSolver`]).
#[derive(Clone, Copy, Debug)]
struct Seed {
    body: RigidBodyHandle,
    /// Application point (m, world).
    point: Vector,
    /// The normal part of the event's impulse (N·s, world).
    impulse: Vector,
    /// Index of its pair in the hooks' marks.
    mark: u32,
}

/// The distant collision response of a rapier world (paper §4.2–4.5): rapier's contacts in, the
/// world API's impulse events applied to rapier's bodies.
///
/// Set up once: [`DcrRapier::new`] with the world's [`WorldParams`] (`h` must be rapier's
/// `integration_parameters.dt`) and [`AdapterParams`], then [`DcrRapier::add_object`] for each rigid
/// body that carries a baked base (the base's object frame is the body's local frame). Per
/// rapier step, once, in this order:
///
/// 1. [`DcrRapier::before_step`] (only does something under [`ApplyMode::InSolver`]);
/// 2. rapier's step, with [`DcrRapier::hooks`] as its `PhysicsHooks` under
///    [`ApplyMode::InSolver`] (any hooks otherwise);
/// 3. [`DcrRapier::after_step`]: reads every solver contact of the elastic objects' colliders
///    (world frame, stable ids, this step's impulses, [`super::contact_id`]), the touching
///    dynamic bodies' states, steps the world, and applies its events.
///
/// [`DcrRapier::step`] does the three on a [`PhysicsWorld`]. Apart from rare growth of the
/// body-index table, a step allocates nothing after warm-up.
///
/// ```
/// use dcr_rapier::dcr_runtime::testing;
/// use dcr_rapier::f64::{rapier::prelude::*, AdapterParams, DcrRapier};
/// use dcr_rapier::{ElasticObjectDesc, ModalModel, WorldParams};
///
/// let mut world = PhysicsWorld::default();
/// world.integration_parameters.dt = 0.01;
/// world.gravity = Vector::new(0.0, 0.0, -9.81);
/// // The elastic plate (a 1 × 0.6 m base in the z = 0 plane) on a static body.
/// let plate = world.insert_body(RigidBodyBuilder::fixed());
/// let slab = ColliderBuilder::cuboid(0.5, 0.3, 0.05).translation(Vector::new(0.5, 0.3, -0.05));
/// world.insert_collider(slab, Some(plate));
/// let mut dcr = DcrRapier::new(WorldParams::default(), AdapterParams::default())?;
/// let model = std::sync::Arc::new(ModalModel::from_base(testing::plate_base())?);
/// dcr.add_object(&world.bodies, &mut world.colliders, plate, ElasticObjectDesc::new(model, 0))?;
/// // A small box resting on it, and a heavy ball dropped next to it.
/// let cube = world.insert_body(RigidBodyBuilder::dynamic().translation(Vector::new(0.8, 0.3, 0.05)));
/// world.insert_collider(ColliderBuilder::cuboid(0.05, 0.05, 0.05).density(500.0), Some(cube));
/// let ball = RigidBodyBuilder::dynamic()
///     .translation(Vector::new(0.3, 0.3, 0.6))
///     .linvel(Vector::new(0.0, 0.0, -3.0));
/// let ball = world.insert_body(ball);
/// world.insert_collider(ColliderBuilder::ball(0.1).density(5000.0), Some(ball));
/// let mut pushed = 0;
/// for _ in 0..40 {
///     pushed += dcr.step(&mut world).iter().filter(|e| e.body == dcr_rapier::f64::body_id(cube)).count();
/// }
/// assert!(pushed > 0, "the ball's impact reaches the box");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct DcrRapier {
    world: DcrWorld,
    params: AdapterParams,
    objects: Vec<ObjectSlot>,
    /// Every elastic object's colliders with the object's index, sorted by handle.
    colliders: Vec<(ColliderHandle, u32)>,
    /// Per collider arena index: its position in `colliders`, or `u32::MAX`.
    collider_rank: Vec<u32>,
    /// Node of each of `colliders` in rapier's contact graph (`u32::MAX`: none), checked
    /// against the graph at the start of every pass (see [`DcrRapier::find_nodes`]).
    nodes: Vec<u32>,
    reports: Vec<ContactReport>,
    sources: Vec<ReportSource>,
    states: Vec<BodyState>,
    /// Per body arena index: the `stamp` of the last step its state was added.
    stamps: Vec<u32>,
    stamp: u32,
    hooks: DcrSolverHooks,
    /// The points that carried an impulse at the previous step and at this one
    /// ([`StepGate::ImpactSteps`]).
    memory: LoadMemory,
    /// In-solver: seeds for the coming step (filled after a step, applied before the next).
    seeds: Vec<Seed>,
    /// Whether `seeds` were applied by `before_step` (and await the hook's verdict).
    seeded: bool,
    /// Report index by contact id, sorted (in-solver event → pair lookup).
    by_id: Vec<(u64, u32)>,
    /// In-solver scratch: this step's events before grouping by pair.
    replays: Vec<Replay>,
    info: AdapterStepInfo,
    step: u64,
    /// The last dt whose re-derivation was refused (reported once per value).
    refused_dt: Option<f64>,
    /// Steps the world took with an h other than rapier's dt.
    h_mismatch_steps: u64,
    /// Whether the coming `after_step` runs with an h other than rapier's dt.
    pending_mismatch: bool,
    /// Whether the world knows rapier's gravity (given in the parameters or by
    /// [`DcrRapier::set_gravity`]); until then it has none and `after_step` warns once.
    gravity_known: bool,
    warned_gravity: bool,
}

impl DcrRapier {
    /// An adapter with an empty world of parameters `params` (`h` must be rapier's
    /// `integration_parameters.dt`). Under [`StepGate::ImpactSteps`] the world classifies with
    /// engine newness (`params.classify.engine_newness` is set). `params.gravity` may stay
    /// unset (the default): [`DcrRapier::step`] gives the world rapier's gravity every step,
    /// and callers of [`DcrRapier::after_step`] give it with [`DcrRapier::set_gravity`] (until
    /// they do, the world has none and the first `after_step` logs a warning).
    ///
    /// # Errors
    /// [`AdapterError::World`] for invalid world parameters ([`DcrWorld::new`]).
    pub fn new(mut params: WorldParams, adapter: AdapterParams) -> Result<DcrRapier, AdapterError> {
        if adapter.gate == StepGate::ImpactSteps {
            params.classify.engine_newness = true;
        }
        let gravity_known = !params.gravity_unset();
        if !gravity_known {
            params.gravity = [0.0; 3];
        }
        Ok(DcrRapier {
            world: DcrWorld::new(params)?,
            params: adapter,
            objects: Vec::new(),
            colliders: Vec::new(),
            collider_rank: Vec::new(),
            nodes: Vec::new(),
            reports: Vec::new(),
            sources: Vec::new(),
            states: Vec::new(),
            stamps: Vec::new(),
            stamp: 0,
            hooks: DcrSolverHooks::default(),
            memory: LoadMemory::default(),
            seeds: Vec::new(),
            seeded: false,
            by_id: Vec::new(),
            replays: Vec::new(),
            info: AdapterStepInfo::default(),
            step: 0,
            refused_dt: None,
            h_mismatch_steps: 0,
            pending_mismatch: false,
            gravity_known,
            warned_gravity: false,
        })
    }

    /// Adds the elastic object carried by rapier body `body`: `desc.body` is set to
    /// [`super::body_id`]`(body)`, `desc.dynamic` to whether the body is dynamic, and
    /// `desc.pose` to the body's current pose (the base's object frame is the body's local
    /// frame). Under [`ApplyMode::InSolver`] the body's colliders get
    /// `ActiveHooks::MODIFY_SOLVER_CONTACTS`. Add a dynamic object after the objects it rests on
    /// (chains only go forward).
    ///
    /// # Errors
    /// [`AdapterError::NoBody`], [`AdapterError::NoColliders`], or the world's refusal
    /// ([`DcrWorld::add_object`]).
    pub fn add_object(
        &mut self,
        bodies: &RigidBodySet,
        colliders: &mut ColliderSet,
        body: RigidBodyHandle,
        mut desc: ElasticObjectDesc,
    ) -> Result<ElasticHandle, AdapterError> {
        let (index, generation) = body.into_raw_parts();
        let rb = bodies
            .get(body)
            .ok_or(AdapterError::NoBody { index, generation })?;
        if rb.colliders().is_empty() {
            return Err(AdapterError::NoColliders { index, generation });
        }
        desc.body = body_id(body);
        desc.dynamic = rb.is_dynamic();
        desc.pose = pose_of(rb.position());
        let threshold = desc.response.impact_threshold;
        let handle = self.world.add_object(desc)?;
        let obj = self.objects.len() as u32;
        self.objects.push(ObjectSlot {
            handle,
            body,
            dynamic: rb.is_dynamic(),
            threshold,
            enabled: true,
            warned_unmapped: false,
        });
        for &c in rb.colliders() {
            self.colliders.push((c, obj));
            let Some(co) = colliders.get_mut(c) else {
                continue;
            };
            if self.params.apply == ApplyMode::InSolver || !self.params.contact_recycling {
                co.set_active_hooks(co.active_hooks() | ActiveHooks::MODIFY_SOLVER_CONTACTS);
            }
        }
        self.rank_colliders();
        // The step's buffers sized at set-up (as the world's): room for each object's
        // prepared number of resting contacts and their bodies, for up to eight objects.
        let n = PREPARED_CONTACTS * self.objects.len().min(8);
        self.reports.reserve(n.saturating_sub(self.reports.len()));
        self.sources.reserve(n.saturating_sub(self.sources.len()));
        self.states.reserve(n.saturating_sub(self.states.len()));
        Ok(handle)
    }

    /// Sorts `colliders` by handle and rebuilds `collider_rank` (set-up only).
    fn rank_colliders(&mut self) {
        self.colliders.sort_by_key(|(c, _)| c.into_raw_parts());
        self.collider_rank.clear();
        for (k, &(c, _)) in self.colliders.iter().enumerate() {
            let i = c.into_raw_parts().0 as usize;
            if i >= self.collider_rank.len() {
                self.collider_rank.resize(i + 1, u32::MAX);
            }
            self.collider_rank[i] = k as u32;
        }
        // Graph nodes are searched again on the next pass.
        self.nodes.clear();
    }

    /// The position of `handle` in `objects`, or the world's stale-handle error.
    fn slot_of(&self, handle: ElasticHandle) -> Result<usize, AdapterError> {
        self.objects
            .iter()
            .position(|o| o.handle == handle)
            .filter(|_| self.world.contains(handle))
            .ok_or(AdapterError::World(WorldError::StaleHandle {
                handle,
                why: "the object was removed or is not from this adapter",
            }))
    }

    /// Removes an elastic object (its world object, see [`DcrWorld::remove_object`]): its
    /// handle becomes stale, its body's contacts are no longer read. The rigid body and its
    /// colliders stay in rapier (remove them there if they go too). Responses of the last step
    /// already replayed or applied are kept. Set-up-time call; the step after it does not
    /// allocate.
    ///
    /// Removing rapier bodies needs no call here: the adapter reads only the contacts rapier
    /// still has after its step, skips impulse events and in-solver replays for bodies no
    /// longer in the body set, and an elastic object whose body was removed from rapier simply
    /// has no contacts (remove it here to free its slot).
    ///
    /// # Errors
    /// [`AdapterError::World`] with [`WorldError::StaleHandle`] for a removed or foreign handle.
    pub fn remove_object(&mut self, handle: ElasticHandle) -> Result<(), AdapterError> {
        let k = self.slot_of(handle)?;
        self.world.remove_object(handle)?;
        self.objects.remove(k);
        let k = k as u32;
        self.colliders.retain(|&(_, o)| o != k);
        for (_, o) in &mut self.colliders {
            if *o > k {
                *o -= 1;
            }
        }
        self.rank_colliders();
        Ok(())
    }

    /// Enables or disables an elastic object from the next step on
    /// ([`DcrWorld::set_enabled`]): a disabled object's contacts are not read, it issues no
    /// events, and its filters restart at rest when it is enabled again. O(1).
    ///
    /// # Errors
    /// [`AdapterError::World`] with [`WorldError::StaleHandle`].
    pub fn set_object_enabled(
        &mut self,
        handle: ElasticHandle,
        enabled: bool,
    ) -> Result<(), AdapterError> {
        let k = self.slot_of(handle)?;
        self.world.set_enabled(handle, enabled)?;
        self.objects[k].enabled = enabled;
        Ok(())
    }

    /// Sets an elastic object's gain (dimensionless, ≥ 0) from the next step on
    /// ([`DcrWorld::set_gain`]).
    ///
    /// # Errors
    /// [`AdapterError::World`]: a stale handle or a negative or non-finite gain.
    pub fn set_object_gain(
        &mut self,
        handle: ElasticHandle,
        gain: f64,
    ) -> Result<(), AdapterError> {
        self.slot_of(handle)?;
        self.world.set_gain(handle, gain)?;
        Ok(())
    }

    /// Sets an elastic object's impact threshold (N·s, ≥ 0) from the next step on, for the
    /// adapter's impact-step gate, the world's classification and the response
    /// ([`DcrWorld::set_impact_threshold`]).
    ///
    /// # Errors
    /// [`AdapterError::World`]: a stale handle or a negative or non-finite threshold.
    pub fn set_object_threshold(
        &mut self,
        handle: ElasticHandle,
        threshold: f64,
    ) -> Result<(), AdapterError> {
        let k = self.slot_of(handle)?;
        self.world.set_impact_threshold(handle, threshold)?;
        self.objects[k].threshold = threshold;
        Ok(())
    }

    /// Changes the world's rigid-body step h to rapier's `dt` (s): every response re-derives
    /// its filters for it ([`DcrWorld::set_h`]). Call it at set-up, or whenever
    /// `integration_parameters.dt` changes; [`DcrRapier::sync_timestep`] is the per-step form.
    ///
    /// # Errors
    /// [`AdapterError::World`] when a response cannot serve `dt` (a transfer table baked for
    /// another h under `TablePolicy::Refuse`) or `dt` is not finite and > 0; nothing changes.
    pub fn set_timestep(&mut self, dt: f64) -> Result<(), AdapterError> {
        self.world.set_h(dt)?;
        Ok(())
    }

    /// The per-step rail: when rapier's `dt` (s) differs from the world's h, re-derives every
    /// response for it ([`DcrRapier::set_timestep`]; a warning through `log` once per new dt,
    /// since the world was set up for another h). When that is refused (a transfer table
    /// under `TablePolicy::Refuse`), logs an error once per dt, keeps the old h and counts the
    /// step in [`AdapterStepInfo::h_mismatch`] and [`DcrRapier::h_mismatch_steps`]: never
    /// silently. O(1) when dt equals h. [`DcrRapier::step`] calls it with
    /// `integration_parameters.dt`; callers of [`DcrRapier::after_step`] call it before.
    pub fn sync_timestep(&mut self, dt: f64) {
        let h = self.world.params().h;
        if dt == h {
            self.refused_dt = None;
            return;
        }
        // rapier's f32 dt widened: equal to h to f32 precision is the same step.
        if (dt - h).abs() <= 1e-6 * h && super::from_f64(h) == super::from_f64(dt) {
            return;
        }
        if self.refused_dt == Some(dt) {
            self.h_mismatch_steps += 1;
            self.pending_mismatch = true;
            return;
        }
        match self.world.set_h(dt) {
            Ok(()) => {
                log::warn!(
                    target: "dcr_rapier",
                    "rapier's dt = {dt} s differs from the world's h = {h} s: the responses \
                     were re-derived for dt (set WorldParams::h to rapier's dt to avoid this)"
                );
                self.refused_dt = None;
            }
            Err(e) => {
                log::error!(
                    target: "dcr_rapier",
                    "rapier's dt = {dt} s differs from the world's h = {h} s and the responses \
                     cannot be re-derived for it ({e}); they keep stepping with h"
                );
                self.refused_dt = Some(dt);
                self.h_mismatch_steps += 1;
                self.pending_mismatch = true;
            }
        }
    }

    /// Tells the world rapier's gravity (m/s², world frame) for the support compensation of
    /// lifted bodies ([`dcr_runtime::WorldParams::gravity`]): a body a response lifts off also
    /// gets the support its contact no longer gives it over the step in which it leaves, so it
    /// ends that step with the response's Δv, gravity included. Both application modes need
    /// it: after the step the body leaves during the next step; in the solver the replay's
    /// restitution pass sends it off at the end of the replay step, and gravity acts over the
    /// following one just the same. O(1); [`DcrRapier::step`] calls it with
    /// `PhysicsWorld::gravity`, callers of [`DcrRapier::after_step`] call it at set-up and when
    /// gravity changes.
    pub fn set_gravity(&mut self, gravity: Vector) {
        let g = arr(gravity);
        if g != self.world.params().gravity || !self.gravity_known {
            // Finite gravity only; rapier's own step fails on a non-finite one anyway.
            self.gravity_known |= self.world.set_gravity(g).is_ok();
        }
    }

    /// Steps the world took with an h other than rapier's dt because re-deriving was refused
    /// ([`DcrRapier::sync_timestep`]).
    pub fn h_mismatch_steps(&self) -> u64 {
        self.h_mismatch_steps
    }

    /// The world (its objects, parameters, counters and energy accounts).
    pub fn world(&self) -> &DcrWorld {
        &self.world
    }

    /// The world, mutably (e.g. to read an object's response).
    pub fn world_mut(&mut self) -> &mut DcrWorld {
        &mut self.world
    }

    /// The adapter's settings.
    pub fn params(&self) -> &AdapterParams {
        &self.params
    }

    /// The hooks to pass to rapier's step under [`ApplyMode::InSolver`].
    pub fn hooks(&self) -> &DcrSolverHooks {
        &self.hooks
    }

    /// The elastic object carried by rapier body `body`, if any.
    pub fn object_of_body(&self, body: RigidBodyHandle) -> Option<ElasticHandle> {
        self.world.object_of_body(body_id(body))
    }

    /// The last step's impulse events (world frame; receiving body as [`super::body_id`]):
    /// applied after the step, or replayed in the next step's solve, or only measured, by
    /// [`AdapterParams::apply`]. Valid until the next [`DcrRapier::after_step`].
    pub fn events(&self) -> &[ImpulseEvent] {
        self.world.events()
    }

    /// The last step's contact reports (what the world was given).
    pub fn reports(&self) -> &[ContactReport] {
        &self.reports
    }

    /// What the last [`DcrRapier::after_step`] did.
    pub fn step_info(&self) -> AdapterStepInfo {
        self.info
    }

    /// Before rapier's step. Under [`ApplyMode::InSolver`]: gives each body receiving a
    /// response the reverse of its normal impulse (its contact points approach the elastic
    /// surface at the requested Δv; the hook's restitution 1 reflects it) and wakes it. Does
    /// nothing in the other modes.
    pub fn before_step(&mut self, bodies: &mut RigidBodySet) {
        if self.params.apply != ApplyMode::InSolver || self.seeds.is_empty() {
            return;
        }
        for s in &self.seeds {
            if let Some(rb) = bodies.get_mut(s.body) {
                rb.apply_impulse_at_point(-s.impulse, s.point, true);
            }
        }
        self.seeded = true;
    }

    /// After rapier's step: reads the elastic objects' contacts and the touching bodies, steps
    /// the world and applies its events (by [`AdapterParams::apply`]). Returns the events.
    pub fn after_step(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
    ) -> &[ImpulseEvent] {
        self.info = AdapterStepInfo {
            step: self.step,
            h_mismatch: std::mem::take(&mut self.pending_mismatch),
            ..Default::default()
        };
        self.step += 1;
        if self.params.apply == ApplyMode::InSolver {
            self.settle_replays(bodies);
        }
        if !self.gravity_known && !self.warned_gravity {
            self.warned_gravity = true;
            log::warn!(
                target: "dcr_rapier",
                "the world was never given rapier's gravity (WorldParams::gravity unset, \
                 DcrRapier::set_gravity not called): a body a response lifts off gets no support \
                 compensation and loses g·h of its push; call \
                 dcr.set_gravity(gravity) at set-up, or step with DcrRapier::step (reported once)"
            );
        }

        if self.params.gate == StepGate::ImpactSteps {
            let hot = self.scan(narrow_phase);
            if !hot && !self.must_step() {
                self.world.advance(1);
                return &[];
            }
        }
        self.info.world_stepped = true;
        for o in &self.objects {
            if o.dynamic && o.enabled {
                if let Some(rb) = bodies.get(o.body) {
                    self.world.set_pose(o.handle, pose_of(rb.position()));
                }
            }
        }
        self.collect(bodies, colliders, narrow_phase);
        let n = self.world.step(&self.reports, &self.states).len();
        self.info.reports = self.reports.len() as u32;
        self.info.bodies = self.states.len() as u32;
        self.info.events = n as u32;
        self.warn_unmapped();
        match self.params.apply {
            ApplyMode::AfterStep => {
                // A body's events come together (its contacts are reported together): look
                // it up once per run.
                let mut current: Option<(u64, Option<&mut RigidBody>)> = None;
                for e in self.world.events() {
                    if current.as_ref().is_none_or(|(id, _)| *id != e.body) {
                        current = Some((e.body, bodies.get_mut(body_handle(e.body))));
                    }
                    if let Some((_, Some(rb))) = current.as_mut() {
                        rb.apply_impulse_at_point(vector(e.impulse), vector(e.point), true);
                    }
                }
            }
            ApplyMode::InSolver => self.prepare_replays(bodies),
            ApplyMode::MeasureOnly => {}
        }
        self.world.events()
    }

    /// One full step of `world`: [`DcrRapier::before_step`], `step_with_events` with
    /// [`DcrRapier::hooks`], [`DcrRapier::after_step`].
    pub fn step(&mut self, world: &mut PhysicsWorld) -> &[ImpulseEvent] {
        self.sync_timestep(to_f64(world.integration_parameters.dt));
        self.set_gravity(world.gravity);
        self.before_step(&mut world.bodies);
        world.step_with_events(&self.hooks, &());
        self.after_step(&mut world.bodies, &world.colliders, &world.narrow_phase)
    }

    /// Logs, once per object, that some of its contacts could not be mapped onto its base
    /// (farther than `max_map_distance` from the surface: usually a base in another frame than
    /// the body, e.g. baked y-up on a z-up body, or a collider far from the mesh).
    fn warn_unmapped(&mut self) {
        for o in &mut self.objects {
            if o.warned_unmapped || !o.enabled {
                continue;
            }
            let info = self.world.object_info(o.handle).response;
            if info.contacts_unmapped + info.impacts_unmapped == 0 {
                continue;
            }
            o.warned_unmapped = true;
            let t = self.world.object_totals(o.handle);
            let r = self.world.response(o.handle);
            log::warn!(
                target: "dcr_rapier",
                "elastic object {} (rapier body {:?}): {} contact(s) and {} impact(s) farther \
                 than max_map_distance = {} m from its base's surface were ignored; check that \
                 the base's object frame is the body's local frame (up axis, units) and the \
                 colliders match the mesh (counted in DcrWorld::object_totals; reported once)",
                o.handle,
                o.body.into_raw_parts(),
                t.contacts_unmapped,
                t.impacts_unmapped,
                r.max_map_distance()
            );
        }
    }

    /// Whether the world must be stepped with contacts whatever the light pass says: while a
    /// response rings. (Its settle window needs no reports under engine newness: no impact can
    /// fire there, and the light pass already remembers which points were loaded.)
    fn must_step(&self) -> bool {
        self.world.needs_step()
    }

    /// Position of elastic collider `c` in `colliders`.
    #[inline]
    fn rank_of(&self, c: ColliderHandle) -> Option<usize> {
        let r = *self.collider_rank.get(c.into_raw_parts().0 as usize)?;
        (r != u32::MAX && self.colliders[r as usize].0 == c).then_some(r as usize)
    }

    /// The light pass of [`StepGate::ImpactSteps`]: records this step's loaded points in
    /// `loaded_now`; whether one is an impact candidate (new and at or above its object's
    /// threshold; a pair of two elastic objects uses the lower threshold).
    /// Refreshes `nodes`: each elastic collider's node in the contact graph. The passes walk
    /// the node's edges themselves rather than through `NarrowPhase::contact_pairs_with`, which
    /// looks up both endpoints of every edge and runs through a flattening iterator that is not
    /// inlined (about 50 instructions per pair, callgrind, dinner: a fifth of the light pass);
    /// the edge order, hence the pair order, is the same. A node moves only when colliders are
    /// removed; then it is searched again (a scan of the graph's nodes).
    fn find_nodes(&mut self, np: &NarrowPhase) {
        let graph = np.contact_graph().raw_graph();
        let nodes = graph.raw_nodes();
        self.nodes.resize(self.colliders.len(), u32::MAX);
        for (k, &(ec, _)) in self.colliders.iter().enumerate() {
            let at = self.nodes[k] as usize;
            if nodes.get(at).is_none_or(|n| n.weight != ec) {
                self.nodes[k] = nodes
                    .iter()
                    .position(|n| n.weight == ec)
                    .map_or(u32::MAX, |i| i as u32);
            }
        }
    }

    fn scan(&mut self, np: &NarrowPhase) -> bool {
        self.memory.begin_step(self.step);
        let mut hot = false;
        self.find_nodes(np);
        let graph = np.contact_graph().raw_graph();
        for k in 0..self.colliders.len() {
            let (ec, obj) = self.colliders[k];
            let own = self.objects[obj as usize].gate_threshold();
            for edge in graph.edges(ColliderGraphIndex::new(self.nodes[k])) {
                let pair = edge.weight();
                let mut threshold = own;
                let other = if pair.collider1 == ec {
                    pair.collider2
                } else {
                    pair.collider1
                };
                if let Some(j) = self.rank_of(other) {
                    if j < k {
                        continue;
                    }
                    threshold =
                        threshold.min(self.objects[self.colliders[j].1 as usize].gate_threshold());
                }
                hot |= scan_pair(pair, threshold, &mut self.memory);
            }
        }
        hot
    }

    /// Fills `reports`, `sources` and `states` from the narrow phase.
    fn collect(&mut self, bodies: &RigidBodySet, colliders: &ColliderSet, np: &NarrowPhase) {
        self.reports.clear();
        self.sources.clear();
        self.states.clear();
        self.memory.begin_read();
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.stamps.iter_mut().for_each(|s| *s = 0);
            self.stamp = 1;
        }
        self.find_nodes(np);
        let graph = np.contact_graph().raw_graph();
        for k in 0..self.colliders.len() {
            let ec = self.colliders[k].0;
            for edge in graph.edges(ColliderGraphIndex::new(self.nodes[k])) {
                let pair = edge.weight();
                let other = if pair.collider1 == ec {
                    pair.collider2
                } else {
                    pair.collider1
                };
                // A pair of two elastic colliders is read once, from the first in order.
                if self.rank_of(other).is_some_and(|j| j < k) {
                    continue;
                }
                let (Some(co1), Some(co2)) =
                    (colliders.get(pair.collider1), colliders.get(pair.collider2))
                else {
                    continue;
                };
                let b1 = co1.parent();
                let b2 = co2.parent();
                if b1.is_some() && b1 == b2 {
                    continue;
                }
                let id1 = b1.map_or(NO_BODY, body_id);
                let id2 = b2.map_or(NO_BODY, body_id);
                let key = collider_pair_key(pair.collider1, pair.collider2);
                let n = read_pair(
                    pair,
                    [co1, co2],
                    [id1, id2],
                    key,
                    &mut self.memory,
                    &mut self.reports,
                    &mut self.sources,
                );
                if n > 0 {
                    for b in [b1, b2].into_iter().flatten() {
                        self.add_state(bodies, b);
                    }
                }
            }
        }
    }

    /// Adds `b`'s state once per step if it is dynamic.
    fn add_state(&mut self, bodies: &RigidBodySet, b: RigidBodyHandle) {
        let i = b.into_raw_parts().0 as usize;
        if i >= self.stamps.len() {
            self.stamps.resize(i + 1, 0);
        }
        if self.stamps[i] == self.stamp {
            return;
        }
        self.stamps[i] = self.stamp;
        if let Some(rb) = bodies.get(b) {
            if rb.is_dynamic() {
                self.states.push(body_state(body_id(b), rb));
            }
        }
    }

    /// In-solver, after the replay step: responses whose pair the hook never saw are applied
    /// now (the seed undone plus the response: twice the impulse).
    fn settle_replays(&mut self, bodies: &mut RigidBodySet) {
        if self.seeded {
            for s in &self.seeds {
                if !self.hooks.marks[s.mark as usize]
                    .seen
                    .load(Ordering::Relaxed)
                {
                    if let Some(rb) = bodies.get_mut(s.body) {
                        rb.apply_impulse_at_point(s.impulse * 2.0, s.point, true);
                    }
                }
            }
            self.info.replay_missed = self
                .hooks
                .marks
                .iter()
                .filter(|m| !m.seen.load(Ordering::Relaxed))
                .count() as u32;
        }
        self.seeded = false;
        self.seeds.clear();
        self.hooks.marks.clear();
    }

    /// In-solver: turns this step's events into seeds and pair marks for the next step.
    fn prepare_replays(&mut self, bodies: &RigidBodySet) {
        let events = self.world.events();
        if events.is_empty() {
            return;
        }
        self.by_id.clear();
        self.by_id.extend(
            self.reports
                .iter()
                .enumerate()
                .map(|(i, r)| (r.id, i as u32)),
        );
        self.by_id.sort_unstable_by_key(|&(id, _)| id);
        self.replays.clear();
        for e in events {
            let Ok(at) = self.by_id.binary_search_by_key(&e.contact, |&(id, _)| id) else {
                continue;
            };
            let ri = self.by_id[at].1 as usize;
            let (r, src) = (&self.reports[ri], &self.sources[ri]);
            let receiver = body_handle(e.body);
            let (elastic_body, elastic) = if r.body1 == e.body {
                (r.body2, src.colliders[1])
            } else {
                (r.body1, src.colliders[0])
            };
            let n = e.normal;
            let jn = dot(e.impulse, n);
            let jt = sub(e.impulse, scale(n, jn));
            let kick = match bodies.get(receiver) {
                Some(rb) if norm(jt) > 0.0 => {
                    // The body's tangential velocity at the point relative to the surface,
                    // plus the kick's Δv = |j_t| / m_eff,t along j_t.
                    let p = vector(e.point);
                    let t = scale(jt, 1.0 / norm(jt));
                    let b = body_state(e.body, rb);
                    let r = sub(e.point, b.center_of_mass);
                    let k = inverse_effective_mass(b.inv_mass, b.inv_inertia, r, t);
                    let mut rel = arr(rb.velocity_at_point(p));
                    if let Some(eb) = bodies.get(body_handle(elastic_body)) {
                        rel = sub(rel, arr(eb.velocity_at_point(p)));
                    }
                    add(sub(rel, scale(n, dot(rel, n))), scale(t, k * norm(jt)))
                }
                _ => [0.0; 3],
            };
            self.replays.push(Replay {
                key: src.pair,
                elastic,
                kick,
                seed: self.seeds.len() as u32,
            });
            self.seeds.push(Seed {
                body: receiver,
                point: vector(e.point),
                impulse: vector(scale(n, jn)),
                mark: 0,
            });
        }
        // One mark per collider pair (sorted by key for the hook), with the mean kick of its
        // responses that carry one (a support or a response without a tangential part has
        // none).
        self.replays.sort_unstable_by_key(|r| r.key);
        let mut i = 0;
        while i < self.replays.len() {
            let key = self.replays[i].key;
            let mut j = i;
            let mut kick = [0.0; 3];
            let mut kicks = 0;
            while j < self.replays.len() && self.replays[j].key == key {
                if self.replays[j].kick != [0.0; 3] {
                    kick = add(kick, self.replays[j].kick);
                    kicks += 1;
                }
                self.seeds[self.replays[j].seed as usize].mark = self.hooks.marks.len() as u32;
                j += 1;
            }
            self.hooks.marks.push(PairMark {
                key,
                elastic: self.replays[i].elastic,
                kick: vector(scale(kick, 1.0 / kicks.max(1) as f64)),
                seen: AtomicBool::new(false),
            });
            i = j;
        }
        self.info.marked_pairs = self.hooks.marks.len() as u32;
    }
}

/// One event replayed through the solver, before grouping by pair.
#[derive(Clone, Copy, Debug)]
struct Replay {
    key: u64,
    elastic: ColliderHandle,
    /// Tangential velocity target (m/s, world).
    kick: [f64; 3],
    /// Index into `seeds`.
    seed: u32,
}

/// A rapier pose as the world API's [`Pose`].
fn pose_of(p: &super::rapier::math::Pose) -> Pose {
    let q = p.rotation;
    Pose::new(
        [to_f64(q.x), to_f64(q.y), to_f64(q.z), to_f64(q.w)],
        arr(p.translation),
    )
}
