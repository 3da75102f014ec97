//! Surface assets: the OBJ / STL / PLY readers agree, defects are refused with their position,
//! and a real asset made by someone else (gmsh's tutorial STL `t13_data.stl`, shipped in the
//! PyPI `gmsh` package, GPL-2.0-or-later) goes through `mesh` → `bake` → `probe` with the real
//! gmsh, plus a copy with a hole that `--mesher gmsh` refuses with the hole's position and the fix.
//!
//! Tests that need gmsh skip with a message when it is missing, unless `DCR_REQUIRE_GMSH=1`
//! (set by `.ci/run`), where they fail.
//!
//! `cargo test --release -p modal-bake --test assets`

use std::path::{Path, PathBuf};
use std::process::Command;

use sha2::Digest;

use modal_bake::mesh::gmsh::{tetrahedralize, GmshParams};
use modal_bake::mesh::surface::{read_surface_bytes, SurfaceError, SurfaceMesh};
use modal_bake::mesh::DEFAULT_STRAIGHT_REL_TOL;

#[path = "common/check_args.rs"]
mod check_args;
use check_args::check_args;

#[path = "common/gmsh_gate.rs"]
mod gmsh_gate;
use gmsh_gate::have_gmsh;

#[path = "common/unit_cube.rs"]
mod unit_cube;
use unit_cube::{cube_tris, CUBE_Q, CUBE_V};

