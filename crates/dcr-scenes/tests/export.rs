//! Scene exports: the run glTF carries one node per body per side, a keyframe per trajectory
//! row equal to the recorded poses, the response events of the on run (upward kicks at the
//! plates, at the rows they were applied); every scene's file passes the Khronos
//! glTF-Validator; outcomes.svg's curves end at the reported figures; the CLI writes both runs,
//! outcomes.svg and the GLB with `--dcr both`; bad calls fail cleanly.

#[path = "../../modal-bake/tests/common/gltf_check.rs"]
mod gltf_check;

use std::path::PathBuf;
use std::sync::OnceLock;

use dcr_scenes::export::{outcome_series, write_outcomes_svg, write_scene_glb, Side};
use dcr_scenes::runner::{ensure_base, run_scene, MethodChoice, RunParams, RunReport};
use dcr_scenes::scene::SceneDesc;
use dcr_scenes::{repo_root, SCENES};
use gltf_check::{validate_gltf, Glb};

fn bases() -> &'static PathBuf {
    static BASES: OnceLock<PathBuf> = OnceLock::new();
    BASES.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bases");
        for s in SCENES {
            for e in &scene(s).elastic {
                ensure_base(&repo_root(), &dir, e, None).expect("base bakes");
            }
        }
        dir
    })
}

fn scene(name: &str) -> SceneDesc {
    SceneDesc::read(&repo_root().join("scenes").join(format!("{name}.json"))).expect("scene reads")
}

fn run(desc: &SceneDesc, dcr: bool, seconds: f64) -> RunReport {
    run_scene(
        desc,
        &RunParams {
            seconds: Some(seconds),
            method: MethodChoice::Scene,
            bases_dir: bases().clone(),
            ..RunParams::new(repo_root(), dcr)
        },
    )
    .expect("scene runs")
}

fn sides<'a>(on: &'a RunReport, off: &'a RunReport) -> [Side<'a>; 2] {
    [
        Side {
            label: "on",
            report: on,
        },
        Side {
            label: "off",
            report: off,
        },
    ]
}

