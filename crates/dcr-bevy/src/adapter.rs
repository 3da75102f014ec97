//! [`DcrContext`]: the one place where the plugin calls `dcr-rapier` (its rapier3d f32 backend,
//! [`dcr_rapier::f32::DcrRapier`]) on bevy_rapier's rapier sets.
//!
//! The systems in [`crate::systems`] hand this module bevy_rapier's `RigidBodySet`,
//! `ColliderSet` and `NarrowPhase` (the same rapier3d types: bevy_rapier3d 0.37 and
//! `dcr_rapier::f32` both wrap rapier3d 0.36) and get back plain data.

use bevy::prelude::{Entity, Resource, Vec3};
use bevy_rapier3d::rapier::prelude::{ColliderSet, NarrowPhase, RigidBodyHandle, RigidBodySet};
use dcr_rapier::f32::{body_handle, AdapterError, AdapterParams, AdapterStepInfo, DcrRapier};
use dcr_rapier::{DcrWorld, ElasticHandle, ElasticObjectDesc, WorldParams};

use crate::DcrResponse;

/// The distant collision response of the default rapier context: a [`DcrRapier`] (the world
/// of elastic objects and the rapier translation) and the entity of each elastic object.
///
/// Read it with `Res<DcrContext>` for the world's counters
/// ([`DcrContext::world`]`.object_info(handle)`, the handle being the elastic entity's
/// [`crate::DcrObject`]) and the last step's adapter report ([`DcrContext::step_info`]).
#[derive(Resource)]
pub struct DcrContext {
    dcr: DcrRapier,
    /// Each elastic object's handle and entity, in the order they were added.
    objects: Vec<(ElasticHandle, Entity)>,
}

impl DcrContext {
    /// A context with an empty world (`world.h` must be bevy_rapier's fixed `dt`).
    ///
    /// # Errors
    /// [`AdapterError::World`] for invalid world parameters.
    pub(crate) fn new(world: WorldParams, adapter: AdapterParams) -> Result<Self, AdapterError> {
        Ok(DcrContext {
            dcr: DcrRapier::new(world, adapter)?,
            objects: Vec::new(),
        })
    }

    /// The world: its objects, parameters, per-object counters and energy accounts.
    pub fn world(&self) -> &DcrWorld {
        self.dcr.world()
    }

    /// What the last physics step's read did (reports, bodies, whether the world was stepped,
    /// events).
    pub fn step_info(&self) -> AdapterStepInfo {
        self.dcr.step_info()
    }

    /// The world's step h (s): the plugin's at build, then bevy_rapier's `dt` (the plugin
    /// follows a change of `TimestepMode::Fixed { dt, substeps: 1 }`).
    pub fn h(&self) -> f64 {
        self.dcr.world().params().h
    }

    /// The elastic entity of `handle`, if it is one of this context's objects.
    pub fn entity_of(&self, handle: ElasticHandle) -> Option<Entity> {
        self.objects
            .iter()
            .find(|(h, _)| *h == handle)
            .map(|&(_, e)| e)
    }

    /// Adds the elastic object carried by rapier body `body` (entity `entity`): the base's
    /// object frame is the body's local frame, its current pose the object's pose.
    pub(crate) fn add_object(
        &mut self,
        bodies: &RigidBodySet,
        colliders: &mut ColliderSet,
        body: RigidBodyHandle,
        entity: Entity,
        desc: ElasticObjectDesc,
    ) -> Result<ElasticHandle, AdapterError> {
        let handle = self.dcr.add_object(bodies, colliders, body, desc)?;
        self.objects.push((handle, entity));
        Ok(handle)
    }

    /// Removes the elastic objects whose entity no longer satisfies `keep` (despawned, or its
    /// [`crate::DcrElastic`] removed): their handles become stale and their bodies' contacts
    /// are no longer read. Returns how many were removed. No allocation.
    pub(crate) fn remove_objects_unless(&mut self, mut keep: impl FnMut(Entity) -> bool) -> usize {
        let mut removed = 0;
        let mut k = 0;
        while k < self.objects.len() {
            let (handle, entity) = self.objects[k];
            if keep(entity) {
                k += 1;
                continue;
            }
            if let Err(e) = self.dcr.remove_object(handle) {
                // Only a handle this context never held could fail; it is dropped all the same.
                log::error!("dcr-bevy: removing the elastic object of entity {entity}: {e}");
            }
            self.objects.remove(k);
            removed += 1;
        }
        removed
    }

    /// Applies an elastic object's run-time settings from the next step on: enabled or
    /// disabled, gain (dimensionless, ≥ 0), impact threshold (N·s, ≥ 0).
    ///
    /// # Errors
    /// A stale handle, or a gain or threshold out of range (the message names it); the
    /// settings before the bad one are applied.
    pub(crate) fn apply_settings(
        &mut self,
        handle: ElasticHandle,
        enabled: bool,
        gain: f64,
        threshold: f64,
    ) -> Result<(), AdapterError> {
        if !self.dcr.world().contains(handle) {
            // The adapter's stale-handle error (the world's getters below panic on one).
            return self.dcr.set_object_gain(handle, gain);
        }
        if self.dcr.world().is_enabled(handle) != enabled {
            self.dcr.set_object_enabled(handle, enabled)?;
        }
        if self.dcr.world().gain(handle) != gain {
            self.dcr.set_object_gain(handle, gain)?;
        }
        if self.dcr.world().impact_threshold(handle) != threshold {
            self.dcr.set_object_threshold(handle, threshold)?;
        }
        Ok(())
    }

    /// The per-step rails: the world's step follows rapier's `dt` (s) — responses re-derived
    /// for a new dt, with a warning once per change — and its gravity (m/s², world) follows
    /// bevy_rapier's, for the support of impulses applied after the step. Returns whether the
    /// world's h now equals `dt` (false when a response cannot serve it: a transfer table
    /// under `TablePolicy::Refuse`, logged as an error by the adapter).
    pub(crate) fn sync(&mut self, dt: f64, gravity: Vec3) -> bool {
        self.dcr.sync_timestep(dt);
        self.dcr.set_gravity(gravity);
        crate::systems::same_step(dt, self.dcr.world().params().h)
    }

    /// Before rapier's step (does something only under the in-solver application mode, which
    /// the plugin refuses).
    pub(crate) fn before_step(&mut self, bodies: &mut RigidBodySet) {
        self.dcr.before_step(bodies);
    }

    /// After rapier's step, before bevy_rapier's writeback: reads the elastic objects' contacts,
    /// steps the world, applies its impulses to the rapier bodies (waking them) and appends one
    /// [`DcrResponse`] per impulse event to `out`.
    pub(crate) fn after_step(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
        out: &mut Vec<DcrResponse>,
    ) {
        let events = self.dcr.after_step(bodies, colliders, narrow_phase);
        for e in events {
            // bevy_rapier stores each body's entity in its `user_data` (`Entity::to_bits`).
            let Some(body) = bodies
                .get(body_handle(e.body))
                .and_then(|rb| Entity::try_from_bits(rb.user_data as u64))
            else {
                continue;
            };
            let object = self
                .objects
                .iter()
                .find(|(h, _)| *h == e.object)
                .map_or(Entity::PLACEHOLDER, |&(_, ent)| ent);
            out.push(DcrResponse {
                body,
                object,
                point: vec3(e.point),
                impulse: vec3(e.impulse),
                normal: vec3(e.normal),
                delta_v: e.delta_v as f32,
                chained: e.chained,
            });
        }
    }
}

/// An `f64` world-API vector as a bevy vector (rounded to `f32`).
fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}
