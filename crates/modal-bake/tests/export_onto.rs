//! `modal-bake export --gltf --onto ASSET`: the morph targets live on the asset's own vertices
//! (its count and file order, unused vertices included), asset vertices that are nodes of the
//! base reproduce the base's nodal modes, points between nodes get the base's own
//! finite-element interpolation (linear, or quadratic on a second-order base), `--units`
//! applies the bake's scaling, the file passes the Khronos glTF-Validator, and bad assets fail
//! with the file and line and nothing written.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::gltf_check::{validate_gltf, Glb};
use dcr_runtime::format::ModesFile;
use gltf::json::{mesh::Semantic, validation::Checked};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .args(args)
        .output()
        .expect("modal-bake runs")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn bake(dir: &Path, mesh: &str, extra: &[&str]) -> PathBuf {
    let mesh = common::gltf_check::repo_root().join(mesh);
    let out = dir.join("base.modes");
    let mut args = vec!["bake", s(&mesh), "-o", s(&out)];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

fn row(rows: &[f64], m: usize, v: usize, j: usize) -> [f64; 3] {
    std::array::from_fn(|a| rows[(v * 3 + a) * m + j])
}

/// An OBJ with `vertices` (× `factor`, written in shortest round-trip form) and triangles.
fn write_obj(path: &Path, vertices: &[[f64; 3]], tris: &[[u32; 3]], factor: f64) {
    let mut t = String::from("# test asset\n");
    for p in vertices {
        writeln!(t, "v {} {} {}", p[0] * factor, p[1] * factor, p[2] * factor).unwrap();
    }
    for f in tris {
        writeln!(t, "f {}/1/1 {}//2 {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
    }
    std::fs::write(path, t).unwrap();
}

/// Per mode, per vertex displacements (m).
type Targets = Vec<Vec<[f64; 3]>>;

/// Vertex count, morph targets, modal coordinates and target names of an --onto GLB.
fn targets(glb: &Glb) -> (usize, Targets, Vec<f64>, Vec<String>) {
    let prim = &glb.root.meshes[0].primitives[0];
    let pos = glb.floats(
        prim.attributes
            .get(&Checked::Valid(Semantic::Positions))
            .unwrap()
            .value(),
    );
    let ex = glb.extras();
    let mut d = Vec::new();
    let mut a = Vec::new();
    for (j, t) in prim.targets.as_ref().unwrap().iter().enumerate() {
        let f = glb.floats(t.positions.unwrap().value());
        d.push(
            f.chunks(3)
                .map(|c| [c[0] as f64, c[1] as f64, c[2] as f64])
                .collect(),
        );
        a.push(ex["dcr"]["modes"][j]["modal_coordinate"].as_f64().unwrap());
    }
    let mesh_extras: serde_json::Value =
        serde_json::from_str(glb.root.meshes[0].extras.as_ref().unwrap().get()).unwrap();
    let names = mesh_extras["targetNames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap().to_string())
        .collect();
    (pos.len() / 3, d, a, names)
}

/// The beam's own surface as an asset, its vertices in reverse order, plus the midpoint of
/// one edge and an unused vertex: the GLB has every asset vertex in file order; the base's
/// vertices carry a_j U_j exactly (to f32), the midpoint the mean of the edge's ends, and the
/// fixed end's vertices are listed as fixed.
#[test]
fn onto_keeps_the_assets_vertices_and_reproduces_the_nodal_modes() {
    let dir = tempfile::tempdir().unwrap();
    let base_path = bake(
        dir.path(),
        "data/meshes/beam.msh",
        &["--fixed", "clamp", "--modes", "5"],
    );
    let base = ModesFile::read(&base_path).unwrap();
    let (ns, m) = (base.num_surface_vertices(), base.num_modes());
    // Asset vertex k is base vertex ns-1-k; then the edge midpoint; then an unused vertex.
    let mut verts: Vec<[f64; 3]> = (0..ns).rev().map(|v| base.surface_vertices[v]).collect();
    let [e0, e1, _] = base.surface_triangles[0];
    let (p0, p1) = (
        base.surface_vertices[e0 as usize],
        base.surface_vertices[e1 as usize],
    );
    verts.push(std::array::from_fn(|a| 0.5 * (p0[a] + p1[a])));
    verts.push([0.5, 0.0, 0.05]); // on the face y = 0, used by no triangle
    let flip = |v: u32| ns as u32 - 1 - v;
    let tris: Vec<[u32; 3]> = base.surface_triangles.iter().map(|t| t.map(flip)).collect();
    let asset = dir.path().join("beam_asset.obj");
    write_obj(&asset, &verts, &tris, 1.0);
    let glb_path = dir.path().join("onto.glb");
    let o = run(&[
        "export",
        s(&base_path),
        "--gltf",
        s(&glb_path),
        "--onto",
        s(&asset),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("largest distance"), "{err}");
    assert!(!err.contains("warning"), "{err}");
    validate_gltf(&glb_path);

    let glb = Glb::read(&glb_path);
    let (nv, d, a, names) = targets(&glb);
    assert_eq!(nv, verts.len(), "vertex count = the asset's");
    assert_eq!(d.len(), m);
    let freqs = base.frequencies_hz();
    let diag = glb.extras()["dcr"]["diagonal_m"].as_f64().unwrap();
    for j in 0..m {
        assert_eq!(names[j], modal_bake::export::mode_title(j, freqs[j]));
        assert!(names[j].starts_with(&format!("mode {} — ", j + 1)));
        for k in 0..ns {
            let u = row(&base.modes, m, ns - 1 - k, j);
            for c in 0..3 {
                assert!(
                    (d[j][k][c] - a[j] * u[c]).abs() <= 1e-6 * diag,
                    "mode {j} asset vertex {k}: {} vs {}",
                    d[j][k][c],
                    a[j] * u[c]
                );
            }
        }
        let (u0, u1) = (
            row(&base.modes, m, e0 as usize, j),
            row(&base.modes, m, e1 as usize, j),
        );
        for c in 0..3 {
            let want = a[j] * 0.5 * (u0[c] + u1[c]);
            assert!(
                (d[j][ns][c] - want).abs() <= 1e-6 * diag,
                "mode {j} midpoint"
            );
        }
    }
    let ex = glb.extras();
    assert_eq!(ex["dcr"]["kind"], "modes_onto");
    assert!(ex["dcr"]["max_mapping_distance_m"].as_f64().unwrap() < 1e-9);
    // The clamped end (x = 0) is held: its asset vertices are listed as fixed and do not move.
    let fixed: Vec<usize> = ex["dcr"]["fixed_vertices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    assert!(!fixed.is_empty());
    for &v in &fixed {
        assert!(
            verts[v][0].abs() < 1e-9,
            "fixed vertex {v} at {:?}",
            verts[v]
        );
        assert!(d.iter().all(|dj| dj[v] == [0.0; 3]));
    }
}

/// A second-order base: asset points at mid-edge nodes take the stored mid-edge rows (the
/// quadratic shape functions, not the mean of the corners); an asset in millimetres with
/// `--units mm` maps like the metre one, and without it is warned about.
#[test]
fn onto_p2_base_interpolates_quadratically_and_honours_units() {
    let dir = tempfile::tempdir().unwrap();
    let base_path = bake(dir.path(), "data/meshes/fv32_p2_h1.msh", &["--modes", "3"]);
    let base = ModesFile::read(&base_path).unwrap();
    let q = base.quadratic.as_ref().expect("a second-order base");
    let (ns, m) = (base.num_surface_vertices(), base.num_modes());
    let mut verts = base.surface_vertices.clone();
    for &[x, y] in &q.edges {
        let (p, r) = (
            base.surface_vertices[x as usize],
            base.surface_vertices[y as usize],
        );
        verts.push(std::array::from_fn(|c| 0.5 * (p[c] + r[c])));
    }
    let asset = dir.path().join("p2.obj");
    write_obj(&asset, &verts, &base.surface_triangles, 1.0);
    let glb_path = dir.path().join("p2.glb");
    let o = run(&[
        "export",
        s(&base_path),
        "--gltf",
        s(&glb_path),
        "--onto",
        s(&asset),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    validate_gltf(&glb_path);
    let glb = Glb::read(&glb_path);
    let (nv, d, a, _) = targets(&glb);
    assert_eq!(nv, verts.len());
    let diag = glb.extras()["dcr"]["diagonal_m"].as_f64().unwrap();
    let mut differs_from_mean = 0.0f64;
    for j in 0..m {
        for (e, &[x, y]) in q.edges.iter().enumerate() {
            let u = row(&q.modes, m, e, j);
            let (ux, uy) = (
                row(&base.modes, m, x as usize, j),
                row(&base.modes, m, y as usize, j),
            );
            for c in 0..3 {
                let got = d[j][ns + e][c];
                assert!(
                    (got - a[j] * u[c]).abs() <= 2e-6 * diag,
                    "mode {j} edge {e}: {got} vs {}",
                    a[j] * u[c]
                );
                differs_from_mean =
                    differs_from_mean.max((a[j] * (u[c] - 0.5 * (ux[c] + uy[c]))).abs());
            }
        }
    }
    // The check has teeth: the mid-edge rows are not the mean of the corners.
    assert!(differs_from_mean > 1e-4 * diag, "{differs_from_mean}");

    // The same asset in millimetres.
    let mm = dir.path().join("p2_mm.obj");
    write_obj(&mm, &verts, &base.surface_triangles, 1000.0);
    let glb_mm = dir.path().join("p2_mm.glb");
    let o = run(&[
        "export",
        s(&base_path),
        "--gltf",
        s(&glb_mm),
        "--onto",
        s(&mm),
        "--units",
        "mm",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (_, d_mm, a_mm, _) = targets(&Glb::read(&glb_mm));
    for j in 0..m {
        assert!((a_mm[j] - a[j]).abs() <= 1e-9 * a[j].abs());
        for v in 0..nv {
            for c in 0..3 {
                assert!((d_mm[j][v][c] - d[j][v][c]).abs() <= 1e-6 * diag);
            }
        }
    }
    let o = run(&[
        "export",
        s(&base_path),
        "--gltf",
        s(&glb_mm),
        "--onto",
        s(&mm),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning") && err.contains("--units"),
        "no unit warning: {err}"
    );
}

/// Bad assets and options: one-line errors naming the file (and OBJ line), no output left.
#[test]
fn onto_bad_assets_fail_with_file_and_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let base_path = bake(
        dir.path(),
        "data/meshes/beam.msh",
        &["--fixed", "clamp", "--modes", "2"],
    );
    let bad_index = dir.path().join("bad_index.obj");
    std::fs::write(&bad_index, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    let bad_number = dir.path().join("bad_number.obj");
    std::fs::write(&bad_number, "v 0 0 0\nv 1 zero 0\n").unwrap();
    let glb = dir.path().join("out.glb");
    let png = dir.path().join("out.png");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "export",
                s(&base_path),
                "--gltf",
                s(&glb),
                "--onto",
                s(&bad_index),
            ],
            "bad_index.obj:4",
        ),
        (
            vec![
                "export",
                s(&base_path),
                "--gltf",
                s(&glb),
                "--onto",
                s(&bad_number),
            ],
            "bad_number.obj:2",
        ),
        (
            vec![
                "export",
                s(&base_path),
                "--gltf",
                s(&glb),
                "--onto",
                "/nonexistent/a.obj",
            ],
            "/nonexistent/a.obj",
        ),
        (
            vec![
                "export",
                s(&base_path),
                "--png",
                s(&png),
                "--onto",
                s(&bad_index),
            ],
            "--gltf",
        ),
    ];
    for (args, needle) in cases {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert!(!glb.exists() && !png.exists(), "an output was written");
}
