//! The transfer method in the scene format: `"method": {"transfer": {...}}` parses, bakes a base
//! with a peak-transfer table into `NAME.transfer.modes` (leaving the modal base alone), and the
//! run's responses inside the table's region come from the table (`ServedBy::TransferTable`),
//! those outside it from the modal base; objects without settings or with a table pinned to
//! another step are refused with an error naming them; `--gain` scales every response.
//!
//! The test scene is the washing scene's floor (data/scenes/floor.msh, 753 free dofs, every
//! mode in its table) at linear order, so its table bakes in seconds. Run with
//! `cargo test --release -p dcr-scenes --test transfer`.

use std::path::{Path, PathBuf};

use dcr_rapier::f64::ApplyMode;
use dcr_runtime::format::ModesFile;
use dcr_scenes::repo_root;
use dcr_scenes::runner::{
    base_path, ensure_base, ensure_transfer_base, run_scene, transfer_base_path, MethodChoice,
    RunParams, RunReport,
};
use dcr_scenes::scene::{MethodDesc, SceneDesc, TableOrderDesc, TransferDesc};
use serde_json::json;

/// Region of the test table: the floor's top where x ≤ 0.5 m (mesh frame).
const REGION_BOX: [f64; 6] = [-2.6, -0.5, -2.1, 0.5, 0.5, 2.1];

/// A 20 kg box dropped at the floor's centre (inside the region), a 1 kg box resting at
/// x = −1.5 m (inside) and one at x = +1.5 m (outside). `method` is the floor's `method`;
/// `transfer` its optional `transfer` settings.
fn floor_scene(method: serde_json::Value, transfer: Option<serde_json::Value>) -> SceneDesc {
    let mut floor = json!({
        "name": "floor",
        "mesh": "data/scenes/floor.msh",
        "material": {"youngs": 1e10, "poisson": 0.3, "density": 540},
        "fixed": ["edges"],
        "body": "static",
        "colliders": [{"shape": {"cuboid": {"half_extents": [2.5, 0.1, 2.0]}},
                       "offset": {"translation": [0, -0.1, 0]}}],
        "method": method,
    });
    if let Some(t) = transfer {
        floor["transfer"] = t;
    }
    let cube = |name: &str, mass: f64, half: f64, at: [f64; 3], vy: f64| {
        json!({
            "name": name,
            "colliders": [{"shape": {"cuboid": {"half_extents": [half, half, half]}}}],
            "mass": mass,
            "pose": {"translation": at},
            "linvel": [0, vy, 0],
        })
    };
    let scene = json!({
        "name": "transfer_floor",
        "h": 0.01,
        "seconds": 0.3,
        "elastic": [floor],
        "props": [
            cube("hammer", 20.0, 0.1, [0.0, 0.35, 0.0], -3.0),
            cube("box_in", 1.0, 0.1, [-1.5, 0.1, 0.5], 0.0),
            cube("box_out", 1.0, 0.1, [1.5, 0.1, 0.5], 0.0),
        ],
        "outcomes": [{"name": "boxes_max_lift", "kind": "max_lift", "bodies": "box_*"}],
    });
    serde_json::from_value(scene).expect("test scene parses")
}

fn transfer_settings() -> serde_json::Value {
    json!({"up": [0, 1, 0], "boxes": [REGION_BOX], "order": "linear"})
}

fn bases_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("transfer_{name}"));
    std::fs::create_dir_all(&dir).expect("bases dir");
    dir
}

fn run(desc: &SceneDesc, bases: &Path, method: MethodChoice, gain: Option<f64>) -> RunReport {
    run_scene(
        desc,
        &RunParams {
            method,
            gain,
            bases_dir: bases.to_path_buf(),
            energy_eta: None,
            ..RunParams::new(repo_root(), true)
        },
    )
    .expect("scene runs")
}

fn body_index(r: &RunReport, name: &str) -> usize {
    r.bodies_all
        .iter()
        .position(|b| b == name)
        .unwrap_or_else(|| panic!("no body {name}"))
}

