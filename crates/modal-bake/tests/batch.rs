//! `modal-bake batch`: bakes across a farm.
//!
//! Expectations: the union of the shards' outputs equals the unsharded run's byte for byte (and
//! `bake`'s); a second run skips every up-to-date base and rebakes a stale one with its reason;
//! two runs on one output folder at once lose nothing; a run killed mid-bake (SIGKILL) resumes,
//! skipping what it finished; a hostile manifest is refused before any work, naming the file,
//! the entry and the field, and writes nothing.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
}

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(rel)
        .canonicalize()
        .unwrap()
}

/// Eight small entries over the committed meshes (absolute mesh paths, outputs relative to
/// the manifest's folder, under `bases/`).
fn entries() -> Vec<serde_json::Value> {
    use serde_json::json;
    let m = |f: &str| data(&format!("meshes/{f}")).display().to_string();
    vec![
        json!({"mesh": m("cube_v41.msh"), "out": "bases/c0.modes", "options": {"fixed": ["bottom"], "modes": 8}}),
        json!({"mesh": m("beam.msh"), "out": "bases/beam.modes", "options": {"fixed": "clamp", "modes": 6}}),
        json!({"mesh": m("cylinder_v41.msh"), "out": "bases/cyl.modes", "options": {"modes": 6}}),
        json!({"mesh": m("cube_v22.msh"), "out": "bases/c3.modes", "options": {"modes": 5, "material": "steel"}}),
        json!({"mesh": m("beam.msh"), "out": "bases/beam_free.modes", "options": {"modes": 4, "lumped": true}}),
        json!({"mesh": m("cylinder_v22_bin.msh"), "out": "bases/cyl2.modes",
               "options": {"fixed": ["bottom"], "rayleigh": [5, 1e-6], "f32": true, "modes": 4}}),
        json!({"mesh": m("cube_v41_bin.msh"), "out": "bases/c6.modes", "options": {"fixed-below": "z=0.01", "modes": 4}}),
        json!({"mesh": m("cube_cell_sets.json"), "out": "bases/c7.modes",
               "options": {"fixed-box": [[0, 0, 0.99, 1, 1, 1]], "modes": 3, "youngs": 2e9, "poisson": 0.25, "density": 900}}),
    ]
}

fn write_manifest(dir: &Path, entries: &[serde_json::Value]) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("manifest.json");
    let text = serde_json::json!({"version": 1, "entries": entries});
    std::fs::write(&path, serde_json::to_string_pretty(&text).unwrap()).unwrap();
    path
}

fn batch(manifest: &Path, extra: &[&str]) -> Output {
    bin()
        .arg("batch")
        .arg(manifest)
        .args(extra)
        .output()
        .expect("modal-bake runs")
}

fn ok(o: &Output) -> serde_json::Value {
    assert!(
        o.status.success(),
        "exit {:?}: {}",
        o.status,
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).expect("--json prints the report")
}

/// Every regular file under `dir` (relative path → bytes), manifests and reports (`.json`,
/// `.toml`) excluded.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let e = e.unwrap();
            let p = e.path();
            let t = e.file_type().unwrap();
            if t.is_dir() {
                stack.push(p);
            } else if t.is_file() {
                // `/`-separated on every platform.
                let rel = p
                    .strip_prefix(dir)
                    .unwrap()
                    .iter()
                    .map(|c| c.to_string_lossy())
                    .collect::<Vec<_>>()
                    .join("/");
                if !rel.ends_with(".json") && !rel.ends_with(".toml") {
                    out.insert(rel, std::fs::read(&p).unwrap());
                }
            }
        }
    }
    out
}

/// The actions of a report by entry index.
fn actions(report: &serde_json::Value) -> BTreeMap<u64, (String, String)> {
    report["entries"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["index"].as_u64().unwrap(),
                (
                    e["action"].as_str().unwrap().to_string(),
                    e["reason"].as_str().unwrap_or("").to_string(),
                ),
            )
        })
        .collect()
}

