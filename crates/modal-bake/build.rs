//! Builds `shim/random_device.c` into a shared object that the fTetWild backend loads into its
//! child process to make fTetWild's output reproducible (see that file). Linux only; elsewhere,
//! or without a C compiler, an empty file is embedded and the backend says its meshes may
//! differ between runs.

use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=shim/random_device.c");
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
