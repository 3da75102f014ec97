//! `modal-bake bake --target-error PCT`: the cheapest representation whose worst error against
//! the bake's own full-order truth is within the target is chosen, recorded in the base
//! (`info` shows it), reproducible byte for byte, and its recorded error is what the runtime
//! gives on the same pairs.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;

use dcr_runtime::format::ModesFile;
use dcr_runtime::{Method, ModalModel};
use modal_bake::full_order::{FullOrderSystem, ModalAll, SystemParams};
use modal_bake::target_error::{PairsParams, ReferencePairs};
use modal_bake::transfer::select_region;

#[path = "common/check_args.rs"]
mod check_args;
use check_args::check_args;

fn beam() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/beam.msh")
}

fn bake(out: &Path, target: &str) -> Output {
    bake_with(out, target, &[])
}

fn bake_with(out: &Path, target: &str, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .args([
            "bake",
            beam().to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args([
            "--fixed",
            "clamp",
            "--transfer-h",
            "0.002",
            "--target-error",
            target,
        ])
        .args(extra)
        // Table plans count per-thread memory: the budgets below assume two threads.
        .env("RAYON_NUM_THREADS", "2")
        .output()
        .unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn the_cheapest_representation_within_the_target_is_chosen_and_recorded() {
    let dir = tempfile::tempdir().unwrap();
    // Lax: the fewest modes (5) already meet it; no table.
    let lax = dir.path().join("lax.modes");
    let o = bake(&lax, "100");
    assert!(o.status.success(), "{}", text(&o));
    let b = ModesFile::read(&lax).unwrap();
    let a = b.meta.accuracy.clone().expect("accuracy recorded");
    assert!(a.met && a.worst_pct <= 100.0 && b.transfer.is_none());
    assert_eq!((b.num_modes(), a.modes), (5, 5));
    // Stricter: no modal base within twice the 20-mode cost is within 70 % worst on this beam
    // (20 modes: ~96 %), so a table is chosen — the smallest one that meets it.
    let strict = dir.path().join("strict.modes");
    let o = bake(&strict, "70");
    assert!(o.status.success(), "{}", text(&o));
    let b = ModesFile::read(&strict).unwrap();
    let a = b.meta.accuracy.clone().unwrap();
    assert!(a.met && a.worst_pct <= 70.0, "{a:?}");
    let t = b.transfer.as_ref().expect("a table");
    assert_eq!(
        (Some(t.modes as usize), Some(t.order)),
        (a.table_modes, a.table_order)
    );
    assert!(a.query_cost < a.query_cost_20 && a.pairs >= 30, "{a:?}");
    assert!(text(&o).contains("target 70 %: met"), "{}", text(&o));
    // The recorded error is the runtime's on the same pairs, against an independent truth run.
    let mesh = modal_bake::mesh::read_mesh(&beam()).unwrap();
    let sp = SystemParams {
        fixed: vec!["clamp".into()],
        ..Default::default()
    };
    let sys = FullOrderSystem::new(mesh, &sp, "beam").unwrap();
    let ma = ModalAll::new(&sys, 6000).unwrap();
    let model = Arc::new(ModalModel::from_base(b.clone()).unwrap());
    let region = select_region(&model, &[], None, 0.5);
    let pp = PairsParams {
        h: 0.002,
        ..PairsParams::default()
    };
    let pairs = ReferencePairs::new(&sys, Some(&ma), &b, &region, &pp, &mut |_| {}).unwrap();
    let mut dr = pairs.response(model, Method::Transfer);
    let (errors, _) = pairs.errors(&mut dr, 1.0);
    let worst = errors.iter().fold(0.0f64, |m, (e, _)| m.max(e.abs()));
    assert!(
        (worst - a.worst_pct).abs() <= 1e-9 * worst,
        "{worst} vs {}",
        a.worst_pct
    );
    // Deterministic: the same bytes again; `info` shows the record.
    let again = dir.path().join("again.modes");
    assert!(bake(&again, "70").status.success());
    assert_eq!(
        std::fs::read(&strict).unwrap(),
        std::fs::read(&again).unwrap()
    );
    let o = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .args(["info", strict.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(text(&o).contains("accuracy target 70 %"), "{}", text(&o));
    // `check` finds each choice up to date with the options the bake printed in place of
    // --target-error, and stale, saying so, with the bake's own.
    let check = |base: &Path, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_modal-bake"))
            .args(["check", beam().to_str().unwrap(), base.to_str().unwrap()])
            .args(["--fixed", "clamp"])
            .args(extra)
            .output()
            .unwrap()
    };
    assert_eq!(check(&lax, &["--modes", "5"]).status.code(), Some(0));
    let (n, order) = (t.modes.to_string(), t.order.to_string());
    let table = [
        "--transfer-h",
        "0.002",
        "--modes",
        "20",
        "--transfer-modes",
        &n,
        "--transfer-order",
        &order,
    ];
    assert_eq!(
        check(&strict, &table).status.code(),
        Some(0),
        "{}",
        text(&check(&strict, &table))
    );
    let o = check(&strict, &["--transfer-h", "0.002"]);
    let printed = format!(
        "`--modes 20 --transfer-modes {n} --transfer-order {order}` in place of --target-error"
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains(&printed), "{}", text(&o));
    let o = bake(&strict, "70");
    assert!(text(&o).contains(&printed), "{}", text(&o));
    // `info` rebuilds the same options from each base's record.
    for base in [&lax, &strict] {
        let args = check_args(base);
        let o = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
            .args(["check", beam().to_str().unwrap(), base.to_str().unwrap()])
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", text(&o));
    }
    let o = check(&lax, &["--transfer-h", "0.002"]);
    assert!(
        text(&o).contains("check it with the bake's options, `--modes 5` in place of --target-error, without --transfer-h"),
        "{}",
        text(&o)
    );
}

#[test]
fn a_target_needs_the_step_and_a_positive_percentage() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.modes");
    let o = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .args([
            "bake",
            beam().to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--fixed", "clamp", "--target-error", "5"])
        .output()
        .unwrap();
    assert!(
        !o.status.success() && text(&o).contains("--transfer-h"),
        "{}",
        text(&o)
    );
    let o = bake(&out, "-3");
    assert!(
        !o.status.success() && text(&o).contains("percentage > 0"),
        "{}",
        text(&o)
    );
    assert!(!text(&o).contains("panicked") && !out.exists());
}

// Every candidate table is held to the bake's budget: one over it is not built (reported as
// skipped, with its estimate), except that the every-mode candidate first becomes the most
// modes that fit when those are more than any table tried before it has. An unmeetable target
// (1e-6 %) makes the choice try every candidate. By their plans on two threads the beam's
// tables need 0.10 GB (160 modes, quadratic) to 0.43 GB (every mode, cubic); 0.05 GB is under
// any table (a plan counts 50 MB before its first row).
#[test]
fn candidate_tables_are_held_to_the_budget() {
    let dir = tempfile::tempdir().unwrap();
    let json = |o: &Output| -> serde_json::Value {
        assert!(o.status.success(), "{}", text(o));
        serde_json::from_slice(&o.stdout).expect("--json output")
    };
    let names = |v: &serde_json::Value, key: &str| -> Vec<String> {
        v[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["representation"].as_str().unwrap().to_string())
            .collect()
    };
    let count = |t: &str| -> Option<usize> {
        t.strip_prefix("20 modes + table of ")
            .and_then(|r| r.split_whitespace().next())
            .and_then(|n| n.parse().ok())
    };
    // 0.2 GB: the 160-mode tables fit; the every-mode quadratic one becomes the most modes that
    // fit (more than 160); the cubic one's most modes are fewer than that, so it is skipped.
    let out = dir.path().join("mid.modes");
    let v = json(&bake_with(&out, "1e-6", &["--max-memory", "0.2", "--json"]));
    let tried = names(&v, "tried");
    let counts: Vec<usize> = tried.iter().filter_map(|t| count(t)).collect();
    assert_eq!(counts.len(), 3, "{tried:?}");
    assert!(counts[..2] == [160, 160] && counts[2] > 160, "{tried:?}");
    assert!(tried[5].ends_with("order 2"), "{tried:?}");
    assert_eq!(
        names(&v, "skipped"),
        ["20 modes + table of every mode, order 3"],
        "{v}"
    );
    let b = ModesFile::read(&out).unwrap();
    let a = b.meta.accuracy.clone().unwrap();
    assert!(!a.met && a.table_modes == Some(counts[2]), "{a:?}");
    // 0.05 GB: no table fits; the four are skipped with their estimates and the choice is the
    // most accurate modal candidate, no table, nothing over the budget built.
    let out = dir.path().join("low.modes");
    let v = json(&bake_with(
        &out,
        "1e-6",
        &["--max-memory", "0.05", "--json"],
    ));
    assert_eq!(names(&v, "tried").len(), 3, "{v}");
    let skipped = v["skipped"].as_array().unwrap();
    assert_eq!(skipped.len(), 4, "{v}");
    for k in skipped {
        assert!(k["estimated_bytes"].as_f64().unwrap() > 5e7, "{k}");
        assert!(
            k["reason"]
                .as_str()
                .unwrap()
                .contains("refused before building"),
            "{k}"
        );
    }
    let b = ModesFile::read(&out).unwrap();
    assert!(
        b.transfer.is_none() && b.num_modes() == 20,
        "{:?}",
        b.meta.accuracy
    );
    // The text output names what was skipped and how to build it.
    let o = bake_with(&out, "1e-6", &["--max-memory", "0.05"]);
    assert!(o.status.success(), "{}", text(&o));
    let t = text(&o);
    assert!(
        t.contains("skipped 20 modes + table of every mode, order 3"),
        "{t}"
    );
    assert!(t.contains("--force builds it"), "{t}");
}
