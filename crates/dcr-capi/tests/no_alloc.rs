//! The per-step C calls (`dcr_response_step`, `dcr_world_step`) do not allocate after warm-up:
//! a counting global allocator sees no allocation on the calling thread over many steps with
//! the same or fewer contacts, nor when, between the world's steps, an object is disabled and
//! enabled, its gain and threshold change, h is set again and another object has been removed
//! (the second run of that pattern, after a first that warms the buffers up to its counts; the
//! removal itself, a set-up-time call, is not counted).

#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use dcr_capi::*;
use dcr_runtime::testing::{plate_base, SplitMix64};

struct Counting;

thread_local! {
    static COUNT: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; only counts (thread-local, no allocation).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> u64 {
    COUNT.with(|c| c.get())
}

/// After warm-up, 200 response steps and 200 world steps with impacts, resting contacts and
/// impulse events allocate nothing.
#[test]
fn per_step_calls_do_not_allocate_after_warm_up() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plate.modes");
    plate_base().write_atomic(&path).unwrap();
    let cpath = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    let mut model = std::ptr::null_mut();
    let mut rng = SplitMix64(11);

    // Per-object response.
    let mut p = DcrResponseParams::defaults();
    p.method = DCR_METHOD_MODAL;
    let mut resp = std::ptr::null_mut();
    let resting: Vec<DcrRestingContact> = (0..20)
        .map(|i| DcrRestingContact {
            id: i,
            point: [rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.0],
        })
        .collect();
    let mut out = vec![DcrContactResponse::default(); resting.len()];
    let start = allocations();
    // SAFETY: valid C string, params and out pointers.
    unsafe {
        assert_eq!(dcr_model_load(cpath.as_ptr(), &mut model), DcrStatus::Ok);
        assert_eq!(dcr_response_create(model, &p, &mut resp), DcrStatus::Ok);
    }
    assert!(
        allocations() > start,
        "the counter sees the set-up's allocations"
    );
    let step = |resp, hits: &[DcrImpact], n_rest: usize, out: &mut [DcrContactResponse]| {
        let mut n = 0;
        // SAFETY: arrays with the counts given; live handle.
        let st = unsafe {
            dcr_response_step(
                resp,
                hits.as_ptr(),
                hits.len(),
                resting.as_ptr(),
                n_rest,
                out.as_mut_ptr(),
                out.len(),
                &mut n,
            )
        };
        assert_eq!(st, DcrStatus::Ok);
    };
    let hit = |rng: &mut SplitMix64| DcrImpact {
        point: [rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.0],
        direction: [0.0, 0.0, -1.0],
        impulse: rng.range(0.5, 2.0),
    };
    let warm = [hit(&mut rng), hit(&mut rng)];
    step(resp, &warm, resting.len(), &mut out);
    let before = allocations();
    for s in 0..200 {
        let hits = [hit(&mut rng), hit(&mut rng)];
        step(resp, &hits[..s % 3], resting.len() - s % 5, &mut out);
    }
    assert!(out.iter().any(|c| c.delta_v > 0.0));
    assert_eq!(allocations() - before, 0, "dcr_response_step allocated");

    // World: the plate static on body 1, boxes 10..19 resting on it, a ball hitting it.
    let mut wp = DcrWorldParams::defaults();
    wp.energy_bound = false;
    wp.gravity = [0.0; 3];
    let mut world = std::ptr::null_mut();
    let mut desc = DcrElasticObjectDesc::defaults();
    desc.model = model;
    desc.body = 1;
    desc.response.method = DCR_METHOD_MODAL;
    let mut handle = 0;
    let mut other = 0;
    // SAFETY: valid params, descriptor and out pointers.
    unsafe {
        assert_eq!(dcr_world_create(&wp, &mut world), DcrStatus::Ok);
        assert_eq!(
            dcr_world_add_object(world, &desc, &mut handle),
            DcrStatus::Ok
        );
        desc.body = 2;
        assert_eq!(
            dcr_world_add_object(world, &desc, &mut other),
            DcrStatus::Ok
        );
    }
    let mut bodies: Vec<DcrBodyState> = (0..10)
        .map(|i| DcrBodyState {
            id: 10 + i,
            inv_mass: 1.0,
            ..Default::default()
        })
        .collect();
    bodies.push(DcrBodyState {
        id: 99,
        inv_mass: 2.0,
        ..Default::default()
    });
    let mut contacts: Vec<DcrContactReport> = (0..10)
        .map(|i| {
            let p = [rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.0];
            DcrContactReport {
                id: 1000 + i,
                body1: 1,
                body2: 10 + i,
                point1: p,
                point2: p,
                normal: [0.0, 0.0, 1.0],
                impulse: 0.0981,
                is_new: false,
            }
        })
        .collect();
    let world_step = |contacts: &[DcrContactReport]| {
        let mut events = std::ptr::null();
        let mut n = 0;
        // SAFETY: arrays with the counts given; live handle; valid out pointers.
        let st = unsafe {
            dcr_world_step(
                world,
                contacts.as_ptr(),
                contacts.len(),
                bodies.as_ptr(),
                bodies.len(),
                &mut events,
                &mut n,
            )
        };
        assert_eq!(st, DcrStatus::Ok);
        n
    };
    for _ in 0..5 {
        world_step(&contacts);
    }
    // Warm-up with an impact (the ball's contact id changes every step: always new).
    let ball = |id: u64, rng: &mut SplitMix64| {
        let p = [rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.0];
        DcrContactReport {
            id,
            body1: 99,
            body2: 1,
            point1: p,
            point2: p,
            normal: [0.0, 0.0, -1.0],
            impulse: 2.0,
            is_new: true,
        }
    };
    contacts.push(ball(5000, &mut rng));
    assert!(world_step(&contacts) > 0);
    contacts.pop();
    // Warm-up with the measured pattern itself (the classification's age table reaches its
    // working size), then the same pattern with fresh contact ids.
    let mut events = 0;
    for round in 0..2u64 {
        let before = allocations();
        for s in 0..200u64 {
            if s % 4 == 0 {
                contacts.push(ball(6000 + 1000 * round + s, &mut rng));
                events += world_step(&contacts);
                contacts.pop();
            } else {
                world_step(&contacts);
            }
        }
        if round == 1 {
            assert_eq!(allocations() - before, 0, "dcr_world_step allocated");
        }
    }
    assert!(events > 0);
    // The same pattern with the lifecycle calls between the steps, twice: the first cycle
    // warms the buffers up to the pattern's counts (re-enabling an object under age-based
    // classification makes its resting contacts new again: a step with more impacts than
    // before), the second is counted. `other` is removed in the first cycle (the removal
    // itself is not counted); the second cycle's steps run after it.
    let mut events_after = 0;
    for cycle in 0..2u64 {
        let mut removal = 0;
        let before = allocations();
        for s in 0..400u64 {
            // SAFETY: live world and handles (`other` is removed once, in the first cycle).
            let st = unsafe {
                match s {
                    40 => dcr_world_set_object_enabled(world, handle, false),
                    80 => dcr_world_set_object_enabled(world, handle, true),
                    120 => dcr_world_set_object_gain(world, handle, 1.5 + cycle as f64),
                    160 => dcr_world_set_object_threshold(world, handle, 0.2),
                    200 => dcr_world_set_h(world, wp.h),
                    300 if cycle == 0 => {
                        let a = allocations();
                        let st = dcr_world_remove_object(world, other);
                        removal += allocations() - a;
                        st
                    }
                    _ => DcrStatus::Ok,
                }
            };
            assert_eq!(st, DcrStatus::Ok, "cycle {cycle}, step {s}");
            if s % 4 == 0 {
                contacts.push(ball(9000 + 1000 * cycle + s, &mut rng));
                let n = world_step(&contacts);
                if s > 80 && cycle == 1 {
                    events_after += n;
                }
                contacts.pop();
            } else {
                world_step(&contacts);
            }
        }
        if cycle == 1 {
            assert_eq!(
                allocations() - before - removal,
                0,
                "dcr_world_step or a lifecycle setter allocated"
            );
        }
    }
    assert!(
        events_after > 0,
        "the plate still answers after the lifecycle calls"
    );

    // SAFETY: live handles, each freed once.
    unsafe {
        dcr_world_free(world);
        dcr_response_free(resp);
        dcr_model_free(model);
    }
}
