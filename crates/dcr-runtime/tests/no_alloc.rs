//! `DistantResponse::step` performs no heap allocation after warm-up.
//!
//! Expectation: once every buffer has seen the largest contact / impact counts, many steps with
//! impacts (some below threshold, some unmapped), forces, and cached resting contacts allocate
//! nothing — for both variants, all methods (heat and Euclidean distances; the transfer table,
//! with its modal fallback for contacts and impacts outside its region and for forces), with
//! and without carry-over. Counted with a global allocator wrapper; this file is its own test binary and
//! holds a single test so no other test thread allocates concurrently.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use dcr_runtime::testing::{box_surface, geometric_omegas, synthetic_base, SplitMix64};
use dcr_runtime::{
    AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind, DistantResponse, ForceInput,
    HeatGeodesic, Impact, Method, ModalModel, ResponseParams, RestingContact, Variant,
};

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
        edges,
        peaks: (0..np * (np + 1) / 2)
            .map(|k| 1e-5 * (1 + k % 5) as f32)
            .collect(),
    });
    let model = Arc::new(ModalModel::from_base(base).unwrap());
    // Several random streams: which buffers the warm-up fills first depends on the inputs.
    for seed in [99, 7, 23] {
        steps_do_not_allocate_with(&model, seed, false);
    }
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
        .build()
        .unwrap();
    pool.install(|| steps_do_not_allocate_with(&model, 5, true));
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
    }
    for params in configs {
        let label = format!(
            "seed {seed}: {:?} carry={} {:?}",
            params.variant, params.carry_over, params.method
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
