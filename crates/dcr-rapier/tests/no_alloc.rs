//! `DcrRapier::before_step` / `after_step` perform no heap allocation after warm-up.
//!
//! Expectation: on a rapier world with ten boxes resting on an elastic plate and a heavy ball
//! kicked up every 0.5 s (an impact on every landing, responses to every box), once every
//! buffer has seen the largest counts, the adapter's per-step calls allocate nothing — after the
//! step and in the solver (seeds, pair marks, hook), reading every step or gated by force
//! events (flagged pairs, load memory, quiet steps), f64 and f32. rapier's own `step` is not
//! counted, nor is rapier's list of modified bodies: `RigidBodySet` hands that list to the
//! step by value (`mem::take`) and rebuilds it from empty, so the first `get_mut` of a body
//! after every step allocates whoever calls it; the test touches every dynamic body right after
//! the step so that only the adapter's own allocations remain. Counted with a global allocator
//! wrapper; this file is its own test binary and holds a single test so no other test thread
//! allocates concurrently.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use dcr_rapier::dcr_runtime::testing::plate_base;
use dcr_rapier::{ElasticObjectDesc, ModalModel, WorldParams};

struct Counting;

static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc_zeroed(layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

macro_rules! run_backend {
    ($m:ident, $apply:ident, $gate:ident) => {{
        use dcr_rapier::$m::rapier::prelude::*;
        use dcr_rapier::$m::{AdapterParams, ApplyMode, DcrRapier, StepGate};

        let mut world = PhysicsWorld::default();
        world.integration_parameters.dt = 0.01;
        world.gravity = Vector::new(0.0, 0.0, -9.81);
        let plate = world.insert_body(RigidBodyBuilder::fixed());
        world.insert_collider(
            ColliderBuilder::cuboid(0.5, 0.3, 0.05).translation(Vector::new(0.5, 0.3, -0.05)),
            Some(plate),
        );
        let model = Arc::new(ModalModel::from_base(plate_base()).expect("base"));
        let mut dcr = DcrRapier::new(
            WorldParams::default(),
            AdapterParams {
                apply: ApplyMode::$apply,
                gate: StepGate::$gate,
                ..AdapterParams::default()
            },
        )
        .expect("adapter");
        dcr.add_object(
            &world.bodies,
            &mut world.colliders,
            plate,
            ElasticObjectDesc::new(model, 0),
        )
        .expect("object");
        for i in 0..10 {
            let (x, y) = (0.1 + 0.09 * i as f32, if i % 2 == 0 { 0.1 } else { 0.5 });
            let b = world.insert_body(
                RigidBodyBuilder::dynamic().translation(Vector::new(x as _, y as _, 0.04)),
            );
            world.insert_collider(ColliderBuilder::cuboid(0.03, 0.03, 0.03).mass(0.2), Some(b));
        }
        let ball =
            world.insert_body(RigidBodyBuilder::dynamic().translation(Vector::new(0.5, 0.3, 0.1)));
        let dynamic: Vec<RigidBodyHandle> = world
            .bodies
            .iter()
            .filter(|(_, b)| b.is_dynamic())
            .map(|(h, _)| h)
            .collect();
        world.insert_collider(ColliderBuilder::ball(0.1).mass(10.0), Some(ball));
        let mut counted = 0;
        let mut events = 0;
        for k in 0..1200 {
            if k % 50 == 20 {
                world.bodies[ball].apply_impulse(Vector::new(0.0, 0.0, 20.0), true);
            }
            let before = ALLOCS.load(Ordering::Relaxed);
            dcr.before_step(&mut world.bodies);
            let mid = ALLOCS.load(Ordering::Relaxed);
            world.step_with_events(dcr.hooks(), &());
            for &h in &dynamic {
                let _ = world.bodies.get_mut(h);
            }
            let mid2 = ALLOCS.load(Ordering::Relaxed);
            events += dcr
                .after_step(&mut world.bodies, &world.colliders, &world.narrow_phase)
                .len();
            let after = ALLOCS.load(Ordering::Relaxed);
            if k >= 400 {
                counted += (mid - before) + (after - mid2);
            }
        }
        (counted, events)
    }};
}

#[test]
fn adapter_steps_do_not_allocate_after_warm_up() {
    let runs = [
        ("f64 after step", run_backend!(f64, AfterStep, EveryStep)),
        ("f64 in solver", run_backend!(f64, InSolver, EveryStep)),
        (
            "f64 after step, gated",
            run_backend!(f64, AfterStep, ImpactSteps),
        ),
        (
            "f64 in solver, gated",
            run_backend!(f64, InSolver, ImpactSteps),
        ),
        ("f32 after step", run_backend!(f32, AfterStep, EveryStep)),
        (
            "f32 in solver, gated",
            run_backend!(f32, InSolver, ImpactSteps),
        ),
    ];
    for (name, (allocs, events)) in runs {
        assert!(
            events > 100,
            "{name}: the impacts reach the boxes ({events} events)"
        );
        assert_eq!(allocs, 0, "{name}: {allocs} allocations in 800 warm steps");
    }
}
