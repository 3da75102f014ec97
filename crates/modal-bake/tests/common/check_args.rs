//! The options `modal-bake info BASE --json` rebuilds from a base's record (`check_args`):
//! the tests check a base with them.

use std::path::Path;
use std::process::Command;

/// `check_args.args` of `info base --json` (panics when the base has none).
pub fn check_args(base: &Path) -> Vec<String> {
    let o = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .arg("info")
        .arg(base)
        .arg("--json")
        .output()
        .expect("modal-bake runs");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("info --json");
    v["check_args"]["args"]
        .as_array()
        .unwrap_or_else(|| panic!("no check_args: {v}"))
        .iter()
        .map(|x| x.as_str().expect("a word").to_string())
        .collect()
}
