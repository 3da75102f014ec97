//! The lifecycle calls and the per-step rails add no allocation to the adapter's step.
//!
//! Expectation: on the scene of `no_alloc.rs` (ten boxes resting on an elastic plate, a heavy
//! ball kicked up every 0.5 s) with a second elastic plate beside it, once warm, the steps
//! allocate nothing while, between them, the first plate is disabled and enabled again and its
//! gain and impact threshold change, after the second plate was removed, with rapier's dt
//! re-checked every step (`sync_timestep`, same dt) and gravity re-set (`set_gravity`); the
//! setters and the rails themselves allocate nothing either, and the responses keep reaching
//! the boxes after all of it. The lifecycle sequence runs twice: the first time (with the
//! removal, a set-up-time call) warms the buffers up to its counts, the second is counted. rapier's own step is
//! not counted, nor the first `get_mut` of a body after it (see `no_alloc.rs`). Counted with a
//! global allocator wrapper; this file is its own test binary with a single test.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use dcr_rapier::dcr_runtime::testing::plate_base;
use dcr_rapier::{ElasticObjectDesc, ModalModel, WorldParams};

struct Counting;

static ALLOCS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocs() -> usize {
    ALLOCS.load(Ordering::Relaxed)
}

/// What one run counted.
#[derive(Debug, Default)]
struct Counted {
    /// Allocations in the adapter's step halves after warm-up.
    steps: usize,
    /// Allocations in the setters and the rails (`sync_timestep`, `set_gravity`).
    calls: usize,
    /// Response events on the boxes after the lifecycle calls.
    events_after: usize,
}

fn run(gate: dcr_rapier::f64::StepGate) -> Counted {
    use dcr_rapier::f64::rapier::prelude::*;
    use dcr_rapier::f64::{AdapterParams, ApplyMode, DcrRapier};

    let mut world = PhysicsWorld::default();
    world.integration_parameters.dt = 0.01;
    world.gravity = Vector::new(0.0, 0.0, -9.81);
    let model = Arc::new(ModalModel::from_base(plate_base()).expect("base"));
    let mut dcr = DcrRapier::new(
        WorldParams::default(),
        AdapterParams {
            apply: ApplyMode::AfterStep,
            gate,
            ..AdapterParams::default()
        },
    )
    .expect("adapter");
    let mut plates = Vec::new();
    for x0 in [0.0, 3.0] {
        let plate =
            world.insert_body(RigidBodyBuilder::fixed().translation(Vector::new(x0, 0.0, 0.0)));
        world.insert_collider(
            ColliderBuilder::cuboid(0.5, 0.3, 0.05).translation(Vector::new(0.5, 0.3, -0.05)),
            Some(plate),
        );
        plates.push(
            dcr.add_object(
                &world.bodies,
                &mut world.colliders,
                plate,
                ElasticObjectDesc::new(model.clone(), 0),
            )
            .expect("object"),
        );
    }
    let (a, b) = (plates[0], plates[1]);
    let mut boxes = Vec::new();
    for i in 0..10 {
        let (x, y) = (
            0.1 + 0.09 * f64::from(i),
            if i % 2 == 0 { 0.1 } else { 0.5 },
        );
        let bx =
            world.insert_body(RigidBodyBuilder::dynamic().translation(Vector::new(x, y, 0.04)));
        world.insert_collider(
            ColliderBuilder::cuboid(0.03, 0.03, 0.03).mass(0.2),
            Some(bx),
        );
        boxes.push(bx);
    }
    // A box on the second plate too, so that it has contacts until it is removed.
    let other =
        world.insert_body(RigidBodyBuilder::dynamic().translation(Vector::new(3.5, 0.3, 0.04)));
    world.insert_collider(
        ColliderBuilder::cuboid(0.03, 0.03, 0.03).mass(0.2),
        Some(other),
    );
    let ball =
        world.insert_body(RigidBodyBuilder::dynamic().translation(Vector::new(0.5, 0.3, 0.1)));
    world.insert_collider(ColliderBuilder::ball(0.1).mass(10.0), Some(ball));
    let dynamic: Vec<RigidBodyHandle> = world
        .bodies
        .iter()
        .filter(|(_, b)| b.is_dynamic())
        .map(|(h, _)| h)
        .collect();

    let mut counted = Counted::default();
    for k in 0..1400 {
        if k % 50 == 20 {
            world.bodies[ball].apply_impulse(Vector::new(0.0, 0.0, 20.0), true);
        }
        // The lifecycle calls, between steps, after warm-up.
        let c0 = allocs();
        match k {
            500 | 900 => dcr.set_object_enabled(a, false).expect("live handle"),
            560 | 960 => dcr.set_object_enabled(a, true).expect("live handle"),
            620 | 1020 => dcr
                .set_object_gain(a, if k < 800 { 1.2 } else { 1.5 })
                .expect("live handle"),
            680 | 1080 => dcr.set_object_threshold(a, 0.2).expect("live handle"),
            _ => {}
        }
        dcr.sync_timestep(world.integration_parameters.dt);
        dcr.set_gravity(world.gravity);
        let c1 = allocs();
        if k == 740 {
            dcr.remove_object(b).expect("live handle");
        }
        let before = allocs();
        dcr.before_step(&mut world.bodies);
        let mid = allocs();
        world.step_with_events(dcr.hooks(), &());
        for &h in &dynamic {
            let _ = world.bodies.get_mut(h);
        }
        let mid2 = allocs();
        let events = dcr.after_step(&mut world.bodies, &world.colliders, &world.narrow_phase);
        let on_boxes = events
            .iter()
            .filter(|e| boxes.iter().any(|&h| dcr_rapier::f64::body_id(h) == e.body))
            .count();
        let after = allocs();
        if k >= 800 {
            counted.steps += (mid - before) + (after - mid2);
            counted.calls += c1 - c0;
        }
        if k > 960 {
            counted.events_after += on_boxes;
        }
    }
    assert!(!dcr.world().contains(b), "the second plate is gone");
    assert_eq!(dcr.world().gain(a), 1.5);
    counted
}

#[test]
fn lifecycle_calls_and_rails_add_no_allocation_to_the_step() {
    use dcr_rapier::f64::StepGate;
    for (name, gate) in [
        ("every step", StepGate::EveryStep),
        ("impact steps", StepGate::ImpactSteps),
    ] {
        let c = run(gate);
        assert!(
            c.events_after > 50,
            "{name}: responses reach the boxes after the lifecycle calls: {c:?}"
        );
        assert_eq!(c.steps, 0, "{name}: allocations in the warm steps: {c:?}");
        assert_eq!(
            c.calls, 0,
            "{name}: allocations in the setters and rails: {c:?}"
        );
    }
}
