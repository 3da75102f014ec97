//! Hostile scene files and options: every field out of range is refused naming the file, the
//! object and the field with the range that works; names are plain file names; runs too long
//! for memory are refused before allocating; outputs never replace the scene file, a FIFO or a
//! device, and nothing is written when the run is refused. Every case was accepted (exit 0,
//! a panic or an abort) before the scene validation and the output policy.

use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use dcr_scenes::repo_root;
use dcr_scenes::scene::SceneDesc;
use serde_json::{json, Value};

fn scene(name: &str) -> Value {
    let p = repo_root().join("scenes").join(format!("{name}.json"));
    serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap()
}

fn write(dir: &Path, v: &Value) -> PathBuf {
    let p = dir.join("s.json");
    std::fs::write(&p, serde_json::to_vec_pretty(v).unwrap()).unwrap();
    p
}

/// Sets `v[path…] = x` (path segments: object keys or array indices).
fn set(v: &mut Value, path: &[&str], x: Value) {
    let mut cur = v;
    for seg in path {
        cur = match seg.parse::<usize>() {
            Ok(i) => &mut cur[i],
            Err(_) => &mut cur[*seg],
        };
    }
    *cur = x;
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dcr-scenes"))
        .args(args)
        .env("DCR_ROOT", repo_root())
        .output()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn the_shipped_scenes_validate() {
    for name in dcr_scenes::SCENES.iter().chain(&["stress"]) {
        let p = repo_root().join("scenes").join(format!("{name}.json"));
        SceneDesc::read(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

// Each mutation of a shipped scene is refused with the field's path and the range that works.
#[test]
fn every_field_out_of_range_is_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let cases: Vec<(&str, Vec<&str>, Value, &str)> = vec![
        (
            "roof",
            vec!["restitution"],
            json!(5),
            "restitution must be in [0, 1]",
        ),
        (
            "roof",
            vec!["props", "1", "friction"],
            json!(-1),
            "props[1].friction must be in [0, 100]",
        ),
        ("roof", vec!["gravity"], json!([0, -1e300, 0]), "gravity[1]"),
        (
            "roof",
            vec!["seconds"],
            json!(-1),
            "seconds must be a finite time > 0 s",
        ),
        ("roof", vec!["seconds"], json!(1e7), "seconds 1e7 s"),
        (
            "roof",
            vec!["h"],
            json!(1e-300),
            "h must be in [1e-5, 0.1] s",
        ),
        (
            "roof",
            vec!["props", "1", "mass"],
            json!(0),
            "props[1].mass must be in [1e-6, 1e9] kg",
        ),
        (
            "roof",
            vec!["props", "0", "pose", "translation"],
            json!([1e300, 0, 0]),
            "props[0].pose.translation[0]",
        ),
        (
            "roof",
            vec!["props", "0", "linvel"],
            json!([0, 1e300, 0]),
            "props[0].linvel[1]",
        ),
        (
            "dinner",
            vec!["props", "0", "colliders", "0", "shape"],
            json!({"ball": {"radius": -1}}),
            "props[0].colliders[0].shape.ball.radius",
        ),
        (
            "dinner",
            vec!["props", "0", "colliders", "0", "shape"],
            json!({"cuboid": {"half_extents": [0, 1, 1]}}),
            "half_extents[0]",
        ),
        (
            "washing",
            vec!["joints", "0", "axis"],
            json!([0, 0, 0]),
            "joints[0].axis must be a non-zero direction",
        ),
        (
            "washing",
            vec!["joints", "0", "stiffness"],
            json!(-1),
            "joints[0].stiffness",
        ),
        (
            "washing",
            vec!["joints", "0", "damping"],
            json!(-1),
            "joints[0].damping",
        ),
        (
            "lowrider",
            vec!["drivers", "0", "period"],
            json!(0),
            "drivers[0].period must be ≥ the step h",
        ),
        (
            "lowrider",
            vec!["drivers", "0", "body"],
            json!("nobody"),
            "drivers[0].body \"nobody\" names no dynamic body",
        ),
        (
            "roof",
            vec!["outcomes", "0", "kind"],
            json!("max_lfit"),
            "outcomes[0].kind \"max_lfit\" is unknown",
        ),
        (
            "roof",
            vec!["outcomes", "0", "bodies"],
            json!("ghost*"),
            "outcomes[0].bodies \"ghost*\" matches no dynamic body",
        ),
        (
            "roof",
            vec!["elastic", "0", "material", "poisson"],
            json!(0.5),
            "elastic[0].material.poisson must be in (-1, 0.5)",
        ),
        (
            "roof",
            vec!["elastic", "0", "modes"],
            json!(0),
            "elastic[0].modes must be in [1, 2000]",
        ),
        (
            "roof",
            vec!["elastic", "0", "rayleigh"],
            json!([-1, 0]),
            "elastic[0].rayleigh[0]",
        ),
        (
            "roof",
            vec!["elastic", "0", "fixed_below"],
            json!([{"axis": "y", "value": 1e300}]),
            "elastic[0].fixed_below[0].value must be finite",
        ),
        (
            "roof",
            vec!["elastic", "0", "fixed_below"],
            json!([{"axis": "w", "value": 0}]),
            "unknown variant `w`",
        ),
        (
            "roof",
            vec!["elastic", "0", "fixed_boxes"],
            json!([[0, 1, 0, 1, 0, 1]]),
            "elastic[0].fixed_boxes[0] must be [xmin, ymin, zmin, xmax, ymax, zmax] with each min ≤ max (got 1 > 0)",
        ),
        (
            "roof",
            vec!["elastic", "0", "fixed_boxes"],
            json!(vec![[0, 0, 0, 1, 1, 1]; 65]),
            "at most 64 fixed_below and 64 fixed_boxes",
        ),
        (
            "roof",
            vec!["name"],
            json!("../../x"),
            "name \"../../x\" must be a plain file name",
        ),
        ("roof", vec!["name"], json!(""), "must be a plain file name"),
        (
            "roof",
            vec!["name"],
            json!("."),
            "must be a plain file name",
        ),
        (
            "roof",
            vec!["elastic", "0", "name"],
            json!("/tmp/abs"),
            "elastic[0].name \"/tmp/abs\" must be a plain file name",
        ),
    ];
    for (name, path, x, needle) in cases {
        let mut v = scene(name);
        set(&mut v, &path, x.clone());
        let p = write(dir.path(), &v);
        let err = SceneDesc::read(&p)
            .err()
            .unwrap_or_else(|| panic!("{name} {path:?} = {x} accepted"))
            .to_string();
        assert!(
            err.contains(needle) && err.contains(s(&p)),
            "{name} {path:?} = {x}: {err:?} lacks {needle:?}"
        );
    }
}

#[test]
fn structural_errors_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    // Two bodies with one name (the NPZ entry names collided after trajectory.npz was written).
    let mut v = scene("roof");
    let first = v["props"][0]["name"].clone();
    set(&mut v, &["props", "1", "name"], first);
    let err = SceneDesc::read(&write(dir.path(), &v))
        .unwrap_err()
        .to_string();
    assert!(err.contains("two bodies are named"), "{err}");
    // A joint from a body to itself.
    let mut v = scene("washing");
    let b1 = v["joints"][0]["body1"].clone();
    set(&mut v, &["joints", "0", "body2"], b1);
    let err = SceneDesc::read(&write(dir.path(), &v))
        .unwrap_err()
        .to_string();
    assert!(err.contains("jointed to itself"), "{err}");
    // Unknown fields (serde).
    let mut v = scene("roof");
    set(&mut v, &["props", "0", "mas"], json!(1));
    let err = SceneDesc::read(&write(dir.path(), &v))
        .unwrap_err()
        .to_string();
    assert!(err.contains("unknown field `mas`"), "{err}");
    // 1,000 copies of a prop 1 mm apart (aborted allocating 1.9 GB).
    let mut v = scene("roof");
    let copies: Vec<Value> = (0..1000).map(|i| json!([i as f64 * 1e-3, 0, 0])).collect();
    set(&mut v, &["props", "0", "copies"], Value::Array(copies));
    let err = SceneDesc::read(&write(dir.path(), &v))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("props[0].copies[0] and props[0].copies[1] are 0.001 m apart"),
        "{err}"
    );
    // Copies: 200,000 bodies of one prop.
    let mut v = scene("roof");
    let copies: Vec<Value> = (0..200_001).map(|i| json!([i as f64, 0, 0])).collect();
    set(&mut v, &["props", "0", "copies"], Value::Array(copies));
    let err = SceneDesc::read(&write(dir.path(), &v))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bodies") && err.contains("at most 100000"),
        "{err}"
    );
}

