//! Per-query cost of the distant response on the paper's Table 1 workloads (and Table 3 for
//! attenuation), plus the heat-geodesic set-up and per-source cost on a ~5k-vertex surface.
//!
//! Each row: 20 modes, a synthetic closed box surface with about the paper's surface-vertex
//! count, smooth random modes, T chosen so S (samples per step) matches the paper, the paper's
//! number of distant resting contacts at random surface points, one impact per step.
//! `first`: a fresh instance (contacts mapped + cached on this query); `cached`: steady state.

use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use dcr_runtime::testing::{box_surface, geometric_omegas, synthetic_base, SplitMix64};
use dcr_runtime::{
    AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind, DistantResponse, HeatGeodesic,
    Impact, Method, ModalModel, ResponseParams, RestingContact, Sampling,
};

/// (name, samples per step, distant contacts, surface vertices, paper ms).
const ROWS: [(&str, usize, usize, usize, f64); 7] = [
    ("dinner", 21, 41, 966, 3.8),
    ("roof", 2, 7, 1002, 0.8),
    ("scaffold", 4, 58, 5384, 27.5),
    ("low-rider", 33, 40, 1570, 5.6),
    ("rockfall", 3, 24, 7182, 18.1),
    ("floor", 59, 26, 360, 1.1),
    ("fridge", 117, 6, 250, 0.2),
];

const H: f64 = 0.01;

struct Workload {
    model: Arc<ModalModel>,
    resting: Vec<RestingContact>,
    impacts: Vec<Impact>,
}

fn workload(verts: usize, contacts: usize, seed: u64) -> Workload {
    let n = (((verts as f64 - 2.0) / 6.0).sqrt().round() as usize).max(2);
    let surface = box_surface(n, [1.2, 0.8, 0.6]);
    let base = synthetic_base(
        surface,
        &geometric_omegas(20, 60.0, 3000.0),
        [1.0, 1e-6],
        seed,
    );
    let model = Arc::new(ModalModel::from_base(base).unwrap());
    let mut rng = SplitMix64(seed);
    let mut point = |rng: &mut SplitMix64| {
        let b = model.base();
        let t = b.surface_triangles[(rng.next_u64() % b.surface_triangles.len() as u64) as usize];
        let (u, v) = (rng.next_f64(), rng.next_f64());
        let (u, v) = if u + v > 1.0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        };
        let w = [1.0 - u - v, u, v];
        let mut p = [0.0; 3];
        for i in 0..3 {
            for k in 0..3 {
                p[k] += w[i] * b.surface_vertices[t[i] as usize][k];
            }
        }
        p
    };
    let resting = (0..contacts)
        .map(|i| RestingContact {
            id: i as u64,
            point: point(&mut rng),
        })
        .collect();
    let impacts = (0..64)
        .map(|_| {
            let p = point(&mut rng);
            let sp = model.project(p, 1.0).unwrap();
            Impact {
                point: p,
                direction: sp.normal.map(|x| -x),
                impulse: 1.0,
            }
        })
        .collect();
    Workload {
        model,
        resting,
        impacts,
    }
}

fn bench_rows(
    c: &mut Criterion,
    label: &str,
    method: impl Fn() -> Method,
    rows: &[(&str, usize, usize, usize, f64)],
) {
    for &(name, s, nc, verts, _) in rows {
        let w = workload(verts, nc, 17);
        let params = ResponseParams {
            sampling: Sampling::Substep(H / s as f64),
            method: method(),
            ..Default::default()
        };
        let fresh = || DistantResponse::new(Arc::clone(&w.model), params.clone()).unwrap();
        assert_eq!(fresh().samples_per_step(), s);
        c.bench_function(&format!("{label}/{name}/first"), |b| {
            let mut i = 0;
            b.iter_batched(
                fresh,
                |mut r| {
                    i += 1;
                    let imp = [w.impacts[i % w.impacts.len()]];
                    black_box(r.step(&imp, &w.resting)[0].delta_v);
                    r
                },
                BatchSize::SmallInput,
            )
        });
        let mut r = fresh();
        for imp in &w.impacts {
            r.step(&[*imp], &w.resting);
        }
        c.bench_function(&format!("{label}/{name}/cached"), |b| {
            let mut i = 0;
            b.iter(|| {
                i += 1;
                let imp = [w.impacts[i % w.impacts.len()]];
                black_box(r.step(&imp, &w.resting)[0].delta_v)
            })
        });
    }
}

fn modal(c: &mut Criterion) {
    bench_rows(c, "modal", || Method::Modal, &ROWS);
}

fn attenuation(c: &mut Criterion) {
    // Paper Table 3: scaffold 30.6 ms, low-rider 6.9 ms first bounce / 5.2 ms later.
    let rows = [ROWS[2], ROWS[3]];
    bench_rows(
        c,
        "attenuation",
        || {
            Method::Attenuation(AttenuationParams {
                law: AttenuationLaw::Simplified { c: 1.0, beta: 0.5 },
                distance: DistanceKind::Heat,
                amplitude: AmplitudeKind::PerVertex,
                cache_capacity: 64,
            })
        },
        &rows,
    );
}

fn geodesic(c: &mut Criterion) {
    let (v, t) = box_surface(29, [1.2, 0.8, 0.6]); // 5048 vertices
    c.bench_function(&format!("heat/setup/{}v", v.len()), |b| {
        b.iter(|| black_box(HeatGeodesic::new(&v, &t).unwrap()))
    });
    let heat = HeatGeodesic::new(&v, &t).unwrap();
    let model = ModalModel::from_base(synthetic_base(
        (v.clone(), t.clone()),
        &[100.0],
        [0.0, 0.0],
        1,
    ))
    .unwrap();
    let sp = model.project([0.3, 0.2, 0.6], 1.0).unwrap();
    let mut ws = heat.workspace();
    let mut out = vec![0.0; v.len()];
    c.bench_function(&format!("heat/source/{}v", v.len()), |b| {
        b.iter(|| {
            heat.distances_from_point_with(&sp, &mut out, &mut ws);
            black_box(out[17])
        })
    });
}

criterion_group!(benches, modal, attenuation, geodesic);
criterion_main!(benches);
