//! Gives the shared library an SONAME (`libdcr_capi.so`) on Linux, so programs linked against
//! it by full path (CMake) record the library's name, not the build path.

fn main() {
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libdcr_capi.so");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