#[test]
fn the_union_of_the_shards_equals_the_unsharded_run_byte_for_byte() {
    let root = tempfile::tempdir().unwrap();
    let whole = write_manifest(&root.path().join("whole"), &entries());
    let report = ok(&batch(&whole, &["--json", "--jobs", "2"]));
    assert_eq!(report["totals"]["baked"], 8, "{report}");
    let reference = files(&root.path().join("whole"));
    assert_eq!(reference.len(), 8, "{:?}", reference.keys());

    let sharded = write_manifest(&root.path().join("sharded"), &entries());
    let mut seen = Vec::new();
    for i in 0..3 {
        let r = ok(&batch(&sharded, &["--json", "--shard", &format!("{i}/3")]));
        for (index, (action, reason)) in actions(&r) {
            assert_eq!((action.as_str(), reason.as_str()), ("baked", "missing"));
            assert_eq!(index % 3, i, "entry {index} in shard {i}/3");
            seen.push(index);
        }
    }
    seen.sort_unstable();
    assert_eq!(
        seen,
        (0..8).collect::<Vec<_>>(),
        "each entry in exactly one shard"
    );
    let union = files(&root.path().join("sharded"));
    assert!(
        union == reference,
        "the shards' bases differ from the unsharded run's"
    );

    // The batch bakes as `bake` does.
    let single = root.path().join("single.modes");
    let o = bin()
        .args(["bake", data("meshes/cube_v41.msh").to_str().unwrap(), "-o"])
        .arg(&single)
        .args(["--fixed", "bottom", "--modes", "8"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read(&single).unwrap() == reference["bases/c0.modes"]);

    // Again: everything is up to date and skipped, nothing rewritten.
    let again = ok(&batch(&sharded, &["--json", "--jobs", "3"]));
    assert!(actions(&again)
        .values()
        .all(|(a, r)| a == "skipped" && r == "up_to_date"));

    // A TOML manifest of the same entries gives the same bases.
    let toml_dir = root.path().join("toml");
    std::fs::create_dir_all(&toml_dir).unwrap();
    let mut text = String::from("version = 1\n");
    for e in entries() {
        text.push_str("\n[[entries]]\n");
        let t: toml::Table = serde_json::from_value(e).unwrap();
        text.push_str(
            &toml::to_string(&t)
                .unwrap()
                .replace("[options]", "[entries.options]"),
        );
    }
    let toml_manifest = toml_dir.join("manifest.toml");
    std::fs::write(&toml_manifest, &text).unwrap();
    let r = ok(&batch(&toml_manifest, &["--json", "--jobs", "2"]));
    assert_eq!(r["totals"]["baked"], 8, "{text}\n{r}");
    assert!(files(&toml_dir) == reference, "TOML manifest: other bases");
}

#[test]
fn stale_bases_are_rebaked_with_their_reason_and_a_failed_entry_does_not_stop_the_others() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("farm");
    let mut list = entries()[..3].to_vec();
    let manifest = write_manifest(&dir, &list);
    ok(&batch(&manifest, &["--json"]));
    // Other parameters for entry 1, a corrupt base for entry 2, a failing entry 3.
    list[1]["options"]["modes"] = 5.into();
    std::fs::write(dir.join("bases/cyl.modes"), b"not a base").unwrap();
    list.push(
        serde_json::json!({"mesh": data("meshes/beam.msh"), "out": "bases/bad.modes",
                                 "options": {"fixed": ["no_such_group"]}}),
    );
    let manifest = write_manifest(&dir, &list);
    let report_path = dir.join("reports/run.json");
    let o = batch(
        &manifest,
        &["--report", report_path.to_str().unwrap(), "--jobs", "2"],
    );
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report_path).unwrap()).unwrap();
    let a = actions(&report);
    assert_eq!(a[&0], ("skipped".into(), "up_to_date".into()));
    assert_eq!(a[&1], ("baked".into(), "parameters_changed".into()));
    // The report and the progress say what changed, read before the base was replaced.
    let detail = "--modes/--max-freq: 6 modes in the base, 5 modes asked";
    assert_eq!(report["entries"][1]["detail"], detail, "{report}");
    assert_eq!(a[&2], ("baked".into(), "unreadable".into()));
    assert_eq!(a[&3].0, "failed");
    let failed = &report["entries"][3];
    assert!(
        failed["error"].as_str().unwrap().contains("no_such_group"),
        "{failed}"
    );
    assert!(!dir.join("bases/bad.modes").exists());
    assert_eq!(report["totals"]["failed"], 1);
    // The progress names each entry.
    let stderr = String::from_utf8_lossy(&o.stderr);
    for i in 0..4 {
        assert!(stderr.contains(&format!("entries[{i}]")), "{stderr}");
    }
    assert!(
        stderr.contains(&format!("stale (parameters changed: {detail}): baking")),
        "{stderr}"
    );
}

