//! The meshing chain: surface inspection on constructed defects (exact counts and positions),
//! the backend `--mesher auto` picks and why, fTetWild on an open surface (the solid made and
//! its distance to the asset), a forced gmsh refused on a defective surface with the fix,
//! reproducible bytes, range checks before any mesher, the time limit and the clean-up of work
//! folders (also on SIGTERM).
//!
//! Tests that need fTetWild (PyPI `pytetwild`) or gmsh skip with a message when it is missing,
//! unless `DCR_REQUIRE_FTETWILD=1` / `DCR_REQUIRE_GMSH=1` (set by `.ci/run`), where they fail.
//!
//! `cargo test --release -p modal-bake --test meshers`

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use modal_bake::mesh::surface::{inspect_surface, DefectKind, SurfaceMesh};

#[path = "common/gmsh_gate.rs"]
mod gmsh_gate;
use gmsh_gate::have_gmsh;

/// Positions and triangles of one part.
type Part = (Vec<[f64; 3]>, Vec<[usize; 3]>);

fn cube(offset: [f64; 3], side: f64) -> Part {
    let mut v = Vec::new();
    for k in 0..8 {
        v.push([
            offset[0] + side * (k & 1) as f64,
            offset[1] + side * ((k >> 1) & 1) as f64,
            offset[2] + side * ((k >> 2) & 1) as f64,
        ]);
    }
    // Outward quads (corner k has x = bit 0, y = bit 1, z = bit 2).
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (v, t)
}

/// Several parts in one surface, coincident positions welded (as the readers do).
fn surface(parts: &[Part]) -> SurfaceMesh {
    let mut v = Vec::new();
    let mut t = Vec::new();
    for (pv, pt) in parts {
        let base = v.len();
        v.extend_from_slice(pv);
        t.extend(pt.iter().map(|tri| tri.map(|i| i + base)));
    }
    SurfaceMesh::welded(v, t)
}

fn obj_text(s: &SurfaceMesh) -> String {
    let mut o = String::new();
    for p in &s.vertices {
        o += &format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]);
    }
    for t in &s.triangles {
        o += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    o
}

fn write_obj(dir: &Path, name: &str, s: &SurfaceMesh) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, obj_text(s)).unwrap();
    p
}

/// A tetrahedron and a second one whose apex pokes through the first one's bottom face: the
/// three side faces of the second cross that face, nothing else meets.
fn pierced_tet() -> SurfaceMesh {
    let t1 = (
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    let t2 = (
        vec![
            [0.2, 0.2, 0.1],
            [0.1, 0.1, -0.5],
            [0.4, 0.1, -0.5],
            [0.1, 0.4, -0.5],
        ],
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]],
    );
    surface(&[t1, t2])
}