/// The scene format: `{"transfer": {...}}` reads into `MethodDesc::Transfer` with its fields
/// (unset ones at their defaults), an empty object is the whole surface, and a misspelt field
/// is refused with its name.
#[test]
fn transfer_method_parses() {
    let d = floor_scene(json!({"transfer": transfer_settings()}), None);
    let MethodDesc::Transfer(t) = &d.elastic[0].method else {
        panic!("method is {:?}", d.elastic[0].method)
    };
    assert_eq!(t.up, Some([0.0, 1.0, 0.0]));
    assert_eq!(t.boxes, vec![REGION_BOX]);
    assert_eq!(t.order, TableOrderDesc::Linear);
    assert_eq!((t.modes, t.h), (None, None));
    let d = floor_scene(json!("modal"), Some(json!({})));
    assert_eq!(d.elastic[0].transfer, Some(TransferDesc::default()));
    let text = json!({"name": "x", "elastic": [{
        "name": "floor", "mesh": "m", "material": {"youngs": 1e9, "poisson": 0.3, "density": 1},
        "body": "static", "method": {"transfer": {"upp": [0, 1, 0]}}}]})
    .to_string();
    let err = serde_json::from_str::<SceneDesc>(&text)
        .expect_err("a misspelt transfer field is refused")
        .to_string();
    assert!(err.contains("upp"), "{err}");
}

/// A scene whose floor's method is `transfer` bakes `floor.transfer.modes` with a table for
/// the scene's h over the region; the responses at the resting box inside the region come from
/// the table and those at the box outside it from the modal base (counted as fallback); the
/// modal base, baked before, is neither rebaked nor changed. The same scene on the modal method
/// serves nothing from a table and gives other Δv (the table sums every mode).
#[test]
fn transfer_scene_bakes_a_table_and_serves_from_it() {
    let bases = bases_dir("serves");
    let desc = floor_scene(json!({"transfer": transfer_settings()}), None);
    let e = &desc.elastic[0];
    let (modal_path, _) = ensure_base(&repo_root(), &bases, e, None).expect("modal base bakes");
    let modal_bytes = std::fs::read(&modal_path).expect("modal base reads");

    let r = run(&desc, &bases, MethodChoice::Scene, None);
    let m = &r.models[0];
    assert_eq!(m.base, "floor.transfer.modes");
    assert!(m.method.starts_with("transfer order 1"), "{}", m.method);
    let base = ModesFile::read(&transfer_base_path(&bases, e)).expect("transfer base reads");
    let table = base.transfer.as_ref().expect("the base has a table");
    assert!((table.h - desc.h).abs() < 1e-12, "table h {}", table.h);
    assert!(
        table.modes as usize > 10 * base.num_modes(),
        "table sums {} modes",
        table.modes
    );
    for &v in &table.vertices {
        let x = base.surface_vertices[v as usize];
        assert!(
            x[0] <= REGION_BOX[3] + 1e-9 && x[1] > -1e-6,
            "region vertex {x:?} outside the box or not on the top"
        );
    }

    let (inside, outside) = (body_index(&r, "box_in"), body_index(&r, "box_out"));
    let of = |b: usize| r.events.iter().filter(move |ev| ev.body == b);
    assert!(of(inside).count() > 0, "no response reached box_in");
    assert!(of(outside).count() > 0, "no response reached box_out");
    assert!(
        of(inside).all(|ev| ev.by_table),
        "a response inside the region came from the modal base"
    );
    assert!(
        of(outside).all(|ev| !ev.by_table),
        "a response outside the region came from the table"
    );
    assert!(m.stats.events_by_table > 0 && m.stats.contacts_by_table > 0);
    assert!(m.stats.contacts_table_fallback > 0);
    assert!(
        m.stats
            .table_fallback_steps
            .contains_key("contacts_outside_region"),
        "{:?}",
        m.stats.table_fallback_steps
    );
    assert_eq!(
        std::fs::read(&modal_path).expect("modal base reads"),
        modal_bytes,
        "the transfer run changed the modal base"
    );
    assert_eq!(modal_path, base_path(&bases, e));

    let modal = run(&desc, &bases, MethodChoice::Modal, None);
    assert_eq!(modal.models[0].base, "floor.modes");
    assert_eq!(modal.models[0].stats.events_by_table, 0);
    let first = |r: &RunReport| {
        r.events
            .iter()
            .find(|ev| ev.body == inside)
            .expect("an event at box_in")
            .delta_v
    };
    let (dv_table, dv_modal) = (first(&r), first(&modal));
    assert!(
        (dv_table - dv_modal).abs() > 0.05 * dv_modal.abs(),
        "table Δv {dv_table} m/s equals the 20-mode Δv {dv_modal} m/s"
    );
}

