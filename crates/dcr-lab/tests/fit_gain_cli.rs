//! End-to-end tests of `dcr-lab fit-gain`: it recovers a known gain, and refuses bad targets.
//! Bases are baked into the repository's `out/bases` (as `dcr-scenes run` does).

use std::process::{Command, Output};

fn fit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dcr-lab"))
        .arg("fit-gain")
        .args(args)
        .output()
        .expect("dcr-lab runs")
}

/// The value fitted at gain 2 is given back as the target: the bisection (on log gain, over
/// the 20-mode method on dinner, a short run after the pot's landing) finds a gain near 2.
#[test]
fn recovers_a_known_gain() {
    let common = ["--method", "modal", "--members", "1", "--seconds", "0.3"];
    // The outcome at gain 2: the end points of a range [2, 2.0001] both evaluate it.
    let probe = fit(&[
        &["dinner", "--target", "plates_max_lift=0", "--min-gain", "2"][..],
        &["--max-gain", "2.0001", "--iterations", "0"],
        &common,
    ]
    .concat());
    let text = String::from_utf8_lossy(&probe.stderr).to_string();
    let lift: f64 = text
        .lines()
        .find(|l| l.contains("gain 2.0000:"))
        .and_then(|l| l.split("plates_max_lift ").nth(1))
        .and_then(|s| s.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no lift at gain 2 in:\n{text}"));
    assert!(lift > 1.0, "plates lift only {lift} mm at gain 2");
    let target = format!("plates_max_lift={lift}");
    let out = fit(&[
        &["dinner", "--target", &target, "--iterations", "14"][..],
        &common,
    ]
    .concat());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let gain: f64 = stdout
        .split("gain ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no gain in: {stdout}"));
    assert!((gain - 2.0).abs() < 0.05, "fitted gain {gain}, expected 2");
}

/// A malformed target, an unknown outcome, a placement distance of half a metre and a target the
/// range cannot reach are refused with a message naming the problem.
#[test]
fn bad_targets_are_refused() {
    for (args, needle) in [
        (
            vec!["dinner", "--target", "plates_max_lift"],
            "OUTCOME=VALUE",
        ),
        (vec!["dinner", "--target", "plates=1"], "no outcome plates"),
        (
            vec![
                "dinner",
                "--target",
                "plates_max_lift=1",
                "--perturbation",
                "0.5",
            ],
            "outside [0, 0.01) m",
        ),
        (
            vec![
                "dinner",
                "--target",
                "plates_max_lift=1e6",
                "--method",
                "modal",
                "--members",
                "1",
                "--seconds",
                "0.25",
                "--max-gain",
                "2",
            ],
            "does not cross",
        ),
    ] {
        let out = fit(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}
