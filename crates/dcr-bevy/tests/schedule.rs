//! The plugin's schedule rails, and why its impulses go in before bevy_rapier's writeback.
//!
//! - a bevy_rapier that does not step in `FixedUpdate`, a variable timestep, or substeps are
//!   refused (no response, the reason in `DcrStatus`);
//! - another fixed step is followed: the world's h becomes rapier's dt; the world's gravity
//!   is bevy_rapier's, also after it changes;
//! - the in-solver application mode is refused at construction;
//! - on plain bevy_rapier: an impulse given to a body with a `Velocity` component after the
//!   writeback is lost at the next step, the same impulse given between the step and the
//!   writeback (where `DcrSet::AfterStep` runs) is kept.

use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_rapier3d::prelude::*;
use dcr_bevy::dcr_rapier::f32::{AdapterParams, ApplyMode};
use dcr_bevy::dcr_rapier::WorldParams;
use dcr_bevy::{DcrContext, DcrPlugin, DcrPluginError, DcrRefusal, DcrStatus};

const H: f64 = 0.01;

fn plugin() -> DcrPlugin {
    DcrPlugin::new(
        WorldParams {
            h: H,
            ..WorldParams::default()
        },
        AdapterParams::default(),
    )
    .expect("valid parameters")
}

fn app(rapier: RapierPhysicsPlugin<NoUserData>) -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin, rapier, plugin()))
        .insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    // What `App::run` does first: the plugin adds bevy's AssetPlugin here when it is missing.
    app.finish();
    app.cleanup();
    app
}

fn status_after(app: &mut App, updates: usize) -> DcrStatus {
    for _ in 0..updates {
        app.update();
    }
    app.world().resource::<DcrStatus>().clone()
}

#[test]
fn a_fixed_one_step_schedule_is_accepted() {
    let mut app = app(RapierPhysicsPlugin::default().in_fixed_schedule());
    let s = status_after(&mut app, 10);
    assert_eq!(s.refused_steps, 0, "{s:?}");
    assert!(s.steps >= 9, "{s:?}");
    assert_eq!(
        *app.world().resource::<TimestepMode>(),
        TimestepMode::Fixed {
            dt: H as f32,
            substeps: 1
        }
    );
    assert_eq!(
        app.world()
            .resource::<Time<Fixed>>()
            .timestep()
            .as_secs_f64(),
        H
    );
}

#[test]
fn bevy_rapier_outside_fixed_update_is_refused() {
    let mut app = app(RapierPhysicsPlugin::default()); // PostUpdate
    let s = status_after(&mut app, 10);
    assert_eq!(s.steps, 0, "{s:?}");
    assert!(s.refused_steps >= 9, "{s:?}");
    assert_eq!(s.last_refusal, Some(DcrRefusal::NotStepped));
}

#[test]
fn a_variable_timestep_or_substeps_are_refused() {
    for mode in [
        TimestepMode::default(),
        TimestepMode::Fixed {
            dt: H as f32,
            substeps: 2,
        },
    ] {
        let mut app = app(RapierPhysicsPlugin::default().in_fixed_schedule());
        app.insert_resource(mode);
        let s = status_after(&mut app, 10);
        assert_eq!(s.steps, 0, "{mode:?}: {s:?}");
        assert!(s.refused_steps >= 9, "{mode:?}: {s:?}");
        assert!(
            matches!(s.last_refusal, Some(DcrRefusal::TimestepMode { h, .. }) if h == H),
            "{mode:?}: {s:?}"
        );
    }
}

#[test]
fn the_world_follows_rapiers_fixed_step_and_gravity() {
    let mut app = app(RapierPhysicsPlugin::default().in_fixed_schedule());
    let s = status_after(&mut app, 3);
    assert_eq!(s.refused_steps, 0, "{s:?}");
    let dcr = app.world().resource::<DcrContext>();
    assert_eq!(dcr.h(), H);
    // bevy_rapier's default gravity, for the support of impulses applied after the step.
    assert_eq!(
        dcr.world().params().gravity,
        [0.0, f64::from(-9.81f32), 0.0]
    );

    // Another fixed step and another gravity: followed from the next step on.
    let dt = 1.0f32 / 60.0;
    app.insert_resource(TimestepMode::Fixed { dt, substeps: 1 });
    let world = app.world_mut();
    let mut configs = world.query::<&mut RapierConfiguration>();
    configs
        .single_mut(world)
        .expect("one rapier context")
        .gravity = Vec3::new(0.0, 0.0, -3.5);
    let s = status_after(&mut app, 3);
    assert_eq!(s.refused_steps, 0, "{s:?}");
    assert!(s.steps >= 5, "{s:?}");
    let dcr = app.world().resource::<DcrContext>();
    assert_eq!(dcr.h(), f64::from(dt));
    assert_eq!(dcr.world().params().gravity, [0.0, 0.0, -3.5]);
}

