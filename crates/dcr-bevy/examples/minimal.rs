//! The smallest dcr-bevy app: the snippet of docs/engine-integration.md ("Bevy"), verbatim
//! from `use` to the end (tests/docs_snippet.rs checks it). Needs `out/bases/table.modes`
//! (`cargo run --release -p dcr-bevy --example dinner` bakes it); runs for 3 s of real time.

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use dcr_bevy::dcr_rapier::{ResponseParams, WorldParams};
use dcr_bevy::{DcrElastic, DcrPlugin, DcrPluginError, DcrResponse, DcrSet, ModesAsset};

fn main() -> Result<(), DcrPluginError> {
    // The world's step h (s): the plugin makes it bevy_rapier's fixed dt and Time<Fixed>'s period.
    let dcr = DcrPlugin::new(
        WorldParams {
            h: 0.01,
            ..default()
        },
        default(),
    )?;
    App::new()
        .add_plugins((
            MinimalPlugins, // or DefaultPlugins
            TransformPlugin,
            AssetPlugin {
                file_path: "out/bases".into(),
                ..default()
            },
            // Required: bevy_rapier in FixedUpdate (one rapier step per fixed update).
            RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule(),
            dcr,
        ))
        .add_systems(Startup, spawn)
        .add_systems(FixedUpdate, print_responses.after(DcrSet::AfterStep))
        .add_systems(Update, quit_after_3_s)
        .run();
    Ok(())
}

fn spawn(mut commands: Commands, assets: Res<AssetServer>) {
    // The elastic table: a fixed body placed where the baked mesh is (the base's object frame
    // is the body's local frame), its collision shapes in that frame, and its base.
    let mut table = DcrElastic::new(assets.load::<ModesAsset>("table.modes"));
    table.response = ResponseParams {
        impact_threshold: 0.5,
        max_map_distance: 0.1,
        ..default()
    };
    commands.spawn((
        RigidBody::Fixed,
        Transform::IDENTITY,
        table,
        children![(
            Collider::cuboid(0.8, 0.02, 0.45),
            Transform::from_xyz(0.0, 0.73, 0.0)
        )],
    ));
    // A plate resting on it (a Velocity component is fine), and a pot dropped elsewhere.
    commands.spawn((
        RigidBody::Dynamic,
        Velocity::zero(),
        Collider::cylinder(0.008, 0.11),
        ColliderMassProperties::Mass(0.5),
        Transform::from_xyz(0.6, 0.758, 0.25),
    ));
    commands.spawn((
        RigidBody::Dynamic,
        Velocity::linear(Vec3::new(0.0, -1.0, 0.0)),
        Collider::cylinder(0.1, 0.13),
        ColliderMassProperties::Mass(5.0),
        Transform::from_xyz(0.05, 1.25, 0.0),
    ));
}

// Each response impulse the plugin applied in this fixed update (already in the velocities).
fn print_responses(mut responses: MessageReader<DcrResponse>) {
    for r in responses.read() {
        println!(
            "{} pushed by {} N·s at {} (Δv {} m/s)",
            r.body, r.impulse, r.point, r.delta_v
        );
    }
}

fn quit_after_3_s(time: Res<Time>, mut exit: MessageWriter<AppExit>) {
    if time.elapsed_secs() > 3.0 {
        exit.write(AppExit::Success);
    }
}