#[test]
fn two_runs_on_one_folder_at_once_lose_nothing() {
    let root = tempfile::tempdir().unwrap();
    let reference_manifest = write_manifest(&root.path().join("ref"), &entries());
    ok(&batch(&reference_manifest, &["--json", "--jobs", "2"]));
    let reference = files(&root.path().join("ref"));

    let dir = root.path().join("shared");
    let manifest = write_manifest(&dir, &entries());
    let spawn = || {
        bin()
            .arg("batch")
            .arg(&manifest)
            .args(["--json", "--jobs", "2"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (spawn(), spawn());
    let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
    for r in [ok(&a), ok(&b)] {
        assert_eq!(r["totals"]["failed"], 0, "{r}");
        assert_eq!(r["totals"]["entries"], 8, "{r}");
    }
    let left = files(&dir);
    assert!(
        left.keys().all(|k| !k.contains(".tmp-")),
        "temporaries left: {:?}",
        left.keys()
    );
    assert!(
        left == reference,
        "the shared folder differs from one run's"
    );
}

#[test]
fn a_run_killed_mid_bake_resumes_skipping_what_it_finished() {
    // A small base, then two of the 8,009-node cliff (most of a second each): the kill lands
    // in the first cliff bake.
    let cliff = data("scenes/cliff.msh").display().to_string();
    let list = vec![
        entries()[0].clone(),
        serde_json::json!({"mesh": cliff, "out": "bases/cliff_a.modes", "options": {"modes": 4}}),
        serde_json::json!({"mesh": cliff, "out": "bases/cliff_b.modes",
                           "options": {"modes": 5, "fixed": ["bottom"]}}),
    ];
    let root = tempfile::tempdir().unwrap();
    let reference_manifest = write_manifest(&root.path().join("ref"), &list);
    ok(&batch(&reference_manifest, &["--json", "--jobs", "2"]));
    let reference = files(&root.path().join("ref"));

    let dir = root.path().join("killed");
    let manifest = write_manifest(&dir, &list);
    let mut child = bin()
        .arg("batch")
        .arg(&manifest)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // SIGKILL right after the first base is written: the next one is being baked.
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    assert!(
        lines.any(|l| l.is_ok_and(|l| l.contains(": baked in"))),
        "no entry finished"
    );
    child.kill().unwrap();
    child.wait().unwrap();
    let finished: Vec<String> = files(&dir)
        .into_keys()
        .filter(|k| k.ends_with(".modes") && !k.contains(".tmp-"))
        .collect();
    assert!(
        !finished.is_empty() && finished.len() < list.len(),
        "killed after {finished:?}"
    );
    for f in &finished {
        assert!(
            files(&dir)[f] == reference[f],
            "{f}: a finished base is whole"
        );
    }

    let report = ok(&batch(&manifest, &["--json"]));
    for e in report["entries"].as_array().unwrap() {
        let out = e["out"].as_str().unwrap();
        let was_finished = finished
            .iter()
            .any(|f| Path::new(out).ends_with(Path::new(f)));
        let expected = if was_finished { "skipped" } else { "baked" };
        assert_eq!(e["action"], expected, "{e}");
    }
    let after = files(&dir);
    assert!(
        after.keys().all(|k| !k.contains(".tmp-")),
        "{:?}",
        after.keys()
    );
    assert!(
        after == reference,
        "the resumed run differs from an uninterrupted one"
    );
}

/// Runs a batch over `manifest` in `dir`, expecting a refusal before any work: exit 1, one
/// `error:` line containing every `needle`, and no file written.
fn refused(dir: &Path, manifest: &Path, extra: &[&str], needles: &[&str]) {
    let before = files(dir);
    let o = batch(manifest, extra);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{needles:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let err = stderr
        .lines()
        .find(|l| l.starts_with("error:"))
        .unwrap_or_else(|| panic!("{needles:?}: no error line: {stderr}"));
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
    assert!(!stderr.contains("batch ["), "work started: {stderr}");
    assert!(files(dir) == before, "{needles:?}: wrote files");
    assert!(!dir.join("bases").exists(), "{needles:?}: made bases/");
}

#[test]
fn hostile_manifests_are_refused_before_any_work_naming_file_entry_and_field() {
    use serde_json::json;
    let root = tempfile::tempdir().unwrap();
    let dir = root.path();
    let mesh = data("meshes/cube_v41.msh").display().to_string();
    let good = |out: &str| json!({"mesh": mesh, "out": out});
    std::fs::create_dir(dir.join("folder.modes")).unwrap();
    let cases: Vec<(serde_json::Value, Vec<&str>)> = vec![
        (
            json!({"entries": [good("a.modes"), {"mesh": mesh}]}),
            vec!["entries[1]", "`out`"],
        ),
        (
            json!({"entries": [{"out": "a.modes"}]}),
            vec!["entries[0]", "`mesh`"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "outt": 1}]}),
            vec!["entries[0]", "unknown key `outt`"],
        ),
        (
            json!({"entries": [good("a.modes")], "jobs": 4}),
            vec!["unknown key `jobs`"],
        ),
        (
            json!({"version": 2, "entries": [good("a.modes")]}),
            vec!["version"],
        ),
        (json!({"entries": []}), vec!["entries is empty"]),
        (
            json!({"entries": {"mesh": mesh}}),
            vec!["entries must be an array"],
        ),
        (json!([good("a.modes")]), vec!["must be a table"]),
        (
            json!({"entries": [{"mesh": 5, "out": "a.modes"}]}),
            vec!["entries[0].mesh must be a string"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": ""}]}),
            vec!["entries[0].out is empty"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"modez": 3}}]}),
            vec!["entries[0].options.modez", "unknown bake option"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"fixed_box": [0,0,0,1,1,1]}}]}),
            vec!["entries[0].options.fixed_box", "did you mean `fixed-box`"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"max-memory": 100}}]}),
            vec!["entries[0].options.max-memory", "command line"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"out": "b.modes"}}]}),
            vec!["entries[0].options.out"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"target-error": 5}}]}),
            vec!["entries[0].options.target-error"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"modes": null}}]}),
            vec!["entries[0].options.modes", "null"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"modes": {"n": 3}}}]}),
            vec!["entries[0].options.modes"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": "--modes 3"}]}),
            vec!["entries[0].options must be a table"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"modes": -1}}]}),
            vec!["entries[0].options.modes"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"modes": 10.5}}]}),
            vec!["entries[0].options.modes", "10.5"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"modes": 1e12}}]}),
            vec!["entries[0].options", "modes"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"youngs": -5}}]}),
            vec!["entries[0].options", "--youngs"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"material": "cheese"}}]}),
            vec!["entries[0].options.material", "cheese"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"modes": 3, "max-freq": 100}}]}),
            vec!["entries[0].options"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"size": 0.1}}]}),
            vec!["entries[0].options", "surface assets"],
        ),
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"rayleigh": [1, 2, 3]}}]}),
            vec!["entries[0].options.rayleigh"],
        ),
        // `object` selects a physical volume of a .msh (checked when the mesh is read: the
        // cube has no 3-D group of that name), not of a meshio JSON.
        (
            json!({"entries": [{"mesh": data("meshes/cube_cell_sets.json").display().to_string(), "out": "a.modes", "options": {"object": "left"}}]}),
            vec!["entries[0].options", "meshio JSON"],
        ),
        // `piece` counts from 1 and selects a piece of a volume mesh, not of a surface asset.
        (
            json!({"entries": [{"mesh": mesh, "out": "a.modes", "options": {"piece": 0}}]}),
            vec!["entries[0].options.piece"],
        ),
        (
            json!({"entries": [{"mesh": data("assets/hp_body.obj").display().to_string(), "out": "a.modes", "options": {"piece": 1}}]}),
            vec!["entries[0].options", "volume mesh", "--object NAME"],
        ),
        // Paths that are inputs, devices, FIFOs, folders; duplicate outputs.
        (
            json!({"entries": [good("a.modes"), {"mesh": mesh, "out": mesh}]}),
            vec!["entries[1].out", "the mesh of entries[0]"],
        ),
        (
            json!({"entries": [good("manifest.json")]}),
            vec!["entries[0].out", "the manifest"],
        ),
        (
            json!({"entries": [good("folder.modes")]}),
            vec!["entries[0].out", "directory"],
        ),
        (
            json!({"entries": [good("a.modes"), good("b.modes"), good("./sub/../a.modes")]}),
            vec!["entries[2].out", "entries[0].out", "same file"],
        ),
        (
            json!({"entries": [{"mesh": "missing.msh", "out": "a.modes"}]}),
            vec!["entries[0].mesh", "missing.msh"],
        ),
        (
            json!({"entries": [{"mesh": ".", "out": "a.modes"}]}),
            vec!["entries[0].mesh", "directory"],
        ),
    ];
    // Devices and FIFOs (Unix): neither is opened nor replaced.
    #[cfg(unix)]
    let cases = {
        let mut cases = cases;
        let fifo = dir.join("fifo");
        assert!(Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        let fifo_s = fifo.display().to_string();
        cases.extend([
            (
                json!({"entries": [good("/dev/null")]}),
                vec!["entries[0].out", "character device"],
            ),
            (
                json!({"entries": [good(&fifo_s)]}),
                vec!["entries[0].out", "FIFO"],
            ),
            (
                json!({"entries": [{"mesh": "/dev/zero", "out": "a.modes"}]}),
                vec!["entries[0].mesh", "character device"],
            ),
            (
                json!({"entries": [{"mesh": fifo_s, "out": "a.modes"}]}),
                vec!["entries[0].mesh", "FIFO"],
            ),
        ]);
        cases
    };
    for (i, (manifest, needles)) in cases.iter().enumerate() {
        let path = dir.join("manifest.json");
        std::fs::write(&path, serde_json::to_string(manifest).unwrap()).unwrap();
        let mut n = vec!["manifest.json"];
        n.extend(needles.iter().copied());
        eprintln!("case {i}: {manifest}");
        refused(dir, &path, &[], &n);
    }

    // Text-level defects.
    let path = dir.join("manifest.json");
    let texts: Vec<(Vec<u8>, &str)> = vec![
        (
            format!(
                r#"{{"entries": [{{"mesh": {}, "out": "a.modes", "out": "b.modes"}}]}}"#,
                serde_json::to_string(&mesh).unwrap()
            )
            .into_bytes(),
            "appears twice",
        ),
        (b"{\"entries\": [".to_vec(), "not valid JSON"),
        (b"\xff\xfe{}".to_vec(), "not UTF-8"),
        (b"".to_vec(), "not valid JSON"),
    ];
    for (text, needle) in &texts {
        std::fs::write(&path, text).unwrap();
        refused(dir, &path, &[], &["manifest.json", needle]);
    }
    let toml_path = dir.join("m.toml");
    std::fs::write(&toml_path, "[[entries]]\nmesh = 3\n").unwrap();
    refused(
        dir,
        &toml_path,
        &[],
        &["m.toml", "entries[0].mesh must be a string"],
    );
    std::fs::write(&toml_path, "[[entries]\n").unwrap();
    refused(dir, &toml_path, &[], &["m.toml", "not valid TOML"]);
    std::fs::remove_file(&toml_path).unwrap();

    // Absurd counts: entries past the limit, a file past the size limit.
    let many: Vec<_> = (0..100_001)
        .map(|i| json!({"mesh": "x", "out": format!("{i}")}))
        .collect();
    std::fs::write(
        &path,
        serde_json::to_string(&json!({"entries": many})).unwrap(),
    )
    .unwrap();
    refused(dir, &path, &[], &["manifest.json", "100001 entries"]);
    let big = std::fs::File::create(&path).unwrap();
    big.set_len(17 << 20).unwrap();
    drop(big);
    refused(dir, &path, &[], &["manifest.json", "MiB"]);

    // The manifest itself as a device or FIFO (never opened), bad --shard and --jobs.
    let valid = dir.join("valid.json");
    std::fs::write(
        &valid,
        serde_json::to_string(&json!({"entries": [good("a.modes")]})).unwrap(),
    )
    .unwrap();
    // The manifest itself a device or a FIFO (Unix).
    #[cfg(unix)]
    {
        refused(
            dir,
            Path::new("/dev/zero"),
            &[],
            &["/dev/zero", "character device"],
        );
        refused(dir, &dir.join("fifo"), &[], &["fifo", "FIFO"]);
    }
    refused(dir, &valid, &["--jobs", "0"], &["--jobs"]);
    refused(dir, &valid, &["--jobs", "100000"], &["--jobs"]);
    refused(
        dir,
        &valid,
        &["--report", valid.to_str().unwrap()],
        &["--report", "the manifest"],
    );
    refused(dir, &valid, &["--report", &mesh], &["--report"]);
    let o = batch(&valid, &["--shard", "3/3"]);
    assert_eq!(o.status.code(), Some(2), "clap refuses the value");
    assert!(String::from_utf8_lossy(&o.stderr).contains("0-based"));
    let o = bin()
        .arg("batch")
        .arg(&valid)
        .args(["--shard", "env:DCR_FARM_TEST_UNSET/4"])
        .env_remove("DCR_FARM_TEST_UNSET")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("DCR_FARM_TEST_UNSET is not set"));
    assert!(!dir.join("a.modes").exists());
}