#[test]
fn inspection_counts_constructed_defects() {
    // Clean.
    let clean = surface(&[cube([0.0; 3], 1.0)]);
    let i = inspect_surface(&clean);
    assert!(i.is_solid(), "{}", i.summary());
    assert_eq!((i.vertices, i.triangles, i.shells), (8, 12, 1));

    // Open: one triangle removed → its three edges are open.
    let (v, mut t) = cube([0.0; 3], 1.0);
    let removed = t.remove(0);
    let open = surface(&[(v.clone(), t)]);
    let i = inspect_surface(&open);
    assert_eq!(i.open_edges, 3);
    assert_eq!(
        (
            i.non_manifold_edges,
            i.non_manifold_vertices,
            i.inconsistent_edges,
            i.self_intersections,
            i.shells
        ),
        (0, 0, 0, 0, 1)
    );
    for d in i.examples.iter().filter(|d| d.kind == DefectKind::OpenEdge) {
        // The midpoint of an edge of the removed triangle.
        let on_removed = (0..3).any(|k| {
            let (a, b) = (v[removed[k]], v[removed[(k + 1) % 3]]);
            (0..3).all(|c| (0.5 * (a[c] + b[c]) - d.at[c]).abs() < 1e-15)
        });
        assert!(on_removed, "{d}");
    }

    // Non-manifold edge: a fin on the cube's edge (0,0,0)–(1,0,0).
    let fin = (
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, -1.0, -1.0]],
        vec![[0, 1, 2]],
    );
    let i = inspect_surface(&surface(&[cube([0.0; 3], 1.0), fin]));
    assert_eq!(i.non_manifold_edges, 1);
    assert_eq!(i.open_edges, 2);
    assert_eq!(i.non_manifold_vertices, 0);
    let d = i
        .examples
        .iter()
        .find(|d| d.kind == DefectKind::NonManifoldEdge)
        .unwrap();
    assert_eq!(d.at, [0.5, 0.0, 0.0]);

    // Non-manifold vertex: two cubes touching at the corner (1, 1, 1).
    let touching = surface(&[cube([0.0; 3], 1.0), cube([1.0; 3], 1.0)]);
    let i = inspect_surface(&touching);
    assert_eq!(i.non_manifold_vertices, 1);
    assert_eq!(i.shells, 2);
    assert_eq!(
        (i.open_edges, i.non_manifold_edges, i.self_intersections),
        (0, 0, 0)
    );
    let d = i
        .examples
        .iter()
        .find(|d| d.kind == DefectKind::NonManifoldVertex)
        .unwrap();
    assert_eq!(d.at, [1.0, 1.0, 1.0]);

    // Self-intersection: three triangle pairs, located on the pierced face z = 0.
    let i = inspect_surface(&pierced_tet());
    assert_eq!(i.self_intersections, 3);
    assert_eq!(i.shells, 2);
    assert_eq!((i.open_edges, i.non_manifold_vertices), (0, 0));
    for d in i
        .examples
        .iter()
        .filter(|d| d.kind == DefectKind::SelfIntersection)
    {
        assert!(
            d.at[2].abs() < 1e-12 && d.at[0] > 0.1 && d.at[1] > 0.1,
            "{d}"
        );
    }

    // Inconsistent orientation: one triangle reversed → its three edges.
    let (v, mut t) = cube([0.0; 3], 1.0);
    t[5].swap(1, 2);
    let i = inspect_surface(&surface(&[(v, t)]));
    assert_eq!(i.inconsistent_edges, 3);
    assert_eq!((i.open_edges, i.shells), (0, 1));

    // Two shells, each clean.
    let i = inspect_surface(&surface(&[cube([0.0; 3], 1.0), cube([3.0; 3], 1.0)]));
    assert_eq!(i.shells, 2);
    assert!(!i.is_solid());
    assert_eq!(i.summary(), "2 shells");
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
}

fn have_ftetwild(test: &str) -> bool {
    match modal_bake::mesh::ftetwild::ftetwild_version(None) {
        Ok(_) => true,
        Err(e) => {
            if std::env::var("DCR_REQUIRE_FTETWILD").as_deref() == Ok("1") {
                panic!("{test}: DCR_REQUIRE_FTETWILD=1 but {e}");
            }
            eprintln!("SKIPPED {test}: {e}");
            false
        }
    }
}