/// Adding transfer settings to an object leaves its modal base's path, parameters and bytes as
/// they were (no rebake); the transfer base is a separate file, rebaked when its settings change
/// and not when they do not.
#[test]
fn transfer_settings_leave_the_modal_base_alone() {
    let bases = bases_dir("separate");
    let root = repo_root();
    let plain = floor_scene(json!("modal"), None);
    let (p0, _) = ensure_base(&root, &bases, &plain.elastic[0], None).expect("modal base bakes");
    let bytes = std::fs::read(&p0).expect("reads");
    let with = floor_scene(json!("modal"), Some(transfer_settings()));
    let e = &with.elastic[0];
    let (p1, baked) = ensure_base(&root, &bases, e, None).expect("modal base checks");
    assert_eq!(p0, p1);
    assert!(!baked, "transfer settings made the modal base stale");
    assert_eq!(std::fs::read(&p1).expect("reads"), bytes);
    assert_eq!(
        dcr_scenes::runner::bake_params(&plain.elastic[0]).hash(),
        dcr_scenes::runner::bake_params(e).hash()
    );

    let t = e.transfer.clone().expect("settings");
    let (tp, _) = ensure_transfer_base(&root, &bases, e, &t, 0.01, None).expect("table bakes");
    assert_ne!(tp, p0);
    let (_, again) = ensure_transfer_base(&root, &bases, e, &t, 0.01, None).expect("checks");
    assert!(!again, "an unchanged table was rebaked");
    let moved = TransferDesc {
        boxes: vec![[-2.6, -0.5, -2.1, 0.0, 0.5, 2.1]],
        ..t
    };
    let (_, rebaked) = ensure_transfer_base(&root, &bases, e, &moved, 0.01, None).expect("rebakes");
    assert!(rebaked, "a changed region did not rebake the table");
    assert_eq!(std::fs::read(&p0).expect("reads"), bytes);
}

/// `--method transfer` on an object without transfer settings, and a table pinned to another
/// step than the scene's, are refused before any bake, naming the object.
#[test]
fn transfer_without_settings_or_at_another_step_is_refused() {
    let bases = bases_dir("refused");
    let params = |method| RunParams {
        method,
        bases_dir: bases.clone(),
        ..RunParams::new(repo_root(), true)
    };
    let plain = floor_scene(json!("modal"), None);
    let err = run_scene(&plain, &params(MethodChoice::Transfer))
        .expect_err("no settings: refused")
        .to_string();
    assert!(
        err.contains("elastic object floor") && err.contains("--method transfer"),
        "{err}"
    );
    let mut pinned = transfer_settings();
    pinned["h"] = json!(0.005);
    let desc = floor_scene(json!({"transfer": pinned}), None);
    let err = format!(
        "{:#}",
        run_scene(&desc, &params(MethodChoice::Scene)).expect_err("other h: refused")
    );
    assert!(
        err.contains("elastic object floor") && err.contains("0.005") && err.contains("0.01"),
        "{err}"
    );
    assert!(
        !transfer_base_path(&bases, &desc.elastic[0]).exists(),
        "a refused run baked a table"
    );
}

