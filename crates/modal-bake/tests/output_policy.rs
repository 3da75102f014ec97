//! Every output of `modal-bake` goes through one policy before anything is written: an output
//! that is the input (also through another spelling or a symbolic link), a FIFO or a device,
//! a folder, or the path of another output of the same command is refused, naming the
//! option, and the input and the node survive untouched. Negative numbers given to options
//! reach the option's range check.

#[cfg(unix)]
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .args(args)
        .output()
        .expect("modal-bake runs")
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A 6-mode clamped beam base in `dir`.
fn beam_base(dir: &Path) -> PathBuf {
    let mesh = repo_root().join("data/meshes/beam.msh");
    let out = dir.join("beam.modes");
    let o = run(&[
        "bake",
        s(&mesh),
        "-o",
        s(&out),
        "--fixed",
        "clamp",
        "--modes",
        "6",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

#[cfg(unix)]
fn mkfifo(p: &Path) {
    let st = Command::new("mkfifo").arg(p).status().unwrap();
    assert!(st.success(), "mkfifo");
}

#[cfg(unix)]
fn refused(args: &[&str], needles: &[&str]) {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} succeeded");
    for n in needles {
        assert!(err.contains(n), "{args:?}: {err:?} lacks {n:?}");
    }
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert_eq!(err.trim().lines().count(), 1, "one-line message: {err}");
}

// Regression: `export BASE --vtu BASE` replaced the base with a VTU (also as `./sub/../BASE`
// and through a symbolic link), `--gltf FIFO` replaced the FIFO with a file, and
// `--vtu x --gltf x --png x` kept only the last. Each exporter refuses each of them.
#[test]
#[cfg(unix)]
fn every_exporter_refuses_the_input_a_fifo_and_a_shared_path() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = beam_base(d);
    let before = std::fs::read(&base).unwrap();
    std::fs::create_dir(d.join("sub")).unwrap();
    let respelled = d.join("sub/../beam.modes");
    let link = d.join("link.modes");
    std::os::unix::fs::symlink(&base, &link).unwrap();
    let fifo = d.join("fifo");
    mkfifo(&fifo);
    for option in ["--vtu", "--gltf", "--png"] {
        for target in [&base, &respelled, &link] {
            refused(
                &["export", s(&base), option, s(target)],
                &[option, "is the base"],
            );
        }
        refused(&["export", s(&base), option, s(&fifo)], &[option, "a FIFO"]);
        refused(
            &["export", s(&base), option, s(&d.join("sub"))],
            &[option, "a directory"],
        );
        refused(
            &["export", s(&base), option, "."],
            &[option, "names a folder"],
        );
    }
    let x = d.join("x");
    refused(
        &[
            "export",
            s(&base),
            "--vtu",
            s(&x),
            "--gltf",
            s(&x),
            "--png",
            s(&x),
        ],
        &["--vtu", "--gltf", "same file"],
    );
    refused(
        &[
            "export",
            s(&base),
            "--vtu",
            s(&x),
            "--png",
            s(&d.join("sub/../x")),
        ],
        &["--vtu", "--png", "same file"],
    );
    assert_eq!(std::fs::read(&base).unwrap(), before, "the base changed");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let mut left: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["beam.modes", "fifo", "link.modes", "sub"]);
}

// A device node survives: `/dev/null` is a character device every machine has (as root the
// rename used to replace it with a regular file).
#[test]
#[cfg(unix)]
fn a_device_node_is_refused_by_every_exporter_and_by_mesh_and_bake() {
    let dir = tempfile::tempdir().unwrap();
    let base = beam_base(dir.path());
    for option in ["--vtu", "--gltf", "--png"] {
        refused(
            &["export", s(&base), option, "/dev/null"],
            &[option, "a character device"],
        );
    }
    let mesh = repo_root().join("data/meshes/beam.msh");
    refused(
        &["bake", s(&mesh), "-o", "/dev/null", "--fixed", "clamp"],
        &["-o", "a character device"],
    );
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
}

// Regression: `--scale -1`, `--rayleigh -1,0` and `--youngs -1e9` were read as unknown flags
// ("unexpected argument '-1' found"); they reach the option's range check. `--scale 1e308`
// failed on a non-finite accessor without naming the option.
#[test]
fn negative_numbers_reach_the_options_range_check() {
    let dir = tempfile::tempdir().unwrap();
    let base = beam_base(dir.path());
    let glb = dir.path().join("x.glb");
    let mesh = repo_root().join("data/meshes/beam.msh");
    let out = dir.path().join("o.modes");
    for (args, needle) in [
        (
            vec!["export", s(&base), "--gltf", s(&glb), "--scale", "-1e-3"],
            "--scale",
        ),
        (
            vec!["export", s(&base), "--gltf", s(&glb), "--scale", "1e308"],
            "--scale",
        ),
        (
            vec!["bake", s(&mesh), "-o", s(&out), "--youngs", "-1e9"],
            "--youngs",
        ),
        (
            vec!["bake", s(&mesh), "-o", s(&out), "--rayleigh", "-1,0"],
            "rayleigh",
        ),
        (
            vec!["check", s(&mesh), s(&out), "--poisson", "-1.5"],
            "--poisson",
        ),
    ] {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    assert!(!out.exists() && !glb.exists());
}

// Regression: `check` said "invalid material" where `bake` names `--poisson`.
#[test]
fn check_names_the_material_option_as_bake_does() {
    let mesh = repo_root().join("data/meshes/beam.msh");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.modes");
    let o = run(&["check", s(&mesh), s(&out), "--poisson", "0.7"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--poisson 0.7"), "{err}");
}

// Every file `modal-bake` writes — each exporter (`--vtu`, `--gltf` also with `--onto`,
// `--png`), `mesh -o`, `bake -o` and `geodesic --npy` — refuses a device reached through a
// symbolic link (`out.x` → `/dev/null`) and a FIFO: the command fails naming the option, and
// the link, the device, the FIFO and the input survive unchanged.
#[test]
#[cfg(unix)]
fn every_output_refuses_a_linked_device_and_a_fifo_and_the_input_survives() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = beam_base(d);
    let before = std::fs::read(&base).unwrap();
    let asset = d.join("a.obj");
    std::fs::write(
        &asset,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let mesh = repo_root().join("data/meshes/beam.msh");
    let null = d.join("null.out");
    std::os::unix::fs::symlink("/dev/null", &null).unwrap();
    let fifo = d.join("fifo.out");
    mkfifo(&fifo);
    for (target, what) in [(&null, "a character device"), (&fifo, "a FIFO")] {
        let t = s(target);
        let commands: Vec<(Vec<&str>, &str)> = vec![
            (vec!["export", s(&base), "--vtu", t], "--vtu"),
            (vec!["export", s(&base), "--gltf", t], "--gltf"),
            (
                vec!["export", s(&base), "--gltf", t, "--onto", s(&asset)],
                "--gltf",
            ),
            (vec!["export", s(&base), "--png", t], "--png"),
            (vec!["mesh", s(&asset), "-o", t], "-o"),
            (vec!["bake", s(&mesh), "-o", t, "--fixed", "clamp"], "-o"),
            (
                vec!["geodesic", s(&base), "--from-vertex", "0", "--npy", t],
                "--npy",
            ),
        ];
        for (args, option) in commands {
            refused(&args, &[option, what]);
        }
    }
    assert_eq!(std::fs::read(&base).unwrap(), before, "the base changed");
    assert!(std::fs::symlink_metadata(&null)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let mut left: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["a.obj", "beam.modes", "fifo.out", "null.out"]);
}
