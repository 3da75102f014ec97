//! The plugin's two systems, on either side of bevy_rapier's step in `FixedUpdate`.
//!
//! [`dcr_before_step`] (in [`crate::DcrSet::BeforeStep`], after bevy_rapier's
//! `PhysicsSet::SyncBackend`) removes the objects whose entity was despawned or lost its
//! [`DcrElastic`], applies changed run-time settings (enabled, gain, impact threshold), adds
//! the elastic objects whose base has loaded and whose body exists, and remembers the change
//! tick. [`dcr_after_step`] (in [`crate::DcrSet::AfterStep`], after
//! `PhysicsSet::StepSimulation` and **before** `PhysicsSet::Writeback`) checks that rapier was
//! stepped once by a fixed step, makes the world's h and gravity bevy_rapier's, reads the
//! contacts, steps the world and applies its impulses in rapier's body set, so that the
//! writeback copies them into the `Velocity` components. An impulse applied after the writeback would be lost for a body with a
//! `Velocity` component: the next `SyncBackend` sees the component changed (by the writeback)
//! and sets the body's velocity back to it.

use bevy::asset::{AssetServer, Assets, LoadState};
use bevy::ecs::change_detection::Tick;
use bevy::ecs::system::SystemChangeTick;
use bevy::prelude::*;
use bevy_rapier3d::prelude::{
    DefaultRapierContext, RapierConfiguration, RapierContextColliders, RapierContextSimulation,
    RapierRigidBodyHandle, RapierRigidBodySet, RigidBody, TimestepMode,
};
use dcr_rapier::{ElasticHandle, ElasticObjectDesc};

use crate::{
    DcrContext, DcrElastic, DcrElasticFailed, DcrObject, DcrRefusal, DcrResponse, DcrStatus,
    ModesAsset,
};

/// The change tick of the last [`dcr_before_step`] run.
#[derive(Resource, Debug, Default)]
pub(crate) struct StepGuard {
    /// `this_run` of the last [`dcr_before_step`].
    pub before: Option<Tick>,
}

/// Relative tolerance of the step-length checks (f32 rounding of `h`).
const DT_TOLERANCE: f64 = 1e-6;

/// Whether two step lengths (s) are the same step, to f32 precision.
pub(crate) fn same_step(dt: f64, h: f64) -> bool {
    (dt - h).abs() <= DT_TOLERANCE * h
}

/// Removes the objects of despawned entities and of entities whose [`DcrElastic`] was removed,
/// applies changed run-time settings, adds the elastic objects that are ready, then runs the
/// adapter's before-step half.
#[allow(clippy::type_complexity)]
// A Bevy system takes each resource and query it reads as its own parameter.
#[allow(clippy::too_many_arguments)]
pub(crate) fn dcr_before_step(
    mut commands: Commands,
    mut dcr: ResMut<DcrContext>,
    mut guard: ResMut<StepGuard>,
    ticks: SystemChangeTick,
    assets: Res<Assets<ModesAsset>>,
    server: Res<AssetServer>,
    elastic: Query<(), With<DcrElastic>>,
    orphans: Query<
        Entity,
        (
            Or<(With<DcrObject>, With<DcrElasticFailed>)>,
            Without<DcrElastic>,
        ),
    >,
    changed: Query<(Entity, &DcrElastic, &DcrObject), Changed<DcrElastic>>,
    pending: Query<
        (
            Entity,
            &DcrElastic,
            Option<&RapierRigidBodyHandle>,
            Has<RigidBody>,
        ),
        (Without<DcrObject>, Without<DcrElasticFailed>),
    >,
    mut context: Query<
        (&mut RapierRigidBodySet, &mut RapierContextColliders),
        With<DefaultRapierContext>,
    >,
) {
    guard.before = Some(ticks.this_run());
    // Despawned, or DcrElastic removed: the object leaves the world (its handle goes stale).
    dcr.remove_objects_unless(|entity| elastic.contains(entity));
    for entity in &orphans {
        commands
            .entity(entity)
            .remove::<(DcrObject, DcrElasticFailed)>();
    }
    for (entity, el, object) in &changed {
        apply_settings(&mut dcr, entity, el, object.0);
    }
    let Ok((mut bodies, mut colliders)) = context.single_mut() else {
        return;
    };
    for (entity, elastic, body, has_rigid_body) in &pending {
        let fail = |commands: &mut Commands, reason: String| {
            log::error!("dcr-bevy: elastic entity {entity}: {reason}");
            commands.entity(entity).insert(DcrElasticFailed { reason });
        };
        if !has_rigid_body {
            fail(
                &mut commands,
                "DcrElastic needs a bevy_rapier RigidBody (Fixed or Dynamic) on the same entity"
                    .into(),
            );
            continue;
        }
        if let LoadState::Failed(err) = server.load_state(&elastic.base) {
            fail(&mut commands, format!("its base did not load: {err}"));
            continue;
        }
        let (Some(body), Some(base)) = (body, assets.get(&elastic.base)) else {
            continue; // the base is loading or bevy_rapier has not made the body yet
        };
        let mut desc = ElasticObjectDesc::new(base.model.clone(), 0);
        desc.response = elastic.response.clone();
        desc.gain = elastic.gain;
        match dcr.add_object(
            &bodies.bodies,
            &mut colliders.colliders,
            body.0,
            entity,
            desc,
        ) {
            Ok(handle) => {
                apply_settings(&mut dcr, entity, elastic, handle);
                commands.entity(entity).insert(DcrObject(handle));
            }
            Err(e) => fail(&mut commands, e.to_string()),
        }
    }
    dcr.before_step(&mut bodies.bodies);
}