/// A run's gain replaces every object's own: on the first response step (before the runs
/// diverge) every impulse at gain 2 is twice the one at gain 1, and at gain 0 nothing moves.
#[test]
fn run_gain_scales_every_response() {
    let bases = bases_dir("gain");
    let desc = floor_scene(json!({"transfer": transfer_settings()}), None);
    let one = run(&desc, &bases, MethodChoice::Scene, Some(1.0));
    let two = run(&desc, &bases, MethodChoice::Scene, Some(2.0));
    assert_eq!(one.models[0].gain, 1.0);
    assert_eq!(two.models[0].gain, 2.0);
    let row = one.events.first().expect("events at gain 1").row;
    let step = |r: &RunReport| -> Vec<[f64; 3]> {
        r.events
            .iter()
            .filter(|ev| ev.row == row)
            .map(|ev| ev.impulse)
            .collect()
    };
    let (a, b) = (step(&one), step(&two));
    assert!(!a.is_empty() && a.len() == b.len());
    for (x, y) in a.iter().zip(&b) {
        for k in 0..3 {
            assert!(
                (y[k] - 2.0 * x[k]).abs() <= 1e-9 * x[k].abs().max(1e-12),
                "gain 2 impulse {y:?} vs gain 1 {x:?}"
            );
        }
    }
    let zero = run(&desc, &bases, MethodChoice::Scene, Some(0.0));
    assert_eq!(zero.injected_ke, 0.0);
    assert!(zero.events.iter().all(|ev| ev.delta_v == 0.0));
}

/// The CLI: `run dinner --method transfer` (the table has no transfer settings) exits non-zero
/// with one line naming the object, before any bake; `--gain -1` is refused by the parser;
/// `--launch sustained-peak` with attenuation is refused before the run.
#[test]
fn cli_refuses_transfer_without_settings_a_negative_gain_and_a_sustained_attenuation() {
    let exe = env!("CARGO_BIN_EXE_dcr-scenes");
    let bases = bases_dir("cli");
    let out = std::process::Command::new(exe)
        .args(["run", "dinner", "--method", "transfer", "--seconds", "0.01"])
        .arg("--bases")
        .arg(&bases)
        .arg("--out")
        .arg(bases.join("run"))
        .current_dir(repo_root())
        .output()
        .expect("dcr-scenes runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "exit 0; stderr {err}");
    assert!(
        err.contains("elastic object table") && err.contains("--method transfer"),
        "{err}"
    );
    assert!(!bases.join("table.transfer.modes").exists());
    let out = std::process::Command::new(exe)
        .args(["run", "dinner", "--gain", "-1"])
        .current_dir(repo_root())
        .output()
        .expect("dcr-scenes runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--gain"), "{err}");
    // The sustained launch needs modal filters: refused with attenuation, before any run.
    let out = std::process::Command::new(exe)
        .args([
            "run",
            "dinner",
            "--launch",
            "sustained-peak",
            "--method",
            "attenuation",
        ])
        .arg("--out")
        .arg(bases.join("run-launch"))
        .current_dir(repo_root())
        .output()
        .expect("dcr-scenes runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("--launch sustained-peak"),
        "{err}"
    );
    assert!(!bases.join("run-launch").exists());
}

