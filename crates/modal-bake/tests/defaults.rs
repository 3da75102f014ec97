//! Defaults an artist can trust, end to end through the `modal-bake` binary: material presets
//! (values baked, frequencies scaling with √(E/ρ), explicit values winning, a warning without
//! a material), the material, selectors and element order in the report and `info`, unit
//! mistakes named in refusals and before the factorization, the size estimate and budget
//! (refusal with the estimate, a coarser size passing), progress lines in logs, and the
//! order-2 default for surface assets.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use dcr_runtime::format::ModesFile;
use modal_bake::fem::MaterialPreset;

#[path = "common/gmsh_gate.rs"]
mod gmsh_gate;
use gmsh_gate::have_gmsh;

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

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// An OBJ of the axis-aligned box [0, a]³ (m) whose faces are each an n × n grid of quads
/// split into triangles (12 n² triangles), outward oriented.
fn box_obj(a: f64, n: usize) -> String {
    let mut s = String::new();
    let mut nv = 0usize;
    // Each face: origin, two in-plane axes (u × v points outward).
    let faces: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), // z = 0, normal −z
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), // z = a, +z
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), // y = 0, −y
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), // y = a, +y
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]), // x = 0, −x
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), // x = a, +x
    ];
    for (o, u, v) in faces {
        for i in 0..=n {
            for j in 0..=n {
                let (fu, fv) = (i as f64 / n as f64, j as f64 / n as f64);
                let p: Vec<f64> = (0..3).map(|k| a * (o[k] + fu * u[k] + fv * v[k])).collect();
                s.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
            }
        }
        let id = |i: usize, j: usize| nv + i * (n + 1) + j + 1;
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                s.push_str(&format!("f {a} {b} {c}\nf {a} {c} {d}\n"));
            }
        }
        nv += (n + 1) * (n + 1);
    }
    s
}

/// `--material` bakes the preset's E, ν, ρ into the base; explicit values win over it (the
/// report says which); and between two presets of equal ν every frequency scales exactly with
/// √(E/ρ) (same mesh, same ν: K ∝ E, M ∝ ρ).
#[test]
fn material_presets_are_baked_and_frequencies_scale_with_the_wave_speed() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = data("meshes/cube_cell_sets.json");
    let base = |name: &str, extra: &[&str]| {
        let out = dir.path().join(format!("{name}.modes"));
        let mut a = vec!["--fixed", "bottom", "--modes", "6", "--json"];
        a.extend_from_slice(extra);
        let r: serde_json::Value = serde_json::from_str(&ok(&bake(&mesh, &out, &a))).unwrap();
        (ModesFile::read(&out).unwrap(), r)
    };
    let (brass, r) = base("brass", &["--material", "brass"]);
    let p = MaterialPreset::find("brass").unwrap();
    assert_eq!(
        [
            brass.material.youngs,
            brass.material.poisson,
            brass.material.density
        ],
        [p.youngs, p.poisson, p.density]
    );
    assert_eq!(r["material_name"], "brass");
    assert_eq!(brass.meta.bake_params["material_choice"]["preset"], "brass");
    // Two presets of equal ν: frequencies scale with √(E/ρ).
    let (alu, _) = base("aluminium", &["--material", "aluminium"]);
    let (pine, _) = base("pine", &["--material", "PINE"]);
    let (p, q) = (
        MaterialPreset::find("aluminium").unwrap(),
        MaterialPreset::find("pine").unwrap(),
    );
    assert_eq!(p.poisson, q.poisson, "the scaling test needs equal ν");
    let ratio = ((p.youngs / p.density) / (q.youngs / q.density)).sqrt();
    for (fb, fa) in alu.frequencies_hz().iter().zip(pine.frequencies_hz()) {
        assert!(
            (fb / fa / ratio - 1.0).abs() < 1e-9,
            "{fb} / {fa} vs √(E/ρ) ratio {ratio}"
        );
    }
    // Explicit --youngs wins over the preset; ν and ρ stay the preset's.
    let (mixed, r) = base("mixed", &["--material", "steel", "--youngs", "1e11"]);
    assert_eq!(mixed.material.youngs, 1e11);
    assert_eq!(mixed.material.density, 7850.0);
    assert_eq!(r["material_name"], "steel with --youngs");
    // An unknown name is refused with the list.
    let o = bake(
        &mesh,
        &dir.path().join("x.modes"),
        &["--material", "unobtainium"],
    );
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("unobtainium") && e.contains("oak") && e.contains("steel"),
        "{e}"
    );
}

