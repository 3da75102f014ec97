//! `DistantResponse::step` and `DcrWorld::step` perform no heap allocation after warm-up.
//!
//! Expectation: once every buffer has seen the largest contact / impact counts, many steps with
//! impacts (some below threshold, some unmapped), forces, and cached resting contacts allocate
//! nothing — for both variants, all methods (heat and Euclidean distances; the transfer table,
//! with its modal fallback for contacts and impacts outside its region and for forces), with
//! and without carry-over, and under the sustained launch (the table beside the carried filters,
//! and the filters alone). The world (a static floor with a transfer table and a dynamic
//! fridge) does not allocate either with impacts, resting contacts that come and go, chained
//! impacts, the energy bound and the lateral kick on, and a stream of new contact ids. Counted with a global allocator wrapper; this file is its own test binary and
//! holds a single test so no other test thread allocates concurrently.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use dcr_runtime::attenuation::HeatGeodesic;
use dcr_runtime::response::{
    AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind, ForceInput, Impact,
    RestingContact, Variant, PREPARED_CONTACTS,
};
use dcr_runtime::testing::{box_surface, geometric_omegas, synthetic_base, SplitMix64};
use dcr_runtime::{
    BodyState, ContactReport, DcrWorld, DistantResponse, ElasticObjectDesc, Launch, Method,
    ModalModel, Pose, ResponseParams, WorldParams,
};

struct Counting;