fn json_of(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// A 0.2 m cube without its top face: an open box with 4 open edges.
fn open_box() -> SurfaceMesh {
    let (v, t) = cube([0.0; 3], 0.2);
    // Quads are (bottom, top, ...): the top's two triangles are 2 and 3.
    let t: Vec<[usize; 3]> = t
        .into_iter()
        .enumerate()
        .filter(|(i, _)| !matches!(i, 2 | 3))
        .map(|(_, t)| t)
        .collect();
    surface(&[(v, t)])
}

/// A cube with its top face removed (an open box, 0.2 m): auto picks fTetWild for the open
/// edges, says what solid it made (the winding-number filter closes the box across its top),
/// and reports the distance to the asset both ways.
#[test]
fn auto_meshes_an_open_surface_with_ftetwild_and_reports_the_distance() {
    if !have_ftetwild("auto_meshes_an_open_surface_with_ftetwild_and_reports_the_distance") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let open = open_box();
    assert_eq!(inspect_surface(&open).open_edges, 4);
    let asset = write_obj(dir.path(), "open_box.obj", &open);
    let msh = dir.path().join("open_box.msh");
    let out = bin()
        .arg("mesh")
        .arg(&asset)
        .arg("-o")
        .arg(&msh)
        .arg("--json")
        .output()
        .unwrap();
    let r = json_of(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("backend: fTetWild"), "{stderr}");
    assert_eq!(r["backend"], "ftetwild");
    let reason = r["reason"].as_str().unwrap();
    assert!(
        reason.contains("4 open edges") && reason.contains("open edge at ("),
        "{reason}"
    );
    let solid = r["report"]["solid"].as_str().unwrap();
    assert!(solid.contains("winding number"), "{solid}");
    // Distance, both sides (m) and relative to the 0.346 m diagonal: every point of the asset
    // lies within fTetWild's envelope (diagonal/1000) of the mesh boundary, up to the sampling;
    // the closure across the missing top is up to half the side (0.1 m) from the asset.
    let d = &r["distance"];
    let h = d["hausdorff_m"].as_f64().unwrap();
    let rel = d["relative"].as_f64().unwrap();
    let a2m = d["asset_to_mesh_m"].as_f64().unwrap();
    let m2a = d["mesh_to_asset_m"].as_f64().unwrap();
    let envelope = r["report"]["envelope_m"].as_f64().unwrap();
    assert!((envelope - 0.2 * 3f64.sqrt() / 1000.0).abs() < 1e-15);
    assert!(a2m > 0.0 && a2m < 2.0 * envelope, "asset→mesh {a2m} m");
    assert!(m2a > 0.09 && m2a <= 0.1 + 1e-9, "mesh→asset {m2a} m");
    assert_eq!(h, a2m.max(m2a));
    assert!((rel - h / (0.2 * 3f64.sqrt())).abs() < 1e-12);
    // The solid is the box: its volume within the envelope and the top's closure of 0.008 m³.
    let mesh = modal_bake::mesh::read_mesh(&msh).unwrap();
    let vol = mesh.volume();
    assert!((vol - 0.008).abs() < 0.0015, "volume {vol} m³");
}

/// Two separate clean cubes: auto sends them to fTetWild as one object and says how to mesh one
/// named object instead; with no located defect there is no "(first: …)".
#[test]
fn auto_says_separate_shells_are_meshed_as_one_object() {
    if !have_ftetwild("auto_says_separate_shells_are_meshed_as_one_object") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let two = surface(&[cube([0.0; 3], 0.1), cube([0.5, 0.0, 0.0], 0.1)]);
    let asset = write_obj(dir.path(), "two.obj", &two);
    let out = bin()
        .arg("mesh")
        .arg(&asset)
        .arg("-o")
        .arg(dir.path().join("two.msh"))
        .args(["--order", "1", "--json"])
        .output()
        .unwrap();
    let r = json_of(&out);
    assert_eq!(r["backend"], "ftetwild");
    let reason = r["reason"].as_str().unwrap();
    assert!(
        reason.starts_with("auto: the surface has 2 shells; gmsh needs")
            && reason.contains("meshed together as one object")
            && reason.contains("--object NAME"),
        "{reason}"
    );
}

/// `--mesher ftetwild` twice, at order 2: the same bytes; the mesh is straight-sided
/// second order; the default `auto` on a clean cube picks gmsh and says why.
#[test]
fn ftetwild_is_reproducible_at_order_2_and_auto_picks_gmsh_for_a_clean_cube() {
    let test = "ftetwild_is_reproducible_at_order_2_and_auto_picks_gmsh_for_a_clean_cube";
    if !have_ftetwild(test) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let asset = write_obj(dir.path(), "cube.obj", &surface(&[cube([0.0; 3], 0.1)]));
    let run = |name: &str, extra: &[&str]| {
        let msh = dir.path().join(name);
        let out = bin()
            .arg("mesh")
            .arg(&asset)
            .arg("-o")
            .arg(&msh)
            .arg("--json")
            .args(extra)
            .output()
            .unwrap();
        (json_of(&out), std::fs::read(&msh).unwrap())
    };
    let (r1, b1) = run("a.msh", &["--mesher", "ftetwild", "--order", "2"]);
    let (r2, b2) = run("b.msh", &["--mesher", "ftetwild", "--order", "2"]);
    assert_eq!(r1["report"]["reproducible"], true);
    assert_eq!(r1["reason"], "--mesher ftetwild");
    assert!(b1 == b2, "two fTetWild runs gave different bytes");
    assert_eq!(r1["tets"], r2["tets"]);
    let mesh = modal_bake::mesh::read_mesh(&dir.path().join("a.msh")).unwrap();
    assert!(mesh.is_quadratic());
    mesh.check_straight(modal_bake::mesh::DEFAULT_STRAIGHT_REL_TOL)
        .unwrap();
    mesh.check_conforming().unwrap();
    assert!((mesh.volume() - 1e-3).abs() < 1e-5, "{}", mesh.volume());

    if !have_gmsh(test) {
        return;
    }
    let (r, _) = run("auto.msh", &[]);
    assert_eq!(r["backend"], "gmsh");
    assert!(
        r["reason"].as_str().unwrap().contains("bounds one solid"),
        "{}",
        r["reason"]
    );
    assert!(r["distance"]["hausdorff_m"].as_f64().unwrap() < 1e-6);
}

/// `--mesher gmsh` on two cubes touching at a corner: refused before gmsh runs, naming the
/// non-manifold vertex, its position and the fix; nothing written.
#[test]
fn forced_gmsh_on_a_non_manifold_vertex_is_refused_with_position_and_fix() {
    let dir = tempfile::tempdir().unwrap();
    let asset = write_obj(
        dir.path(),
        "touching.obj",
        &surface(&[cube([0.0; 3], 1.0), cube([1.0; 3], 1.0)]),
    );
    let msh = dir.path().join("touching.msh");
    let out = bin()
        .arg("mesh")
        .arg(&asset)
        .arg("-o")
        .arg(&msh)
        .args(["--mesher", "gmsh", "--gmsh", "/nonexistent/gmsh"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("touching.obj")
            && err.contains("non-manifold vertex at (1.000000, 1.000000, 1.000000) m")
            && err.contains("use --mesher ftetwild or --mesher auto"),
        "{err}"
    );
    assert!(
        !err.contains("gmsh not found"),
        "refused before gmsh: {err}"
    );
    assert!(!msh.exists());
}

/// A vertex at 1e39 m (in range for f64, far outside what the bake supports) is refused
/// before any mesher, naming the vertex; a `--size` implying billions of tetrahedra too.
#[test]
fn out_of_range_vertex_and_too_fine_size_are_refused_before_meshing() {
    let dir = tempfile::tempdir().unwrap();
    let (mut v, t) = cube([0.0; 3], 1.0);
    v[6] = [1e39, 1.0, 1.0];
    let far = write_obj(dir.path(), "far.obj", &surface(&[(v, t)]));
    let out = bin()
        .arg("mesh")
        .arg(&far)
        .arg("-o")
        .arg(dir.path().join("far.msh"))
        .args([
            "--gmsh",
            "/nonexistent/gmsh",
            "--ftetwild",
            "/nonexistent/ftetwild",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("far.obj") && err.contains("vertex ") && err.contains("1e39"),
        "{err}"
    );
    assert!(err.contains("outside ±1e6 m"), "{err}");

    let ok = write_obj(dir.path(), "cube.obj", &surface(&[cube([0.0; 3], 1.0)]));
    let out = bin()
        .arg("mesh")
        .arg(&ok)
        .arg("-o")
        .arg(dir.path().join("cube.msh"))
        // --force: past the size budget, the mesher's own hard limit still refuses.
        .args(["--size", "1e-4", "--gmsh", "/nonexistent/gmsh", "--force"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--size 1e-4 m") && err.contains("tetrahedra") && err.contains("use --size"),
        "{err}"
    );
    assert!(!dir.path().join("cube.msh").exists());
}

/// A fake gmsh that answers `--version` and then hangs as a launcher would: it starts a
/// `sleep 60` (holding the output pipe), writes its pid to `DIR/helper.pid` and waits for it.
#[cfg(unix)]
fn hanging_gmsh(dir: &Path) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let p = dir.join("fake-gmsh");
    let pid = dir.join("helper.pid");
    std::fs::write(
        &p,
        format!(
            "#!/bin/sh\nif [ \"$1\" = \"--version\" ]; then echo 4.99.0; exit 0; fi\n\
             sleep 60 &\necho $! > '{}'\nwait\n",
            pid.display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    p
}

/// Whether the process the fake gmsh started (its pid in `DIR/helper.pid`) is still running
/// 2 s after the call; false as soon as it has ended (a zombie waiting for its reaper counts
/// as ended). The grace is for the
/// kernel: a SIGKILL sent just before modal-bake exits takes effect when the killed process is
/// next scheduled, which on a loaded machine can be after the test looks; a helper left
/// running would live its 60 s.
#[cfg(unix)]
fn helper_runs(dir: &Path) -> bool {
    let runs = || {
        let Ok(pid) = std::fs::read_to_string(dir.join("helper.pid")) else {
            return false;
        };
        std::fs::read_to_string(format!("/proc/{}/stat", pid.trim())).is_ok_and(|stat| {
            stat.rsplit(')')
                .next()
                .is_some_and(|rest| !rest.trim_start().starts_with('Z'))
        })
    };
    let start = std::time::Instant::now();
    while runs() {
        if start.elapsed() > std::time::Duration::from_secs(2) {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    false
}

#[cfg(unix)]
fn work_dirs(tmp: &Path) -> Vec<String> {
    std::fs::read_dir(tmp)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("modal-bake-"))
        .collect()
}

/// A hanging gmsh is stopped at `--mesher-timeout` with a message naming the option — with
/// the process it started, which holds the output pipe (else the run would wait 60 s for it)
/// — and its work folder is removed.
#[cfg(unix)]
#[test]
fn a_hanging_mesher_times_out_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = dir.path().join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let fake = hanging_gmsh(dir.path());
    let asset = write_obj(dir.path(), "cube.obj", &surface(&[cube([0.0; 3], 1.0)]));
    let start = std::time::Instant::now();
    let out = bin()
        .arg("mesh")
        .arg(&asset)
        .arg("-o")
        .arg(dir.path().join("cube.msh"))
        .args(["--mesher", "gmsh", "--mesher-timeout", "1", "--gmsh"])
        .arg(&fake)
        .env("TMPDIR", &tmp)
        .output()
        .unwrap();
    assert!(!out.status.success());
    // Not the helper's 60 s: the run does not wait for the pipe it held.
    assert!(
        start.elapsed().as_secs() < 30,
        "returned after {:?}",
        start.elapsed()
    );
    assert!(
        !helper_runs(dir.path()),
        "the fake gmsh's helper outlived the run"
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("did not finish meshing")
            && err.contains("within 1 s")
            && err.contains("--mesher-timeout"),
        "{err}"
    );
    assert!(work_dirs(&tmp).is_empty(), "{:?}", work_dirs(&tmp));
    assert!(!dir.path().join("cube.msh").exists());
}

/// SIGTERM while the mesher runs: modal-bake ends by the signal, ends the mesher with the
/// process it started, and removes its work folder.
#[cfg(unix)]
#[test]
fn sigterm_while_meshing_removes_the_work_folder() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = dir.path().join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let fake = hanging_gmsh(dir.path());
    let asset = write_obj(dir.path(), "cube.obj", &surface(&[cube([0.0; 3], 1.0)]));
    let mut child = bin()
        .arg("mesh")
        .arg(&asset)
        .arg("-o")
        .arg(dir.path().join("cube.msh"))
        .args(["--mesher", "gmsh", "--gmsh"])
        .arg(&fake)
        .env("TMPDIR", &tmp)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while work_dirs(&tmp).is_empty() {
        assert!(
            start.elapsed().as_secs() < 60,
            "no work folder appeared in {}",
            tmp.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // Let gmsh start inside it.
    std::thread::sleep(std::time::Duration::from_millis(300));
    let ok = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
    let status = child.wait().unwrap();
    assert!(!status.success());
    assert!(work_dirs(&tmp).is_empty(), "{:?}", work_dirs(&tmp));
    assert!(
        !helper_runs(dir.path()),
        "the fake gmsh's helper outlived modal-bake"
    );
}

/// `auto` on a clean cube with a gmsh that fails: fTetWild runs instead, and the report names
/// the fallback and gmsh's error.
#[cfg(unix)]
#[test]
fn auto_falls_back_to_ftetwild_when_gmsh_fails() {
    use std::os::unix::fs::PermissionsExt;
    if !have_ftetwild("auto_falls_back_to_ftetwild_when_gmsh_fails") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let fake = dir.path().join("failing-gmsh");
    std::fs::write(
        &fake,
        "#!/bin/sh\nif [ \"$1\" = \"--version\" ]; then echo 4.99.0; exit 0; fi\necho 'Error   : No tetrahedra (a fake gmsh)'; exit 1\n",
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    let asset = write_obj(dir.path(), "cube.obj", &surface(&[cube([0.0; 3], 0.1)]));
    let out = bin()
        .arg("mesh")
        .arg(&asset)
        .arg("-o")
        .arg(dir.path().join("cube.msh"))
        .arg("--json")
        .arg("--gmsh")
        .arg(&fake)
        .output()
        .unwrap();
    let r = json_of(&out);
    assert_eq!(r["backend"], "ftetwild");
    let fallback = r["report"]["fallback_from"].as_str().unwrap();
    assert!(
        fallback.starts_with("gmsh failed") && fallback.contains("No tetrahedra (a fake gmsh)"),
        "{fallback}"
    );
    assert!(
        r["reason"]
            .as_str()
            .unwrap()
            .contains("gmsh failed, so fTetWild ran"),
        "{}",
        r["reason"]
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("falling back to fTetWild"), "{stderr}");
}

/// `MODAL_BAKE_PYTHON` is the Python both Python launchers run (gmsh's module, pytetwild): a
/// missing interpreter is named in the not-found error of each (not a silent fall back to
/// `python3`), and a real one (this machine's `python3`, by its full path) meshes the open box
/// with fTetWild and is named in the backend line.
#[test]
fn modal_bake_python_names_the_interpreter_of_the_python_meshers() {
    if !have_ftetwild("modal_bake_python_names_the_interpreter_of_the_python_meshers") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let asset = write_obj(dir.path(), "open_box.obj", &open_box());
    let msh = dir.path().join("open_box.msh");
    let missing = dir.path().join("no-such-python");
    // A folder holding a gmsh.py: the Python launcher of `--gmsh` (the file is never read).
    let gmsh_dir = dir.path().join("gmsh_module");
    std::fs::create_dir(&gmsh_dir).unwrap();
    std::fs::write(gmsh_dir.join("gmsh.py"), "").unwrap();
    // gmsh is only run on a closed surface: the cube with its top.
    let closed = write_obj(dir.path(), "cube.obj", &surface(&[cube([0.0; 3], 0.2)]));
    for (mesher, input, needle) in [
        ("ftetwild", &asset, "fTetWild not found"),
        ("gmsh", &closed, "gmsh not found"),
    ] {
        let out = bin()
            .arg("mesh")
            .arg(input)
            .arg("-o")
            .arg(&msh)
            .args(["--mesher", mesher, "--gmsh"])
            .arg(&gmsh_dir)
            .env("MODAL_BAKE_PYTHON", &missing)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{mesher}: {err}");
        assert!(err.contains(needle), "{mesher}: {err}");
        assert!(err.contains(&*missing.to_string_lossy()), "{mesher}: {err}");
        assert!(!msh.exists(), "{mesher}: a mesh was written");
    }
    let which = Command::new("sh")
        .args(["-c", "command -v python3"])
        .output()
        .unwrap();
    let python = String::from_utf8(which.stdout).unwrap().trim().to_string();
    assert!(python.starts_with('/'), "no python3 on PATH: {python}");
    let out = bin()
        .arg("mesh")
        .arg(&asset)
        .arg("-o")
        .arg(&msh)
        .args(["--mesher", "ftetwild"])
        .env("MODAL_BAKE_PYTHON", &python)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(
        report.contains(&format!("({python} + pytetwild ")),
        "the backend line names {python}: {report}"
    );
    assert!(msh.is_file());
}