/// A bake without a material warns, naming the values used and how to choose; with a preset
/// or all three values it does not.
#[test]
fn a_bake_without_a_material_warns_with_the_values() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = data("meshes/cube_cell_sets.json");
    let out = dir.path().join("d.modes");
    let o = bake(&mesh, &out, &["--fixed", "bottom", "--modes", "4"]);
    ok(&o);
    let e = stderr(&o);
    assert!(
        e.contains("warning: no material given")
            && e.contains("E 1.1e9 Pa")
            && e.contains("ρ 770 kg/m³")
            && e.contains("--material oak|pine|steel"),
        "{e}"
    );
    for extra in [
        &["--material", "oak"][..],
        &["--youngs", "1e9", "--poisson", "0.3", "--density", "700"][..],
    ] {
        let mut a = vec!["--fixed", "bottom", "--modes", "4"];
        a.extend_from_slice(extra);
        let o = bake(&mesh, &out, &a);
        ok(&o);
        assert!(!stderr(&o).contains("no material given"), "{extra:?}");
    }
    // Only some values: the rest are defaulted, and named.
    let o = bake(
        &mesh,
        &out,
        &["--fixed", "bottom", "--modes", "4", "--youngs", "2e9"],
    );
    ok(&o);
    let e = stderr(&o);
    assert!(
        e.contains("--poisson, --density not set") && !e.contains("--youngs, "),
        "{e}"
    );
}

/// The bake report and `info` (text and JSON) print the material with its name, the element
/// order and every fixed-node selector with the nodes it fixed.
#[test]
fn report_and_info_print_material_selector_and_order() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.modes");
    let report = ok(&bake(
        &data("meshes/cube_cell_sets.json"),
        &out,
        &[
            "--material",
            "glass",
            "--fixed",
            "bottom",
            "--fixed-below",
            "z=0.01",
            "--modes",
            "4",
        ],
    ));
    assert!(
        report.contains("material: glass: E 7.0000e10 Pa, ν 0.22, ρ 2500 kg/m³"),
        "{report}"
    );
    assert!(
        report.contains("element order 1 (4-node tetrahedra)"),
        "{report}"
    );
    assert!(
        report.contains("group bottom: ") && report.contains("below z=0.01: "),
        "{report}"
    );
    let info = ok(&run(&["info", out.to_str().unwrap()]));
    assert!(info.contains("material: glass: E 7.0000e10 Pa"), "{info}");
    assert!(info.contains("element order 1"), "{info}");
    assert!(
        info.contains("by group bottom (") && info.contains("; below z=0.01 ("),
        "{info}"
    );
    assert!(
        !info.contains("warning"),
        "a 1 m glass cube is plausible: {info}"
    );
    let v: serde_json::Value =
        serde_json::from_slice(&run(&["info", out.to_str().unwrap(), "--json"]).stdout).unwrap();
    assert_eq!(v["material"]["name"], "glass");
    assert_eq!(v["order"], 1);
    assert_eq!(v["fixed_by"].as_array().unwrap().len(), 2);
    // Free-free: said as such.
    let ff = dir.path().join("ff.modes");
    ok(&bake(
        &data("meshes/cube_cell_sets.json"),
        &ff,
        &["--material", "glass", "--modes", "2"],
    ));
    let info = ok(&run(&["info", ff.to_str().unwrap()]));
    assert!(info.contains("fixed: nothing (free-free"), "{info}");
}