static ALLOCS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Whether allocations on this thread are counted: the test's thread and the workers of
    /// its rayon pool. The harness's own threads (which may allocate while the test runs) are
    /// not the code under test.
    static COUNTED: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNTED.with(Cell::get) {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn surface_point(rng: &mut SplitMix64) -> [f64; 3] {
    // A point on (or just off) the box [0,1]×[0,0.6]×[0,0.4] surface: the top face.
    [
        rng.range(0.0, 1.0),
        rng.range(0.0, 0.6),
        0.4 + rng.range(-0.001, 0.001),
    ]
}

#[test]
fn steps_do_not_allocate_after_warm_up() {
    COUNTED.with(|c| c.set(true));
    let om = geometric_omegas(20, 100.0, 3000.0);
    let mut base = synthetic_base(box_surface(8, [1.0, 0.6, 0.4]), &om, [1.0, 1e-6], 3);
    // A synthetic transfer table over the top face's half x ≤ 0.5 m: some impacts and contacts
    // fall outside it (modal fallback).
    let vertices: Vec<u32> = (0..base.surface_vertices.len())
        .filter(|&v| {
            let p = base.surface_vertices[v];
            p[2] >= 0.4 - 1e-9 && p[0] <= 0.5 + 1e-9
        })
        .map(|v| v as u32)
        .collect();
    // With edge midpoints, so the steps run the P2 lookup.
    let edges =
        dcr_runtime::format::TransferTable::region_edges(&base.surface_triangles, &vertices);
    let np = vertices.len() + edges.len();
    base.transfer = Some(dcr_runtime::format::TransferTable {
        h: 0.01,
        rayleigh: base.rayleigh,
        modes: 40,
        samples: 100,
        vertices,
        order: 2,
        edges,
        faces: Vec::new(),
        peaks: (0..np * (np + 1) / 2)
            .map(|k| 1e-5 * (1 + k % 5) as f32)
            .collect(),
    });
    let model = Arc::new(ModalModel::from_base(base).unwrap());
    first_step_does_not_allocate(&model);
    // Several random streams: which buffers the warm-up fills first depends on the inputs.
    for seed in [99, 7, 23] {
        steps_do_not_allocate_with(&model, seed, false);
    }
    world_steps_do_not_allocate(&model);
    // Two-thread heat queries inside a rayon pool (the worker's allocations count too): a
    // surface large enough to fork, under a nested-dissection order that splits.
    let surface = box_surface(20, [1.0, 0.6, 0.4]);
    let order = dcr_runtime::testing::bisection_order(surface.0.len(), &surface.1);
    let mut base = synthetic_base(surface, &om, [1.0, 1e-6], 3);
    base.surface_order = Some(order);
    let model = Arc::new(ModalModel::from_base(base).unwrap());
    let heat = model.heat_geodesic().unwrap();
    assert!(heat.splits_in_two() && heat.factor_len() >= HeatGeodesic::PARALLEL_MIN_ENTRIES);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .start_handler(|_| COUNTED.with(|c| c.set(true)))
        .build()
        .unwrap();
    pool.install(|| steps_do_not_allocate_with(&model, 5, true));
}

/// Set-up sizes a response for `PREPARED_CONTACTS` resting contacts: its very first step, with
/// that many contacts all mapped now and an impact, allocates nothing (both variants).
fn first_step_does_not_allocate(model: &Arc<ModalModel>) {
    let mut rng = SplitMix64(3);
    let resting: Vec<RestingContact> = (0..PREPARED_CONTACTS as u64)
        .map(|i| RestingContact {
            id: 500 + i,
            point: surface_point(&mut rng),
        })
        .collect();
    let impacts = [Impact {
        point: [0.5, 0.3, 0.4],
        direction: [0.0, 0.0, -1.0],
        impulse: 2.0,
    }];
    // The default method (the base's transfer table, with the modal method for what it cannot
    // serve) and the modal method.
    let methods = [ResponseParams::default().method, Method::Modal];
    for (method, variant) in methods
        .into_iter()
        .flat_map(|m| [(m.clone(), Variant::PerContact), (m, Variant::PerNode)])
    {
        let params = ResponseParams {
            variant,
            method: method.clone(),
            ..ResponseParams::default()
        };
        let mut resp = DistantResponse::new(model.clone(), params).unwrap();
        let before = ALLOCS.load(Ordering::Relaxed);
        let out = resp.step(&impacts, &resting);
        let allocs = ALLOCS.load(Ordering::Relaxed) - before;
        assert_eq!(out.len(), PREPARED_CONTACTS);
        assert!(out.iter().all(|r| r.mapped) && out.iter().any(|r| r.delta_v > 0.0));
        assert_eq!(
            resp.last_step_info().contacts_mapped_now as usize,
            PREPARED_CONTACTS
        );
        assert_eq!(
            allocs, 0,
            "{method:?}, {variant:?}: the first step allocated {allocs} times"
        );
    }
}

/// `parallel`: only the heat configurations, with two-thread queries.
fn steps_do_not_allocate_with(model: &Arc<ModalModel>, seed: u64, parallel: bool) {
    let mut rng = SplitMix64(seed);
    let resting: Vec<RestingContact> = (0..30)
        .map(|i| RestingContact {
            id: 1000 + i,
            point: surface_point(&mut rng),
        })
        .collect();
    let heat = |capacity, parallel_heat| {
        Method::Attenuation(AttenuationParams {
            law: AttenuationLaw::Full {
                alpha: 0.1,
                beta: 0.5,
                r0: 0.05,
            },
            distance: DistanceKind::Heat,
            amplitude: AmplitudeKind::PerVertex,
            cache_capacity: capacity,
            parallel_heat,
        })
    };
    let euclid = Method::Attenuation(AttenuationParams {
        distance: DistanceKind::Euclidean,
        amplitude: AmplitudeKind::MeanOver(vec![1, 2, 3]),
        ..Default::default()
    });
    let mut configs = Vec::new();
    for variant in [Variant::PerContact, Variant::PerNode] {
        for carry_over in [false, true] {
            let methods = if parallel {
                vec![heat(64, true), heat(0, true)]
            } else {
                vec![
                    Method::Modal,
                    heat(64, false),
                    heat(0, false),
                    euclid.clone(),
                    Method::Attenuation(AttenuationParams {
                        distance: DistanceKind::HeatTable,
                        ..Default::default()
                    }),
                ]
            };
            for method in methods {
                configs.push(ResponseParams {
                    variant,
                    carry_over,
                    method,
                    ..Default::default()
                });
            }
        }
    }
    // The transfer table (appended last: the other configurations see the same random input).
    for variant in [Variant::PerContact, Variant::PerNode]
        .into_iter()
        .filter(|_| !parallel)
    {
        for carry_over in [false, true] {
            configs.push(ResponseParams {
                variant,
                carry_over,
                method: Method::Transfer,
                ..Default::default()
            });
        }
        // The sustained launch: the table beside the carried filters, and the filters alone.
        for method in [Method::Transfer, Method::Modal] {
            configs.push(ResponseParams {
                variant,
                carry_over: true,
                method,
                launch: Launch::SustainedPeak,
                ..Default::default()
            });
        }
    }
    for params in configs {
        let label = format!(
            "seed {seed}: {:?} carry={} {:?} {:?}",
            params.variant, params.carry_over, params.method, params.launch
        );
        let mut resp = DistantResponse::new(Arc::clone(model), params).unwrap();
        let mut impacts = Vec::with_capacity(4);
        let forces = [ForceInput {
            point: [0.5, 0.3, 0.4],
            force: [0.0, 0.0, -3.0],
        }];
        let mut run = |resp: &mut DistantResponse, rng: &mut SplitMix64, n: usize| {
            let mut sum = 0.0;
            for step in 0..n {
                impacts.clear();
                for i in 0..(step % 4) {
                    impacts.push(Impact {
                        point: surface_point(rng),
                        direction: [0.0, 0.0, -1.0],
                        // Some below threshold, one far away (unmapped) now and then.
                        impulse: if i == 2 { 1e-5 } else { rng.range(0.01, 5.0) },
                    });
                }
                if step % 7 == 3 && !impacts.is_empty() {
                    impacts[0].point = [5.0, 5.0, 5.0];
                }
                let f: &[ForceInput] = if step % 5 == 0 { &forces } else { &[] };
                // Resting contacts in a rotating order and a varying subset.
                let k = step % resting.len();
                let sub = if step % 3 == 0 {
                    &resting[..]
                } else {
                    &resting[k / 2..]
                };
                let out = resp.step_with_forces(&impacts, f, sub);
                sum += out.iter().map(|c| c.delta_v).sum::<f64>();
            }
            sum
        };
        run(&mut resp, &mut rng, 40);
        let before = ALLOCS.load(Ordering::SeqCst);
        let sum = run(&mut resp, &mut rng, 600);
        let allocs = ALLOCS.load(Ordering::SeqCst) - before;
        assert!(sum > 0.0, "{label}: no response at all");
        assert_eq!(
            allocs, 0,
            "{label}: {allocs} allocations in 600 steps after warm-up"
        );
    }
}

/// The world: floor (static, transfer table) → fridge (dynamic) chains, 12 dynamic bodies,
/// resting contacts from a pool that come and go, a few new impact ids every step, η = 0.5
/// and the lateral kick on the fridge.
fn world_steps_do_not_allocate(model: &Arc<ModalModel>) {
    const FLOOR: u64 = 1;
    const FRIDGE: u64 = 2;
    let mut world = DcrWorld::new(WorldParams {
        energy_eta: Some(0.5),
        gravity: [0.0; 3],
        ..Default::default()
    })
    .unwrap();
    let floor = ElasticObjectDesc::new(Arc::clone(model), FLOOR);
    world.add_object(floor).unwrap();
    let mut fridge = ElasticObjectDesc::new(Arc::clone(model), FRIDGE);
    fridge.dynamic = true;
    fridge.gain = 20.0;
    fridge.response.lateral_kick = true;
    fridge.pose = Pose::from_axis_angle([0.0, 0.0, 1.0], 0.4, [0.2, 0.1, 0.4]);
    let fridge_pose = fridge.pose;
    let fridge_h = world.add_object(fridge).unwrap();
    let mut rng = SplitMix64(5);
    let bodies: Vec<BodyState> = (2..14)
        .map(|id| BodyState {
            id,
            inv_mass: 1.0 / rng.range(0.5, 5.0),
            inv_inertia: [[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 1.5]],
            center_of_mass: [rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.5],
            linvel: [0.0, 0.0, rng.range(-0.5, 0.5)],
            angvel: [0.0, rng.range(-1.0, 1.0), 0.0],
        })
        .collect();
    // The fridge (body 2) at rest: the floor's pushes give it kinetic energy to pass on.
    let mut bodies = bodies;
    bodies[0].linvel = [0.0; 3];
    bodies[0].angvel = [0.0; 3];
    let mut contacts: Vec<ContactReport> = Vec::with_capacity(64);
    let mut next_id = 10_000u64;
    let mut run = |world: &mut DcrWorld, rng: &mut SplitMix64, n: usize| {
        let mut total = 0.0;
        for step in 0..n {
            world.set_pose(fridge_h, fridge_pose);
            contacts.clear();
            // The fridge rests on the floor; bodies rest on the floor or the fridge.
            contacts.push(floor_contact(1, FRIDGE, [0.5, 0.3, 0.4], 0.5));
            for k in 0..30u64 {
                if (k + step as u64).is_multiple_of(7) {
                    continue; // comes and goes
                }
                let other = 3 + k % 11;
                if k % 3 == 0 {
                    let p = fridge_pose.transform_point(surface_point(rng));
                    contacts.push(fridge_contact(&fridge_pose, 100 + k, other, p, 0.05));
                } else {
                    contacts.push(floor_contact(100 + k, other, surface_point(rng), 0.05));
                }
            }
            for _ in 0..(step % 3) {
                next_id += 1;
                let p = surface_point(rng);
                contacts.push(floor_contact(
                    next_id,
                    3 + next_id % 11,
                    p,
                    rng.range(0.5, 5.0),
                ));
            }
            let events = world.step(&contacts, &bodies);
            total += events.iter().map(|e| e.impulse[2].abs()).sum::<f64>();
        }
        total
    };
    run(&mut world, &mut rng, 300);
    let before = ALLOCS.load(Ordering::SeqCst);
    let total = run(&mut world, &mut rng, 600);
    let allocs = ALLOCS.load(Ordering::SeqCst) - before;
    assert!(total > 0.0, "world: no response at all");
    let info = world.object_info(fridge_h);
    assert!(info.energy.total_received > 0.0, "world: no chain");
    assert_eq!(
        allocs, 0,
        "world: {allocs} allocations in 600 steps after warm-up"
    );
}

fn floor_contact(id: u64, other: u64, p: [f64; 3], impulse: f64) -> ContactReport {
    ContactReport {
        id,
        body1: 1,
        body2: other,
        point1: p,
        point2: p,
        normal: [0.0, 0.0, 1.0],
        impulse,
        is_new: false,
    }
}

fn fridge_contact(pose: &Pose, id: u64, other: u64, p: [f64; 3], impulse: f64) -> ContactReport {
    let r = pose.rotation_matrix();
    ContactReport {
        id,
        body1: 2,
        body2: other,
        point1: p,
        point2: p,
        normal: [r[0][2], r[1][2], r[2][2]],
        impulse,
        is_new: false,
    }
}