#[test]
fn dinner_glb_nodes_keyframes_and_events_match_the_runs() {
    let desc = scene("dinner");
    let (on, off) = (run(&desc, true, 0.5), run(&desc, false, 0.5));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dinner.glb");
    let info = write_scene_glb(&desc, &repo_root(), bases(), &sides(&on, &off), &path).unwrap();
    validate_gltf(&path);
    let glb = Glb::read(&path);
    let nodes = &glb.root.nodes;
    let by_name = |n: &str| {
        nodes
            .iter()
            .position(|x| x.name.as_deref() == Some(n))
            .unwrap_or_else(|| panic!("no node {n}"))
    };
    // Two sides, each with every body of the world (table + 13 props).
    let (s_on, s_off) = (by_name("on"), by_name("off"));
    assert_eq!(nodes[s_on].children.as_ref().unwrap().len(), 14);
    assert_eq!(nodes[s_off].children.as_ref().unwrap().len(), 14);
    assert_eq!(info.body_nodes, 28);
    // The on side is left of the off side, apart by more than the table's 1.6 m.
    let (x_on, x_off) = (
        nodes[s_on].translation.unwrap()[0],
        nodes[s_off].translation.unwrap()[0],
    );
    assert!(x_off - x_on > 1.6, "sides {x_on} and {x_off} overlap");
    // One animation, translation + rotation per dynamic body per side (14 each).
    assert_eq!(glb.root.animations.len(), 1);
    let anim = &glb.root.animations[0];
    assert_eq!(anim.channels.len(), 2 * 2 * 13);
    // plate_0's translation keyframes are its recorded positions, one per row.
    let plate = by_name("on_plate_0");
    let col = on
        .trajectory
        .names
        .iter()
        .position(|n| n == "plate_0")
        .unwrap();
    let ch = anim
        .channels
        .iter()
        .find(|c| {
            c.target.node.value() == plate
                && matches!(
                    c.target.path.as_ref().unwrap(),
                    gltf::json::animation::Property::Translation
                )
        })
        .expect("plate_0 translation channel");
    let s = &anim.samplers[ch.sampler.value()];
    let (t, p) = (glb.floats(s.input.value()), glb.floats(s.output.value()));
    assert_eq!(t.len(), on.trajectory.rows());
    for k in 0..t.len() {
        assert!((t[k] as f64 - k as f64 * desc.h).abs() < 1e-6);
        let q = on.trajectory.pos(k, col);
        for a in 0..3 {
            assert_eq!(p[3 * k + a], q[a] as f32, "row {k} axis {a}");
        }
    }
    // Events: every response of the on run, none off; plates kicked upwards at the rows the
    // trajectory shows them leaving the table.
    let ex = glb.extras();
    let sides_ex = ex["dcr"]["sides"].as_array().unwrap();
    let ev_on = sides_ex[0]["events"].as_array().unwrap();
    assert_eq!(ev_on.len(), on.events.len());
    assert!(!ev_on.is_empty());
    assert!(sides_ex[1]["events"].as_array().unwrap().is_empty());
    let first = on
        .events
        .iter()
        .filter(|e| on.bodies_all[e.body] == "plate_0")
        .map(|e| e.row)
        .min()
        .expect("plate_0 receives a response");
    for e in ev_on {
        let node = e["node"].as_str().unwrap();
        assert!(
            nodes.iter().any(|n| n.name.as_deref() == Some(node)),
            "{node}"
        );
        assert!((e["time"].as_f64().unwrap() - e["row"].as_f64().unwrap() * desc.h).abs() < 1e-12);
        if e["body"].as_str().unwrap().starts_with("plate") {
            assert!(
                e["impulse"][1].as_f64().unwrap() > 0.0,
                "plate kicked downwards: {e}"
            );
        }
    }
    let y0 = on.trajectory.pos(0, col)[1];
    let rise = |k: usize| on.trajectory.pos(k, col)[1] - y0;
    assert!(
        rise(first - 1).abs() < 1e-4,
        "plate_0 moved before its response"
    );
    assert!(
        rise(first + 1) > 1e-4,
        "plate_0 does not rise right after its response"
    );
    // Same trajectory on both sides until the first response.
    let first_any = on.events.iter().map(|e| e.row).min().unwrap();
    for k in 0..first_any {
        assert_eq!(on.trajectory.pos(k, col), off.trajectory.pos(k, col));
    }
}

#[test]
fn every_scene_exports_a_valid_glb() {
    let dir = tempfile::tempdir().unwrap();
    for name in SCENES {
        let desc = scene(name);
        let (on, off) = (run(&desc, true, 0.05), run(&desc, false, 0.05));
        let path = dir.path().join(format!("{name}.glb"));
        let info = write_scene_glb(&desc, &repo_root(), bases(), &sides(&on, &off), &path)
            .unwrap_or_else(|e| panic!("{name}: {e:#}"));
        assert_eq!(info.keyframes, 6, "{name}");
        validate_gltf(&path);
    }
}