#[test]
fn the_shard_index_is_read_from_the_variable_named() {
    let root = tempfile::tempdir().unwrap();
    let manifest = write_manifest(root.path(), &entries()[..3]);
    let o = bin()
        .arg("batch")
        .arg(&manifest)
        .args(["--json", "--shard", "env:JOB_COMPLETION_INDEX/2"])
        .env("JOB_COMPLETION_INDEX", "1")
        .output()
        .unwrap();
    let r = ok(&o);
    assert_eq!(r["shard"]["source"], "$JOB_COMPLETION_INDEX");
    assert_eq!(actions(&r).keys().copied().collect::<Vec<_>>(), vec![1]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("shard 1/2 ($JOB_COMPLETION_INDEX)"),
        "{stderr}"
    );
}

/// Mutates `text` once (seeded): a byte flipped, the text truncated, a byte deleted, a slice
/// repeated, or a JSON/TOML token inserted.
fn mutate(text: &[u8], rng: &mut dcr_runtime::testing::SplitMix64) -> Vec<u8> {
    let mut b = text.to_vec();
    let at = |rng: &mut dcr_runtime::testing::SplitMix64, n: usize| {
        (rng.next_u64() % n.max(1) as u64) as usize
    };
    match rng.next_u64() % 5 {
        0 => {
            let i = at(rng, b.len());
            b[i] ^= (rng.next_u64() % 255 + 1) as u8;
        }
        1 => b.truncate(at(rng, b.len())),
        2 => {
            b.remove(at(rng, b.len()));
        }
        3 => {
            let i = at(rng, b.len());
            let j = (i + at(rng, 40)).min(b.len());
            let slice = b[i..j].to_vec();
            let k = at(rng, b.len());
            b.splice(k..k, slice);
        }
        _ => {
            let tokens: [&[u8]; 12] = [
                b"{",
                b"}",
                b"[",
                b"]",
                b",",
                b"\"",
                b":",
                b"-",
                b"1e999",
                b"null",
                b"=",
                b"\n[[entries]]\n",
            ];
            let t = tokens[at(rng, tokens.len())];
            let k = at(rng, b.len());
            b.splice(k..k, t.iter().copied());
        }
    }
    b
}

