//! `dcr-lab scene-truth`'s per-scene settings: `--scene-seconds SCENE=S` and `--scene-dt
//! SCENE=S` reach that scene's run over `--seconds` and `--dt`, and malformed or foreign values
//! of either are refused before any run; `--no-prop-feedback` is refused with `--page`;
//! every scene is planned before any runs.

use std::process::{Command, Output};

fn scene_truth(args: &[&str]) -> Output {
    let cache = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("scene_truth_cli_cache");
    Command::new(env!("CARGO_BIN_EXE_dcr-lab"))
        .arg("scene-truth")
        .args(args)
        .arg("--eigen-cache")
        .arg(&cache)
        .output()
        .expect("dcr-lab runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// Dinner's pot first touches the table 0.17 s in: 0.05 s for dinner alone (over a --seconds
/// that would run) stops before its first contact, and the error quotes the scene's 0.05 s.
#[test]
fn scene_seconds_reach_their_scene() {
    let o = scene_truth(&[
        "dinner",
        "--seconds",
        "0.45",
        "--scene-seconds",
        "dinner=0.05",
    ]);
    let e = stderr(&o);
    assert!(!o.status.success(), "{e}");
    assert!(
        e.contains("first contact comes after the 0.05 s simulated"),
        "{e}"
    );
}

/// A first step of 1 ns for dinner alone (over the default --dt, which fits) puts its finest
/// run above the work budget, refused before it starts.
#[test]
fn scene_dt_reaches_its_scene() {
    let o = scene_truth(&["dinner", "--seconds", "0.45", "--scene-dt", "dinner=1e-9"]);
    let e = stderr(&o);
    assert!(!o.status.success(), "{e}");
    assert!(e.contains("above the budget"), "{e}");
}

/// Refused with the value and what is expected: no `=`, a non-number, a non-positive time, a
/// scene not run.
#[test]
fn malformed_scene_seconds_are_refused() {
    for (v, says) in [
        ("dinner", "expected SCENE=SECONDS"),
        ("dinner=soon", "is not a number of seconds"),
        ("dinner=-1", "positive seconds"),
        ("dinner=NaN", "positive seconds"),
        ("roof=1", "not among the scenes run"),
    ] {
        for flag in ["--scene-seconds", "--scene-dt"] {
            let o = scene_truth(&["dinner", flag, v]);
            let e = stderr(&o);
            assert!(!o.status.success(), "{flag} {v}: {e}");
            assert!(e.contains(says), "{flag} {v}: {e}");
        }
    }
}

/// `--no-prop-feedback` measures an assumption; with `--page` it is refused before any run
/// (the page compares the methods with the two-way reference).
#[test]
fn no_prop_feedback_is_refused_with_the_page() {
    let page = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("no_feedback_page");
    let o = scene_truth(&[
        "dinner",
        "--no-prop-feedback",
        "--page",
        page.to_str().expect("utf-8 path"),
    ]);
    let e = stderr(&o);
    assert!(!o.status.success(), "{e}");
    assert!(
        e.contains("--no-prop-feedback") && e.contains("--page"),
        "{e}"
    );
    assert!(!page.join("outcomes.md").exists(), "nothing written");
}

/// Every scene is planned before any runs: the scaffold over a dense limit it exceeds stops the
/// command with that scene named, and dinner (which could run) has not started a run.
#[test]
fn a_scene_that_cannot_run_stops_the_others_before_they_start() {
    let o = scene_truth(&["dinner", "scaffold", "--max-dense-dofs", "6000"]);
    let e = stderr(&o);
    assert!(!o.status.success(), "{e}");
    assert!(
        e.contains("nothing was run; 1 of 2 scenes cannot be") && e.contains("scaffold:"),
        "{e}"
    );
    assert!(e.contains("above the dense limit 6000"), "{e}");
    assert!(!e.contains("dinner dt"), "dinner started a run: {e}");
}
