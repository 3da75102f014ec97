//! End-to-end tests of the `modal-bake` binary: byte-identical bases across input forms and
//! runs, `check` exit codes, `info --json` keys, `info` of a volume mesh, and the bad-input corpus (clear error naming
//! the file and location, non-zero exit, no panic, no output left behind).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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

fn bake(mesh: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut a = vec!["bake", mesh.to_str().unwrap(), "-o", out.to_str().unwrap()];
    a.extend_from_slice(extra);
    run(&a)
}

#[test]
fn every_input_form_gives_a_byte_identical_base_and_rebaking_is_identical() {
    let dir = tempfile::tempdir().unwrap();
    let forms = [
        "meshes/cube_v22.msh",
        "meshes/cube_v22_bin.msh",
        "meshes/cube_v41.msh",
        "meshes/cube_v41_bin.msh",
        "meshes/cube_cell_sets.json",
        "meshes/cube_gmsh_physical.json",
    ];
    let mut first: Option<Vec<u8>> = None;
    for (i, f) in forms.iter().enumerate() {
        let out = dir.path().join(format!("{i}.modes"));
        let o = bake(&data(f), &out, &["--fixed", "bottom", "--modes", "8"]);
        assert!(
            o.status.success(),
            "{f}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let bytes = std::fs::read(&out).unwrap();
        match &first {
            None => first = Some(bytes),
            Some(b) => assert!(b == &bytes, "{f} gives a different base than {}", forms[0]),
        }
    }
    // Twice, same file: bit-identical.
    let again = dir.path().join("again.modes");
    assert!(bake(
        &data(forms[2]),
        &again,
        &["--fixed", "bottom", "--modes", "8"]
    )
    .status
    .success());
    assert!(first.unwrap() == std::fs::read(&again).unwrap());
    // The base carries the heat geodesic's elimination order, and loading under it gives the
    // distances of an AMD factor computed at load.
    let base = dcr_runtime::format::ModesFile::read(&again).unwrap();
    let order = base
        .surface_order
        .as_deref()
        .expect("the bake stores surface_order");
    let (v, t) = (&base.surface_vertices, &base.surface_triangles);
    let stored = dcr_runtime::attenuation::HeatGeodesic::with_ordering(v, t, Some(order)).unwrap();
    let amd = dcr_runtime::attenuation::HeatGeodesic::new(v, t).unwrap();
    let (mut a, mut b) = (vec![0.0; v.len()], vec![0.0; v.len()]);
    stored.distances_from_vertex(0, &mut a);
    amd.distances_from_vertex(0, &mut b);
    let scale = b.iter().fold(0.0f64, |m, x| m.max(*x));
    assert!(scale > 0.0);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-9 * scale, "{x} vs {y}");
    }
}