// Seeded mutation fuzzing of the manifest reader (JSON and TOML) through the binary: every
// mutated manifest is read whole or refused (exit 1) with one error line naming the file and a
// location (an entry and field, a line, a byte offset, a key), never a panic; `--dry-run`
// writes nothing. `DCR_FUZZ_ITERS` (default 150 per form) runs longer.
#[test]
fn mutated_manifests_are_read_or_refused_with_a_location_never_a_panic() {
    let iters: usize = std::env::var("DCR_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(150);
    let root = tempfile::tempdir().unwrap();
    let dir = root.path();
    let list = &entries()[..3];
    let json_text =
        serde_json::to_vec_pretty(&serde_json::json!({"version": 1, "entries": list})).unwrap();
    let mut toml_text = String::from("version = 1\n");
    for e in list {
        let t: toml::Table = serde_json::from_value(e.clone()).unwrap();
        toml_text.push_str("\n[[entries]]\n");
        toml_text.push_str(
            &toml::to_string(&t)
                .unwrap()
                .replace("[options]", "[entries.options]"),
        );
    }
    let located = regex_lite(&[
        "entries[",
        "line ",
        "offset ",
        "`version`",
        "version:",
        "entries is empty",
        "entries must be",
        "the manifest",
        "key `",
        "no `entries`",
    ]);
    let mut rng = dcr_runtime::testing::SplitMix64(
        std::env::var("DCR_FUZZ_SEED")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(27),
    );
    let (mut read, mut refused) = (0, 0);
    for (name, text) in [("m.json", json_text), ("m.toml", toml_text.into_bytes())] {
        let path = dir.join(name);
        for _ in 0..iters {
            let mutated = mutate(&text, &mut rng);
            std::fs::write(&path, &mutated).unwrap();
            let o = batch(&path, &["--dry-run"]);
            let stderr = String::from_utf8_lossy(&o.stderr);
            let shown = String::from_utf8_lossy(&mutated);
            match o.status.code() {
                Some(0) => read += 1,
                Some(1) => {
                    refused += 1;
                    let errors: Vec<&str> =
                        stderr.lines().filter(|l| l.starts_with("error:")).collect();
                    assert_eq!(errors.len(), 1, "{shown}\n{stderr}");
                    assert!(
                        errors[0].contains(name),
                        "no file named: {}\n{shown}",
                        errors[0]
                    );
                    assert!(located(errors[0]), "no location: {}\n{shown}", errors[0]);
                }
                _ => panic!("{:?}: {stderr}\n{shown}", o.status),
            }
            assert!(!stderr.contains("panicked"), "{stderr}");
        }
    }
    let names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 2, "--dry-run wrote {names:?}");
    assert!(read > 0 && refused > 0, "read {read}, refused {refused}");
}

