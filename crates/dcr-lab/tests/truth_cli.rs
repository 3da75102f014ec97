//! End-to-end tests of `dcr-lab truth`: probe's JSON shape, the two methods agree, clear errors on bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(rel)
}

fn truth(extra: &[&str]) -> Output {
    truth_fixed(&["--fixed", "clamp"], extra)
}

/// `dcr-lab truth` on the beam with the fixed-node options `fixed`.
fn truth_fixed(fixed: &[&str], extra: &[&str]) -> Output {
    let mut a = fixed.to_vec();
    a.extend_from_slice(extra);
    truth_at_beam_points(&data("meshes/beam.msh"), &a)
}

/// `dcr-lab truth MESH` at the beam's impact (1 N·s) and two contacts, with h = 2 ms and dt =
/// 5e-7 s unless `extra` sets them, and `extra`.
fn truth_at_beam_points(mesh: &Path, extra: &[&str]) -> Output {
    let mut a = vec!["truth", mesh.to_str().unwrap()];
    a.extend_from_slice(&[
        "--impact",
        "1.0,0.05,0.1",
        "--impulse",
        "1",
        "--contact",
        "0.5,0.05,0.1",
        "--contact",
        "0.8,0.0,0.05",
    ]);
    // The window and step unless `extra` sets them.
    for (flag, value) in [("--h", "0.002"), ("--dt", "5e-7")] {
        if !extra.contains(&flag) {
            a.extend_from_slice(&[flag, value]);
        }
    }
    a.extend_from_slice(extra);
    Command::new(env!("CARGO_BIN_EXE_dcr-lab"))
        .args(&a)
        .output()
        .expect("dcr-lab runs")
}

fn peaks(out: &Output) -> Vec<f64> {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let cs = v["contacts"].as_array().expect("contacts");
    assert_eq!(cs.len(), 2);
    for c in cs {
        for k in [
            "point",
            "triangle",
            "bary",
            "distance_m",
            "peak_displacement_m",
            "delta_v_mps",
        ] {
            assert!(!c[k].is_null(), "missing {k} in {c}");
        }
        let p = c["peak_displacement_m"].as_f64().unwrap();
        let dv = c["delta_v_mps"].as_f64().unwrap();
        assert!((dv - p / 0.002).abs() <= 1e-12 * dv.abs());
    }
    cs.iter()
        .map(|c| c["peak_displacement_m"].as_f64().unwrap())
        .collect()
}

#[test]
fn truth_json_methods_agree() {
    let a = peaks(&truth(&["--json"]));
    let b = peaks(&truth(&["--json", "--method", "modal-all"]));
    for (x, y) in a.iter().zip(&b) {
        assert!(
            *y > 0.0 && ((x - y) / y).abs() < 0.01,
            "newmark {x} vs modal-all {y}"
        );
    }
}

/// The reference takes the bake's fixed-node selectors: the beam clamped by `--fixed-below
/// x=0` or a box around x = 0 (its `clamp` group's nodes) answers bit for bit as with
/// `--fixed clamp`, and free-free differently.
#[test]
fn truth_takes_every_fixed_node_selector() {
    let args = ["--json", "--method", "modal-all"];
    let group = peaks(&truth(&args));
    let below = peaks(&truth_fixed(&["--fixed-below", "x=0"], &args));
    let boxed = peaks(&truth_fixed(&["--fixed-box", "-1,-1,-1,0,1,1"], &args));
    assert_eq!(below, group);
    assert_eq!(boxed, group);
    let free = peaks(&truth_fixed(&[], &args));
    assert!(
        free.iter()
            .zip(&group)
            .all(|(f, g)| ((f - g) / g).abs() > 1e-3),
        "{free:?} vs {group:?}"
    );
}

#[test]
fn truth_rejects_bad_input_with_a_clear_message() {
    for (extra, needle) in [
        (&["--fixed", "nope"][..], "no node group named"),
        (&["--fixed-below", "x=-1"][..], "fixes no node"),
        (&["--dt", "0"][..], "dt = 0"),
        (&["--modes", "5"][..], "--method modal-all"),
        (&["--impulse", "nan"][..], "impulse"),
        (&["--impulse", "-1"][..], "impulse"),
        (&["--contact", "3,0,0"][..], "farther than"),
    ] {
        let out = truth(extra);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{extra:?} succeeded");
        assert!(err.contains(needle), "{extra:?}: {err}");
        assert!(!err.contains("panicked"), "{extra:?}: {err}");
    }
}