/// The 1 m cube written in millimetres and read as metres (1.7 km across): a selector that
/// fixes one edge is refused as collinear with the likely unit named and the fix; baking it
/// with a plane selector warns about the size and the mass before the factorization; `info`
/// on that base warns too.
#[test]
fn a_millimetre_mesh_is_named_in_refusals_before_factorization_and_in_info() {
    let dir = tempfile::tempdir().unwrap();
    let src = data("meshes/cube_cell_sets.json");
    let mm = dir.path().join("mm.json");
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&src).unwrap()).unwrap();
    for p in v["points"].as_array_mut().unwrap() {
        for c in p.as_array_mut().unwrap() {
            *c = serde_json::json!((c.as_f64().unwrap() * 1000.0).round());
        }
    }
    std::fs::write(&mm, serde_json::to_vec(&v).unwrap()).unwrap();
    let out = dir.path().join("mm.modes");
    let o = bake(
        &mm,
        &out,
        &["--material", "oak", "--fixed-box", "0,0,0,0.005,0.005,1000"],
    );
    assert!(!o.status.success());
    assert!(!out.exists());
    let e = stderr(&o);
    assert!(
        e.contains("collinear") && e.contains("millimetres") && e.contains("--units mm"),
        "{e}"
    );
    // A plane selector bakes, but the size and mass warnings come before the factorization.
    let o = bin()
        .args(["bake", mm.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .args(["--material", "oak", "--fixed", "bottom", "--modes", "3"])
        .env("MODAL_BAKE_PROGRESS_EVERY", "0")
        .output()
        .unwrap();
    ok(&o);
    let e = stderr(&o);
    let (size, mass, factor) = (
        e.find("--units mm").expect("size warning"),
        e.find("weighs").expect("mass warning"),
        e.find("factoring")
            .expect("progress line of the factorization"),
    );
    assert!(size < factor && mass < factor, "{e}");
    let info = ok(&run(&["info", out.to_str().unwrap()]));
    assert!(
        info.contains("warning: the object is") && info.contains("millimetres"),
        "{info}"
    );
    assert!(info.contains("warning: the object weighs"), "{info}");
}

/// Plain progress lines (stderr not a terminal): every stage is announced and closed with
/// its duration when the interval is 0.
#[test]
fn progress_lines_appear_in_logs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.modes");
    let o = bin()
        .args(["bake", data("meshes/cube_cell_sets.json").to_str().unwrap()])
        .args([
            "-o",
            out.to_str().unwrap(),
            "--material",
            "steel",
            "--modes",
            "4",
        ])
        .env("MODAL_BAKE_PROGRESS_EVERY", "0")
        .output()
        .unwrap();
    ok(&o);
    let e = stderr(&o);
    for stage in [
        "assembling K and M",
        "factoring K − σM",
        "eigensolve:",
        "writing",
    ] {
        assert!(e.contains(&format!("] {stage}")), "{stage}: {e}");
    }
    assert!(e.contains("assembling K and M: done in"), "{e}");
    assert!(e.lines().all(|l| !l.contains('\r')), "no terminal codes");
}

/// A surface asset: meshed at order 2 without --order (order 1 with a transfer table, whose
/// dense all-mode eigensolve finds the six rigid modes of this coarse ABS box); its
/// size estimate is printed and is within a factor 3 of the tetrahedra gmsh makes.
#[test]
fn surface_assets_default_to_order_2_and_the_estimate_is_close() {
    if !have_gmsh("surface_assets_default_to_order_2_and_the_estimate_is_close") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let asset = dir.path().join("box.obj");
    std::fs::write(&asset, box_obj(0.1, 2)).unwrap();
    let msh = dir.path().join("box.msh");
    let o = bin()
        .args(["mesh", asset.to_str().unwrap(), "-o", msh.to_str().unwrap()])
        .args(["--size", "0.02", "--json"])
        .env("MODAL_BAKE_PROGRESS_EVERY", "0")
        .output()
        .unwrap();
    let r: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(r["order"], 2);
    let e = stderr(&o);
    assert!(e.contains("size estimate for"), "{e}");
    assert!(
        e.contains("] meshing") && e.contains(": done in") && e.contains("backend: gmsh"),
        "progress of the gmsh stage: {e}"
    );
    let estimate: f64 = e
        .split("~")
        .nth(1)
        .and_then(|s| s.split(" tetrahedra").next())
        .map(|s| s.replace(',', "").parse().unwrap())
        .expect("the estimate's tetrahedra");
    let tets = r["tets"].as_f64().unwrap();
    assert!(
        estimate / tets < 3.0 && tets / estimate < 3.0,
        "estimate {estimate} vs {tets} tetrahedra"
    );
    // bake of the asset: order 2; with a transfer table: order 1 and a note.
    let out = dir.path().join("box.modes");
    let r: serde_json::Value = serde_json::from_str(&ok(&bake(
        &asset,
        &out,
        &[
            "--size",
            "0.03",
            "--material",
            "abs",
            "--modes",
            "3",
            "--json",
        ],
    )))
    .unwrap();
    assert_eq!(r["order"], 2);
    let o = bake(
        &asset,
        &out,
        &[
            "--size",
            "0.03",
            "--material",
            "abs",
            "--modes",
            "3",
            "--json",
            "--transfer-h",
            "0.001",
            "--transfer-modes",
            "20",
        ],
    );
    let r: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(r["order"], 1);
    assert!(stderr(&o).contains("--order 1"), "{}", stderr(&o));
}

