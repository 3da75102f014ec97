//! The elastic object's life in a Bevy app: it follows its entity and its `DcrElastic`.
//!
//! - despawning the table right after its first response (a run without the despawn answers
//!   more impacts later) removes its object: no response after it, the handle stale, no error
//!   logged, the plugin keeps stepping;
//! - removing the `DcrElastic` component removes the object and its `DcrObject`; inserting one
//!   again adds a new object (next generation);
//! - `enabled = false` on the component silences the table (the plates stay put) and the world
//!   counts the disabled steps; `gain = 2` set after the object was added doubles the first
//!   response (same step, same state).
//!
//! The dinner scene of `examples/dinner.rs`, headless; the base baked once into
//! `CARGO_TARGET_TMPDIR`.

// The velocity records of the example are read by tests/dinner.rs only.
#[allow(dead_code)]
#[path = "../examples/dinner.rs"]
mod dinner;

use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

use bevy::prelude::*;
use dcr_bevy::{DcrContext, DcrElastic, DcrObject, DcrResponse, DcrSet, DcrStatus, ModesAsset};

fn bases() -> PathBuf {
    static BASES: OnceLock<PathBuf> = OnceLock::new();
    BASES
        .get_or_init(|| {
            let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bases");
            dinner::table_base(&dir).expect("the table's base bakes");
            dir
        })
        .clone()
}

/// Every warning and error logged through `log` in this test binary.
static LOGGED: Mutex<Vec<String>> = Mutex::new(Vec::new());

struct Capture;

impl log::Log for Capture {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record) {
        if self.enabled(r.metadata()) {
            if let Ok(mut v) = LOGGED.lock() {
                v.push(format!("{} {}: {}", r.level(), r.target(), r.args()));
            }
        }
    }
    fn flush(&self) {}
}

fn capture_logs() {
    static ONCE: OnceLock<()> = OnceLock::new();
    ONCE.get_or_init(|| {
        let _ = log::set_logger(&Capture);
        log::set_max_level(log::LevelFilter::Warn);
    });
}

/// The responses received, with the fixed update they arrived in.
#[derive(Resource, Default)]
struct Received {
    update: u32,
    messages: Vec<(u32, DcrResponse)>,
}

fn receive(mut messages: MessageReader<DcrResponse>, mut received: ResMut<Received>) {
    received.update += 1;
    let update = received.update;
    received
        .messages
        .extend(messages.read().map(|&m| (update, m)));
}

/// The dinner app with the plugin, the base loaded and the scene spawned; returns the app and
/// the table entity.
fn dinner_app() -> (App, Entity) {
    capture_logs();
    let mut app = dinner::headless_app(&bases(), true);
    app.init_resource::<Received>()
        .add_systems(FixedUpdate, receive.after(DcrSet::AfterStep));
    let handle = app
        .world()
        .resource::<AssetServer>()
        .load::<ModesAsset>("table.modes");
    dinner::wait_for_base(&mut app, &handle).expect("the base loads");
    dinner::spawn_dinner(app.world_mut(), Some(handle), false);
    let world = app.world_mut();
    let table = world
        .query_filtered::<Entity, With<DcrElastic>>()
        .single(world)
        .expect("one table");
    (app, table)
}

fn updates(app: &mut App, n: u32) {
    for _ in 0..n {
        app.update();
    }
}

fn object_of(app: &App, entity: Entity) -> Option<DcrObject> {
    app.world().get::<DcrObject>(entity).copied()
}