/// Coordinates starting with a minus sign are values, not flags.
#[test]
fn truth_accepts_negative_coordinates() {
    let out = truth(&[
        "--json",
        "--direction",
        "-1,-0.5,0",
        "--contact",
        "-0.03,0.05,0.05",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["contacts"].as_array().unwrap().len(), 3);
    let d = v["info"]["impact_direction"].as_array().unwrap();
    assert!(d[0].as_f64().unwrap() < 0.0);
}

/// Exit status 3 and `"converged": false` when the step cannot be refined enough; exit 0 and
/// the step reached otherwise.
#[test]
fn truth_exit_status_says_whether_it_converged() {
    let out = truth(&[
        "--json",
        "--dt",
        "1e-4",
        "--tol",
        "1e-7",
        "--max-refinements",
        "1",
    ]);
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["convergence"]["converged"], false);
    assert_eq!(v["convergence"]["history"].as_array().unwrap().len(), 2);
    let out = truth(&["--json", "--dt", "1e-4", "--method", "modal-all"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let c = &v["convergence"];
    assert_eq!(c["converged"], true);
    assert!(c["estimated_error_pct"].as_f64().unwrap() < 0.5);
    assert!(c["history"].as_array().unwrap().len() >= 3);
    assert_eq!(c["cross_check"]["method"], "newmark");
    assert_eq!(c["dt_reached"], v["info"]["dt"]);
    let text = truth(&["--dt", "1e-4", "--method", "modal-all"]);
    let s = String::from_utf8_lossy(&text.stdout);
    assert!(s.contains("converged at dt ="), "{s}");
}

/// [`truth_at_beam_points`] with `--json --method modal-all` and `extra`.
fn beam_points_truth(mesh: &Path, extra: &[&str]) -> Output {
    let mut a = vec!["--json", "--method", "modal-all"];
    a.extend_from_slice(extra);
    truth_at_beam_points(mesh, &a)
}

/// The reference reads its mesh as `modal-bake bake` does: the beam written in millimetres
/// beside a half-size copy of itself, read with `--units mm --piece 1`, answers as the metre
/// beam alone (to rounding: the coordinates went through ×1000 and ÷1000); the whole file is
/// refused with its pieces, and a surface asset with the `modal-bake mesh` that makes its
/// bake's tetrahedra.
#[test]
fn truth_reads_the_mesh_as_the_bake_does() {
    let dir = tempfile::tempdir().unwrap();
    let beam = modal_bake::mesh::read_mesh(&data("meshes/beam.msh")).unwrap();
    let mut two = beam.clone();
    let n = beam.nodes.len();
    two.nodes.extend(
        beam.nodes
            .iter()
            .map(|p| [0.5 * p[0], 0.5 * p[1] + 1.0, 0.5 * p[2]]),
    );
    two.tets.extend(beam.tets.iter().map(|t| t.map(|v| v + n)));
    two.tet_ids = (1..=two.tets.len() as u64).collect();
    let clamp = two.groups.get_mut("clamp").unwrap();
    clamp.extend(beam.groups["clamp"].iter().map(|v| v + n));
    for p in &mut two.nodes {
        *p = p.map(|x| x * 1000.0);
    }
    let path = dir.path().join("two_mm.json");
    std::fs::write(&path, two.to_meshio_json("clamp", "clamp").to_string()).unwrap();
    let run = |mesh: &Path, extra: &[&str]| {
        let mut a = vec!["--fixed", "clamp"];
        a.extend_from_slice(extra);
        beam_points_truth(mesh, &a)
    };
    let metre = peaks(&run(&data("meshes/beam.msh"), &[]));
    let selected = peaks(&run(&path, &["--units", "mm", "--piece", "1"]));
    for (a, b) in metre.iter().zip(&selected) {
        assert!(((a - b) / a).abs() < 1e-9, "{metre:?} vs {selected:?}");
    }
    let whole = run(&path, &["--units", "mm"]);
    let err = String::from_utf8_lossy(&whole.stderr);
    assert!(
        !whole.status.success()
            && err.contains("2 disconnected pieces")
            && err.contains("--piece N"),
        "{err}"
    );
    let asset = data("assets/hp_body.obj");
    let o = run(&asset, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && err.contains("a surface asset; dcr-lab truth works on a mesh of 4-node tetrahedra: mesh the asset as the bake did, `modal-bake mesh ")
            && err.contains(" --order 1` with the bake's --units"),
        "{err}"
    );
}

/// `--base`: the reference of a base's own object (material, damping, fixed nodes from its
/// record) — the same peaks, bit for bit, as with those options typed — beside the base's
/// response at the same points with its error; another mesh, or material options with
/// `--base`, are refused.
#[test]
fn truth_of_a_base_compares_the_base() {
    let dir = tempfile::tempdir().unwrap();
    let beam = data("meshes/beam.msh");
    let base = dir.path().join("beam.modes");
    let params = modal_bake::bake::BakeParams {
        material: dcr_runtime::format::MaterialSi {
            youngs: 2e11,
            poisson: 0.29,
            density: 7850.0,
        },
        fixed: vec!["clamp".into()],
        ..Default::default()
    };
    modal_bake::bake::bake_file(&beam, &params, &base, &mut |_| {}).unwrap();
    let run = beam_points_truth;
    let with_base = run(&beam, &["--base", base.to_str().unwrap()]);
    let typed = run(
        &beam,
        &[
            "--youngs",
            "2e11",
            "--poisson",
            "0.29",
            "--density",
            "7850",
            "--fixed",
            "clamp",
        ],
    );
    let truth = peaks(&with_base);
    assert_eq!(truth, peaks(&typed));
    let v: serde_json::Value = serde_json::from_slice(&with_base.stdout).unwrap();
    let b = &v["base"];
    assert_eq!(b["modes"], 20);
    for (k, t) in truth.iter().enumerate() {
        let c = &b["contacts"][k];
        let peak = c["peak_displacement_m"].as_f64().unwrap();
        assert!(peak > 0.0 && c["served_by"] == "modal", "{c}");
        let e = c["error_pct"].as_f64().unwrap();
        assert!((e - 100.0 * (peak - t) / t).abs() < 1e-9, "{c}");
    }
    // Near the impact 20 modes are within a few percent of the reference.
    assert!(
        b["contacts"][0]["error_pct"].as_f64().unwrap().abs() < 5.0,
        "{b}"
    );
    let other = run(
        &data("meshes/cube_v41.msh"),
        &["--base", base.to_str().unwrap()],
    );
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(
        !other.status.success()
            && err.contains("cube_v41.msh is not the mesh")
            && err.contains("beam.modes was baked from"),
        "{err}"
    );
    let both = run(
        &beam,
        &["--base", base.to_str().unwrap(), "--youngs", "1e9"],
    );
    let err = String::from_utf8_lossy(&both.stderr);
    assert!(
        !both.status.success() && err.contains("cannot be used with"),
        "{err}"
    );
}
