//! `dcr-lab accuracy`: options outside their range are refused before any work, naming the
//! option and what is accepted, and nothing is written.

use std::process::{Command, Output};

fn accuracy(out: &std::path::Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dcr-lab"))
        .arg("accuracy")
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("dcr-lab runs")
}

#[test]
fn bad_options_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("report");
    for (args, says) in [
        (&["--newmark-impacts", "0"][..], "--newmark-impacts"),
        (&["--newmark-impacts", "7"][..], "1..=6"),
        (&["--only", "teapot"][..], "known: table, roof, scaffold"),
        (&["--impacts", "cliff"][..], "expected NAME=N"),
        (&["--impacts", "cliff=0"][..], "from 1 to 6"),
        (&["--impacts", "cliff=x"][..], "whole number"),
        (&["--impacts", "teapot=2"][..], "--impacts teapot"),
    ] {
        let o = accuracy(&out, args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} accepted");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!out.join("accuracy.md").exists(), "{args:?} wrote a report");
    }
}

// Regression: a missing `--root` left an empty `OUT/accuracy/` behind; an `--out` that is a
// file or a device is refused before any work.
#[test]
fn a_bad_root_or_output_folder_is_refused_and_leaves_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("report");
    let o = accuracy(&out, &["--root", "/nonexistent/root", "--quick"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("--root /nonexistent/root"), "{err}");
    assert!(!out.exists(), "left {}", out.display());
    let file = dir.path().join("file");
    std::fs::write(&file, b"x").unwrap();
    for (bad, says) in [
        (file.as_path(), "a regular file"),
        ("/dev/null".as_ref(), "a character device"),
    ] {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
        let o = accuracy(bad, &["--quick", "--root", root]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(err.contains("--out") && err.contains(says), "{err}");
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}

// Regression: `--max-dense-dofs 1000000000` let a dense eigensolve of an 18k-dof mesh panic
// on a failed allocation; `--dt -1e-5` was an "unexpected argument".
#[test]
fn dense_size_and_negative_steps_are_refused_by_option() {
    let mesh = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/meshes/cube_v41.msh"
    );
    for (args, says) in [
        (
            vec!["--max-dense-dofs", "1000000000", "--method", "modal-all"],
            "--max-dense-dofs",
        ),
        (vec!["--dt", "-1e-5"], "step dt must be finite and > 0 s"),
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_dcr-lab"))
            .args([
                "truth",
                mesh,
                "--impact",
                "0.5,0.5,1",
                "--contact",
                "0.2,0.3,1",
            ])
            .args(["--impulse", "1"])
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?}");
        assert!(
            err.contains(says) && !err.contains("unexpected argument"),
            "{args:?}: {err}"
        );
    }
}
