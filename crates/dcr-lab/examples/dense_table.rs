//! A transfer table from every mode of a mesh beyond the bake's dense limit (6000 free dofs):
//! the dense all-mode eigensolve of the whole mesh (memory ≈ 6 n² doubles), the table over the
//! object's report region, and its errors against the report's cached truth at the same pairs.
//!
//! ```sh
//! cargo run --release -p dcr-lab --example dense_table -- cliff 2
//! ```
//!
//! Arguments: object name, impacts (as the report used; the truth must be in
//! `out/truth-cache`, else it is computed). Prints the seconds of each stage and the errors.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use dcr_lab::accuracy::truth_cache::cached_converged_peaks;
use dcr_lab::accuracy::{
    abs_errors, all_objects, base20, load_mesh, maxv, median, pairs_params, system_params, Base20,
    H,
};
use dcr_runtime::{Method, ModalModel};
use modal_bake::bake::mode_set_from_dense;
use modal_bake::full_order::{FullOrderSystem, ModalAll, PeakSolver};
use modal_bake::target_error::ReferencePairs;
use modal_bake::transfer::{build_transfer_table, TransferModes, TransferParams};

fn main() -> anyhow::Result<()> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "cliff".into());
    let impacts: usize = std::env::args().nth(2).map_or(Ok(6), |s| s.parse())?;
    let spec = all_objects()
        .into_iter()
        .find(|o| o.name == name)
        .ok_or_else(|| anyhow::anyhow!("no object {name}"))?;
    let mesh = load_mesh(&spec, Path::new("."))?;
    let Base20 {
        base: base20,
        seconds: base20_s,
        region,
        ..
    } = base20(&spec, &mesh)?;
    let sys = FullOrderSystem::new(mesh, &system_params(&spec), &spec.source)?;
    // The report's pairs and Newmark truth (read from the cache).
    let pp = pairs_params(impacts);
    let mut hit = false;
    let pairs = ReferencePairs::with_truth(&sys, None, &base20, &region, &pp, &mut |tp| {
        assert!(matches!(tp.solver, PeakSolver::Newmark));
        cached_converged_peaks(
            Some(Path::new("out/truth-cache")),
            &sys,
            tp,
            &mut |_| {},
            &mut hit,
        )
    })?;
    eprintln!("{name}: {} free dofs, truth from the cache: {hit}", sys.n());
    let t = Instant::now();
    let ma = ModalAll::new(&sys, usize::MAX)?;
    let eig_s = t.elapsed().as_secs_f64();
    eprintln!(
        "{name}: dense eigensolve of {} dofs in {eig_s:.0} s",
        sys.n()
    );
    let set = mode_set_from_dense(&base20, &sys, &ma, ma.eigenvalues.len());
    drop(ma);
    let tp = TransferParams {
        h: H,
        modes: TransferModes::All,
        boxes: spec.boxes.clone(),
        up: spec.up,
        ..Default::default()
    };
    let t = Instant::now();
    let table = build_transfer_table(&set, &tp, base20.rayleigh, &mut |_| {})?;
    let table_s = t.elapsed().as_secs_f64();
    let (order, points, samples) = (table.order, table.num_points(), table.samples);
    let mut b = base20.clone();
    b.transfer = Some(table);
    let tmp = std::env::temp_dir().join(format!("dense_table_{}.modes", std::process::id()));
    b.write_atomic(&tmp)?;
    let bytes = std::fs::metadata(&tmp)?.len();
    let _ = std::fs::remove_file(&tmp);
    let mut dr = pairs.response(Arc::new(ModalModel::from_base(b)?), Method::Transfer);
    let (errors, _) = pairs.errors(&mut dr, 1.0);
    let (v, i, a) = (
        abs_errors(&errors, |x| x),
        abs_errors(&errors, |x| !x),
        abs_errors(&errors, |_| true),
    );
    println!(
        "{name}: table, all {} modes (dense), order {order} ({points} points, S = {samples}): \
         at vertices {:.1} / {:.1} %, inside triangles {:.1} / {:.1} %, all {:.1} / {:.1} % \
         (median / worst, {} pairs); bake {:.0} s (20-mode base {base20_s:.1} s, dense \
         eigensolve {eig_s:.0} s, table {table_s:.0} s), base {:.0} KiB",
        set.num_modes(),
        median(&v),
        maxv(&v),
        median(&i),
        maxv(&i),
        median(&a),
        maxv(&a),
        a.len(),
        base20_s + eig_s + table_s,
        bytes as f64 / 1024.0
    );
    Ok(())
}