/// An on-demand table over `--max-bake-time` is refused once its modes are known, before a row
/// is built: the error names the object, the estimate and the scene settings that lower it,
/// and no base is written; the mode count it suggests bakes within the same budget. (The
/// floor's every-mode cubic table: 753 modes, ~50 s on one thread, against a 1 s budget.)
#[test]
fn cli_refuses_an_on_demand_table_over_the_budget() {
    let exe = env!("CARGO_BIN_EXE_dcr-scenes");
    let bases = bases_dir("budget");
    let _ = std::fs::remove_dir_all(&bases);
    let desc = floor_scene(json!({"transfer": {}}), None);
    let scene = bases.join("scene.json");
    std::fs::create_dir_all(&bases).unwrap();
    std::fs::write(&scene, serde_json::to_vec(&desc).unwrap()).unwrap();
    let dcr = |extra: &[&str]| {
        std::process::Command::new(exe)
            .arg("run")
            .arg(&scene)
            .args(["--seconds", "0.02", "--dcr", "on", "--max-bake-time", "1"])
            .args(extra)
            .arg("--bases")
            .arg(bases.join("bases"))
            .arg("--out")
            .arg(bases.join("run"))
            .env("RAYON_NUM_THREADS", "1")
            .current_dir(repo_root())
            .output()
            .expect("dcr-scenes runs")
    };
    let out = dcr(&[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "exit 0; stderr {err}");
    for needle in [
        "elastic object floor: ",
        "transfer table: refused before building",
        "753 modes",
        "`transfer.modes` ",
        "`transfer.up`",
        "--force-bake",
    ] {
        assert!(err.contains(needle), "{needle:?} missing: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!bases.join("bases/floor.transfer.modes").exists());
    // The suggested count bakes within the same budget.
    let k: usize = err
        .split("`transfer.modes` ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .expect("a suggested mode count");
    let fitted = floor_scene(json!({"transfer": {"modes": k}}), None);
    std::fs::write(&scene, serde_json::to_vec(&fitted).unwrap()).unwrap();
    let out = dcr(&[]);
    assert!(
        out.status.success(),
        "{k} modes: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(bases.join("bases/floor.transfer.modes").exists());
}

/// The support of lifted bodies in the scene runner, in both application modes: a box the
/// response lifts off gets its support event (m g h along the up axis, at its centre of mass)
/// and ends the step in which it leaves moving up at the response's Δv (rapier's symplectic
/// Euler: the row's displacement over h is the end-of-step velocity), not at Δv − g h, which it
/// would be if gravity took g h off it over that step with its contact no longer carrying it.
/// In the solver it leaves a step later (after the replay), as fast to within the restitution
/// pass's single sweep over the box's four contacts.
#[test]
fn a_lifted_box_leaves_with_the_velocity_its_response_asks_for() {
    let bases = bases_dir("support");
    let desc = floor_scene(json!("modal"), None);
    // The scene's gravity along its up axis (y), taken off per step.
    let gh = -desc.gravity[1] * desc.h;
    let mut left = Vec::new();
    for apply in [ApplyMode::AfterStep, ApplyMode::InSolver] {
        // Gain 30: a push several times g h (the floor's own Δv is a tenth of it).
        let r = run_scene(
            &desc,
            &RunParams {
                method: MethodChoice::Scene,
                gain: Some(30.0),
                bases_dir: bases.clone(),
                energy_eta: None,
                apply,
                ..RunParams::new(repo_root(), true)
            },
        )
        .expect("scene runs");
        let b = body_index(&r, "box_in");
        let row = r
            .events
            .iter()
            .find(|e| e.body == b && e.delta_v > 0.0)
            .expect("box_in pushed")
            .row;
        let at_row = || r.events.iter().filter(|e| e.body == b && e.row == row);
        let dv = at_row().map(|e| e.delta_v).fold(0.0, f64::max);
        assert!(dv > 2.0 * gh, "{apply:?}: Δv {dv} m/s against g h {gh} m/s");
        // The box weighs 1 kg.
        let support: Vec<_> = at_row().filter(|e| e.delta_v == 0.0).collect();
        assert_eq!(support.len(), 1, "{apply:?}: one support event");
        assert!(
            (support[0].impulse[1] - gh).abs() < 1e-9,
            "{apply:?}: support {:?} N·s vs m g h = {gh} N·s",
            support[0].impulse
        );
        let t = &r.trajectory;
        let col = t.names.iter().position(|n| n == "box_in").unwrap();
        // The event's row is when it acts (in the solver: the end of the replay step, one
        // step later); the box leaves over the step after it.
        let v = (t.pos(row + 1, col)[1] - t.pos(row, col)[1]) / desc.h;
        left.push(v);
        // Its corners ask for slightly different Δv (the largest taken here), so its centre
        // leaves a little below the largest; g h lower would be the lost support. (In the
        // solver: compared with the after-step run below.)
        assert!(
            apply == ApplyMode::InSolver || (v - dv).abs() <= 0.3 * gh,
            "{apply:?}: left at {v} m/s for a Δv of {dv} m/s"
        );
    }
    assert!(
        (left[0] - left[1]).abs() <= 0.3 * gh,
        "left at {} m/s after the step, {} m/s in the solver",
        left[0],
        left[1]
    );
}
