//! Builds `shim/random_device.c` into a shared object that the fTetWild backend loads into its
//! child process to make fTetWild's output reproducible (see that file). Linux only; elsewhere,
//! or without a C compiler, an empty file is embedded and the backend says its meshes may
//! differ between runs.
//!
//! Also sets `MODAL_BAKE_BUILD_HASH`: a SHA-256 of every source file of this crate and of the
//! workspace crates it builds on (`dcr-runtime`, `dcr-files`), `Cargo.toml`, the workspace's
//! `Cargo.lock`, the compiler's version and the target — what makes two builds mesh an asset
//! alike (`mesh::BUILD_HASH`).

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

/// Every file under `dir`, sorted, as (path relative to `root`, bytes).
fn files(root: &Path, dir: &Path, out: &mut Vec<(String, Vec<u8>)>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            files(root, &p, out);
        } else if let Ok(bytes) = std::fs::read(&p) {
            let rel = p.strip_prefix(root).unwrap_or(&p).display().to_string();
            out.push((rel, bytes));
        }
    }
}

fn build_hash() -> String {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let mut all = Vec::new();
    for dir in ["src", "shim", "../dcr-runtime/src", "../dcr-files/src"] {
        let d = manifest.join(dir);
        println!("cargo:rerun-if-changed={}", d.display());
        files(&manifest, &d, &mut all);
    }
    for file in ["Cargo.toml", "../../Cargo.lock"] {
        let f = manifest.join(file);
        println!("cargo:rerun-if-changed={}", f.display());
        if let Ok(bytes) = std::fs::read(&f) {
            all.push((file.to_string(), bytes));
        }
    }
    let mut h = Sha256::new();
    for (name, bytes) in &all {
        h.update((name.len() as u64).to_le_bytes());
        h.update(name.as_bytes());
        h.update((bytes.len() as u64).to_le_bytes());
        h.update(bytes);
    }
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = std::process::Command::new(rustc)
        .arg("-V")
        .output()
        .map(|o| o.stdout)
        .unwrap_or_default();
    h.update(&version);
    h.update(std::env::var("TARGET").unwrap_or_default().as_bytes());
    format!("sha256:{:x}", h.finalize())
}

fn main() {
    println!("cargo:rerun-if-changed=shim/random_device.c");
    println!("cargo:rustc-env=MODAL_BAKE_BUILD_HASH={}", build_hash());
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"))
        .join("random_device_shim.so");
    let linux = std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux");
    let built = linux
        && cc::Build::new()
            .get_compiler()
            .to_command()
            .args(["-shared", "-fPIC", "-O2", "-o"])
            .arg(&out)
            .arg("shim/random_device.c")
            .status()
            .is_ok_and(|s| s.success());
    if !built {
        println!("cargo:warning=fTetWild random_device shim not built: fTetWild meshes may differ between runs");
        std::fs::write(&out, b"").expect("OUT_DIR is writable");
    }
}