fn obj(v: &[[f64; 3]], quads: bool) -> Vec<u8> {
    let mut s = String::from("# cube\no cube\n");
    for p in v {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    if quads {
        for q in CUBE_Q {
            s += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
        }
    } else {
        for t in cube_tris() {
            s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
    }
    s.into_bytes()
}

fn stl_ascii(v: &[[f64; 3]], tris: &[[usize; 3]]) -> Vec<u8> {
    let mut s = String::from("solid cube\n");
    for t in tris {
        s += "facet normal 0 0 0\nouter loop\n";
        for &i in t {
            s += &format!("vertex {} {} {}\n", v[i][0], v[i][1], v[i][2]);
        }
        s += "endloop\nendfacet\n";
    }
    s += "endsolid cube\n";
    s.into_bytes()
}

fn stl_binary(v: &[[f64; 3]], tris: &[[usize; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for &i in t {
            for k in 0..3 {
                b.extend_from_slice(&(v[i][k] as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

fn ply_ascii(v: &[[f64; 3]]) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face 6\nproperty list uchar int vertex_indices\nend_header\n",
        v.len()
    );
    for p in v {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for q in CUBE_Q {
        s += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    s.into_bytes()
}

fn ply_binary(v: &[[f64; 3]]) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face 12\nproperty list uchar uint vertex_indices\nend_header\n",
        v.len()
    )
    .into_bytes();
    for p in v {
        for x in p {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    for t in cube_tris() {
        b.push(3);
        for i in t {
            b.extend_from_slice(&(i as u32).to_le_bytes());
        }
    }
    b
}

/// Sorted triangles as position triples: equal for equal surfaces whatever the vertex order.
fn canonical(s: &SurfaceMesh) -> Vec<[[u64; 3]; 3]> {
    let mut out: Vec<[[u64; 3]; 3]> = s
        .triangles
        .iter()
        .map(|t| {
            let mut c = t.map(|v| s.vertices[v].map(f64::to_bits));
            let r = (0..3).min_by_key(|&k| c[k]).unwrap();
            c.rotate_left(r);
            c
        })
        .collect();
    out.sort_unstable();
    out
}

/// Every reader gives the same closed cube (12 triangles, 8 welded vertices, volume 1 m³).
#[test]
fn readers_agree_on_a_cube() {
    let v = CUBE_V;
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("cube.obj", obj(&v, false)),
        ("quads.OBJ", obj(&v, true)),
        ("cube.stl", stl_ascii(&v, &cube_tris())),
        ("cube_bin.stl", stl_binary(&v, &cube_tris())),
        ("cube.ply", ply_ascii(&v)),
        ("cube_bin.ply", ply_binary(&v)),
    ];
    let mut first: Option<Vec<[[u64; 3]; 3]>> = None;
    for (name, bytes) in files {
        let mut s = read_surface_bytes(&bytes, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((s.vertices.len(), s.triangles.len()), (8, 12), "{name}");
        let info = s.check_closed(name).unwrap();
        assert!(
            (info.volume_m3 - 1.0).abs() < 1e-15 && !info.flipped,
            "{name}"
        );
        let c = canonical(&s);
        match &first {
            None => first = Some(c),
            Some(f) => assert_eq!(f, &c, "{name} differs"),
        }
    }
}

/// Defects are refused with what and where: a hole (open edge, both ends in m), a
/// non-manifold vertex, a flipped triangle, two shells; inward triangles are reversed; a
/// binary STL whose count lies is refused before allocation.
#[test]
fn surface_defects_are_refused_with_positions() {
    let v = CUBE_V;
    let mut tris = cube_tris();
    let hole = tris.remove(4); // a triangle of the y = 0 face
    let err = SurfaceMesh {
        vertices: v.to_vec(),
        triangles: tris.clone(),
    }
    .check_closed("hole.stl")
    .unwrap_err();
    let SurfaceError::OpenEdge {
        a, b, open_edges, ..
    } = &err
    else {
        panic!("{err}")
    };
    assert_eq!(*open_edges, 3);
    assert!(
        hole.iter().any(|&i| v[i] == *a) && hole.iter().any(|&i| v[i] == *b),
        "{err}"
    );
    assert!(err.to_string().contains("hole.stl") && err.to_string().contains("open edge from ("));

    let mut flipped = cube_tris();
    flipped[3].swap(1, 2);
    let err = SurfaceMesh {
        vertices: v.to_vec(),
        triangles: flipped,
    }
    .check_closed("f.obj")
    .unwrap_err();
    assert!(matches!(err, SurfaceError::Orientation { .. }), "{err}");

    // Two cubes touching at one corner: a non-manifold vertex at (1, 1, 1).
    let mut verts = v.to_vec();
    verts.extend(v.iter().map(|p| p.map(|x| x + 1.0)));
    let mut two = cube_tris();
    two.extend(
        cube_tris()
            .iter()
            .map(|t| t.map(|i| if i == 0 { 6 } else { i + 8 })),
    );
    let mut s = SurfaceMesh::welded(verts.clone(), two);
    let err = s.check_closed("touch.ply").unwrap_err();
    let SurfaceError::NonManifoldVertex { at, fans, .. } = &err else {
        panic!("{err}")
    };
    assert_eq!((*at, *fans), ([1.0, 1.0, 1.0], 2));

    // Two separate cubes.
    let mut apart = cube_tris();
    apart.extend(cube_tris().iter().map(|t| t.map(|i| i + 8)));
    let far: Vec<[f64; 3]> = v
        .iter()
        .chain(v.iter())
        .enumerate()
        .map(|(i, p)| if i < 8 { *p } else { p.map(|x| x + 3.0) })
        .collect();
    let err = SurfaceMesh {
        vertices: far,
        triangles: apart,
    }
    .check_closed("two.stl")
    .unwrap_err();
    assert!(
        matches!(err, SurfaceError::Shells { shells: 2, .. }),
        "{err}"
    );

    let mut inward = SurfaceMesh {
        vertices: v.to_vec(),
        triangles: cube_tris().iter().map(|t| [t[0], t[2], t[1]]).collect(),
    };
    let info = inward.check_closed("in.stl").unwrap();
    assert!(info.flipped && (info.volume_m3 - 1.0).abs() < 1e-15);
    assert!(inward.signed_volume() > 0.0);

    let mut lying = stl_binary(&v, &cube_tris());
    lying[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let err = read_surface_bytes(&lying, "lie.stl").unwrap_err();
    assert!(
        err.to_string().contains("declares 4294967295 triangles"),
        "{err}"
    );
    let huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n\
                 property float x\nproperty float y\nproperty float z\nend_header\n\0\0\0\0";
    let err = read_surface_bytes(huge, "huge.ply").unwrap_err();
    assert!(err.to_string().contains("huge.ply"), "{err}");
    let err = read_surface_bytes(b"v 0 0 0\nf 1 2 3\n", "bad.obj").unwrap_err();
    assert!(err.to_string().contains("bad.obj"), "{err}");
}

/// gmsh's tutorial STL (a real asset from the PyPI `gmsh` package, coordinates in mm),
/// found beside the Python installation that has the `gmsh` module; `None` (skip) when it is
/// missing, unless `DCR_REQUIRE_GMSH=1`.
fn t13_asset(test: &str) -> Option<PathBuf> {
    let prefix = Command::new("python3")
        .args(["-c", "import sys, gmsh; print(sys.prefix)"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    let p = prefix.map(|d| Path::new(&d).join("share/doc/gmsh/tutorials/t13_data.stl"));
    match p {
        Some(p) if p.is_file() => Some(p),
        _ => {
            let msg = "the PyPI gmsh package (python3 -m pip install gmsh) and its tutorials/t13_data.stl are missing";
            if std::env::var("DCR_REQUIRE_GMSH").as_deref() == Ok("1") {
                panic!("{test}: DCR_REQUIRE_GMSH=1 but {msg}");
            }
            eprintln!("SKIPPED {test}: {msg}");
            None
        }
    }
}

/// A base's `meta.bake_params`.
fn modal_bake_base(path: &Path) -> serde_json::Value {
    dcr_runtime::format::ModesFile::read(path)
        .unwrap()
        .meta
        .bake_params
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
}

/// The real asset: `mesh --order 2` (straight-sided 10-node tets in gmsh's node order, the
/// same bytes twice), `bake` with `--fixed-below`, `probe` (a finite, non-zero response that
/// decays away from the impact); its copy with a hole is refused with the hole's position.
#[test]
fn real_asset_mesh_bake_probe_and_a_holed_copy() {
    if !have_gmsh("real_asset_mesh_bake_probe_and_a_holed_copy") {
        return;
    }
    let Some(asset) = t13_asset("real_asset_mesh_bake_probe_and_a_holed_copy") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let msh = dir.path().join("t13.msh");
    let run = |c: &mut Command| {
        let out = c.output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let mesh_args = |out: &Path| {
        let mut c = bin();
        c.arg("mesh").arg(&asset).arg("-o").arg(out);
        // One size per curvature (no thickness-aware sizing): a light mesh of the real asset,
        // the same as before thickness-aware sizing existed.
        c.args(["--units", "mm", "--size", "0.006", "--order", "2"]);
        c.arg("--no-thickness-sizing");
        c
    };
    run(&mut mesh_args(&msh));
    let again = dir.path().join("again.msh");
    run(&mut mesh_args(&again));
    assert_eq!(std::fs::read(&msh).unwrap(), std::fs::read(&again).unwrap());
    let mesh = modal_bake::mesh::read_mesh(&msh).unwrap();
    assert!(mesh.is_quadratic());
    mesh.check_straight(DEFAULT_STRAIGHT_REL_TOL).unwrap();
    mesh.check_conforming().unwrap();
    let zmin = mesh
        .nodes
        .iter()
        .map(|p| p[2])
        .fold(f64::INFINITY, f64::min);
    let zmax = mesh
        .nodes
        .iter()
        .map(|p| p[2])
        .fold(f64::NEG_INFINITY, f64::max);

    let base = dir.path().join("t13.modes");
    let below = format!("z={}", zmin + 0.05 * (zmax - zmin));
    let report = run(bin()
        .arg("bake")
        .arg(&msh)
        .arg("-o")
        .arg(&base)
        .args(["--youngs", "2e11", "--density", "7800", "--modes", "12"])
        .args(["--fixed-below", &below, "--json"]));
    let r: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert_eq!(r["order"], 2);
    let fixed = r["fixed_by"][0][1].as_u64().unwrap();
    assert!(fixed > 3 && fixed == r["fixed_nodes"].as_u64().unwrap());

    // Probe: impact at the top, contacts near and far.
    let model = dcr_runtime::ModalModel::load(&base).unwrap();
    assert!(model.is_quadratic());
    let top = model
        .base()
        .surface_vertices
        .iter()
        .copied()
        .max_by(|a, b| a[2].total_cmp(&b[2]))
        .unwrap();
    // The contact: the surface vertex nearest the top one.
    let d2 = |p: &[f64; 3]| (0..3).map(|k| (p[k] - top[k]).powi(2)).sum::<f64>();
    let near = model
        .base()
        .surface_vertices
        .iter()
        .copied()
        .filter(|p| d2(p) > 0.0)
        .min_by(|a, b| d2(a).total_cmp(&d2(b)))
        .unwrap();
    let fmt = |p: [f64; 3]| format!("{},{},{}", p[0], p[1], p[2]);
    let probe = run(bin()
        .arg("probe")
        .arg(&base)
        .args(["--impact", &fmt(top), "--impulse", "0.01", "--json"])
        .args(["--contact", &fmt(near), "--h", "0.001"]));
    let p: serde_json::Value = serde_json::from_str(&probe).unwrap();
    let peak = p["contacts"][0]["peak_displacement_m"].as_f64().unwrap();
    assert!(peak.is_finite() && peak > 0.0, "{probe}");

    // The same asset with one facet removed: refused, the open edge at the hole (m).
    let text = std::fs::read_to_string(&asset).unwrap();
    let start = text.find("facet").unwrap();
    let end = text[start..].find("endfacet").unwrap() + start + "endfacet".len();
    let removed: Vec<[f64; 3]> = text[start..end]
        .lines()
        .filter_map(|l| l.trim().strip_prefix("vertex "))
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .map(|x| x.parse::<f32>().unwrap() as f64 * 1e-3)
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let holed = dir.path().join("holed.stl");
    std::fs::write(&holed, format!("{}{}", &text[..start], &text[end..])).unwrap();
    let out = bin()
        .arg("mesh")
        .arg(&holed)
        .arg("-o")
        .arg(dir.path().join("holed.msh"))
        .args(["--units", "mm", "--mesher", "gmsh"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(!dir.path().join("holed.msh").exists());
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        err.contains("holed.stl")
            && err.contains("open edge from (")
            && err.contains("use --mesher ftetwild or --mesher auto"),
        "{err}"
    );
    // The positions printed (6 decimals, m) are corners of the removed facet.
    let printed: Vec<f64> = err
        .split("open edge from (")
        .nth(1)
        .unwrap()
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter(|s| !s.is_empty())
        .take(6)
        .map(|s| s.parse().unwrap())
        .collect();
    for end in [&printed[..3], &printed[3..6]] {
        assert!(
            removed
                .iter()
                .any(|v| (0..3).all(|k| (v[k] - end[k]).abs() < 1e-6)),
            "{end:?} is not a corner of the removed facet {removed:?}"
        );
    }
}

// Expectation: a base of a surface asset records the meshing options it was meshed with;
// `info` shows them and a stale `check` names the ones that differ (the usual cause of a
// changed geometry for an asset), while the same options find it up to date.
#[test]
fn an_asset_base_records_its_meshing_and_check_names_a_change() {
    if !have_gmsh("an_asset_base_records_its_meshing_and_check_names_a_change") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let asset = dir.path().join("cube.obj");
    std::fs::write(&asset, obj(&CUBE_V.map(|p| p.map(|x| 0.1 * x)), false)).unwrap();
    let base = dir.path().join("cube.modes");
    let run = |cmd: &str, extra: &[&str]| {
        bin()
            .arg(cmd)
            .arg(&asset)
            .args(if cmd == "bake" { vec!["-o"] } else { vec![] })
            .arg(&base)
            .args(["--modes", "4", "--material", "steel", "--order", "1"])
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run("bake", &["--size", "0.05"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let info = bin().arg("info").arg(&base).output().unwrap();
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(
        text.contains("  meshed from its surface asset with --mesher auto --size 0.05 --order 1\n"),
        "{text}"
    );
    assert_eq!(run("check", &["--size", "0.05"]).status.code(), Some(0));
    // The options `info` rebuilds from the record check it too.
    let args = check_args(&base);
    assert!(args.windows(2).any(|w| w == ["--size", "0.05"]), "{args:?}");
    let o = bin()
        .arg("check")
        .arg(&asset)
        .arg(&base)
        .args(&args)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{args:?}");
    // An unchanged asset is not meshed again: the base records its bytes, its surface, the
    // meshers' versions and this build. Other bytes of the same surface (a comment) are not
    // meshed again either; a moved vertex is meshed again and found stale; a base recorded
    // without the surface matches the same bytes only; one from another build is meshed again.
    let json = |extra: &[&str]| {
        let mut e = vec!["--size", "0.05", "--json"];
        e.extend_from_slice(extra);
        let o = run("check", &e);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        (
            v["up_to_date"].clone(),
            v["meshed_again"].clone(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (fresh, again, err) = json(&[]);
    assert_eq!((fresh, again), (true.into(), false.into()), "{err}");
    assert!(!err.contains("meshing"), "{err}");
    let key = &modal_bake_base(&base)["asset_key"];
    assert_eq!(key["build"], modal_bake::mesh::BUILD_HASH);
    assert!(
        key["meshers"]["gmsh"].is_string()
            && key["sha256"].as_str().unwrap().starts_with("sha256:"),
        "{key}"
    );
    let (_, _, err) = json(&["--youngs", "3e9"]);
    assert!(
        err.contains("meshing"),
        "a stale base's detail comes from meshing: {err}"
    );
    let mut text = std::fs::read_to_string(&asset).unwrap();
    text += "# the same surface\n";
    std::fs::write(&asset, &text).unwrap();
    let (fresh, again, err) = json(&[]);
    assert_eq!(
        (fresh, again),
        (true.into(), false.into()),
        "a comment leaves the surface: {err}"
    );
    let moved = obj(&CUBE_V.map(|p| p.map(|x| 0.1001 * x)), false);
    std::fs::write(&asset, &moved).unwrap();
    let (fresh, again, err) = json(&[]);
    assert_eq!(
        (fresh, again),
        (false.into(), true.into()),
        "moved vertices are meshed again: {err}"
    );
    std::fs::write(&asset, &text).unwrap();
    let mut b = dcr_runtime::format::ModesFile::read(&base).unwrap();
    let surface = b.meta.bake_params["asset_key"]
        .as_object_mut()
        .unwrap()
        .remove("surface")
        .unwrap();
    assert!(
        surface.as_str().unwrap().starts_with("sha256:"),
        "{surface}"
    );
    b.write_atomic(&base).unwrap();
    let (fresh, again, err) = json(&[]);
    assert_eq!(
        (fresh, again),
        (true.into(), true.into()),
        "without a recorded surface other bytes are meshed again: {err}"
    );
    b.meta.bake_params["asset_key"]["bytes"] = (text.len() as u64).into();
    b.meta.bake_params["asset_key"]["sha256"] =
        format!("sha256:{:x}", sha2::Sha256::digest(text.as_bytes())).into();
    b.write_atomic(&base).unwrap();
    assert_eq!(
        json(&[]).1,
        serde_json::json!(false),
        "the key now names these bytes"
    );
    b.meta.bake_params["asset_key"]["build"] = "sha256:another build".into();
    b.write_atomic(&base).unwrap();
    assert_eq!(
        json(&[]).1,
        serde_json::json!(true),
        "another build meshes again"
    );
    let o = run("check", &["--size", "0.04", "--uniform-size"]);
    assert_eq!(o.status.code(), Some(1));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("stale (geometry changed): the base's asset was meshed with `--mesher auto --size 0.05 --order 1`, this with `--mesher auto --size 0.04 --order 1 --uniform-size`: give the bake's meshing options; "),
        "{text}"
    );
}

// Expectation: `batch` skips an unchanged asset's base without meshing it again, and
// re-bakes it (meshing) when an option changes.
#[test]
fn batch_skips_an_unchanged_asset_without_meshing() {
    if !have_gmsh("batch_skips_an_unchanged_asset_without_meshing") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let asset = dir.path().join("cube.obj");
    std::fs::write(&asset, obj(&CUBE_V.map(|p| p.map(|x| 0.1 * x)), false)).unwrap();
    let manifest = dir.path().join("m.json");
    let write = |modes: u32| {
        let m = serde_json::json!({"version": 1, "entries": [
            {"mesh": asset, "out": "cube.modes",
             "options": {"modes": modes, "material": "steel", "size": 0.05, "order": 1}}]});
        std::fs::write(&manifest, m.to_string()).unwrap();
    };
    let batch = || {
        let o = bin()
            .arg("batch")
            .arg(&manifest)
            .arg("--json")
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let e = &v["entries"][0];
        (
            e["action"].as_str().unwrap().to_string(),
            String::from_utf8_lossy(&o.stderr).contains("not meshed again"),
        )
    };
    write(4);
    assert_eq!(batch(), ("baked".to_string(), false));
    assert_eq!(batch(), ("skipped".to_string(), true));
    write(5);
    assert_eq!(batch(), ("baked".to_string(), false));
}

/// A missing gmsh is an error that says how to install it.
#[test]
fn missing_gmsh_says_how_to_install() {
    let mut s = SurfaceMesh {
        vertices: CUBE_V.to_vec(),
        triangles: cube_tris(),
    };
    s.check_closed("cube.stl").unwrap();
    let params = GmshParams {
        gmsh: Some("/nonexistent/gmsh".into()),
        ..Default::default()
    };
    let err = tetrahedralize(&s, &params, "cube.stl")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("pip install gmsh") && err.contains("apt-get install gmsh"),
        "{err}"
    );
}
