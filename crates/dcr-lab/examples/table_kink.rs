//! Where a transfer table misses inside a triangle: for one object of the accuracy report (at
//! most 6000 free dofs: the exact reference is the runtime's modal method over every mode), the
//! default table's worst pair, then the peak along a line across that contact's triangle —
//! from the corner with the largest barycentric weight through the contact to the opposite
//! edge — exactly and from the table.
//!
//! ```sh
//! cargo run --release -p dcr-lab --example table_kink -- fridge-surface
//! ```
//!
//! Then the same with the impact walked across its triangle (the contact fixed).
//!
//! Inside a triangle the exact peak is max_t |Σ_k β_k g_k(t)| over the corners' signals:
//! continuous, but kinked where the dominant lobe changes sign (a nodal line of the response
//! crossing the triangle); an interpolant of peaks, exact at its nodes, rounds such a V off
//! on the whole triangle around it. Truths are read from `out/truth-cache` when there.

use std::path::Path;
use std::sync::Arc;

use dcr_lab::accuracy::truth_cache::cached_converged_peaks;
use dcr_lab::accuracy::{
    all_objects, base20, load_mesh, pairs_params, system_params, Base20, H, IMPACTS,
};
use dcr_runtime::response::RestingContact;
use dcr_runtime::{Method, ModalModel};
use modal_bake::bake::mode_set_from_dense;
use modal_bake::full_order::{FullOrderSystem, ModalAll};
use modal_bake::target_error::ReferencePairs;
use modal_bake::transfer::{build_transfer_table, TransferModes, TransferParams, DENSE_MAX_DOFS};

fn main() -> anyhow::Result<()> {
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "fridge-surface".into());
    let spec = all_objects()
        .into_iter()
        .find(|o| o.name == name)
        .ok_or_else(|| anyhow::anyhow!("no object {name}"))?;
    let mesh = load_mesh(&spec, Path::new("."))?;
    let Base20 {
        base: base20,
        region,
        ..
    } = base20(&spec, &mesh)?;
    let sys = FullOrderSystem::new(mesh, &system_params(&spec), &spec.source)?;
    anyhow::ensure!(
        sys.n() <= DENSE_MAX_DOFS,
        "{name}: more than {DENSE_MAX_DOFS} free dofs"
    );
    let ma = ModalAll::new(&sys, DENSE_MAX_DOFS)?;
    let pp = pairs_params(IMPACTS);
    let cache = Path::new("out/truth-cache");
    let mut hit = false;
    let pairs = ReferencePairs::with_truth(&sys, Some(&ma), &base20, &region, &pp, &mut |tp| {
        cached_converged_peaks(Some(cache), &sys, tp, &mut |_| {}, &mut hit)
    })?;
    let set = mode_set_from_dense(&base20, &sys, &ma, ma.eigenvalues.len());
    let tp = TransferParams {
        h: H,
        modes: TransferModes::All,
        boxes: spec.boxes.clone(),
        up: spec.up,
        ..Default::default()
    };
    let mut with_table = base20.clone();
    with_table.transfer = Some(build_transfer_table(
        &set,
        &tp,
        base20.rayleigh,
        &mut |_| {},
    )?);
    let table = Arc::new(ModalModel::from_base(with_table)?);
    let mut dt = pairs.response(Arc::clone(&table), Method::Transfer);
    let mut de = pairs.response(Arc::new(ModalModel::from_base(set)?), Method::Modal);
    // The worst pair of the table against the truth.
    let mut worst = (0.0f64, 0, 0);
    for (i, imp) in pairs.impacts.iter().enumerate() {
        let out = dt.step(std::slice::from_ref(imp), &pairs.resting);
        for (c, o) in out.iter().enumerate() {
            let t = pairs.truth.peaks[i][c];
            let e = 100.0 * (o.peak_displacement - t) / t;
            if pairs.pair_ok[i][c] && e.abs() > worst.0.abs() {
                worst = (e, i, c);
            }
        }
    }
    let (e, i, c) = worst;
    let imp = pairs.impacts[i];
    println!(
        "{name}: worst pair {e:+.1} %: impact {:?} -> contact {:?} (truth {:.4e} m)",
        imp.point, pairs.resting[c].point, pairs.truth.peaks[i][c]
    );
    let rc = [RestingContact {
        id: 1_000_000,
        point: pairs.resting[c].point,
    }];
    let walk = |what: &str, at: [f64; 3], f: &mut dyn FnMut([f64; 3]) -> (f64, f64)| {
        let Some(sp) = table.project(at, 0.1) else {
            println!("{what}: off the surface");
            return;
        };
        let v = table
            .triangle(sp.triangle)
            .map(|k| table.base().surface_vertices[k]);
        let k0 = (0..3)
            .max_by(|&a, &b| sp.bary[a].total_cmp(&sp.bary[b]))
            .unwrap_or(0);
        println!(
            "{what} in triangle {v:?}: from corner {k0} through the point to the opposite edge"
        );
        println!(
            "{:>5} {:>12} {:>12} {:>8}",
            "s", "exact m", "table m", "error %"
        );
        let rest = (1.0 - sp.bary[k0]).max(1e-12);
        for k in 0..=10 {
            let s = k as f64 / 10.0;
            let b: Vec<f64> = (0..3)
                .map(|j| {
                    if j == k0 {
                        1.0 - s
                    } else {
                        s * sp.bary[j] / rest
                    }
                })
                .collect();
            let p = [0, 1, 2].map(|a| (0..3).map(|j| b[j] * v[j][a]).sum::<f64>());
            let (x, y) = f(p);
            println!("{s:5.1} {x:12.4e} {y:12.4e} {:+8.1}", 100.0 * (y - x) / x);
        }
    };
    walk("the contact", pairs.resting[c].point, &mut |p| {
        let r = [RestingContact {
            id: 1_000_001,
            point: p,
        }];
        let x = de.step(std::slice::from_ref(&imp), &r)[0].peak_displacement;
        let y = dt.step(std::slice::from_ref(&imp), &r)[0].peak_displacement;
        (x, y)
    });
    walk("the impact", imp.point, &mut |p| {
        let moved = dcr_runtime::response::Impact { point: p, ..imp };
        let x = de.step(std::slice::from_ref(&moved), &rc)[0].peak_displacement;
        let y = dt.step(std::slice::from_ref(&moved), &rc)[0].peak_displacement;
        (x, y)
    });
    Ok(())
}
