//! Cost of the C boundary on a cached query: `DistantResponse::step` (Rust) against
//! `dcr_response_step` (the `extern "C"` function, through the rlib) on the same base, the same
//! parameters and the same inputs, in one run.
//!
//! Workload: the dinner row of dcr-runtime's query bench (paper Table 1): a synthetic closed
//! box surface of ~966 vertices, 20 modes, S = 21 filter samples per step, 41 distant resting
//! contacts, one impact per step cycling through 64 impacts, modal method, contacts cached
//! (steady state). The two calls are timed in interleaved batches (Rust, C, C, Rust, …) so the
//! machine's load drifts affect both alike; the figure is the median over batches of the
//! per-call time, and the median of the per-round ratio C / Rust.
//!
//! `cargo bench -p dcr-capi --bench ffi_overhead [-- --rounds N --batch K]`; writes
//! `out/bench/capi_ffi_overhead.json` (workspace root) and prints it.

#![allow(unsafe_code)]

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use dcr_capi::*;
use dcr_runtime::response::{Impact, Sampling};
use dcr_runtime::testing::{box_surface, geometric_omegas, synthetic_base, SplitMix64};
use dcr_runtime::{DistantResponse, Method, ModalModel, ResponseParams};

const H: f64 = 0.01;
const SAMPLES: usize = 21;
const CONTACTS: usize = 41;
const VERTS: usize = 966;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let rounds = arg("--rounds", 40);
    let batch = arg("--batch", 200);

    // The dinner workload, as in dcr-runtime's benches/query.rs.
    let n = (((VERTS as f64 - 2.0) / 6.0).sqrt().round() as usize).max(2);
    let base = synthetic_base(
        box_surface(n, [1.2, 0.8, 0.6]),
        &geometric_omegas(20, 60.0, 3000.0),
        [1.0, 1e-6],
        17,
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dinner.modes");
    base.write_atomic(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let model = Arc::new(ModalModel::from_base(base).unwrap());
    let mut rng = SplitMix64(17);
    let point = |rng: &mut SplitMix64| {
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
    let resting: Vec<dcr_runtime::response::RestingContact> = (0..CONTACTS)
        .map(|i| dcr_runtime::response::RestingContact {
            id: i as u64,
            point: point(&mut rng),
        })
        .collect();
    let impacts: Vec<Impact> = (0..64)
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

    // Rust.
    let params = ResponseParams {
        sampling: Sampling::Substep(H / SAMPLES as f64),
        method: Method::Modal,
        ..Default::default()
    };
    let mut rust = DistantResponse::new(Arc::clone(&model), params).unwrap();
    assert_eq!(rust.samples_per_step(), SAMPLES);

    // C, on the same base (loaded from its bytes) and parameters.
    let mut cmodel = std::ptr::null_mut();
    let mut cresp = std::ptr::null_mut();
    let mut p = DcrResponseParams::defaults();
    p.sampling = DCR_SAMPLING_SUBSTEP;
    p.sampling_value = H / SAMPLES as f64;
    p.method = DCR_METHOD_MODAL;
    // SAFETY: valid byte slice, params and out pointers.
    unsafe {
        assert_eq!(
            dcr_model_load_bytes(bytes.as_ptr(), bytes.len(), &mut cmodel),
            DcrStatus::Ok
        );
        assert_eq!(dcr_response_create(cmodel, &p, &mut cresp), DcrStatus::Ok);
    }
    let c_impacts: Vec<DcrImpact> = impacts
        .iter()
        .map(|i| DcrImpact {
            point: i.point,
            direction: i.direction,
            impulse: i.impulse,
        })
        .collect();
    let c_resting: Vec<DcrRestingContact> = resting
        .iter()
        .map(|c| DcrRestingContact {
            id: c.id,
            point: c.point,
        })
        .collect();
    let mut out = vec![DcrContactResponse::default(); CONTACTS];
    let c_step = |k: usize, out: &mut [DcrContactResponse]| {
        let mut count = 0;
        // SAFETY: arrays with the counts given; live handle.
        let st = unsafe {
            dcr_response_step(
                cresp,
                &c_impacts[k % c_impacts.len()],
                1,
                c_resting.as_ptr(),
                c_resting.len(),
                out.as_mut_ptr(),
                out.len(),
                &mut count,
            )
        };
        debug_assert_eq!(st, DcrStatus::Ok);
        black_box(out[0].delta_v)
    };

    // Warm-up (contacts mapped and cached, buffers sized); both paths give the same bits.
    for k in 0..impacts.len() {
        let r = rust.step(&impacts[k..k + 1], &resting)[0].delta_v;
        let c = c_step(k, &mut out);
        assert_eq!(r.to_bits(), c.to_bits());
    }

    let mut t_rust = Vec::with_capacity(rounds * 2);
    let mut t_c = Vec::with_capacity(rounds * 2);
    let mut ratios = Vec::with_capacity(rounds);
    let mut k = 0usize;
    let mut time_rust = |k: &mut usize| {
        let t0 = Instant::now();
        for _ in 0..batch {
            *k += 1;
            let i = *k % impacts.len();
            black_box(rust.step(&impacts[i..i + 1], &resting)[0].delta_v);
        }
        t0.elapsed().as_secs_f64() / batch as f64
    };
    let mut time_c = |k: &mut usize| {
        let t0 = Instant::now();
        for _ in 0..batch {
            *k += 1;
            c_step(*k, &mut out);
        }
        t0.elapsed().as_secs_f64() / batch as f64
    };
    for r in 0..rounds {
        // ABBA order within a round: a linear drift cancels in the round's ratio.
        let (a1, b1, b2, a2) = if r % 2 == 0 {
            let a1 = time_rust(&mut k);
            let b1 = time_c(&mut k);
            let b2 = time_c(&mut k);
            (a1, b1, b2, time_rust(&mut k))
        } else {
            let b1 = time_c(&mut k);
            let a1 = time_rust(&mut k);
            let a2 = time_rust(&mut k);
            (a1, b1, time_c(&mut k), a2)
        };
        t_rust.extend([a1, a2]);
        t_c.extend([b1, b2]);
        ratios.push((b1 + b2) / (a1 + a2));
    }
    let rust_us = median(&mut t_rust) * 1e6;
    let c_us = median(&mut t_c) * 1e6;
    let ratio = median(&mut ratios);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let json = serde_json::json!({
        "workload": "dinner (966 surface vertices, 20 modes, S = 21, 41 cached contacts, 1 impact)",
        "rounds": rounds,
        "batch": batch,
        "rust_median_us": rust_us,
        "c_median_us": c_us,
        "c_over_rust_median_ratio": ratio,
        "overhead_percent": (ratio - 1.0) * 100.0,
        "loadavg": load.trim(),
    });
    let text = serde_json::to_string_pretty(&json).unwrap();
    println!("{text}");
    let out_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../out/bench");
    if std::fs::create_dir_all(&out_dir).is_ok() {
        let _ = std::fs::write(out_dir.join("capi_ffi_overhead.json"), text + "\n");
    }
    // SAFETY: live handles, each freed once.
    unsafe {
        dcr_response_free(cresp);
        dcr_model_free(cmodel);
    }
}
