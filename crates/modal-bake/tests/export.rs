//! `modal-bake export`: the VTU opens in meshio and in VTK's own reader (ParaView's) with every
//! mode shape bit-exact, the GLB's morph
//! targets are the scaled mode shapes and pass the Khronos glTF-Validator, the PNG sheet shows
//! one distinct panel per mode, outputs are deterministic, and bad options fail with a clear
//! message and no file written.

mod common;
#[path = "common/meshio_gate.rs"]
mod meshio_gate;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::gltf_check::{validate_gltf, Glb};
use dcr_runtime::format::ModesFile;
use modal_bake::export::mode_label;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("modal-bake runs")
}

/// A 6-mode clamped beam base in `dir`.
fn beam_base(dir: &Path) -> PathBuf {
    let mesh = common::gltf_check::repo_root().join("data/meshes/beam.msh");
    let out = dir.join("beam.modes");
    let o = run(&[
        "bake",
        mesh.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--fixed",
        "clamp",
        "--modes",
        "6",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn mode(base: &ModesFile, v: usize, j: usize) -> [f64; 3] {
    let m = base.num_modes();
    std::array::from_fn(|a| base.modes[(v * 3 + a) * m + j])
}

#[test]
#[cfg_attr(
    windows,
    ignore = "needs python3 with meshio or vtk; the Python cross-checks run on Linux"
)]
fn vtu_opened_by_meshio_carries_the_surface_and_every_mode_shape_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let base_path = beam_base(dir.path());
    let vtu = dir.path().join("beam.vtu");
    let o = run(&["export", s(&base_path), "--vtu", s(&vtu)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let body = r#"
m = meshio.read(sys.argv[1])
tri = [c.data.tolist() for c in m.cells if c.type == "triangle"]
print(json.dumps({"points": m.points.tolist(), "types": [c.type for c in m.cells],
                  "triangles": tri[0] if tri else [],
                  "point_data": {k: v.tolist() for k, v in m.point_data.items()}}))
"#;
    let Some(text) = meshio_gate::run_with_meshio(body, &[vtu.as_os_str()]) else {
        return;
    };
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let base = ModesFile::read(&base_path).unwrap();
    // Geometry: same points and triangles, bit for bit.
    let pts = v["points"].as_array().unwrap();
    assert_eq!(pts.len(), base.num_surface_vertices());
    for (p, q) in pts.iter().zip(&base.surface_vertices) {
        for a in 0..3 {
            assert_eq!(p[a].as_f64().unwrap(), q[a]);
        }
    }
    assert_eq!(v["types"], serde_json::json!(["triangle"]));
    let tris = v["triangles"].as_array().unwrap();
    assert_eq!(tris.len(), base.surface_triangles.len());
    for (t, u) in tris.iter().zip(&base.surface_triangles) {
        for a in 0..3 {
            assert_eq!(t[a].as_u64().unwrap(), u[a] as u64);
        }
    }
    // Every mode (6 ≤ 20: all by default), named with number and frequency, bit-exact.
    let freqs = base.frequencies_hz();
    let pd = v["point_data"].as_object().unwrap();
    assert_eq!(pd.len(), base.num_modes() + 1, "{:?}", pd.keys());
    for j in 0..base.num_modes() {
        let name = mode_label(j, freqs[j]);
        let arr = pd
            .get(&name)
            .unwrap_or_else(|| panic!("no array {name}: {:?}", pd.keys()));
        let arr = arr.as_array().unwrap();
        for (vtx, row) in arr.iter().enumerate() {
            let u = mode(&base, vtx, j);
            for a in 0..3 {
                assert_eq!(row[a].as_f64().unwrap(), u[a], "{name} vertex {vtx}");
            }
        }
    }
    let s2v = pd["surface_to_volume"].as_array().unwrap();
    assert_eq!(s2v[0].as_u64().unwrap(), base.surface_to_volume[0] as u64);
}

/// VTK's own XML reader (the one ParaView uses, from the PyPI `vtk` package) opens the file:
/// every cell a triangle, every mode array with its values bit-exact.
#[test]
#[cfg_attr(
    windows,
    ignore = "needs python3 with meshio or vtk; the Python cross-checks run on Linux"
)]
fn vtu_opened_by_vtks_own_reader_as_paraview_does() {
    let dir = tempfile::tempdir().unwrap();
    let base_path = beam_base(dir.path());
    let vtu = dir.path().join("beam.vtu");
    let o = run(&["export", s(&base_path), "--vtu", s(&vtu), "--modes", "3"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let script = r#"
import json, sys
try:
    import vtk
except ImportError:
    print("NO_VTK"); sys.exit(0)
r = vtk.vtkXMLUnstructuredGridReader()
r.SetFileName(sys.argv[1])
r.Update()
g = r.GetOutput()
pd = g.GetPointData()
arrays = {pd.GetArrayName(i): [list(pd.GetArray(i).GetTuple(k)) for k in range(g.GetNumberOfPoints())]
          for i in range(pd.GetNumberOfArrays())}
print(json.dumps({"error": r.GetErrorCode(), "points": g.GetNumberOfPoints(),
                  "types": sorted({g.GetCellType(c) for c in range(g.GetNumberOfCells())}),
                  "cells": g.GetNumberOfCells(), "arrays": arrays}))
"#;
    let out = Command::new("python3")
        .args(["-c", script, s(&vtu)])
        .output()
        .expect("python3 runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "vtk failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    if text.trim() == "NO_VTK" {
        assert!(
            std::env::var_os("CI").is_none() || std::env::var_os("DCR_NO_VTK").is_some(),
            "the vtk package is not installed under CI"
        );
        eprintln!("SKIPPED: vtk not installed (pip install vtk)");
        return;
    }
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let base = ModesFile::read(&base_path).unwrap();
    assert_eq!(v["error"], 0);
    assert_eq!(
        v["points"].as_u64().unwrap() as usize,
        base.num_surface_vertices()
    );
    assert_eq!(
        v["cells"].as_u64().unwrap() as usize,
        base.surface_triangles.len()
    );
    assert_eq!(v["types"], serde_json::json!([5]), "VTK_TRIANGLE only");
    let freqs = base.frequencies_hz();
    let arrays = v["arrays"].as_object().unwrap();
    assert_eq!(arrays.len(), 4, "{:?}", arrays.keys());
    for j in 0..3 {
        let rows = arrays[&mode_label(j, freqs[j])].as_array().unwrap();
        for (vtx, row) in rows.iter().enumerate() {
            let u = mode(&base, vtx, j);
            for a in 0..3 {
                assert_eq!(row[a].as_f64().unwrap(), u[a], "mode {j} vertex {vtx}");
            }
        }
    }
}

#[test]
fn glb_morph_targets_are_the_scaled_mode_shapes_and_pass_the_gltf_validator() {
    let dir = tempfile::tempdir().unwrap();
    let base_path = beam_base(dir.path());
    let glb_path = dir.path().join("beam.glb");
    let o = run(&[
        "export",
        s(&base_path),
        "--gltf",
        s(&glb_path),
        "--modes",
        "4",
        "--scale",
        "0.1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    validate_gltf(&glb_path);
    let base = ModesFile::read(&base_path).unwrap();
    let glb = Glb::read(&glb_path);
    let ex = glb.extras();
    assert_eq!(ex["dcr"]["kind"], "modes");
    assert_eq!(ex["dcr"]["scale"], 0.1);
    let diag = ex["dcr"]["diagonal_m"].as_f64().unwrap();
    // Beam 1.0 × 0.1 × 0.1 m: diagonal √1.02.
    assert!((diag - 1.02f64.sqrt()).abs() < 1e-9, "{diag}");
    let prim = &glb.root.meshes[0].primitives[0];
    let targets = prim.targets.as_ref().unwrap();
    assert_eq!(targets.len(), 4);
    assert_eq!(glb.root.animations.len(), 4);
    let freqs = base.frequencies_hz();
    for (j, t) in targets.iter().enumerate() {
        let a = ex["dcr"]["modes"][j]["modal_coordinate"].as_f64().unwrap();
        let d = glb.floats(t.positions.unwrap().value());
        let mut peak: f64 = 0.0;
        for v in 0..base.num_surface_vertices() {
            let u = mode(&base, v, j);
            let mut n2 = 0.0;
            for k in 0..3 {
                let want = a * u[k];
                let got = d[3 * v + k] as f64;
                assert!(
                    (got - want).abs() <= 1e-6 * diag,
                    "mode {j} vertex {v}: {got} vs {want}"
                );
                n2 += want * want;
            }
            peak = peak.max(n2.sqrt());
        }
        // The largest displacement at weight 1 is scale × diagonal.
        assert!(
            (peak - 0.1 * diag).abs() < 1e-9 * diag,
            "mode {j}: peak {peak}"
        );
        // One animation per mode, named like the VTU array, driving only its own weight.
        let anim = &glb.root.animations[j];
        assert_eq!(anim.name.as_deref(), Some(mode_label(j, freqs[j]).as_str()));
        let w = glb.floats(anim.samplers[0].output.value());
        let keys = glb.floats(anim.samplers[0].input.value()).len();
        assert_eq!(w.len(), keys * 4);
        let own: f32 = (0..keys).map(|k| w[k * 4 + j].abs()).fold(0.0, f32::max);
        let others: f32 = (0..keys)
            .flat_map(|k| (0..4).filter(move |&i| i != j).map(move |i| (k, i)))
            .map(|(k, i)| w[k * 4 + i].abs())
            .fold(0.0, f32::max);
        assert!(
            (own - 1.0).abs() < 1e-6 && others == 0.0,
            "animation {j}: {own} {others}"
        );
    }
}

fn panel_ink(p: &tiny_skia::Pixmap, x0: u32, y0: u32, w: u32, h: u32) -> (usize, Vec<u8>) {
    let mut ink = 0;
    let mut pixels = Vec::new();
    for y in y0 + 22..y0 + h {
        for x in x0..x0 + w {
            let c = p.pixel(x, y).unwrap();
            pixels.extend([c.red(), c.green(), c.blue()]);
            if c.red() < 200 || c.green() < 200 || c.blue() < 200 {
                ink += 1;
            }
        }
    }
    (ink, pixels)
}

#[test]
fn png_sheet_has_one_distinct_panel_per_mode_and_exports_are_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let base_path = beam_base(dir.path());
    let outs = |tag: &str| {
        let (v, g, p) = (
            dir.path().join(format!("{tag}.vtu")),
            dir.path().join(format!("{tag}.glb")),
            dir.path().join(format!("{tag}.png")),
        );
        let o = run(&[
            "export",
            s(&base_path),
            "--vtu",
            s(&v),
            "--gltf",
            s(&g),
            "--png",
            s(&p),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        [v, g, p].map(|f| std::fs::read(f).unwrap())
    };
    let a = outs("a");
    let b = outs("b");
    assert!(a == b, "two exports of the same base differ");
    validate_gltf(&dir.path().join("a.glb"));
    let png = tiny_skia::Pixmap::decode_png(&a[2]).unwrap();
    // 6 modes in 4 columns: 2 rows of 320 × 240 panels between the title and legend bands.
    let (title, legend) = (
        modal_bake::export::SHEET_TITLE_H as u32,
        modal_bake::export::SHEET_LEGEND_H as u32,
    );
    assert_eq!((png.width(), png.height()), (1280, title + 480 + legend));
    let mut panels = Vec::new();
    for k in 0..8u32 {
        let (ink, px) = panel_ink(&png, (k % 4) * 320 + 1, title + (k / 4) * 240 + 1, 318, 217);
        if k < 6 {
            // The beam fills a good part of its panel...
            assert!(ink > 318 * 217 / 50, "panel {k}: {ink} coloured pixels");
            panels.push(px);
        } else {
            // ...and the two panels past the last mode stay blank.
            assert_eq!(ink, 0, "panel {k} should be empty");
        }
    }
    for i in 0..panels.len() {
        for j in i + 1..panels.len() {
            assert!(
                panels[i] != panels[j],
                "modes {i} and {j} render identically"
            );
        }
    }
}

#[test]
fn bad_export_options_fail_with_a_clear_message_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let base_path = beam_base(dir.path());
    let glb = dir.path().join("x.glb");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["export", s(&base_path)], "nothing to write"),
        (
            vec!["export", s(&base_path), "--gltf", s(&glb), "--modes", "0"],
            "at least 1",
        ),
        (
            vec!["export", s(&base_path), "--gltf", s(&glb), "--modes", "99"],
            "only 6 modes",
        ),
        (
            vec!["export", s(&base_path), "--gltf", s(&glb), "--scale", "-1"],
            "scale",
        ),
        (
            vec!["export", "/nonexistent/x.modes", "--gltf", s(&glb)],
            "/nonexistent/x.modes",
        ),
        (
            vec!["export", s(&base_path), "--png", "/nonexistent/dir/x.png"],
            "/nonexistent/dir/x.png",
        ),
    ];
    for (args, needle) in cases {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "one-line message: {err}");
    }
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        left,
        vec!["beam.modes".to_string()],
        "files left behind: {left:?}"
    );
}

/// A second-order base exports its 6-node triangles as four linear ones each: the VTU holds
/// the corners then one point per mid-edge node, at the edge's midpoint, with the stored
/// edge rows bit-exact as its displacements; the GLB carries the same vertices (its morph
/// targets are the scaled rows) and passes the Khronos glTF-Validator.
#[test]
#[cfg_attr(
    windows,
    ignore = "needs python3 with meshio or vtk; the Python cross-checks run on Linux"
)]
fn p2_base_exports_mid_edge_points_with_their_rows() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = common::gltf_check::repo_root().join("data/meshes/fv32_p2_h1.msh");
    let base_path = dir.path().join("p2.modes");
    let o = run(&["bake", s(&mesh), "-o", s(&base_path), "--modes", "3"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let base = ModesFile::read(&base_path).unwrap();
    let q = base.quadratic.as_ref().expect("a second-order base");
    let (ns, ne, m) = (base.num_surface_vertices(), q.edges.len(), base.num_modes());
    let edge_row =
        |e: usize, j: usize| -> [f64; 3] { std::array::from_fn(|a| q.modes[(e * 3 + a) * m + j]) };
    let (vtu, glb_path) = (dir.path().join("p2.vtu"), dir.path().join("p2.glb"));
    let o = run(&[
        "export",
        s(&base_path),
        "--vtu",
        s(&vtu),
        "--gltf",
        s(&glb_path),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    validate_gltf(&glb_path);
    let glb = Glb::read(&glb_path);
    let diag = glb.extras()["dcr"]["diagonal_m"].as_f64().unwrap();
    let prim = &glb.root.meshes[0].primitives[0];
    let pos = glb.floats(
        prim.attributes
            .get(&gltf::json::validation::Checked::Valid(
                gltf::json::mesh::Semantic::Positions,
            ))
            .unwrap()
            .value(),
    );
    assert_eq!(pos.len(), 3 * (ns + ne));
    let targets = prim.targets.as_ref().unwrap();
    for (j, t) in targets.iter().enumerate() {
        let a = glb.extras()["dcr"]["modes"][j]["modal_coordinate"]
            .as_f64()
            .unwrap();
        let d = glb.floats(t.positions.unwrap().value());
        for e in 0..ne {
            let u = edge_row(e, j);
            for k in 0..3 {
                let got = d[3 * (ns + e) + k] as f64;
                assert!((got - a * u[k]).abs() <= 1e-6 * diag, "mode {j} edge {e}");
            }
        }
    }

    let body = r#"
m = meshio.read(sys.argv[1])
print(json.dumps({"points": m.points.tolist(),
                  "triangles": [c.data.tolist() for c in m.cells if c.type == "triangle"][0],
                  "point_data": {k: v.tolist() for k, v in m.point_data.items()}}))
"#;
    let Some(text) = meshio_gate::run_with_meshio(body, &[vtu.as_os_str()]) else {
        return;
    };
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let pts = v["points"].as_array().unwrap();
    assert_eq!(pts.len(), ns + ne);
    assert_eq!(
        v["triangles"].as_array().unwrap().len(),
        4 * base.surface_triangles.len()
    );
    let freqs = base.frequencies_hz();
    let pd = v["point_data"].as_object().unwrap();
    for (e, &[a, b]) in q.edges.iter().enumerate() {
        let (pa, pb) = (
            base.surface_vertices[a as usize],
            base.surface_vertices[b as usize],
        );
        for k in 0..3 {
            assert_eq!(
                pts[ns + e][k].as_f64().unwrap(),
                0.5 * (pa[k] + pb[k]),
                "edge {e}"
            );
        }
        assert_eq!(
            pd["surface_to_volume"][ns + e].as_u64().unwrap(),
            q.edge_to_volume[e] as u64
        );
        for j in 0..m {
            let row = &pd[&mode_label(j, freqs[j])][ns + e];
            let u = edge_row(e, j);
            for k in 0..3 {
                assert_eq!(row[k].as_f64().unwrap(), u[k], "mode {j} edge {e}");
            }
        }
    }
    // Corners keep their rows.
    for vtx in 0..ns {
        let row = &pd[&mode_label(0, freqs[0])][vtx];
        let u = mode(&base, vtx, 0);
        for k in 0..3 {
            assert_eq!(row[k].as_f64().unwrap(), u[k]);
        }
    }
}
