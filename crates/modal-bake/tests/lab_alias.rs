//! `modal-bake truth` and `modal-bake fit-attenuation` run the `dcr-lab` executable with the same
//! subcommand and arguments, say so in one line on stderr, and exit with its exit code.
//!
//! A stand-in script plays `dcr-lab` (through `DCR_LAB`), so these tests do not need the lab
//! built; `crates/dcr-lab/tests` test the tools themselves.

#![cfg(unix)]

use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::Command;

/// A fake `dcr-lab` that prints its arguments one per line and exits with `code`.
fn fake_lab(dir: &Path, code: i32) -> std::path::PathBuf {
    let p = dir.join("fake-dcr-lab");
    std::fs::write(
        &p,
        format!("#!/bin/sh\nfor a in \"$@\"; do echo \"$a\"; done\nexit {code}\n"),
    )
    .unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    p
}

#[test]
fn aliases_forward_every_argument_and_the_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    for (sub, code) in [("truth", 0), ("fit-attenuation", 3)] {
        let lab = fake_lab(dir.path(), code);
        let out = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
            .env("DCR_LAB", &lab)
            .args([sub, "mesh.msh", "--impact", "-1,0.5,0", "--json", "--help"])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let args: Vec<&str> = stdout.lines().collect();
        // A negative value is joined to its option (`--impact=-1,0.5,0`: the same to clap, and
        // never taken for an option of its own).
        assert_eq!(
            args,
            [sub, "mesh.msh", "--impact=-1,0.5,0", "--json", "--help"]
        );
        assert_eq!(out.status.code(), Some(code), "{sub}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(&format!("dcr-lab {sub}")), "{err}");
    }
}

#[test]
fn a_missing_lab_is_a_clear_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .env("DCR_LAB", "/nonexistent/dcr-lab")
        .args(["truth", "x.msh"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(err.contains("cargo build --release -p dcr-lab"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}
