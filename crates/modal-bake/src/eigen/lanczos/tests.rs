//! Tests of the Lanczos path.

use super::super::ritz::FLOOR_FACTOR;
use super::super::{solve_lowest as solve, EigenParams, EigenResult};
use crate::fem::{assemble_clamped, Material};
use crate::mesh::TetMesh;
use std::cell::Cell;

thread_local! {
    /// Replaces [`PURIFY_ABOVE`] for the tests on this thread.
    pub(super) static PURIFY_ABOVE_OVERRIDE: Cell<Option<f64>> = const { Cell::new(None) };
}

/// Selective purification changes only the cost: with no pair purified up front, the
/// unpurified top modes fail the residual check and the fallback purifies every vector,
/// giving the bits of purifying all of them from the start; the default threshold gives
/// the same eigenvalues (to 1e-12) with every residual converged.
#[test]
fn purifying_fewer_vectors_keeps_the_result() {
    let mesh = TetMesh::structured_box([24, 4, 4], [1.0, 0.16, 0.16]);
    let mat = Material::new(2e11, 0.3, 7800.0).unwrap();
    let (_, k, m) = assemble_clamped(&mesh, &mat, false, &mesh.groups["xmin"]).unwrap();
    let params = EigenParams {
        nev: 12,
        tol: 1e-10,
        ..Default::default()
    };
    let run = |above: Option<f64>| {
        PURIFY_ABOVE_OVERRIDE.set(above);
        let r = solve(&k, &m, &params, &mut |_| {}).expect("converges");
        PURIFY_ABOVE_OVERRIDE.set(None);
        r
    };
    let bits = |r: &EigenResult| -> Vec<u64> {
        let vals = r.eigenvalues.iter().map(|v| v.to_bits());
        vals.chain(
            r.vectors
                .col_iter()
                .flat_map(|c| c.iter().map(|v| v.to_bits())),
        )
        .collect()
    };
    let (all, none, default) = (run(Some(0.0)), run(Some(f64::INFINITY)), run(None));
    assert_eq!((all.info.residual_checks, all.info.purified), (1, 12));
    assert_eq!(
        none.info.purified, 12,
        "the fallback purifies all 12 vectors"
    );
    assert!(
        (1..12).contains(&default.info.purified),
        "the default purifies some, not all: {}",
        default.info.purified
    );
    assert_eq!(bits(&all), bits(&none), "fallback must purify every vector");
    for (a, d) in all.eigenvalues.iter().zip(&default.eigenvalues) {
        assert!((a - d).abs() <= 1e-12 * a, "{a} vs {d}");
    }
    for (r, f) in default.residuals.iter().zip(&default.residual_floors) {
        assert!(*r <= params.tol.max(FLOOR_FACTOR * f), "residual {r:e}");
    }
}
