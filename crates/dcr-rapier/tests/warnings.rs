//! The adapter's warnings through the `log` crate (its own test binary: one global logger).
//!
//! Expectations: an elastic object whose contacts lie far from its base's surface (here its
//! collider sits 0.5 m below the base's face, as a base in another frame would) gets its
//! unmapped contacts counted in the world's totals and exactly one warning, however many
//! impacts follow; rapier's dt other than the world's h is warned once; an adapter stepped
//! with `after_step` whose world was never given rapier's gravity is warned once (one stepped
//! with `DcrRapier::step`, which gives it, is not).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use dcr_rapier::dcr_runtime::testing::plate_base;
use dcr_rapier::f64::rapier::prelude::*;
use dcr_rapier::f64::{AdapterParams, DcrRapier, StepGate};
use dcr_rapier::{ElasticObjectDesc, ModalModel, WorldParams};

static UNMAPPED: AtomicUsize = AtomicUsize::new(0);
static TIMESTEP: AtomicUsize = AtomicUsize::new(0);
static GRAVITY: AtomicUsize = AtomicUsize::new(0);
static LAST: Mutex<String> = Mutex::new(String::new());

struct Counter;

impl log::Log for Counter {
    fn enabled(&self, _: &log::Metadata<'_>) -> bool {
        true
    }
    fn log(&self, r: &log::Record<'_>) {
        if r.level() > log::Level::Warn || r.target() != "dcr_rapier" {
            return;
        }
        let text = r.args().to_string();
        if text.contains("max_map_distance") {
            UNMAPPED.fetch_add(1, Ordering::SeqCst);
        }
        if text.contains("rapier's dt") {
            TIMESTEP.fetch_add(1, Ordering::SeqCst);
        }
        if text.contains("never given rapier's gravity") {
            GRAVITY.fetch_add(1, Ordering::SeqCst);
        }
        *LAST.lock().unwrap() = text;
    }
    fn flush(&self) {}
}

static LOGGER: Counter = Counter;

#[test]
fn unmapped_contacts_and_a_wrong_step_are_warned_once() {
    log::set_logger(&LOGGER).unwrap();
    log::set_max_level(log::LevelFilter::Warn);
    let mut world = PhysicsWorld::default();
    world.integration_parameters.dt = 0.01;
    world.gravity = Vector::new(0.0, 0.0, -9.81);
    let plate = world.insert_body(RigidBodyBuilder::fixed());
    // The slab's top at z = -0.5: every contact is 0.5 m from the base's face (z = 0).
    let slab = ColliderBuilder::cuboid(0.5, 0.3, 0.05).translation(Vector::new(0.5, 0.3, -0.55));
    world.insert_collider(slab, Some(plate));
    let params = WorldParams {
        h: 0.02,
        ..WorldParams::default()
    };
    let adapter = AdapterParams {
        gate: StepGate::EveryStep,
        ..AdapterParams::default()
    };
    let mut dcr = DcrRapier::new(params, adapter).unwrap();
    let model = Arc::new(ModalModel::from_base(plate_base()).unwrap());
    let h = dcr
        .add_object(
            &world.bodies,
            &mut world.colliders,
            plate,
            ElasticObjectDesc::new(model, 0),
        )
        .unwrap();
    let b =
        world.insert_body(RigidBodyBuilder::dynamic().translation(Vector::new(0.85, 0.3, -0.47)));
    world.insert_collider(ColliderBuilder::ball(0.03).mass(0.2), Some(b));
    for _ in 0..30 {
        dcr.step(&mut world);
    }
    assert_eq!(TIMESTEP.load(Ordering::SeqCst), 1, "dt ≠ h warned once");
    for drop in 0..3 {
        let ball = world.insert_body(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.25 + 0.1 * drop as f64, 0.3, -0.2))
                .linvel(Vector::new(0.0, 0.0, -3.0)),
        );
        world.insert_collider(ColliderBuilder::ball(0.1).density(5000.0), Some(ball));
        for _ in 0..30 {
            assert!(dcr.step(&mut world).is_empty(), "unmapped: no response");
        }
    }
    let t = dcr.world().object_totals(h);
    assert!(t.impacts >= 3, "{t:?}");
    assert!(t.contacts_unmapped + t.impacts_unmapped >= 3, "{t:?}");
    assert_eq!(
        UNMAPPED.load(Ordering::SeqCst),
        1,
        "one warning per object: {}",
        LAST.lock().unwrap()
    );
    assert_eq!(TIMESTEP.load(Ordering::SeqCst), 1);
    assert_eq!(
        GRAVITY.load(Ordering::SeqCst),
        0,
        "DcrRapier::step gives the gravity"
    );
    assert_eq!(dcr.world().params().gravity, [0.0, 0.0, -9.81]);

    // Stepped by hand without set_gravity: the world has none, and says so once.
    let mut world = PhysicsWorld::default();
    world.integration_parameters.dt = 0.01;
    world.gravity = Vector::new(0.0, 0.0, -9.81);
    let mut dcr = DcrRapier::new(WorldParams::default(), AdapterParams::default()).unwrap();
    assert_eq!(dcr.world().params().gravity, [0.0; 3]);
    for _ in 0..3 {
        dcr.before_step(&mut world.bodies);
        world.step_with_events(dcr.hooks(), &());
        dcr.after_step(&mut world.bodies, &world.colliders, &world.narrow_phase);
    }
    assert_eq!(
        GRAVITY.load(Ordering::SeqCst),
        1,
        "{}",
        LAST.lock().unwrap()
    );
    dcr.set_gravity(world.gravity);
    assert_eq!(dcr.world().params().gravity, [0.0, 0.0, -9.81]);
}
