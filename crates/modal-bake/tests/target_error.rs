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

fn beam() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/beam.msh")
}

fn bake(out: &Path, target: &str) -> Output {
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
