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
