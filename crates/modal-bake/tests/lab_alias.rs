//! `modal-bake truth` and `modal-bake fit-attenuation` moved to `dcr-lab`: whatever the
//! arguments (`--help` included), they say which `dcr-lab` subcommand to run, in one line, and
//! fail without running anything. `crates/dcr-lab/tests` test the tools themselves.

use std::process::Command;

#[test]
fn moved_subcommands_name_their_dcr_lab_replacement_and_fail() {
    for sub in ["truth", "fit-attenuation"] {
        for args in [
            vec![sub, "mesh.msh", "--impact", "-1,0.5,0", "--json"],
            vec![sub, "--help"],
            vec![sub],
        ] {
            let out = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
                .env("DCR_LAB", "/bin/true")
                .args(&args)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
            assert!(out.stdout.is_empty(), "{args:?}");
            assert_eq!(err.trim().lines().count(), 1, "{err}");
            assert!(err.contains(&format!("dcr-lab {sub}")), "{err}");
            assert!(err.contains("cargo build --release -p dcr-lab"), "{err}");
            assert!(!err.contains("panicked"), "{err}");
        }
    }
}