#[test]
fn despawning_the_table_mid_run_removes_its_object() {
    // Reference: the table answers more impacts after its first response.
    let (mut app, _) = dinner_app();
    updates(&mut app, 100);
    let reference = app.world().resource::<Received>().messages.clone();
    let first = reference.first().expect("the pot's landing is answered").0;
    assert!(
        reference.iter().any(|&(u, _)| u > first),
        "responses after the first update with one: {reference:?}"
    );

    // Despawned right after its first response.
    let (mut app, table) = dinner_app();
    let mut n = 0;
    while app.world().resource::<Received>().messages.is_empty() {
        app.update();
        n += 1;
        assert!(n < 100, "no response within 1 s");
    }
    assert_eq!(app.world().resource::<Received>().update, first);
    let handle = object_of(&app, table).expect("the table's object").0;
    let steps_before = app.world().resource::<DcrStatus>().steps;
    let received_before = app.world().resource::<Received>().messages.len();
    let logged_before = LOGGED.lock().unwrap().len();

    app.world_mut().entity_mut(table).despawn();
    updates(&mut app, 100 - first);

    let received = app.world().resource::<Received>();
    assert_eq!(
        received.messages.len(),
        received_before,
        "responses after the despawn: {:?}",
        &received.messages[received_before..]
    );
    let ctx = app.world().resource::<DcrContext>();
    assert_eq!(ctx.world().num_objects(), 0);
    assert!(!ctx.world().contains(handle), "the handle is stale");
    assert_eq!(ctx.entity_of(handle), None);
    let status = app.world().resource::<DcrStatus>();
    assert_eq!(status.refused_steps, 0, "{status:?}");
    assert!(
        status.steps >= steps_before + u64::from(100 - first) - 1,
        "{status:?}"
    );
    let logged = LOGGED.lock().unwrap();
    let new: Vec<&String> = logged[logged_before..]
        .iter()
        .filter(|l| l.contains("does not exist") || l.contains("elastic object"))
        .collect();
    assert!(new.is_empty(), "errors after the despawn: {new:?}");
}

#[test]
fn removing_and_reinserting_the_component_replaces_the_object() {
    let (mut app, table) = dinner_app();
    updates(&mut app, 5);
    let first = object_of(&app, table).expect("the table's object").0;
    let component = app
        .world()
        .get::<DcrElastic>(table)
        .expect("DcrElastic")
        .clone();

    // Removed before the pot lands: no object, no response, the plates stay put.
    app.world_mut().entity_mut(table).remove::<DcrElastic>();
    updates(&mut app, 60);
    assert_eq!(object_of(&app, table), None, "DcrObject removed with it");
    let ctx = app.world().resource::<DcrContext>();
    assert_eq!(ctx.world().num_objects(), 0);
    assert!(!ctx.world().contains(first));
    assert!(app.world().resource::<Received>().messages.is_empty());

    // Inserted again: a new object in the same slot, next generation.
    app.world_mut().entity_mut(table).insert(component);
    updates(&mut app, 2);
    let second = object_of(&app, table).expect("a new object").0;
    assert_eq!(second.index(), first.index());
    assert_ne!(second, first);
    let ctx = app.world().resource::<DcrContext>();
    assert!(ctx.world().contains(second) && !ctx.world().contains(first));
    assert_eq!(ctx.entity_of(second), Some(table));
}

#[test]
fn disabling_silences_the_table_and_gain_scales_its_response() {
    // Reference: the first response with the defaults.
    let (mut app, _) = dinner_app();
    updates(&mut app, 100);
    let reference = app.world().resource::<Received>().messages.clone();
    assert!(!reference.is_empty(), "the pot's landing is answered");

    // Disabled after the object was added, before the landing.
    let (mut app, table) = dinner_app();
    updates(&mut app, 5);
    let handle = object_of(&app, table).expect("the object").0;
    app.world_mut()
        .get_mut::<DcrElastic>(table)
        .expect("DcrElastic")
        .enabled = false;
    updates(&mut app, 95);
    assert!(
        app.world().resource::<Received>().messages.is_empty(),
        "a disabled table answers nothing"
    );
    let ctx = app.world().resource::<DcrContext>();
    assert!(!ctx.world().is_enabled(handle));
    let totals = ctx.world().object_totals(handle);
    assert!(totals.disabled_steps >= 90, "{totals:?}");
    assert_eq!(totals.events, 0, "{totals:?}");

    // Gain 2 set after the object was added: the same first response, twice the Δv.
    let (mut app, table) = dinner_app();
    updates(&mut app, 5);
    app.world_mut()
        .get_mut::<DcrElastic>(table)
        .expect("DcrElastic")
        .gain = 2.0;
    updates(&mut app, 95);
    let doubled = app.world().resource::<Received>().messages.clone();
    let (at, first) = reference[0];
    let (at2, first2) = doubled[0];
    assert_eq!(at, at2, "the first response comes at the same step");
    assert_eq!(first.body, first2.body);
    assert!(
        (first2.delta_v - 2.0 * first.delta_v).abs() <= 1e-4 * first.delta_v,
        "Δv {} with gain 2 vs {} with gain 1",
        first2.delta_v,
        first.delta_v
    );
}