/// Whether a message holds any of `needles`.
fn regex_lite(needles: &'static [&'static str]) -> impl Fn(&str) -> bool {
    move |s| needles.iter().any(|n| s.contains(n))
}

// A surface asset is checked as `check` checks it (meshed again the same way and compared):
// baked once, then up to date; another element order makes it stale. Needs gmsh (skipped
// without it unless `DCR_REQUIRE_GMSH=1`).
#[test]
fn a_surface_asset_entry_is_meshed_checked_and_skipped_when_fresh() {
    if modal_bake::mesh::gmsh::gmsh_version(None).is_err() {
        assert_ne!(
            std::env::var("DCR_REQUIRE_GMSH").as_deref(),
            Ok("1"),
            "DCR_REQUIRE_GMSH=1 but gmsh does not run"
        );
        eprintln!("SKIPPED: gmsh does not run");
        return;
    }
    let root = tempfile::tempdir().unwrap();
    let dir = root.path();
    // A 0.1 m cube, outward faces.
    let v = [
        [0, 0, 0],
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 1, 1],
    ];
    let q = [
        [1, 4, 3, 2],
        [5, 6, 7, 8],
        [1, 2, 6, 5],
        [3, 4, 8, 7],
        [2, 3, 7, 6],
        [1, 5, 8, 4],
    ];
    let mut obj = String::from("o cube\n");
    for p in v {
        obj += &format!(
            "v {} {} {}\n",
            0.1 * p[0] as f64,
            0.1 * p[1] as f64,
            0.1 * p[2] as f64
        );
    }
    for f in q {
        obj += &format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]);
    }
    std::fs::write(dir.join("cube.obj"), obj).unwrap();
    let entry = |order: u8| {
        serde_json::json!({"mesh": "cube.obj", "out": "bases/cube.modes",
                           "options": {"order": order, "size": 0.04, "modes": 4, "material": "pine"}})
    };
    let manifest = write_manifest(dir, &[entry(1)]);
    let first = ok(&batch(&manifest, &["--json"]));
    assert_eq!(actions(&first)[&0], ("baked".into(), "missing".into()));
    let again = ok(&batch(&manifest, &["--json"]));
    assert_eq!(actions(&again)[&0], ("skipped".into(), "up_to_date".into()));
    let manifest = write_manifest(dir, &[entry(2)]);
    let finer = ok(&batch(&manifest, &["--json"]));
    assert_eq!(
        actions(&finer)[&0],
        ("baked".into(), "geometry_changed".into())
    );
}

