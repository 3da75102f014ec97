//! Hostile and abusive uses of the `modal-bake` binary, each a regression test of a defect
//! class: values that overflow silently, writes that fail silently or clobber what they should
//! not, signals that leave temporaries behind. Each asserts a clean refusal (exit code, a
//! message naming the file or option and the range that works) or the right result.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

#[path = "common/check_args.rs"]
mod check_args;
use check_args::check_args;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
}

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(rel)
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("modal-bake runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Bakes the cube (free-free, 6 modes) into `dir/cube.modes`.
fn cube_base(dir: &Path) -> PathBuf {
    let out = dir.join("cube.modes");
    let o = run(&[
        "bake",
        data("meshes/cube_v41.msh").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--modes",
        "6",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

/// Copies the `.modes` archive `src` to `dst` with every surface-vertex coordinate scaled by
/// `scale` (bypassing validation, as a foreign or broken writer would).
fn scaled_copy(src: &Path, dst: &Path, scale: f64) {
    use ndarray_npy::{NpzReader, NpzWriter};
    let mut r = NpzReader::new(std::fs::File::open(src).unwrap()).unwrap();
    let mut w = NpzWriter::new(std::fs::File::create(dst).unwrap());
    for name in r.names().unwrap() {
        let key = name.trim_end_matches(".npy").to_string();
        match key.as_str() {
            "surface_vertices" | "eigenvalues" | "frequencies_hz" | "modes" | "material"
            | "rayleigh" | "residuals" => {
                let mut a: ndarray::ArrayD<f64> = r.by_name(&name).unwrap();
                if key == "surface_vertices" {
                    a.mapv_inplace(|x| x * scale);
                }
                w.add_array(key, &a).unwrap();
            }
            "meta" => {
                let a: ndarray::ArrayD<u8> = r.by_name(&name).unwrap();
                w.add_array(key, &a).unwrap();
            }
            "format_version" => {
                let a: ndarray::ArrayD<u32> = r.by_name(&name).unwrap();
                w.add_array(key, &a).unwrap();
            }
            _ => {
                let a: ndarray::ArrayD<u32> = r.by_name(&name).unwrap();
                w.add_array(key, &a).unwrap();
            }
        }
    }
    w.finish().unwrap();
}

// Regression: `probe --direction 1e308,1e308,1e308` normalised an infinite length and applied
// no impulse (all peaks 0, exit 0). Any finite non-zero direction is a direction: it gives the
// response of (1, 1, 1)/√3. A zero direction is refused.
#[test]
fn probe_direction_of_any_finite_length_works() {
    let dir = tempfile::tempdir().unwrap();
    let base = cube_base(dir.path());
    let probe = |direction: &str| {
        run(&[
            "probe",
            base.to_str().unwrap(),
            "--impact",
            "0.5,0.5,1",
            "--impulse",
            "1",
            "--contact",
            "0.2,0.3,1",
            "--direction",
            direction,
            "--json",
        ])
    };
    let unit = probe("1,1,1");
    assert!(unit.status.success(), "{}", stderr(&unit));
    let huge = probe("1e308,1e308,1e308");
    assert!(huge.status.success(), "{}", stderr(&huge));
    let tiny = probe("1e-320,1e-320,1e-320");
    assert!(tiny.status.success(), "{}", stderr(&tiny));
    let v: serde_json::Value = serde_json::from_slice(&unit.stdout).unwrap();
    let peak = v["contacts"][0]["peak_displacement_m"].as_f64().unwrap();
    assert!(peak > 0.0, "{v}");
    assert_eq!(huge.stdout, unit.stdout);
    assert_eq!(tiny.stdout, unit.stdout);
    let zero = probe("0,0,0");
    assert_eq!(zero.status.code(), Some(1));
    assert!(stderr(&zero).contains("--direction"), "{}", stderr(&zero));
}

// Regression: `geodesic` on a base whose surface was scaled by 1e150 returned all zeros (exit
// 0): squared lengths overflow. The base is refused on load, naming the entry and the range.
#[test]
fn geodesic_refuses_a_surface_outside_the_coordinate_range() {
    let dir = tempfile::tempdir().unwrap();
    let base = cube_base(dir.path());
    let far = dir.path().join("far.modes");
    scaled_copy(&base, &far, 1e150);
    for sub in [
        &["geodesic", far.to_str().unwrap(), "--from-vertex", "0"][..],
        &["info", far.to_str().unwrap()][..],
    ] {
        let o = run(sub);
        assert_eq!(o.status.code(), Some(1), "{sub:?}");
        let err = stderr(&o);
        assert!(
            err.contains("far.modes")
                && err.contains("surface_vertices[")
                && err.contains("±1e6 m"),
            "{err}"
        );
    }
    // Within the range, distances scale with the surface.
    let near = dir.path().join("near.modes");
    scaled_copy(&base, &near, 1e5);
    let d = |p: &Path| -> Vec<f64> {
        let o = run(&[
            "geodesic",
            p.to_str().unwrap(),
            "--from-vertex",
            "0",
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["distances_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (a, b) = (d(&base), d(&near));
    let max = a.iter().fold(0.0f64, |m, x| m.max(*x));
    assert!(max > 0.5);
    for (x, y) in a.iter().zip(&b) {
        assert!((x * 1e5 - y).abs() <= 1e-9 * max * 1e5, "{x} vs {y}");
    }
}

fn bake_to(out: &Path, mesh: &Path) -> Output {
    run(&[
        "bake",
        mesh.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--modes",
        "4",
    ])
}

// Regression: `-o` equal to the input mesh overwrote the mesh with the base; `-o` onto a device
// replaced the device node. Both are refused before baking, naming `-o`, and nothing changes.
#[test]
#[cfg(unix)]
fn output_onto_an_input_or_a_non_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("m.msh");
    std::fs::copy(data("meshes/cube_v41.msh"), &mesh).unwrap();
    let before = std::fs::read(&mesh).unwrap();
    let link = dir.path().join("link.msh");
    std::fs::hard_link(&mesh, &link).unwrap();
    let dotted = dir.path().join(".").join("m.msh");
    for out in [&mesh, &link, &dotted] {
        let o = bake_to(out, &mesh);
        assert_eq!(o.status.code(), Some(1), "{}", out.display());
        let err = stderr(&o);
        assert!(err.contains("-o") && err.contains("is the input"), "{err}");
    }
    assert_eq!(
        std::fs::read(&mesh).unwrap(),
        before,
        "the mesh is untouched"
    );
    let fifo = dir.path().join("pipe.modes");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let folder = dir.path().join("folder.modes");
    std::fs::create_dir(&folder).unwrap();
    for (out, what) in [(&fifo, "a FIFO"), (&folder, "a directory")] {
        let o = bake_to(out, &mesh);
        assert_eq!(o.status.code(), Some(1));
        assert!(stderr(&o).contains(what), "{}", stderr(&o));
    }
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let o = run(&[
        "geodesic",
        data("meshes/cube_v41.msh").to_str().unwrap(),
        "--from-vertex",
        "0",
        "--npy",
        folder.to_str().unwrap(),
    ]);
    assert!(stderr(&o).contains("--npy"), "{}", stderr(&o));
    // Only the mesh, its link, the FIFO and the folder: no temporary anywhere.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 4);
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 0);
}

// Regression: the README's first bake (`-o out/beam.modes` on a fresh clone) failed because
// `out/` did not exist, printing the cause twice. The folder is created, and said so.
#[test]
fn a_missing_output_folder_is_created_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out/nested/beam.modes");
    let o = bake_to(&out, &data("meshes/beam.msh"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
    assert!(
        stderr(&o).contains(&format!(
            "created folder {}",
            out.parent().unwrap().display()
        )),
        "{}",
        stderr(&o)
    );
    // A folder that cannot be made (its parent is a file): one clear line, the cause once.
    let file = dir.path().join("plain");
    std::fs::write(&file, b"x").unwrap();
    let o = bake_to(&file.join("sub/x.modes"), &data("meshes/beam.msh"));
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("plain") && err.contains("not a folder"),
        "{err}"
    );
}

/// Runs `args` with stdout on `/dev/full` (every write fails: no space left on device).
fn run_full(args: &[&str]) -> Output {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    bin()
        .args(args)
        .stdout(full)
        .output()
        .expect("modal-bake runs")
}

// Regression: `info`, `geodesic` and `probe --json` redirected to a full device exited 0. A
// failed write of stdout is an error (exit 1; 2 for `check`), for every subcommand that prints;
// a closed pipe (`| head`) is not.
#[test]
fn a_failed_stdout_write_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let base = cube_base(dir.path());
    let b = base.to_str().unwrap();
    let mesh = data("meshes/cube_v41.msh");
    let m = mesh.to_str().unwrap();
    let out2 = dir.path().join("again.modes");
    let probe = [
        "probe",
        b,
        "--impact",
        "0.5,0.5,1",
        "--impulse",
        "1",
        "--contact",
        "0.2,0.3,1",
    ];
    let cases: Vec<(Vec<&str>, i32)> = vec![
        (vec!["info", b], 1),
        (vec!["info", b, "--json"], 1),
        (vec!["geodesic", b, "--from-vertex", "0"], 1),
        (vec!["geodesic", b, "--from-vertex", "0", "--json"], 1),
        (probe.to_vec(), 1),
        ([&probe[..], &["--json"]].concat(), 1),
        (vec!["check", m, b, "--modes", "6"], 2),
        (
            vec![
                "bake",
                m,
                "-o",
                out2.to_str().unwrap(),
                "--modes",
                "6",
                "--json",
            ],
            1,
        ),
    ];
    for (args, code) in cases {
        let o = run_full(&args);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("cannot write to standard output"),
            "{args:?}: {}",
            stderr(&o)
        );
        // A closed pipe ends output quietly.
        let mut child = bin()
            .args(&args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("error"), "{args:?}: {}", stderr(&o));
    }
}

/// Writes the cube mesh with every coordinate multiplied by `scale` (and node 1 moved to
/// `outlier`, if given) as MSH 2.2 ASCII at `path`.
fn scaled_cube(path: &Path, scale: f64, outlier: Option<f64>) {
    let m = modal_bake::mesh::read_mesh(&data("meshes/cube_v41.msh")).unwrap();
    let mut text = format!(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n{}\n",
        m.nodes.len()
    );
    for (i, p) in m.nodes.iter().enumerate() {
        let mut q = p.map(|x| x * scale);
        if i == 0 {
            if let Some(o) = outlier {
                q[0] = o;
            }
        }
        text += &format!("{} {:e} {:e} {:e}\n", i + 1, q[0], q[1], q[2]);
    }
    text += &format!("$EndNodes\n$Elements\n{}\n", m.tets.len());
    for (k, t) in m.tets.iter().enumerate() {
        text += &format!(
            "{} 4 0 {} {} {} {}\n",
            k + 1,
            t[0] + 1,
            t[1] + 1,
            t[2] + 1,
            t[3] + 1
        );
    }
    text += "$EndElements\n";
    std::fs::write(path, text).unwrap();
}

// Expectation: a stale base says what differs, by the options that change it, so that a farm
// knows whether the mesh, an option or the tool moved: each parameter with both values, the
// mesh's counts, size, moved nodes and fixed set, the unit and selection the base was read
// with, the tool's output version and the transfer table's options.
#[test]
fn check_names_what_differs() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("c.modes");
    let b = base.to_str().unwrap();
    let cube = data("meshes/cube_v41.msh");
    let check = |mesh: &Path, extra: &[&str]| {
        let mut a = vec!["check", mesh.to_str().unwrap(), b];
        if !extra.contains(&"--modes") {
            a.extend_from_slice(&["--modes", "4"]);
        }
        a.extend_from_slice(extra);
        let o = run(&a);
        let mut j = a.clone();
        j.push("--json");
        let v: serde_json::Value = serde_json::from_slice(&run(&j).stdout).unwrap();
        let text = String::from_utf8_lossy(&o.stdout).trim().to_string();
        let detail = v["detail"].as_str().unwrap_or("").to_string();
        // The plain line carries the JSON's detail.
        assert!(text.ends_with(&detail), "{text} / {v}");
        (
            o.status.code(),
            v["reason"].as_str().unwrap().to_string(),
            detail,
        )
    };
    assert!(bake_to(&base, &cube).status.success());
    assert_eq!(
        check(&cube, &[]),
        (Some(0), "up_to_date".into(), String::new())
    );

    // Parameters: exactly the ones that differ, with both values and units.
    let (_, reason, d) = check(&cube, &["--density", "800", "--rayleigh", "5,1e-7"]);
    assert_eq!(reason, "parameters_changed");
    assert_eq!(
        d,
        "--density: 770 kg/m³ in the base, 800 kg/m³ asked; --rayleigh: 10,1e-7 in the base, 5,1e-7 asked"
    );
    let (_, _, d) = check(&cube, &["--modes", "6", "--f32"]);
    assert!(
        d.contains("--modes/--max-freq: 4 modes in the base, 6 modes asked"),
        "{d}"
    );
    assert!(d.contains("--f32: off in the base, on asked"), "{d}");
    assert!(!d.contains("--youngs") && !d.contains("--density"), "{d}");

    // Geometry: the size, the unit, the fixed set, a moved node.
    let other = dir.path().join("other.msh");
    scaled_cube(&other, 2.0, None);
    let (_, reason, d) = check(&other, &[]);
    assert_eq!(reason, "geometry_changed");
    assert!(d.contains("this mesh is 2× the base's size"), "{d}");
    let (_, _, d) = check(&cube, &["--units", "cm"]);
    assert!(
        d.starts_with(
            "the base was read from its file as the whole file in metres, this as `--units cm`"
        ),
        "{d}"
    );
    assert!(d.contains("0.01× the base's size"), "{d}");
    let (_, _, d) = check(&cube, &["--fixed-below", "z=0.01"]);
    let fixed = modal_bake::mesh::read_mesh(&cube)
        .unwrap()
        .nodes
        .iter()
        .filter(|p| p[2] <= 0.01)
        .count();
    assert!(fixed > 0);
    assert_eq!(
        d,
        format!("the base fixes 0 nodes, these options fix {fixed} (--fixed, --fixed-below, --fixed-box, --fixed-near)")
    );
    let x0 = modal_bake::mesh::read_mesh(&cube).unwrap().nodes[0][0];
    scaled_cube(&other, 1.0, Some(x0 + 1e-3));
    let (_, _, d) = check(&other, &[]);
    assert!(d.contains("surface nodes moved by up to 1.000e-3 m"), "{d}");
    assert!(d.contains("volume node 0)"), "{d}");

    // The transfer table: asked for and missing, then built with another step.
    let (_, reason, d) = check(&cube, &["--transfer-h", "0.01"]);
    assert_eq!(reason, "transfer_table_changed");
    assert_eq!(
        d,
        "the base has no transfer table; --transfer-h 0.01 asks for one"
    );
    let o = run(&[
        "bake",
        cube.to_str().unwrap(),
        "-o",
        b,
        "--modes",
        "4",
        "--transfer-h",
        "0.01",
        "--transfer-modes",
        "12",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, _, d) = check(&cube, &["--transfer-h", "0.005", "--transfer-modes", "12"]);
    assert_eq!(d, "--transfer-h: 0.01 in the base, 0.005 asked");
    let (_, _, d) = check(&cube, &[]);
    assert_eq!(
        d,
        "the base holds a transfer table (--transfer-h 0.01 s); no --transfer-h was given"
    );

    // An edited record: the hash alone, then the parameters unreadable.
    let mut edited = dcr_runtime::format::ModesFile::read(&base).unwrap();
    edited.meta.params_hash = "sha256:0".into();
    edited.write_atomic(&base).unwrap();
    let table = ["--transfer-h", "0.01", "--transfer-modes", "12"];
    let (_, reason, d) = check(&cube, &table);
    assert_eq!(reason, "parameters_changed");
    assert!(
        d.starts_with(
            "every recorded parameter equals these options, but the base's parameter hash does not"
        ),
        "{d}"
    );
    edited.meta.bake_params["material"] = serde_json::json!("steel");
    edited.write_atomic(&base).unwrap();
    let (_, _, d) = check(&cube, &table);
    assert!(
        d.starts_with("its recorded parameters (meta.bake_params) do not read as this modal-bake"),
        "{d}"
    );

    // The tool: another output version.
    let mut old = dcr_runtime::format::ModesFile::read(&base).unwrap();
    old.meta.bake_params["output_version"] = serde_json::json!(0);
    old.write_atomic(&base).unwrap();
    let (_, reason, d) = check(&cube, &[]);
    assert_eq!(reason, "tool_changed");
    assert!(d.contains("(output version 0); this modal-bake"), "{d}");
    assert!(d.ends_with("writes output version 1"), "{d}");
}

// Expectation: `info` rebuilds from a base's record the options `check` finds it up to date
// with — every parameter, selector, selection and table option, negative values included —
// so a base found on a farm says how to check (and bake) it again.
#[test]
fn info_gives_the_options_that_check_the_base() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("rich.modes");
    let b = base.to_str().unwrap();
    let cube = data("meshes/cube_v41.msh");
    let m = cube.to_str().unwrap();
    let options = [
        "--material",
        "oak",
        "--youngs",
        "1.3e10",
        "--modes",
        "5",
        "--fixed",
        "bottom",
        "--fixed-box=-0.1,-0.1,0.99,1.1,1.1,1.1",
        "--rayleigh",
        "5,2e-7",
        "--lumped",
        "--f32",
        "--transfer-h",
        "0.004",
        "--transfer-modes",
        "30",
        "--transfer-region=-0.1,-0.1,0.5,1.1,1.1,1.1",
        "--transfer-up",
        "0,0,1",
        "--transfer-oversample",
        "2",
        "--transfer-order",
        "2",
    ];
    let mut a = vec!["bake", m, "-o", b];
    a.extend(options);
    let o = run(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&run(&["info", b, "--json"]).stdout).unwrap();
    let args = check_args(&base);
    assert!(v["check_args"]["missing"].as_array().unwrap().is_empty());
    for needed in [
        "--lumped",
        "--f32",
        "--fixed-box=-0.1,-0.1,0.99,1.1,1.1,1.1",
        "--transfer-up",
    ] {
        assert!(args.iter().any(|x| x == needed), "{needed}: {args:?}");
    }
    let mut c = vec!["check", m, b];
    c.extend(args.iter().map(String::as_str));
    let o = run(&c);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stdout)
    );
    // The text says the same, with MESH for the file the base does not name.
    let text = String::from_utf8_lossy(&run(&["info", b]).stdout).into_owned();
    assert!(
        text.contains(&format!(
            "  check it with: modal-bake check MESH {b} {}\n",
            args.join(" ")
        )),
        "{text}"
    );
    // Each option dropped in turn makes the base stale: none is printed for nothing.
    for i in 0..args.len() {
        if args[i].starts_with("--")
            && !args[i].contains('=')
            && args.get(i + 1).is_some_and(|v| !v.starts_with("--"))
        {
            let mut fewer: Vec<&str> = vec!["check", m, b];
            fewer.extend(
                args.iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i && *j != i + 1)
                    .map(|(_, x)| x.as_str()),
            );
            let o = run(&fewer);
            // Stale, or (without --transfer-h) an error: never up to date.
            assert_ne!(
                o.status.code(),
                Some(0),
                "without {} {}",
                args[i],
                args[i + 1]
            );
        }
    }
}