#[test]
fn check_exit_codes_follow_staleness() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = data("meshes/cube_v41.msh");
    let out = dir.path().join("c.modes");
    let m = mesh.to_str().unwrap();
    let o = out.to_str().unwrap();
    assert_eq!(
        run(&["check", m, o, "--modes", "6"]).status.code(),
        Some(1),
        "missing → 1"
    );
    assert!(bake(&mesh, &out, &["--modes", "6"]).status.success());
    assert_eq!(
        run(&["check", m, o, "--modes", "6"]).status.code(),
        Some(0),
        "fresh → 0"
    );
    assert_eq!(
        run(&["check", m, o, "--modes", "7"]).status.code(),
        Some(1),
        "other params → 1"
    );
    assert_eq!(
        run(&["check", m, o, "--modes", "6", "--youngs", "2e9"])
            .status
            .code(),
        Some(1)
    );
    // Same geometry in another form is still up to date (hash of parsed geometry, not bytes).
    let json = data("meshes/cube_cell_sets.json");
    assert_eq!(
        run(&["check", json.to_str().unwrap(), o, "--modes", "6"])
            .status
            .code(),
        Some(0)
    );
    // A base without the stored heat-geodesic order (an older bake) is stale.
    let fresh = dcr_runtime::format::ModesFile::read(&out).unwrap();
    let mut old = fresh.clone();
    old.surface_order = None;
    old.write_atomic(&out).unwrap();
    assert_eq!(
        run(&["check", m, o, "--modes", "6"]).status.code(),
        Some(1),
        "no surface_order → 1"
    );
    fresh.write_atomic(&out).unwrap();
    let bad = data("bad/truncated.msh");
    assert_eq!(
        run(&["check", bad.to_str().unwrap(), o]).status.code(),
        Some(2),
        "unreadable mesh → 2"
    );
    // The peak-transfer table is part of what a base is: asking for one (or another one) makes
    // a base without it (or with another) stale, and a base with one is stale for a plain check.
    let table = [
        "--modes",
        "6",
        "--transfer-h",
        "0.01",
        "--transfer-modes",
        "6",
    ];
    let check = |extra: &[&str]| {
        let mut args = vec!["check", m, o];
        args.extend_from_slice(extra);
        run(&args).status.code()
    };
    assert_eq!(check(&table), Some(1), "table asked, base has none → 1");
    let o2 = bake(&mesh, &out, &table);
    assert!(
        o2.status.success(),
        "{}",
        String::from_utf8_lossy(&o2.stderr)
    );
    assert_eq!(check(&table), Some(0), "same table → 0");
    assert_eq!(check(&["--modes", "6"]), Some(1), "no table asked → 1");
    assert_eq!(
        check(&[
            "--modes",
            "6",
            "--transfer-h",
            "0.02",
            "--transfer-modes",
            "6"
        ]),
        Some(1),
        "other step → 1"
    );
    assert_eq!(
        check(&[&table[..], &["--transfer-up", "0,0,1"]].concat()),
        Some(1),
        "other region → 1"
    );
    assert_eq!(
        check(&["--modes", "6", "--transfer-h", "-1"]),
        Some(2),
        "invalid table parameters → 2"
    );
    std::fs::write(&out, b"garbage").unwrap();
    assert_eq!(
        run(&["check", m, o, "--modes", "6"]).status.code(),
        Some(1),
        "corrupt base → stale"
    );
}

#[test]
fn info_json_has_the_documented_keys() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.modes");
    assert!(bake(&data("meshes/cube_v41.msh"), &out, &["--modes", "5"])
        .status
        .success());
    let o = run(&["info", out.to_str().unwrap(), "--json"]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["modes"], 5);
    assert_eq!(v["frequencies_hz"].as_array().unwrap().len(), 5);
    assert_eq!(v["eigenvalues"].as_array().unwrap().len(), 5);
    assert_eq!(v["format_version"], 1);
    assert_eq!(
        v["rigid_modes_excluded"], 6,
        "free-free cube: six rigid modes excluded"
    );
    assert!(v["surface_vertices"].as_u64().unwrap() > 0);
    assert!(v["surface_triangles"].as_u64().unwrap() > 0);
    assert_eq!(
        v["surface_order"], true,
        "the bake stores the heat ordering"
    );
    assert!(v["source_hash"].as_str().unwrap().starts_with("sha256:"));
    // f = √λ / 2π for every mode.
    for (f, l) in v["frequencies_hz"]
        .as_array()
        .unwrap()
        .iter()
        .zip(v["eigenvalues"].as_array().unwrap())
    {
        let (f, l) = (f.as_f64().unwrap(), l.as_f64().unwrap());
        assert!((f - l.sqrt() / (2.0 * std::f64::consts::PI)).abs() <= 1e-12 * f);
    }
}

