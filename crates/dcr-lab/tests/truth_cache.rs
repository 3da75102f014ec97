//! The accuracy report's truth cache: a cached truth is bit-identical to the computed one, any
//! changed input is a different entry, and a damaged entry is recomputed and replaced.
//!
//! Run with `cargo test --release -p dcr-lab --test truth_cache`.

use dcr_lab::accuracy::truth_cache::{cached_converged_peaks, key};
use modal_bake::full_order::{
    ConvergedPeaks, FullOrderSystem, PeakSolver, PeakWindow, RefineParams, SystemParams,
};
use modal_bake::mesh::TetMesh;
use modal_bake::target_error::TruthProblem;

fn system(youngs: f64) -> FullOrderSystem {
    let mut p = SystemParams {
        fixed: vec!["xmin".into()],
        ..Default::default()
    };
    p.material.youngs = youngs;
    FullOrderSystem::new(
        TetMesh::structured_box([6, 2, 2], [1.0, 0.2, 0.15]),
        &p,
        "box",
    )
    .unwrap()
}

/// One load at the free end's top node, one row at the middle of the top.
fn load_and_row(sys: &FullOrderSystem, row_at: [f64; 3]) -> (Vec<f64>, Vec<f64>) {
    let i = sys.surface.project([1.0, 0.1, 0.15]).unwrap();
    let c = sys.surface.project(row_at).unwrap();
    (
        sys.load_vector(&i, [0.0, 0.0, -1.0], 1.0),
        sys.contact_row(&c),
    )
}

fn refine() -> RefineParams {
    RefineParams {
        max_refinements: 2,
        ..RefineParams::default()
    }
}

fn solve(
    dir: &std::path::Path,
    sys: &FullOrderSystem,
    loads: &[Vec<f64>],
    rows: &[Vec<f64>],
) -> (ConvergedPeaks, bool) {
    let r = refine();
    let t = TruthProblem {
        solver: PeakSolver::Newmark,
        loads,
        rows,
        window: PeakWindow { h: 2e-3, dt: 2e-5 },
        refine: &r,
    };
    let mut hit = false;
    let c = cached_converged_peaks(Some(dir), sys, &t, &mut |_| {}, &mut hit).unwrap();
    (c, hit)
}

fn bits(c: &ConvergedPeaks) -> Vec<u64> {
    c.peaks
        .iter()
        .flatten()
        .map(|x| x.to_bits())
        .chain([
            c.dt.to_bits(),
            c.estimated_error.to_bits(),
            c.last_change.to_bits(),
        ])
        .chain(c.history.iter().map(|l| l.change.to_bits()))
        .collect()
}

#[test]
fn cached_truth_is_bit_identical_and_keyed_by_every_input() {
    let dir = tempfile::tempdir().unwrap();
    let sys = system(1e9);
    let (f, w) = load_and_row(&sys, [0.5, 0.1, 0.15]);
    let (loads, rows) = (vec![f.clone()], vec![w.clone()]);
    let (first, hit) = solve(dir.path(), &sys, &loads, &rows);
    assert!(!hit, "an empty cache cannot hit");
    assert!(first.peaks[0][0] > 0.0);
    // NaN (the first level's change) survives the round trip too.
    assert!(first.history[0].change.is_nan());
    let (second, hit) = solve(dir.path(), &sys, &loads, &rows);
    assert!(hit, "the same problem must be read from the cache");
    assert_eq!(bits(&first), bits(&second));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    // Another row, another material, another window: other keys.
    let (_, w2) = load_and_row(&sys, [0.25, 0.1, 0.15]);
    let r = refine();
    let base = TruthProblem {
        solver: PeakSolver::Newmark,
        loads: &loads,
        rows: &rows,
        window: PeakWindow { h: 2e-3, dt: 2e-5 },
        refine: &r,
    };
    let k0 = key(&sys, &base);
    let rows2 = vec![w2];
    let other_row = TruthProblem {
        rows: &rows2,
        ..base
    };
    let other_window = TruthProblem {
        window: PeakWindow { h: 2e-3, dt: 1e-5 },
        ..base
    };
    let stiffer = system(2e9);
    assert_ne!(k0, key(&sys, &other_row));
    assert_ne!(k0, key(&sys, &other_window));
    assert_ne!(k0, key(&stiffer, &base));
    let (other, hit) = solve(dir.path(), &stiffer, &loads, &rows);
    assert!(!hit);
    assert!(
        (other.peaks[0][0] - first.peaks[0][0]).abs() > 1e-3 * first.peaks[0][0],
        "a stiffer material must give another peak"
    );
}

#[test]
fn damaged_entry_is_recomputed_and_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let sys = system(1e9);
    let (f, w) = load_and_row(&sys, [0.5, 0.1, 0.15]);
    let (loads, rows) = (vec![f], vec![w]);
    let (first, _) = solve(dir.path(), &sys, &loads, &rows);
    let entry = std::fs::read_dir(dir.path())
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let text = std::fs::read_to_string(&entry).unwrap();
    std::fs::write(&entry, &text[..text.len() / 2]).unwrap();
    let (again, hit) = solve(dir.path(), &sys, &loads, &rows);
    assert!(!hit, "a truncated entry must not be used");
    assert_eq!(bits(&first), bits(&again));
    let (_, hit) = solve(dir.path(), &sys, &loads, &rows);
    assert!(hit, "the recomputed entry replaces the damaged one");
}