#[test]
fn outcome_curves_end_at_the_reported_figures_and_the_svg_has_one_per_run() {
    let desc = scene("dinner");
    let (on, off) = (run(&desc, true, 0.5), run(&desc, false, 0.5));
    for r in [&on, &off] {
        for o in &desc.outcomes {
            let v = outcome_series(o, &r.trajectory, 1000);
            assert_eq!(v.len(), r.trajectory.rows());
            assert_eq!(v.last().unwrap().1, r.outcomes[&o.name].0, "{}", o.name);
            if o.kind.starts_with("max_") && o.kind != "max_slide" {
                assert!(
                    v.windows(2).all(|w| w[1].1 >= w[0].1),
                    "{} not monotone",
                    o.name
                );
            }
            // Thinned to at most 10 points: first and last rows kept, same values there.
            let few = outcome_series(o, &r.trajectory, 10);
            assert!(few.len() <= 10, "{} points", few.len());
            assert_eq!(few[0], v[0]);
            assert_eq!(few.last(), v.last());
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("outcomes.svg");
    write_outcomes_svg(&desc, &[&on, &off], &path).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"));
    for o in &desc.outcomes {
        assert!(svg.contains(&o.name), "{} missing", o.name);
    }
    assert!(svg.contains("dcr on") && svg.contains("dcr off"));
    // One curve + one legend entry per run and outcome, in each run's colour.
    let n = desc.outcomes.len();
    assert_eq!(svg.matches(r##"stroke="#C83C28""##).count(), 2 * n);
    assert_eq!(svg.matches(r##"stroke="#5A5A5A""##).count(), 2 * n);
}

#[test]
fn export_refuses_no_runs_and_runs_of_another_scene() {
    let desc = scene("dinner");
    let roof = run(&scene("roof"), false, 0.02);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.glb");
    let e = write_scene_glb(&desc, &repo_root(), bases(), &[], &path).unwrap_err();
    assert!(e.to_string().contains("no run"), "{e}");
    let e = write_scene_glb(
        &desc,
        &repo_root(),
        bases(),
        &[Side {
            label: "off",
            report: &roof,
        }],
        &path,
    )
    .unwrap_err();
    assert!(e.to_string().contains("not a run of scene dinner"), "{e}");
    assert!(!path.exists());
}

#[test]
fn cli_run_both_writes_both_runs_outcomes_svg_and_the_glb() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("dinner");
    let glb = dir.path().join("dinner.glb");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_dcr-scenes"))
        .args([
            "run",
            "dinner",
            "--dcr",
            "both",
            "--seconds",
            "0.3",
            "--out",
        ])
        .arg(&out)
        .arg("--bases")
        .arg(bases())
        .arg("--gltf")
        .arg(&glb)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "on/summary.json",
        "off/summary.json",
        "on/trajectory.npz",
        "outcomes.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let on: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("on/summary.json")).unwrap())
            .unwrap();
    assert_eq!(on["dcr"], true);
    validate_gltf(&glb);
}

#[test]
fn cli_table1_gltf_writes_one_on_off_file_per_scene() {
    let dir = tempfile::tempdir().unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_dcr-scenes"))
        .args([
            "table1",
            "--scenes",
            "dinner,roof",
            "--seconds",
            "0.3",
            "--bases",
        ])
        .arg(bases())
        .arg("--gltf")
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for s in ["dinner", "roof"] {
        let path = dir.path().join(format!("{s}.glb"));
        validate_gltf(&path);
        let ex = Glb::read(&path).extras();
        let labels: Vec<_> = ex["dcr"]["sides"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| {
                (
                    s["label"].as_str().unwrap().to_string(),
                    s["dcr"].as_bool().unwrap(),
                )
            })
            .collect();
        assert_eq!(labels, [("on".into(), true), ("off".into(), false)], "{s}");
        assert_eq!(ex["dcr"]["scene"], s);
    }
}

/// `table1 --json` names the launch rule of its runs, and the sustained launch changes the
/// roof's outcome (its nail box slides further while the roof rings).
#[test]
fn cli_table1_json_names_the_launch_rule() {
    let table1 = |launch: &str| -> serde_json::Value {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_dcr-scenes"))
            .args(["table1", "--json", "--scenes", "roof", "--seconds", "0.45"])
            .args(["--launch", launch, "--bases"])
            .arg(bases())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice(&o.stdout).expect("table1 --json prints JSON")
    };
    let slide = |v: &serde_json::Value| v["outcomes"]["nailbox_slide"]["on"].as_f64().unwrap();
    let paper = table1("peak-over-step");
    let sustained = table1("sustained-peak");
    let (p, s) = (&paper["scenes"][0], &sustained["scenes"][0]);
    assert_eq!(p["launch"], "peak_over_step");
    assert_eq!(s["launch"], "sustained_peak");
    assert!(slide(s) > 2.0 * slide(p), "{} vs {} mm", slide(s), slide(p));
}
