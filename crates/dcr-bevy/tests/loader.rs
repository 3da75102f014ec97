//! The `.modes` asset loader and the attachment of elastic entities: a valid base becomes an
//! elastic object (`DcrObject`); a corrupt or missing base, or an entity without a rigid body,
//! gets `DcrElasticFailed` with a reason that names the asset, and never panics.

use std::path::Path;
use std::time::{Duration, Instant};

use bevy::asset::AssetPlugin;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_rapier3d::prelude::*;
use dcr_bevy::dcr_rapier::f32::AdapterParams;
use dcr_bevy::dcr_rapier::WorldParams;
use dcr_bevy::{DcrContext, DcrElastic, DcrElasticFailed, DcrObject, DcrPlugin, ModesAsset};

fn app(assets: &Path) -> App {
    let plugin = DcrPlugin::new(
        WorldParams {
            h: 0.01,
            ..WorldParams::default()
        },
        AdapterParams::default(),
    )
    .expect("valid parameters");
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        TransformPlugin,
        AssetPlugin {
            file_path: assets.display().to_string(),
            ..AssetPlugin::default()
        },
        RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule(),
        plugin,
    ))
    .insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    app
}

/// Spawns a fixed slab with a `DcrElastic` of asset `path` (with a rigid body or not) and
/// updates until the plugin decided; returns the entity.
fn attach(app: &mut App, path: &str, rigid_body: bool) -> Entity {
    let base = app
        .world()
        .resource::<AssetServer>()
        .load::<ModesAsset>(path.to_string());
    let mut e = app.world_mut().spawn((
        Collider::cuboid(0.5, 0.3, 0.05),
        Transform::IDENTITY,
        DcrElastic::new(base),
    ));
    if rigid_body {
        e.insert(RigidBody::Fixed);
    }
    let e = e.id();
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(60) {
        app.update();
        let w = app.world();
        if w.get::<DcrObject>(e).is_some() || w.get::<DcrElasticFailed>(e).is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    e
}

#[test]
fn a_valid_base_loads_and_becomes_an_elastic_object() {
    let dir = tempfile::tempdir().unwrap();
    dcr_runtime::testing::plate_base()
        .write_atomic(&dir.path().join("plate.modes"))
        .unwrap();
    let mut app = app(dir.path());
    let e = attach(&mut app, "plate.modes", true);
    let w = app.world();
    assert!(
        w.get::<DcrElasticFailed>(e).is_none(),
        "{:?}",
        w.get::<DcrElasticFailed>(e)
    );
    let handle = w.get::<DcrObject>(e).expect("attached").0;
    let ctx = w.resource::<DcrContext>();
    assert_eq!(ctx.entity_of(handle), Some(e));
    assert_eq!(ctx.world().num_objects(), 1);
    let base = &w.get::<DcrElastic>(e).unwrap().base;
    let asset = w.resource::<Assets<ModesAsset>>().get(base).unwrap();
    assert_eq!(asset.model.num_modes(), 8);
}

#[test]
fn a_corrupt_or_missing_base_is_reported_on_the_entity() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.modes"), b"not a zip archive at all").unwrap();
    let mut bytes = Vec::new();
    let full = dir.path().join("full.modes");
    dcr_runtime::testing::plate_base()
        .write_atomic(&full)
        .unwrap();
    bytes.extend(std::fs::read(&full).unwrap());
    bytes.truncate(bytes.len() / 2);
    std::fs::write(dir.path().join("truncated.modes"), &bytes).unwrap();
    let mut app = app(dir.path());
    for name in ["bad.modes", "truncated.modes", "missing.modes"] {
        let e = attach(&mut app, name, true);
        let failed = app
            .world()
            .get::<DcrElasticFailed>(e)
            .unwrap_or_else(|| panic!("{name}: no DcrElasticFailed"));
        assert!(failed.reason.contains(name), "{name}: {}", failed.reason);
        assert!(app.world().get::<DcrObject>(e).is_none());
    }
    assert_eq!(
        app.world().resource::<DcrContext>().world().num_objects(),
        0
    );
}

#[test]
fn an_elastic_entity_without_a_rigid_body_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    dcr_runtime::testing::plate_base()
        .write_atomic(&dir.path().join("plate.modes"))
        .unwrap();
    let mut app = app(dir.path());
    let e = attach(&mut app, "plate.modes", false);
    let failed = app.world().get::<DcrElasticFailed>(e).expect("reported");
    assert!(failed.reason.contains("RigidBody"), "{}", failed.reason);
}
