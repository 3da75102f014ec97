//! The bake-time peak-transfer table (`modal-bake bake --transfer-h`, `modal_bake::transfer`).
//!
//! Expectations: every table entry equals the peak `modal-bake probe` reports for the same
//! modes, sampling, impact vertex (unit inward-normal impulse) and contact vertex — in both
//! directions, so the stored symmetric table is the reciprocity of the real response; entries
//! at edge midpoints (inside flat faces) equal the probe at the midpoint; baking
//! twice gives identical bytes; `info` shows the table; bad options are clear errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use dcr_runtime::format::ModesFile;
use dcr_runtime::ModalModel;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
}

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run modal-bake")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Bakes the beam (clamped) with 8 runtime modes and a table with `modes` table modes over
/// every surface vertex (or the region `extra` options select).
fn bake_beam_with(out: &Path, modes: &str, extra: &[&str]) -> Output {
    bin()
        .args(beam_args(out, modes, extra))
        .output()
        .expect("run modal-bake")
}

/// The arguments of [`bake_beam_with`].
fn beam_args(out: &Path, modes: &str, extra: &[&str]) -> Vec<String> {
    let mesh = data("data/meshes/beam.msh");
    let mut args: Vec<String> = [
        "bake",
        mesh.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--fixed",
        "clamp",
        "--modes",
        "8",
        "--transfer-h",
        "0.004",
        "--transfer-modes",
        modes,
    ]
    .map(String::from)
    .into();
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

fn bake_beam(out: &Path, modes: &str) -> Output {
    bake_beam_with(out, modes, &[])
}

/// The beam baked into `dir/name` with a table of the base's own 8 modes over every surface
/// vertex: (path, base, table).
fn beam_with_own_mode_table(
    dir: &Path,
    name: &str,
) -> (PathBuf, ModesFile, dcr_runtime::format::TransferTable) {
    let path = dir.join(name);
    let o = bake_beam(&path, "8");
    assert!(o.status.success(), "{}", text(&o));
    let base = ModesFile::read(&path).unwrap();
    let t = base.transfer.clone().expect("table stored");
    (path, base, t)
}

#[test]
fn table_entries_equal_probe_in_both_directions() {
    let dir = tempfile::tempdir().unwrap();
    // Table with the base's own 8 modes at the table's sampling: the probe must reproduce it.
    let (with, base, t) = beam_with_own_mode_table(dir.path(), "beam_t.modes");
    assert_eq!(t.modes, 8);
    assert_eq!(t.len(), base.num_surface_vertices());
    let model = ModalModel::from_base(base.clone()).unwrap();
    let x = &base.surface_vertices;
    let n = model.vertex_normals();
    // Three well-separated free (not clamped) vertex pairs (a, b): probe a→b and b→a.
    let free: Vec<usize> = (0..x.len())
        .filter(|&v| !base.fixed_nodes.contains(&base.surface_to_volume[v]))
        .collect();
    let nf = free.len();
    let pairs = [
        (free[1], free[nf - 2]),
        (free[nf / 3], free[2 * nf / 3]),
        (free[5], free[nf / 2]),
    ];
    for (a, b) in pairs {
        let mut got = [0.0; 2];
        for (k, (i, j)) in [(a, b), (b, a)].into_iter().enumerate() {
            got[k] = probe_point(&with, &t, x[i], n[i].map(|c| -c), x[j], "modal");
        }
        let ta = t.vertices.binary_search(&(a as u32)).unwrap();
        let tb = t.vertices.binary_search(&(b as u32)).unwrap();
        let table = t.peak(ta, tb);
        assert!(table > 0.0, "pair ({a}, {b}): zero entry");
        for (k, g) in got.iter().enumerate() {
            let rel = (g - table).abs() / table;
            // f32 storage: ≤ 6e-8 relative; the probe maps the vertex with ~1e-15 bary error.
            assert!(
                rel < 1e-6,
                "pair ({a}, {b}) direction {k}: probe {g:e} vs table {table:e} (rel {rel:e})"
            );
        }
        // Reciprocity of the real response, independent of the packed storage.
        assert!(
            (got[0] - got[1]).abs() <= 1e-9 * got[0].abs(),
            "reciprocity: {got:?}"
        );
    }
}

/// Peak (m) `modal-bake probe` (per-contact variant: n_pᵀ Σ β_j u_j) reports for a unit
/// impulse at `imp` along `dir` seen at `con`, sampled as the table `t` is.
fn probe_point(
    base: &Path,
    t: &dcr_runtime::format::TransferTable,
    imp: [f64; 3],
    dir: [f64; 3],
    con: [f64; 3],
    method: &str,
) -> f64 {
    let fmt = |p: [f64; 3]| format!("{},{},{}", p[0], p[1], p[2]);
    let o = run(&[
        "probe",
        base.to_str().unwrap(),
        "--impact",
        &fmt(imp),
        "--direction",
        &fmt(dir),
        "--impulse",
        "1",
        "--contact",
        &fmt(con),
        "--h",
        &format!("{}", t.h),
        "--substep",
        &format!("{}", t.h / f64::from(t.samples)),
        "--method",
        method,
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let want = if method == "transfer" {
        "transfer_table"
    } else {
        method
    };
    assert_eq!(v["contacts"][0]["served_by"], want);
    v["contacts"][0]["peak_displacement_m"].as_f64().unwrap()
}

/// Every kind of table point (vertex, edge point, face centroid) holds the peak the modal probe
/// gives at that point, for order 2 (midpoints) and order 3 (two points per edge, centroids):
/// point → point, vertex → point and point → vertex, on flat faces (where an impulse along one
/// vertex's inward normal is the table's blend of the corners' normals).
#[test]
fn every_point_kind_equals_the_probe_at_that_point() {
    let dir = tempfile::tempdir().unwrap();
    for order in ["2", "3"] {
        let path = dir.path().join(format!("beam_o{order}.modes"));
        let o = bake_beam_with(&path, "8", &["--transfer-order", order]);
        assert!(o.status.success(), "{}", text(&o));
        let base = ModesFile::read(&path).unwrap();
        let t = base.transfer.clone().expect("table stored");
        assert_eq!(t.order.to_string(), order);
        assert_eq!(
            t.edges,
            dcr_runtime::format::TransferTable::region_edges(&base.surface_triangles, &t.vertices)
        );
        let model = ModalModel::from_base(base.clone()).unwrap();
        let (x, n) = (&base.surface_vertices, model.vertex_normals());
        let vert = |k: u32| t.vertices[k as usize] as usize;
        let fixed = |v: usize| base.fixed_nodes.contains(&base.surface_to_volume[v]);
        // Points whose corners share one normal and are free, by kind.
        let flat_points = |range: std::ops::Range<usize>| -> Vec<usize> {
            range
                .filter(|&p| {
                    let (vs, ws) = t.point_support(p);
                    let vs: Vec<usize> = (0..3)
                        .filter(|&k| ws[k] != 0.0)
                        .map(|k| vert(vs[k]))
                        .collect();
                    vs.iter().all(|&v| !fixed(v))
                        && vs
                            .iter()
                            .all(|&v| (0..3).all(|k| (n[v][k] - n[vs[0]][k]).abs() < 1e-12))
                })
                .collect()
        };
        let nr = t.len();
        let ne = t.edges.len();
        let edge_pts = flat_points(nr..nr + if order == "3" { 2 * ne } else { ne });
        let face_pts = flat_points(nr + 2 * ne..t.num_points());
        assert!(edge_pts.len() > 10, "{} flat edge points", edge_pts.len());
        assert_eq!(face_pts.is_empty(), order == "2");
        let pos = |p: usize| {
            let (vs, ws) = t.point_support(p);
            let mut q = [0.0; 3];
            for k in 0..3 {
                for c in 0..3 {
                    q[c] += ws[k] * x[vert(vs[k])][c];
                }
            }
            q
        };
        let inward = |p: usize| n[vert(t.point_support(p).0[0])].map(|c| -c);
        let (e1, e2) = (edge_pts[2], edge_pts[edge_pts.len() - 3]);
        let v1 = t.point_support(e1).0[0] as usize;
        let mut cases = vec![(e1, e2), (v1, e2), (e2, v1)];
        if let (Some(&f1), Some(&f2)) = (face_pts.first(), face_pts.last()) {
            cases.extend([(f1, f2), (f1, e2), (v1, f2)]);
        }
        // Points next to the beam's edges, whose corners' normals differ: the table holds the
        // response along their interpolated normal (the runtime's and the probe's).
        let blended = |p: usize| {
            let (vs, ws) = t.point_support(p);
            let mut q = [0.0; 3];
            for k in 0..3 {
                for c in 0..3 {
                    q[c] += ws[k] * n[vert(vs[k])][c];
                }
            }
            let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            q.map(|x| x / l)
        };
        let bent: Vec<usize> = (nr..t.num_points())
            .filter(|&p| {
                let (vs, ws) = t.point_support(p);
                let vs: Vec<usize> = (0..3)
                    .filter(|&k| ws[k] != 0.0)
                    .map(|k| vert(vs[k]))
                    .collect();
                vs.iter().all(|&v| !fixed(v))
                    && vs
                        .iter()
                        .any(|&v| (0..3).any(|k| (n[v][k] - n[vs[0]][k]).abs() > 1e-3))
            })
            .collect();
        assert!(bent.len() > 10, "{} bent points", bent.len());
        let (b1, b2) = (bent[1], bent[bent.len() - 2]);
        cases.extend([(b1, b2), (b1, e2), (e1, b2), (v1, b2), (b2, v1)]);
        let inward = |p: usize| {
            if bent.contains(&p) {
                blended(p).map(|c| -c)
            } else {
                inward(p)
            }
        };
        for (p, q) in cases {
            let got = probe_point(&path, &t, pos(p), inward(p), pos(q), "modal");
            let table = t.peak(p, q);
            // `probe --method transfer` serves a node from the table itself (exact there).
            let looked_up = probe_point(&path, &t, pos(p), inward(p), pos(q), "transfer");
            assert!(
                (looked_up - table).abs() <= 1e-9 * table,
                "order {order}, points ({p}, {q}): lookup {looked_up:e} vs table {table:e}"
            );
            assert!(
                table > 0.0 && (got - table).abs() / table < 1e-6,
                "order {order}, points ({p}, {q}): probe {got:e} vs table {table:e}"
            );
        }
    }
}

#[test]
fn baking_twice_is_bit_identical_and_info_shows_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.modes");
    let b = dir.path().join("b.modes");
    // More table modes than the base keeps: the dense all-mode eigensolve provides them.
    for p in [&a, &b] {
        let o = bake_beam(p, "60");
        assert!(o.status.success(), "{}", text(&o));
        assert!(text(&o).contains("transfer table:"), "{}", text(&o));
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let base = ModesFile::read(&a).unwrap();
    let t = base.transfer.as_ref().unwrap();
    assert_eq!(t.modes, 60);
    assert_eq!(base.num_modes(), 8);
    let o = run(&["info", a.to_str().unwrap()]);
    assert!(o.status.success());
    assert!(
        text(&o).contains(&format!("transfer table: {} region vertices", t.len())),
        "{}",
        text(&o)
    );
    let o = run(&["info", a.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["transfer"]["modes"], 60);
}

/// The same inputs give the same bytes on any thread count: a table whose 100 modes come from
/// the dense all-mode eigensolve (the base keeps 8), baked with RAYON_NUM_THREADS = 1, 2 and 4.
#[test]
fn table_is_bit_identical_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = data("data/meshes/beam.msh");
    let bytes: Vec<Vec<u8>> = [1, 2, 4]
        .iter()
        .map(|threads| {
            let out = dir.path().join(format!("t{threads}.modes"));
            let o = bin()
                .env("RAYON_NUM_THREADS", threads.to_string())
                .args(["bake", mesh.to_str().unwrap(), "-o", out.to_str().unwrap()])
                .args(["--fixed", "clamp", "--modes", "8", "--transfer-h", "0.01"])
                .args(["--transfer-modes", "100", "--json"])
                .output()
                .unwrap();
            assert!(o.status.success(), "{}", text(&o));
            let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            assert_eq!(v["transfer"]["mode_source"], "dense", "{v}");
            std::fs::read(&out).unwrap()
        })
        .collect();
    assert!(bytes[0] == bytes[1], "1 vs 2 threads differ");
    assert!(bytes[0] == bytes[2], "1 vs 4 threads differ");
}

#[test]
fn region_options_select_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.modes");
    let all = {
        let o = bake_beam(&out, "8");
        assert!(o.status.success(), "{}", text(&o));
        ModesFile::read(&out).unwrap()
    };
    let x = &all.surface_vertices;
    let xmax = x.iter().fold(f64::NEG_INFINITY, |a, p| a.max(p[0]));
    let half = format!("-1e9,-1e9,-1e9,{},1e9,1e9", 0.5 * xmax);
    let o = bake_beam_with(
        &out,
        "8",
        &["--transfer-region", &half, "--transfer-up", "0,0,1"],
    );
    assert!(o.status.success(), "{}", text(&o));
    let b = ModesFile::read(&out).unwrap();
    let t = b.transfer.unwrap();
    let model = ModalModel::from_base(all.clone()).unwrap();
    let expect: Vec<u32> = (0..x.len())
        .filter(|&v| x[v][0] <= 0.5 * xmax && model.vertex_normals()[v][2] >= 0.5)
        .map(|v| v as u32)
        .collect();
    assert!(!expect.is_empty() && expect.len() < x.len());
    assert_eq!(t.vertices, expect);
}

#[test]
fn bad_transfer_options_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bad.modes");
    let mesh = data("data/meshes/beam.msh");
    let cases: [(&[&str], &str); 6] = [
        (
            &["--transfer-h", "-1"],
            "parameter `transfer.h` must be a positive step",
        ),
        (
            &["--transfer-h", "0"],
            "parameter `transfer.h` must be a positive step",
        ),
        (
            &["--transfer-h", "0.01", "--transfer-modes", "0"],
            "mode count",
        ),
        (
            &["--transfer-h", "0.01", "--transfer-region", "1,1,1,0,0,0"],
            "minimum",
        ),
        (
            &["--transfer-h", "0.01", "--transfer-up", "0,0,0"],
            "transfer.up",
        ),
        (
            &[
                "--transfer-h",
                "0.01",
                "--transfer-region",
                "100,100,100,101,101,101",
            ],
            "selects no surface vertex",
        ),
    ];
    for (extra, needle) in cases {
        let mut args = vec![
            "bake",
            mesh.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--fixed",
            "clamp",
            "--modes",
            "4",
        ];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(!o.status.success(), "{extra:?} succeeded");
        let msg = text(&o);
        assert!(msg.contains(needle), "{extra:?}: {msg}");
        assert!(!msg.contains("panicked"), "{extra:?}: {msg}");
        assert!(!out.exists(), "{extra:?}: a file was written");
    }
    // Region options without --transfer-h are refused by the parser.
    let o = run(&[
        "bake",
        mesh.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--transfer-up",
        "0,0,1",
    ]);
    assert!(!o.status.success());
}

/// A table whose estimate is over `--max-time` is refused once its modes are known, before a
/// row is built, naming the estimate and the fixes; nothing is written; the mode count it
/// suggests then builds within the same budget; `--force` builds the refused table.
#[test]
fn a_table_over_the_budget_is_refused_before_it_is_built() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.modes");
    // Every mode, one thread: an estimate of ~16 s against a 1 s budget on any machine.
    let bake = |modes: &str, extra: &[&str]| {
        let budget = ["--max-time", "1", "--json"];
        bin()
            .args(beam_args(&out, modes, &[&budget[..], extra].concat()))
            .env("RAYON_NUM_THREADS", "1")
            .output()
            .expect("run modal-bake")
    };
    let o = bake("all", &[]);
    let msg = text(&o);
    assert!(!o.status.success(), "{msg}");
    for needle in [
        "transfer table: refused before building",
        "534 modes",
        "samples per step come from the highest mode",
        "`transfer.modes` ",
        "--force",
    ] {
        assert!(msg.contains(needle), "{needle:?} missing: {msg}");
    }
    assert!(!msg.contains("transfer table: 1"), "rows were built: {msg}");
    assert!(!out.exists(), "a base was written");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    let k = msg
        .split("`transfer.modes` ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .expect("a suggested mode count")
        .to_string();
    let o = bake(&k, &[]);
    assert!(o.status.success(), "{k} modes: {}", text(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json report");
    let t = &report["transfer"];
    assert_eq!(t["modes"].as_u64(), k.parse().ok());
    assert!(t["estimated_s"].as_f64().unwrap() <= 1.0, "{t}");
    let o = bake("all", &["--force", "--transfer-order", "2"]);
    assert!(o.status.success(), "--force: {}", text(&o));
    assert!(out.exists());
}

/// A region that selects nothing is refused before the table's modes are solved: the region
/// depends on the surface only.
#[test]
fn an_empty_region_is_refused_before_the_tables_modes_are_solved() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.modes");
    let o = bin()
        .args(beam_args(
            &out,
            "all",
            &["--transfer-region", "100,100,100,101,101,101"],
        ))
        .env("MODAL_BAKE_PROGRESS_EVERY", "0")
        .output()
        .expect("run modal-bake");
    let msg = text(&o);
    assert!(!o.status.success(), "{msg}");
    assert!(msg.contains("selects no surface vertex"), "{msg}");
    assert!(msg.contains("eigensolve"), "no progress lines: {msg}");
    assert!(
        !msg.contains("solving for the transfer table's modes"),
        "the table's modes were solved first: {msg}"
    );
    assert!(!out.exists());
}

/// `check` with the bake's own options says fresh for a table baked at its default mode count
/// (`auto`, recorded resolved for the mesh), and stale when a table option changes.
#[test]
fn check_is_fresh_after_a_default_table_bake() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("beam.modes");
    let mesh = data("data/meshes/beam.msh");
    let (mesh, out_s) = (mesh.to_str().unwrap(), out.to_str().unwrap());
    let common = ["--fixed", "clamp", "--modes", "8", "--transfer-order", "1"];
    let mut bake = vec!["bake", mesh, "-o", out_s, "--transfer-h", "0.004"];
    bake.extend_from_slice(&common);
    let o = run(&bake);
    assert!(o.status.success(), "{}", text(&o));
    let check = |h: &str| {
        let mut args = vec!["check", mesh, out_s, "--transfer-h", h];
        args.extend_from_slice(&common);
        run(&args)
    };
    let o = check("0.004");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = check("0.005");
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("transfer"), "{}", text(&o));
}