/// `info MESH`: a volume mesh is summarised before baking — its size and volume, its pieces
/// largest first (the numbers `--piece` takes, and the pieces' volumes add up to the mesh's),
/// its groups with node counts, and a curved second-order mesh is told `--straighten`; a
/// surface asset is sent to `mesh --dry-run`; an unreadable mesh is the reader's located error.
#[test]
fn info_summarises_a_volume_mesh_before_baking() {
    let o = run(&[
        "info",
        data("bad/two_pieces.msh").to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (v["kind"].as_str(), v["tets"].as_u64(), v["order"].as_u64()),
        (Some("volume mesh"), Some(2), Some(1))
    );
    let pieces = v["pieces"].as_array().unwrap();
    assert_eq!(pieces.len(), 2);
    let sum: f64 = pieces
        .iter()
        .map(|p| p["volume_m3"].as_f64().unwrap())
        .sum();
    assert!(
        (sum - v["volume_m3"].as_f64().unwrap()).abs() < 1e-15 && (sum - 1.0 / 3.0).abs() < 1e-15
    );
    assert_eq!(
        pieces[1]["bbox_m"],
        serde_json::json!([[5.0, 0.0, 0.0], [6.0, 1.0, 1.0]])
    );
    assert_eq!(v["bake_estimate"]["within_default_budget"], true);
    assert!(v["bake_estimate"]["peak_bytes"].as_f64().unwrap() > 0.0);
    let o = run(&["info", data("meshes/cube_v41.msh").to_str().unwrap()]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for part in [
        "1,140 4-node tetrahedra (order 1)",
        "volume 1 m³",
        "pieces: 1 (connected)",
        "bottom (58 nodes)",
        "corner (1 node)",
        "bake (20 modes, free-free): about",
    ] {
        assert!(text.contains(part), "{part}: {text}");
    }
    let o = run(&["info", data("bad/second_order_only.msh").to_str().unwrap()]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("elements: curved (element 1") && text.contains("bake with --straighten"),
        "{text}"
    );
    let o = run(&["info", data("assets/hp_body.obj").to_str().unwrap()]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--dry-run"));
    let o = run(&["info", data("bad/missing_node.msh").to_str().unwrap()]);
    let text = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && text.contains("missing_node.msh:") && text.contains("names node 99"),
        "{text}"
    );
}

/// Each bad input: exit ≠ 0, no panic, a message naming the file (and where), no output file.
#[test]
fn bad_inputs_fail_cleanly_with_located_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, &[&str], &str)] = &[
        ("bad/truncated.msh", &[], "truncated.msh:"),
        ("bad/non_numeric.msh", &[], "non_numeric.msh:"),
        ("bad/nan_coordinate.msh", &[], "nan_coordinate.msh:"),
        ("bad/inf_coordinate.msh", &[], "inf_coordinate.msh:"),
        ("bad/missing_node.msh", &[], "missing_node.msh"),
        ("bad/zero_volume.msh", &[], "zero_volume.msh"),
        ("bad/no_tets.msh", &[], "no_tets.msh: no 4-node or 10-node tetrahedra in the mesh (it holds 2 triangles)"),
        ("bad/huge_count.msh", &[], "huge_count.msh"),
        (
            "bad/two_pieces.msh",
            &[],
            "2 disconnected pieces, largest first: piece 1: 1 tetrahedron, 0.1667 m³, from (0, 0, 0) to (1, 1, 1) m; piece 2: 1 tetrahedron, 0.1667 m³, from (5, 0, 0) to (6, 1, 1) m; bake each piece as its own object (--piece N bakes piece N alone; --object NAME",
        ),
        ("bad/bad_shape.json", &[], "bad_shape.json"),
        ("bad/negative_index.json", &[], "negative_index.json"),
        ("bad/not_a_mesh.msh", &[], "not_a_mesh.msh"),
        ("bad/repeated_nodes.msh", &[], "repeated_nodes.msh:21:"),
        (
            "bad/repeated_nodes_v41.msh",
            &[],
            "repeated_nodes_v41.msh:24:",
        ),
        (
            "bad/negative_node_tag.msh",
            &[],
            "negative_node_tag.msh:15:",
        ),
        ("bad/extra_value.msh", &[], "extra_value.msh:18:"),
        ("bad/permuted_duplicate_tet.msh", &[], "elements 5 and 7"),
        ("bad/overlapping_tets.msh", &[], "elements 5 and 7 overlap"),
        (
            "meshes/cube_v41.msh",
            &["--fixed", "no_such_group"],
            "no_such_group",
        ),
        ("meshes/cube_v41.msh", &["--youngs", "-5"], "--youngs"),
        (
            "meshes/cube_v41.msh",
            &["--modes", "0"],
            "parameter `modes`: the mode count must be at least 1",
        ),
        ("meshes/cube_v41.msh", &["--modes", "100000"], "modes"),
        ("meshes/cube_v41.msh", &["--rayleigh", "nan,1"], "rayleigh"),
    ];
    for (i, (file, extra, needle)) in cases.iter().enumerate() {
        let out = dir.path().join(format!("bad{i}.modes"));
        let o = bake(&data(file), &out, extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{file} {extra:?} must fail");
        assert_ne!(o.status.code(), Some(101), "{file}: panicked: {err}");
        assert!(!err.contains("panicked"), "{file}: {err}");
        assert!(
            err.contains(needle),
            "{file} {extra:?}: message `{err}` should mention `{needle}`"
        );
        assert!(!out.exists(), "{file}: output left behind");
    }
    // Nothing half-written: no temporary files either.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

// Regression: `check` panicked (exit 101) on a mesh whose `$Nodes` repeats after `$Elements`.
// A mesh that cannot be read is an error (exit 2) naming the file and line, for every kind of
// refusal in data/bad, and `check` never panics.
#[test]
fn check_exits_2_on_every_unreadable_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never.modes");
    let mut checked = 0;
    for entry in std::fs::read_dir(data("bad")).unwrap() {
        let path = entry.unwrap().path();
        let o = run(&["check", path.to_str().unwrap(), out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            matches!(o.status.code(), Some(1) | Some(2)),
            "{}: exit {:?}: {err}",
            path.display(),
            o.status.code()
        );
        if o.status.code() == Some(2) {
            assert!(
                err.contains(path.file_name().unwrap().to_str().unwrap()),
                "{}: {err}",
                path.display()
            );
            checked += 1;
        }
    }
    assert!(checked >= 25, "{checked} refusals");
    let o = run(&[
        "check",
        data("bad/repeated_nodes.msh").to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("repeated_nodes.msh:21:"));
}

// Regression: a base baked from gmsh's MSH 2.2 binary file was stale for the MSH 4.1 ASCII
// file of the same mesh (coordinates an ulp apart through `%.16g`).
#[test]
fn check_sees_gmsh_ascii_and_binary_forms_as_one_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cyl.modes");
    let o = bake(
        &data("meshes/cylinder_v22_bin.msh"),
        &out,
        &["--modes", "4", "--fixed", "bottom"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ascii = data("meshes/cylinder_v41.msh");
    let o = run(&[
        "check",
        ascii.to_str().unwrap(),
        out.to_str().unwrap(),
        "--modes",
        "4",
        "--fixed",
        "bottom",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
}

#[test]
fn an_inverted_tet_is_reoriented_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("inv.modes");
    let o = bake(
        &data("bad/inverted_tet.msh"),
        &out,
        &["--modes", "2", "--json"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["reoriented_tets"], 1);
}

/// The readable `probe` output names, per contact, what served it (as `--json`'s `served_by`).
#[test]
fn probe_text_reports_what_served_each_contact() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.modes");
    assert!(bake(&data("meshes/cube_v41.msh"), &out, &["--modes", "6"])
        .status
        .success());
    let o = out.to_str().unwrap();
    let probe = |method: &str| {
        let r = run(&[
            "probe",
            o,
            "--impact",
            "0.5,0.5,1",
            "--impulse",
            "1",
            "--contact",
            "0.2,0.3,1",
            "--method",
            method,
        ]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        String::from_utf8(r.stdout).unwrap()
    };
    // No table in this base: the default transfer method runs the modal one.
    for (method, served) in [("transfer", "modal"), ("attenuation", "attenuation")] {
        let text = probe(method);
        let mut lines = text.lines().skip(1);
        assert!(lines.next().unwrap().ends_with("served_by"), "{text}");
        assert!(lines.next().unwrap().ends_with(served), "{method}: {text}");
    }
}

/// `points` of the meshio JSON `src` replaced by `f(coordinate)`, written to `dst`.
fn rescaled_json(src: &Path, dst: &Path, f: impl Fn(f64) -> f64) {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(src).unwrap()).unwrap();
    for p in v["points"].as_array_mut().unwrap() {
        for c in p.as_array_mut().unwrap() {
            *c = serde_json::json!(f(c.as_f64().unwrap()));
        }
    }
    std::fs::write(dst, serde_json::to_vec(&v).unwrap()).unwrap();
}

#[test]
fn units_mm_bakes_the_metre_mesh_and_check_needs_the_same_units() {
    let dir = tempfile::tempdir().unwrap();
    let src = data("meshes/cube_cell_sets.json");
    let args = ["--fixed", "bottom", "--modes", "8", "--material", "oak"];
    // Whole millimetres: k/1000 is one correctly rounded division, so the mm mesh read with
    // --units mm has exactly the coordinates of the metre mesh written in decimal.
    let (m_mesh, mm_mesh) = (dir.path().join("m.json"), dir.path().join("mm.json"));
    rescaled_json(&src, &m_mesh, |x| (x * 1000.0).round() / 1000.0);
    rescaled_json(&src, &mm_mesh, |x| (x * 1000.0).round());
    let (m_base, mm_base) = (dir.path().join("m.modes"), dir.path().join("mm.modes"));
    let o = bake(&m_mesh, &m_base, &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut with_units = args.to_vec();
    with_units.extend(["--units", "mm"]);
    let o = bake(&mm_mesh, &mm_base, &with_units);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("warning"), "{stderr}");
    // The same bits but for the record of the unit each was read in.
    let read = |p: &Path| dcr_runtime::format::ModesFile::read(p).unwrap();
    let (mut a, mut b) = (read(&m_base), read(&mm_base));
    assert_eq!(a.meta.bake_params["selection"]["units"], "m");
    assert_eq!(b.meta.bake_params["selection"]["units"], "mm");
    for base in [&mut a, &mut b] {
        base.meta.bake_params["selection"]["units"] = serde_json::Value::Null;
    }
    let bytes = |m: &dcr_runtime::format::ModesFile| {
        let path = dir.path().join("cmp.modes");
        m.write_atomic(&path).unwrap();
        std::fs::read(&path).unwrap()
    };
    assert!(
        bytes(&a) == bytes(&b),
        "--units mm on a whole-millimetre mesh must give the metre mesh's bits"
    );
    // check: fresh with the same --units, stale (geometry changed) without.
    let check = |units: &[&str]| {
        let mut a = vec![
            "check",
            mm_mesh.to_str().unwrap(),
            mm_base.to_str().unwrap(),
        ];
        a.extend_from_slice(&args);
        a.extend_from_slice(units);
        a.push("--json");
        run(&a)
    };
    let o = check(&["--units", "mm"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let o = check(&[]);
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["reason"], "geometry_changed");
    let detail = v["detail"].as_str().unwrap();
    assert!(
        detail.starts_with(
            "the base was read from its file as `--units mm`, this as the whole file in metres"
        ) && detail.contains("this mesh is 1000× the base's size"),
        "{detail}"
    );
    // Without --units the millimetre mesh is 1.7 km across: the warning suggests --units mm.
    let o = bake(&mm_mesh, &dir.path().join("huge.modes"), &args);
    assert!(o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("warning") && stderr.contains("--units mm"),
        "{stderr}"
    );

    // Arbitrary decimals (1/6 m): x·1000 then /1000 may move a coordinate by one ulp, so
    // the bits may differ; the frequencies agree to 1e-12 relative.
    let mm_any = dir.path().join("mm_any.json");
    rescaled_json(&src, &mm_any, |x| x * 1000.0);
    let (a, b) = (dir.path().join("a.modes"), dir.path().join("b.modes"));
    assert!(bake(&src, &a, &args).status.success());
    assert!(bake(&mm_any, &b, &with_units).status.success());
    let a = dcr_runtime::format::ModesFile::read(&a).unwrap();
    let b = dcr_runtime::format::ModesFile::read(&b).unwrap();
    assert_eq!(a.eigenvalues.len(), 8);
    for (x, y) in a.eigenvalues.iter().zip(&b.eigenvalues) {
        assert!((x - y).abs() <= 1e-12 * x.abs(), "{x} vs {y}");
    }
}

/// `modal-bake --help` names every environment variable the program reads: each string literal
/// passed to `env::var` / `env::var_os` in its sources (and `PYTHON_ENV`'s value), found by
/// scanning them, so a new variable cannot be added without its line in the help.
#[test]
fn help_lists_every_environment_variable_the_program_reads() {
    let help = String::from_utf8(run(&["--help"]).stdout).unwrap();
    let env_part = help
        .split("Environment:")
        .nth(1)
        .unwrap_or_else(|| panic!("no Environment section in --help:\n{help}"));
    fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                sources(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    sources(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src"),
        &mut files,
    );
    let mut names = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for pat in ["env::var(\"", "env::var_os(\"", "_ENV: &str = \""] {
            for part in text.split(pat).skip(1) {
                let name = part.split('"').next().unwrap().to_string();
                if !name.is_empty() {
                    names.push(name);
                }
            }
        }
    }
    for n in ["MODAL_BAKE_PYTHON", "MODAL_BAKE_PROGRESS_EVERY", "PATH"] {
        assert!(
            names.iter().any(|m| m == n),
            "the scan missed {n}: {names:?}"
        );
    }
    // TMPDIR is read through std::env::temp_dir; the shard variables by name at run time.
    names.extend(["TMPDIR", "JOB_COMPLETION_INDEX", "SLURM_ARRAY_TASK_ID"].map(String::from));
    for n in &names {
        assert!(
            env_part.contains(n.as_str()),
            "{n} is read but not in --help:\n{env_part}"
        );
    }
}