#[test]
fn the_in_solver_mode_and_a_bad_step_are_refused_at_construction() {
    let in_solver = AdapterParams {
        apply: ApplyMode::InSolver,
        ..AdapterParams::default()
    };
    assert!(matches!(
        DcrPlugin::new(WorldParams::default(), in_solver),
        Err(DcrPluginError::InSolver)
    ));
    for h in [0.0, -0.01, f64::NAN] {
        let world = WorldParams {
            h,
            ..WorldParams::default()
        };
        assert!(
            matches!(
                DcrPlugin::new(world, AdapterParams::default()),
                Err(DcrPluginError::World(_))
            ),
            "h = {h}"
        );
    }
}

/// Where a test system gives the box its impulse.
#[derive(Resource, Clone, Copy, PartialEq)]
enum Kick {
    BeforeWriteback,
    AfterWriteback,
}

#[derive(Component)]
struct Boxed;

/// The box's vertical velocity in rapier at the start of each step (after `SyncBackend`).
#[derive(Resource, Default)]
struct Seen(Vec<f32>);

/// Upward impulse given once (N·s) to the 1 kg box.
const J: f32 = 0.5;
/// The fixed update on which it is given.
const KICK_AT: usize = 30;

/// Counts fixed updates and gives the box its impulse on update [`KICK_AT`] when `at` is
/// the configured place.
fn kick(
    at: Kick,
    when: &Kick,
    n: &mut usize,
    bodies: &mut Query<&mut RapierRigidBodySet>,
    boxed: &Query<&RapierRigidBodyHandle, With<Boxed>>,
) {
    if *when != at {
        return;
    }
    *n += 1;
    if *n != KICK_AT {
        return;
    }
    let (Ok(mut set), Ok(h)) = (bodies.single_mut(), boxed.single()) else {
        return;
    };
    if let Some(rb) = set.bodies.get_mut(h.0) {
        rb.apply_impulse(Vec3::new(0.0, J, 0.0), true);
    }
}

fn kick_before_writeback(
    when: Res<Kick>,
    mut n: Local<usize>,
    mut bodies: Query<&mut RapierRigidBodySet>,
    boxed: Query<&RapierRigidBodyHandle, With<Boxed>>,
) {
    kick(Kick::BeforeWriteback, &when, &mut n, &mut bodies, &boxed);
}

fn kick_after_writeback(
    when: Res<Kick>,
    mut n: Local<usize>,
    mut bodies: Query<&mut RapierRigidBodySet>,
    boxed: Query<&RapierRigidBodyHandle, With<Boxed>>,
) {
    kick(Kick::AfterWriteback, &when, &mut n, &mut bodies, &boxed);
}

fn watch(
    context: ReadRapierContext,
    boxed: Query<&RapierRigidBodyHandle, With<Boxed>>,
    mut seen: ResMut<Seen>,
) {
    let (Ok(ctx), Ok(h)) = (context.single(), boxed.single()) else {
        return;
    };
    if let Some(rb) = ctx.rigidbody_set.bodies.get(h.0) {
        seen.0.push(rb.linvel().y);
    }
}

/// The box's vertical velocity at the start of the step after the kick (m/s).
fn velocity_after_kick(when: Kick) -> f32 {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        TransformPlugin,
        RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule(),
    ))
    .insert_resource(TimestepMode::Fixed {
        dt: H as f32,
        substeps: 1,
    })
    .insert_resource(Time::<Fixed>::from_seconds(H))
    .insert_resource(TimeUpdateStrategy::FixedTimesteps(1))
    .insert_resource(when)
    .init_resource::<Seen>()
    .add_systems(
        FixedUpdate,
        (
            kick_before_writeback
                .after(PhysicsSet::StepSimulation)
                .before(PhysicsSet::Writeback),
            kick_after_writeback.after(PhysicsSet::Writeback),
            watch
                .after(PhysicsSet::SyncBackend)
                .before(PhysicsSet::StepSimulation),
        ),
    );
    app.world_mut().spawn((
        RigidBody::Fixed,
        Collider::cuboid(2.0, 0.1, 2.0),
        Transform::from_xyz(0.0, -0.1, 0.0),
    ));
    app.world_mut().spawn((
        Boxed,
        RigidBody::Dynamic,
        Collider::cuboid(0.1, 0.1, 0.1),
        ColliderMassProperties::Mass(1.0),
        Transform::from_xyz(0.0, 0.1, 0.0),
        Velocity::zero(),
    ));
    for _ in 0..KICK_AT + 5 {
        app.update();
    }
    let seen = &app.world().resource::<Seen>().0;
    // `watch` saw one value per fixed update; the kick was in update KICK_AT (1-based), so
    // the next step starts at index KICK_AT.
    seen[KICK_AT]
}

#[test]
fn an_impulse_after_the_writeback_is_lost_and_one_before_it_is_kept() {
    let kept = velocity_after_kick(Kick::BeforeWriteback);
    let lost = velocity_after_kick(Kick::AfterWriteback);
    // 0.5 N·s on 1 kg: 0.5 m/s up when kept; the box at rest on the floor otherwise.
    assert!((kept - J).abs() < 0.02, "kept: {kept} m/s");
    assert!(lost.abs() < 0.02, "lost: {lost} m/s");
}
