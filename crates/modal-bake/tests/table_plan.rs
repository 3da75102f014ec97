//! A transfer table's plan (`modal_bake::transfer::plan_transfer_table`) and its budget
//! (`TransferParams::budget`).
//!
//! Expectations: the plan counts what the build then computes (points, region vertices, modes,
//! samples per step, bent points); its sampling is the coarsest that resolves the highest mode
//! summed (T = π/(2ω)); a build over its budget is refused before any row is computed, and the
//! mode count it suggests is the largest that fits (`OverBudget::most_modes`); a budget the
//! plan fits changes no bit.

use std::path::Path;

use dcr_runtime::format::ModesFile;
use dcr_runtime::ModalModel;
use modal_bake::bake::{bake_mesh, BakeParams, Budget, ModeRequest};
use modal_bake::transfer::{
    build_transfer_table, plan_transfer_table, OverBudget, TableOrder, TransferError,
    TransferModes, TransferParams,
};

/// The beam (clamped) with its lowest `n` modes, as a table's mode set.
fn beam_modes(n: usize) -> ModesFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/beam.msh");
    let mesh = modal_bake::mesh::read_mesh(&path).expect("beam mesh");
    let params = BakeParams {
        modes: ModeRequest::Count(n),
        fixed: vec!["clamp".into()],
        ..BakeParams::default()
    };
    bake_mesh(mesh, &params, "beam.msh", &mut |_| {})
        .expect("bake")
        .0
}

fn params(modes: TransferModes, order: TableOrder) -> TransferParams {
    TransferParams {
        h: 0.004,
        modes,
        order,
        ..TransferParams::default()
    }
}

#[test]
fn the_plan_counts_what_the_build_computes() {
    let set = beam_modes(60);
    for order in [TableOrder::Linear, TableOrder::Quadratic, TableOrder::Cubic] {
        let tp = params(TransferModes::Count(40), order);
        let plan = plan_transfer_table(&set, &tp).expect("plan");
        let mut seen = Vec::new();
        let table = build_transfer_table(&set, &tp, [10.0, 1e-7], &mut |p| seen.push(p.plan))
            .expect("table");
        assert_eq!(plan.points, table.num_points(), "{order:?}");
        assert_eq!(plan.vertices, table.len());
        assert_eq!(plan.modes, table.modes as usize);
        assert_eq!(plan.samples, table.samples as usize);
        assert_eq!(plan.order, table.order);
        assert!(plan.bent <= plan.points - plan.vertices);
        if order == TableOrder::Linear {
            assert_eq!(plan.bent, 0, "vertices are never bent points");
        } else {
            // The beam's box edges make points between vertices of different normals.
            assert!(plan.bent > 0, "{order:?}: no bent point on a box");
        }
        assert!(!seen.is_empty() && seen.iter().all(|p| *p == plan));
        assert!(plan.seconds() > 0.0 && plan.seconds().is_finite());
        assert!(plan.bytes() > 0.0 && plan.bytes().is_finite());
    }
}

#[test]
fn the_sampling_is_the_coarsest_that_resolves_the_highest_mode() {
    let set = beam_modes(60);
    let model = ModalModel::from_base(set.clone()).expect("model");
    let mut last = 0;
    for k in [1, 5, 20, 60] {
        let plan = plan_transfer_table(&set, &params(TransferModes::Count(k), TableOrder::Linear))
            .expect("plan");
        let w = model.omega()[k - 1];
        assert_eq!(plan.omega_max, w);
        let quarter = std::f64::consts::FRAC_PI_2 / w;
        let s = plan.samples as f64;
        assert!(
            0.004 / s <= quarter * (1.0 + 1e-12),
            "{k} modes: T > π/(2ω)"
        );
        assert!(
            plan.samples == 1 || 0.004 / (s - 1.0) > quarter,
            "{k} modes: {s} samples, fewer would do"
        );
        assert!(plan.samples >= last, "samples fall as modes are added");
        last = plan.samples;
    }
}

/// Builds `params`' table from `set` under `budget`, expecting the refusal: its reason, and how
/// many rows were computed before it.
fn refusal(set: &ModesFile, params: &TransferParams, budget: Budget) -> (Box<OverBudget>, usize) {
    let mut rows = 0;
    let err = build_transfer_table(
        set,
        &TransferParams {
            budget: Some(budget),
            ..params.clone()
        },
        [10.0, 1e-7],
        &mut |_| rows += 1,
    )
    .expect_err("over the budget");
    let text = err.to_string();
    assert!(text.contains("refused before building"), "{text}");
    match err {
        TransferError::OverBudget(o) => (o, rows),
        e => panic!("expected OverBudget, got {e}"),
    }
}

#[test]
fn a_build_over_its_budget_is_refused_with_the_most_modes_that_fit() {
    let set = beam_modes(120);
    let all = params(TransferModes::Count(120), TableOrder::Quadratic);
    let full = plan_transfer_table(&set, &all).expect("plan");
    let budget = Budget {
        max_seconds: full.seconds() / 8.0,
        max_bytes: 1e12,
    };
    let (o, rows) = refusal(&set, &all, budget);
    assert_eq!(rows, 0, "a refused build computed rows");
    assert_eq!(o.plan, full);
    // The first fix: the most modes that fit.
    let k: usize = o.fixes[0]
        .strip_prefix("`transfer.modes` ")
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no mode count in {:?}", o.fixes));
    let plan_k = |k| {
        plan_transfer_table(
            &set,
            &params(TransferModes::Count(k), TableOrder::Quadratic),
        )
        .expect("plan")
    };
    assert!(k < 120);
    assert!(plan_k(k).fits(&budget), "{k} modes do not fit");
    assert!(!plan_k(k + 1).fits(&budget), "{} modes fit too", k + 1);
    // The refusal's largest table is the suggestion's ...
    assert_eq!(o.most_modes, Some(plan_k(k)));
    // ... and that many modes build within the same budget.
    build_transfer_table(
        &set,
        &TransferParams {
            budget: Some(budget),
            ..params(TransferModes::Count(k), TableOrder::Quadratic)
        },
        [10.0, 1e-7],
        &mut |_| {},
    )
    .expect("the suggested mode count builds");
    // A budget below one mode's table has no largest table and no mode-count fix.
    let tiny = Budget {
        max_seconds: 1e-12,
        max_bytes: 1e15,
    };
    let (o, _) = refusal(&set, &all, tiny);
    assert_eq!(o.most_modes, None);
    assert!(
        !o.fixes.iter().any(|f| f.contains("`transfer.modes`")),
        "{:?}",
        o.fixes
    );
}

#[test]
fn a_budget_the_plan_fits_changes_no_bit() {
    let set = beam_modes(30);
    let tp = params(TransferModes::Count(30), TableOrder::Cubic);
    let plan = plan_transfer_table(&set, &tp).expect("plan");
    let free = build_transfer_table(&set, &tp, [10.0, 1e-7], &mut |_| {}).expect("table");
    let held = build_transfer_table(
        &set,
        &TransferParams {
            budget: Some(Budget {
                max_seconds: 2.0 * plan.seconds(),
                max_bytes: 2.0 * plan.bytes(),
            }),
            ..tp
        },
        [10.0, 1e-7],
        &mut |_| {},
    )
    .expect("within the budget");
    assert_eq!(free, held);
}