/// Makes the object's run-time settings those of its component; an error (a value out of
/// range) is logged, naming the entity.
fn apply_settings(
    dcr: &mut DcrContext,
    entity: Entity,
    elastic: &DcrElastic,
    handle: ElasticHandle,
) {
    if let Err(e) = dcr.apply_settings(
        handle,
        elastic.enabled,
        elastic.gain,
        elastic.response.impact_threshold,
    ) {
        log::error!("dcr-bevy: elastic entity {entity}: its DcrElastic settings: {e}");
    }
}

/// Checks the step, makes the world's h and gravity bevy_rapier's, reads rapier's contacts, steps the world, applies its impulses before
/// bevy_rapier's writeback and writes one [`DcrResponse`] message per impulse.
#[allow(clippy::too_many_arguments)]
pub(crate) fn dcr_after_step(
    mut dcr: ResMut<DcrContext>,
    mut status: ResMut<DcrStatus>,
    guard: Res<StepGuard>,
    ticks: SystemChangeTick,
    mode: Res<TimestepMode>,
    fixed: Res<Time<Fixed>>,
    mut context: Query<
        (
            Ref<RapierContextSimulation>,
            &RapierContextColliders,
            &mut RapierRigidBodySet,
            &RapierConfiguration,
        ),
        With<DefaultRapierContext>,
    >,
    mut writer: MessageWriter<DcrResponse>,
    mut buffer: Local<Vec<DcrResponse>>,
    mut warned_fixed: Local<bool>,
) {
    let refusal = 'check: {
        let Ok((sim, _, _, config)) = context.single_mut() else {
            break 'check Some(DcrRefusal::NoContext);
        };
        if !config.physics_pipeline_active {
            status.paused_steps += 1;
            return;
        }
        if !matches!(*mode, TimestepMode::Fixed { substeps: 1, .. }) {
            break 'check Some(DcrRefusal::TimestepMode {
                found: format!("{:?}", *mode),
                h: dcr.h(),
            });
        }
        let stepped = guard
            .before
            .is_some_and(|before| sim.last_changed().is_newer_than(before, ticks.this_run()));
        if !stepped {
            break 'check Some(DcrRefusal::NotStepped);
        }
        // The rails: h follows rapier's dt (responses re-derived, a warning once per change),
        // gravity follows bevy_rapier's.
        let dt = f64::from(sim.integration_parameters.dt);
        if !dcr.sync(dt, config.gravity) {
            break 'check Some(DcrRefusal::StepLength { dt, h: dcr.h() });
        }
        None
    };
    let h = dcr.h();
    if let Some(reason) = refusal {
        if status.last_refusal.as_ref() != Some(&reason) {
            log::error!("dcr-bevy: response refused: {reason}");
        }
        status.refused_steps += 1;
        status.last_refusal = Some(reason);
        return;
    }
    if !*warned_fixed && !same_step(fixed.timestep().as_secs_f64(), h) {
        *warned_fixed = true;
        log::warn!(
            "dcr-bevy: Time<Fixed> runs every {} s but rapier steps by h = {h} s: the \
             simulation runs at {:.3}× real time (DcrPlugin sets Time<Fixed> to h at build)",
            fixed.timestep().as_secs_f64(),
            h / fixed.timestep().as_secs_f64()
        );
    }
    let Ok((sim, colliders, mut bodies, _)) = context.single_mut() else {
        return;
    };
    buffer.clear();
    dcr.after_step(
        &mut bodies.bodies,
        &colliders.colliders,
        &sim.narrow_phase,
        &mut buffer,
    );
    status.steps += 1;
    status.total_events += buffer.len() as u64;
    writer.write_batch(buffer.drain(..));
}