/// Over the budget: a fine --size is refused before gmsh runs, with the estimate, the
/// budget and a --size that fits; that size then meshes without --force. A finely
/// tessellated surface with --keep-surface is refused up front too.
#[test]
fn an_over_budget_surface_is_refused_with_the_estimate() {
    if !have_gmsh("an_over_budget_surface_is_refused_with_the_estimate") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let asset = dir.path().join("box.obj");
    std::fs::write(&asset, box_obj(0.1, 2)).unwrap();
    let out = dir.path().join("box.modes");
    let o = bake(&asset, &out, &["--size", "0.0005", "--material", "steel"]);
    assert!(!o.status.success());
    assert!(!out.exists());
    let e = stderr(&o);
    assert!(
        e.contains("refused before meshing or baking")
            && e.contains("tetrahedra")
            && e.contains("the budget of 2 GB and 5.0 min")
            && e.contains("--force")
            && !e.contains("meshing box.obj with gmsh"),
        "{e}"
    );
    // The suggested size fits under a budget small enough to keep the test quick.
    let o = bake(
        &asset,
        &out,
        &["--size", "0.002", "--material", "steel", "--max-time", "5"],
    );
    assert!(!o.status.success());
    let e = stderr(&o);
    let fit: String = e
        .split("a coarser --size ")
        .nth(1)
        .expect("a --size that fits")
        .split(' ')
        .next()
        .unwrap()
        .to_string();
    ok(&bake(
        &asset,
        &out,
        &[
            "--size",
            &fit,
            "--material",
            "steel",
            "--max-time",
            "5",
            "--modes",
            "3",
        ],
    ));
    // A 120,000-triangle surface kept as the boundary: refused up front, suggesting to drop
    // --keep-surface.
    let fine = dir.path().join("fine.obj");
    std::fs::write(&fine, box_obj(0.1, 100)).unwrap();
    let o = run(&[
        "mesh",
        fine.to_str().unwrap(),
        "-o",
        dir.path().join("fine.msh").to_str().unwrap(),
        "--keep-surface",
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("refused before meshing") && e.contains("drop --keep-surface"),
        "{e}"
    );
}

/// An estimate over the budget by less than its element count's uncertainty does not refuse a
/// surface before meshing: the 0.1 m box at --size 6 mm is estimated at 1.6 GB to bake and
/// meshes to 1.5 GB (gmsh has made as few as 1/2.5 of the estimate's elements). Under 1.4 GB
/// it is meshed with a note, `mesh` warns that the mesh's bake is over, and `bake` refuses it
/// on the mesh's exact counts; under 0.4 GB even the fewest elements are over and it is refused
/// before meshing, as before.
#[test]
fn an_estimate_within_its_uncertainty_meshes_first_and_the_exact_counts_decide() {
    if !have_gmsh("an_estimate_within_its_uncertainty_meshes_first_and_the_exact_counts_decide") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let asset = dir.path().join("box.obj");
    std::fs::write(&asset, box_obj(0.1, 2)).unwrap();
    let msh = dir.path().join("box.msh");
    let common = ["--size", "0.006", "--max-memory", "1.4"];
    let mut a = vec!["mesh", asset.to_str().unwrap(), "-o", msh.to_str().unwrap()];
    a.extend(common);
    let o = run(&a);
    let e = stderr(&o);
    assert!(o.status.success() && msh.exists(), "{e}");
    assert!(
        e.contains("its element count is uncertain before meshing")
            && e.contains("gmsh has made as few as 0.40 times it"),
        "{e}"
    );
    assert!(
        e.contains("baking it (20 modes) is estimated on its counts")
            && e.contains("`modal-bake bake` will refuse it"),
        "{e}"
    );
    // `bake` of the asset: meshed, then refused on the exact counts (no `~`).
    let out = dir.path().join("box.modes");
    let mut a = vec!["--material", "steel"];
    a.extend(common);
    let o = bake(&asset, &out, &a);
    let e = stderr(&o);
    assert!(!o.status.success() && !out.exists(), "{e}");
    assert!(
        e.contains("box.obj (order 2, --mesher auto) ...")
            && e.contains("refused before baking: estimated 22,"),
        "{e}"
    );
    // Far over: refused before meshing.
    let o = bake(&asset, &out, &["--size", "0.006", "--max-memory", "0.4"]);
    let e = stderr(&o);
    assert!(
        !o.status.success()
            && e.contains("refused before meshing or baking")
            && !e.contains("(order 2, --mesher auto) ..."),
        "{e}"
    );
}

/// `--target-error` without a transfer table picks a surface asset's mesh: it refines --size
/// until the lowest modes move by less than the target, reports each mesh, bakes the last;
/// a target the budget cannot reach is baked at the finest mesh that fits, with a warning.
#[test]
fn target_error_refines_the_mesh_of_a_surface_asset() {
    if !have_gmsh("target_error_refines_the_mesh_of_a_surface_asset") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let asset = dir.path().join("box.obj");
    std::fs::write(&asset, box_obj(0.1, 2)).unwrap();
    let out = dir.path().join("box.modes");
    let common = ["--size", "0.04", "--material", "aluminium", "--modes", "3"];
    let mut a = common.to_vec();
    a.extend(["--target-error", "5", "--json"]);
    let o = bake(&asset, &out, &a);
    let r: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    let e = stderr(&o);
    assert!(e.contains("target error 5 %: met at --size"), "{e}");
    let steps = e.matches("  size ").count();
    assert!(steps >= 2, "{e}");
    // The base is the last (finest) mesh's: its tetrahedra are the last step's.
    let last_tets: u64 = e
        .lines()
        .rfind(|l| l.starts_with("  size "))
        .and_then(|l| l.split(": ").nth(1))
        .and_then(|l| l.split(' ').next())
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(r["tets"].as_u64().unwrap(), last_tets);
    assert_eq!(r["order"], 2);
    // The base records the choice: the size chosen (the last printed) as its meshing, and
    // `check` finds it up to date at that --size, stale at the size asked for, saying why.
    let base = dcr_runtime::format::ModesFile::read(&out).unwrap();
    let choice = &base.meta.bake_params["mesh_choice"];
    let size = base.meta.bake_params["meshing"]["size"].as_f64().unwrap();
    assert_eq!(choice["size"].as_f64(), Some(size));
    assert_eq!(
        (choice["target_error_pct"].as_f64(), &choice["met"]),
        (Some(5.0), &serde_json::json!(true))
    );
    assert_eq!(choice["meshes"].as_u64(), Some(steps as u64));
    assert!(
        e.contains(&format!("met at --size {size:.4e} m")),
        "{size} {e}"
    );
    let check = |size: &str| {
        let mut a = vec!["check", asset.to_str().unwrap(), out.to_str().unwrap()];
        a.extend(["--material", "aluminium", "--modes", "3", "--size", size]);
        Command::new(env!("CARGO_BIN_EXE_modal-bake"))
            .args(&a)
            .output()
            .unwrap()
    };
    assert_eq!(check(&size.to_string()).status.code(), Some(0));
    let o = check("0.04");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.code() == Some(1)
            && text.contains(&format!("meshed with `--mesher auto --size {size} --order 2` (the --size `bake --target-error 5` chose), this with `--mesher auto --size 0.04 --order 2`")),
        "{text}"
    );
    // An unreachable target within a tiny budget: baked anyway at the finest mesh that fits,
    // with the warning.
    let mut a = common.to_vec();
    a.extend(["--target-error", "1e-6", "--max-time", "3"]);
    let o = bake(&asset, &out, &a);
    ok(&o);
    assert!(stderr(&o).contains("NOT met"), "{}", stderr(&o));
}