// Regression: numerical internals instead of causes — a mesh scaled by 1e100 or 1e150 ("Ritz
// vectors not M-independent", "|volume| inf m³ below NaN m³"), a coordinate of 2147483648
// ("NonPositivePivot"), an outlier node at 1e12 m (a healthy tet blamed), E = 1e300 or 1e308,
// ρ = 1e-300 ("NoConvergence"). Each names the input out of range and the range that works.
#[test]
fn out_of_range_inputs_are_named_with_the_range_that_works() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.modes");
    let bake = |mesh: &Path, extra: &[&str]| {
        let mut a = vec![
            "bake",
            mesh.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--modes",
            "4",
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    let cube = data("meshes/cube_v41.msh");
    for (scale, outlier) in [
        (1e100, None),
        (1e150, None),
        (1.0, Some(2147483648.0)),
        (1.0, Some(1e12)),
    ] {
        let mesh = dir.path().join("scaled.msh");
        scaled_cube(&mesh, scale, outlier);
        let o = bake(&mesh, &[]);
        assert_eq!(o.status.code(), Some(1));
        let err = stderr(&o);
        assert!(
            err.contains("scaled.msh") && err.contains("node") && err.contains("±1e6 m"),
            "{scale} {outlier:?}: {err}"
        );
    }
    for (option, value, range) in [
        ("--youngs", "1e300", "1e14"),
        ("--youngs", "1e308", "1e14"),
        ("--density", "1e-300", "0.01"),
        ("--density", "1e300", "1e6"),
    ] {
        let o = bake(&cube, &[option, value]);
        assert_eq!(o.status.code(), Some(1), "{option} {value}");
        let err = stderr(&o);
        assert!(
            err.contains(option) && err.contains(range),
            "{option} {value}: {err}"
        );
    }
    // The ends of the ranges bake.
    for extra in [
        &["--youngs", "1"][..],
        &["--youngs", "1e14"],
        &["--density", "0.01"],
        &["--density", "1e6"],
    ] {
        let o = bake(&cube, extra);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    }
    for scale in [1e-4, 1e5] {
        let mesh = dir.path().join("ok.msh");
        scaled_cube(&mesh, scale, None);
        let o = bake(&mesh, &[]);
        assert!(o.status.success(), "scale {scale}: {}", stderr(&o));
    }
}

// Regression: wrong units were accepted silently — `--youngs 11` (GPa meant) baked 0.003 Hz
// modes, `--density 0.77` (g/cm³ meant) a 19 g bench, a mesh in millimetres a 1.9e10 kg
// bench. Each bakes (the values are legal) with a warning naming the likely mistake.
#[test]
fn likely_unit_mistakes_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.modes");
    let cube = data("meshes/cube_v41.msh");
    let mm = dir.path().join("mm.msh");
    scaled_cube(&mm, 1000.0, None);
    for (mesh, extra, needle) in [
        (&cube, &["--youngs", "11"][..], "GPa"),
        (&cube, &["--density", "0.77"], "g/cm³"),
        (&mm, &[], "millimetres"),
    ] {
        let mut a = vec![
            "bake",
            mesh.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--modes",
            "4",
        ];
        a.extend_from_slice(extra);
        let o = run(&a);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(
            err.contains("warning") && err.contains(needle),
            "{extra:?}: {err}"
        );
    }
    let o = run(&[
        "bake",
        cube.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--modes",
        "4",
        "--material",
        "oak",
    ]);
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

// Regression: without a terminal (CI logs) a bake was silent however long it ran, and the bar
// said "(assembling K and M)" while factoring. Plain lines name each long stage and its
// progress (`MODAL_BAKE_PROGRESS_EVERY` = 0 reports every stage here; the default is 5 s).
#[test]
fn progress_without_a_terminal_is_plain_lines() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.modes");
    let o = bin()
        .args([
            "bake",
            data("meshes/beam.msh").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--fixed",
            "clamp",
            "--modes",
            "6",
        ])
        .env("MODAL_BAKE_PROGRESS_EVERY", "0")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    for needle in [
        "reading mesh: done",
        "assembling K and M: done",
        "factoring K − σM: done",
        "modes converged",
        "writing: done",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    // By default a short bake prints no progress at all.
    let o = bake_to(&out, &data("meshes/beam.msh"));
    assert!(o.status.success());
    assert!(!stderr(&o).contains("bake ["), "{}", stderr(&o));
}

// Expectation: `check --json` says why a base is stale — missing, unreadable, geometry changed,
// parameters changed, tool changed (a base written by a modal-bake whose output differs:
// `meta.bake_params.output_version`) — with the exit codes of the plain check (0, 1, 2).
#[test]
fn check_json_gives_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("c.modes");
    let b = base.to_str().unwrap();
    let cube = data("meshes/cube_v41.msh");
    let check = |mesh: &Path, extra: &[&str]| {
        let mut a = vec!["check", mesh.to_str().unwrap(), b, "--modes", "4", "--json"];
        a.extend_from_slice(extra);
        let o = run(&a);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        (
            o.status.code(),
            v["reason"].as_str().unwrap_or("").to_string(),
            v,
        )
    };
    assert_eq!(check(&cube, &[]).1, "missing");
    assert!(bake_to(&base, &cube).status.success());
    let (code, reason, v) = check(&cube, &[]);
    assert_eq!((code, reason.as_str()), (Some(0), "up_to_date"), "{v}");
    assert_eq!(check(&cube, &["--density", "800"]).1, "parameters_changed");
    let other = dir.path().join("other.msh");
    scaled_cube(&other, 2.0, None);
    assert_eq!(check(&other, &[]).1, "geometry_changed");
    let mut old = dcr_runtime::format::ModesFile::read(&base).unwrap();
    old.meta.bake_params["output_version"] = serde_json::json!(0);
    old.write_atomic(&base).unwrap();
    let (code, reason, _) = check(&cube, &[]);
    assert_eq!((code, reason.as_str()), (Some(1), "tool_changed"));
    std::fs::write(&base, b"not a base").unwrap();
    let (code, reason, v) = check(&cube, &[]);
    assert_eq!((code, reason.as_str()), (Some(1), "unreadable"));
    assert!(v["detail"].as_str().unwrap().contains("c.modes"), "{v}");
    let (code, _, v) = check(&data("bad/truncated.msh"), &[]);
    assert_eq!(code, Some(2));
    assert!(
        v["error"].as_str().unwrap().contains("truncated.msh"),
        "{v}"
    );
}