// SIGTERM and SIGINT to a batch baking two entries at once: the process ends by the signal,
// every finished base is whole and no temporary is left.
#[test]
#[cfg(unix)]
fn a_signal_mid_batch_ends_it_leaving_whole_bases_and_no_temporary() {
    use std::os::unix::process::ExitStatusExt;
    for (signal, number) in [("-TERM", 15), ("-INT", 2)] {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("farm");
        let manifest = write_manifest(&dir, &entries());
        let mut child = bin()
            .arg("batch")
            .arg(&manifest)
            .args(["--jobs", "2"])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
        assert!(
            lines.any(|l| l.is_ok_and(|l| l.contains(": baked in"))),
            "{signal}: no entry finished"
        );
        let sent = Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success());
        let status = child.wait().unwrap();
        let left = files(&dir);
        if status.signal().is_none() {
            // The batch finished before the signal landed: all eight bases are there.
            assert!(
                status.success() && left.len() == 8,
                "{signal}: {status:?} {:?}",
                left.keys()
            );
            continue;
        }
        assert_eq!(status.signal(), Some(number), "{signal}");
        assert!(
            left.keys().all(|k| !k.contains(".tmp-")),
            "{signal}: {:?}",
            left.keys()
        );
        for (name, bytes) in &left {
            let path = dir.join(name);
            assert!(!bytes.is_empty());
            dcr_runtime::format::ModesFile::read(&path)
                .unwrap_or_else(|e| panic!("{signal}: {name} is not a whole base: {e}"));
        }
    }
}