/// A table whose modes come from the dense all-mode eigensolve is built on the base's own
/// boundary conditions whichever selector fixes them: the beam clamped by `--fixed-below x=0`
/// (the nodes of its `clamp` group, at x = 0) gets the same fixed nodes, modes and table as
/// with `--fixed clamp`. A table built on the free-free object instead reads about a third of
/// the clamped beam's peaks.
#[test]
fn a_table_follows_every_fixed_node_selector() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = data("data/meshes/beam.msh");
    let table = [
        "--modes",
        "8",
        "--transfer-h",
        "0.004",
        "--transfer-modes",
        "60",
    ];
    // `modal-bake COMMAND MESH OUT --FIXED... --table options` for `bake` and `check`.
    let run_on = |command: &str, name: &str, fixed: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![command, mesh.to_str().unwrap()];
        if command == "bake" {
            args.push("-o");
        }
        args.push(out.to_str().unwrap());
        args.extend_from_slice(fixed);
        args.extend_from_slice(&table);
        run(&args)
    };
    let bake = |name: &str, fixed: &[&str]| {
        let o = run_on("bake", name, fixed);
        assert!(o.status.success(), "{}", text(&o));
        ModesFile::read(&dir.path().join(name)).unwrap()
    };
    let check = |name: &str, fixed: &[&str]| run_on("check", name, fixed);
    let group = bake("group.modes", &["--fixed", "clamp"]);
    let below = bake("below.modes", &["--fixed-below", "x=0"]);
    let boxed = bake("box.modes", &["--fixed-box", "-1,-1,-1,0,1,1"]);
    assert!(!group.fixed_nodes.is_empty());
    for other in [&below, &boxed] {
        assert_eq!(other.fixed_nodes, group.fixed_nodes);
        assert_eq!(other.eigenvalues, group.eigenvalues);
        let (t, g) = (
            other.transfer.as_ref().unwrap(),
            group.transfer.as_ref().unwrap(),
        );
        assert_eq!(t.modes, 60);
        assert!(t == g, "the tables differ");
    }
    // A table base fixed by a half-space but baked when its extra modes were solved with the
    // groups alone (it lacks `modes_fixed_by`) is stale; the fresh one is up to date.
    let o = check("below.modes", &["--fixed-below", "x=0"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let mut old = below.clone();
    let removed = old.meta.bake_params["transfer"]
        .as_object_mut()
        .unwrap()
        .remove("modes_fixed_by");
    assert_eq!(removed, Some(serde_json::json!("every selector")));
    old.write_atomic(&dir.path().join("below.modes")).unwrap();
    let o = check("below.modes", &["--fixed-below", "x=0"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("transfer"), "{}", text(&o));
    // A base fixed by groups alone records nothing new.
    assert!(group.meta.bake_params["transfer"]
        .get("modes_fixed_by")
        .is_none());
}