// Regression: `--seconds 1e300` panicked (capacity overflow), `seconds: 1e7` aborted on an
// 8 GB allocation, `--seconds -1` was an "unexpected argument".
#[test]
fn run_lengths_beyond_memory_and_negative_seconds_are_refused_by_option() {
    for (secs, needle) in [
        ("1e300", "--seconds 1e300 s is"),
        ("1e7", "--seconds 1e7 s is"),
        ("-1", "--seconds must be a finite time > 0 s (got -1)"),
    ] {
        let o = run(&["run", "roof", "--seconds", secs, "--out", "/nonexistent/x"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(err.contains(needle), "{secs}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

// Regression: `--gltf SCENE.json` overwrote the scene file, `--gltf FIFO` / a device replaced
// the node, `--gltf .` failed after the run's outputs were written with its cause twice. All
// are refused before anything runs; nothing is written.
#[test]
fn outputs_never_replace_the_scene_a_fifo_or_a_device_and_refusals_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = write(d, &scene("roof"));
    let before = std::fs::read(&p).unwrap();
    let fifo = d.join("fifo.glb");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    std::fs::create_dir(d.join("sub")).unwrap();
    let out = d.join("out");
    let bases = d.join("bases");
    let respelled = d.join("sub/../s.json");
    for (gltf, needle) in [
        (s(&p), "is the scene file"),
        (s(&respelled), "is the scene file"),
        (s(&fifo), "a FIFO"),
        ("/dev/null", "a character device"),
        (".", "names a folder"),
    ] {
        let o = run(&[
            "run",
            s(&p),
            "--gltf",
            gltf,
            "--out",
            s(&out),
            "--bases",
            s(&bases),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{gltf}");
        assert!(
            err.contains("--gltf") && err.contains(needle),
            "{gltf}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
    // The run's folder as a file, and a scene file as `--out`'s outputs.
    let o = run(&["run", s(&p), "--out", s(&p), "--bases", s(&bases)]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--out"));
    assert_eq!(std::fs::read(&p).unwrap(), before, "the scene changed");
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(!out.exists() && !bases.exists(), "something was written");
}

// Regression: a scene file that is a FIFO blocked forever, `/dev/zero` was read to 2 GB.
#[test]
fn non_regular_scene_files_are_refused_before_opening() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("f.json");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let zero = dir.path().join("z.json");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    for p in [&fifo, &zero] {
        let err = SceneDesc::read(p).unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
        let o = run(&["run", s(p)]);
        assert!(!o.status.success());
        assert!(String::from_utf8_lossy(&o.stderr).contains("not a regular file"));
    }
}

// Every file `dcr-scenes` writes — the run's `--out` files (trajectory, timings, summary,
// outcomes plot), the bases it bakes into `--bases`, and `table1 --gltf DIR`'s per-scene GLB —
// refuses a device reached through a symbolic link (`FILE` → `/dev/null`) before anything
// runs: the command fails naming the option, and the link, the device and the scene survive.
#[test]
fn every_output_refuses_a_linked_device_and_the_scene_survives() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = write(d, &scene("roof"));
    let before = std::fs::read(&p).unwrap();
    let link = |dir: &Path, name: &str| {
        std::fs::create_dir_all(dir).unwrap();
        let l = dir.join(name);
        std::os::unix::fs::symlink("/dev/null", &l).unwrap();
        l
    };
    let refused = |args: &[&str], option: &str, l: &Path| {
        let o = run(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(
            err.contains(option) && err.contains("a character device"),
            "{args:?}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(std::fs::symlink_metadata(l)
            .unwrap()
            .file_type()
            .is_symlink());
    };
    for (i, name) in [
        "trajectory.npz",
        "timings.npz",
        "summary.json",
        "outcomes.svg",
    ]
    .iter()
    .enumerate()
    {
        let out = d.join(format!("out{i}"));
        let l = link(&out, name);
        let bases = d.join(format!("bases{i}"));
        refused(
            &["run", s(&p), "--out", s(&out), "--bases", s(&bases)],
            "--out",
            &l,
        );
        assert!(!bases.exists(), "a base was baked");
    }
    for (i, name) in ["roof.modes", "roof.transfer.modes"].iter().enumerate() {
        let bases = d.join(format!("linked_bases{i}"));
        let l = link(&bases, name);
        let out = d.join(format!("linked_out{i}"));
        refused(
            &["run", s(&p), "--out", s(&out), "--bases", s(&bases)],
            "--bases",
            &l,
        );
        assert!(!out.exists(), "the run wrote");
    }
    let gltf = d.join("gltf");
    let l = link(&gltf, "roof.glb");
    refused(
        &["table1", "--scenes", "roof", "--gltf", s(&gltf)],
        "--gltf",
        &l,
    );
    assert_eq!(std::fs::read(&p).unwrap(), before, "the scene changed");
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
}