// Regression: a request beyond the mesh's modes said "N modes requested but only M free
// dofs" (the dofs, not the modes, and without the rigid modes). It names the exact limit.
#[test]
fn a_request_beyond_the_mesh_names_the_exact_limit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.modes");
    let cube = data("meshes/cube_v41.msh");
    let nodes = modal_bake::mesh::read_mesh(&cube).unwrap().nodes.len();
    let limit = 3 * nodes - 6;
    let o = run(&[
        "bake",
        cube.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--modes",
        &(limit + 1).to_string(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains(&format!("at most {limit} modes for this mesh")),
        "{}",
        stderr(&o)
    );
}

/// A request for every mode is met, not refused: `--modes` at the exact limit 3n − 6 of the
/// free-free beam and a `--max-freq` far beyond its highest mode both bake all 564 elastic
/// modes (the same ones), and a clamped cube bakes its 3n − fixed dofs' worth.
#[test]
fn every_mode_of_a_small_mesh_bakes() {
    let dir = tempfile::tempdir().unwrap();
    let beam = data("meshes/beam.msh");
    let limit = 3 * modal_bake::mesh::read_mesh(&beam).unwrap().nodes.len() - 6;
    let bake = |mesh: &std::path::Path, name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut a = vec!["bake", mesh.to_str().unwrap(), "-o", out.to_str().unwrap()];
        a.extend_from_slice(extra);
        let o = run(&a);
        assert_eq!(o.status.code(), Some(0), "{extra:?}: {}", stderr(&o));
        dcr_runtime::format::ModesFile::read(&out).unwrap()
    };
    let count = bake(&beam, "count.modes", &["--modes", &limit.to_string()]);
    let capped = bake(&beam, "cap.modes", &["--max-freq", "1e300"]);
    assert_eq!(count.eigenvalues.len(), limit);
    assert_eq!(count.eigenvalues, capped.eigenvalues);
    assert!(count.residuals.iter().all(|&r| r <= 1e-8));
    let cube = data("meshes/cube_v41.msh");
    let mesh = modal_bake::mesh::read_mesh(&cube).unwrap();
    let limit = 3 * (mesh.nodes.len() - mesh.groups["bottom"].len());
    let clamped = bake(
        &cube,
        "cube.modes",
        &["--fixed", "bottom", "--modes", &limit.to_string()],
    );
    assert_eq!(clamped.eigenvalues.len(), limit);
    assert!(clamped.residuals.iter().all(|&r| r <= 1e-8));
}
