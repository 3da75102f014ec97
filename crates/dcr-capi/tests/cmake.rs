//! The CMake snippet of docs/engine-integration.md ("C and C++"), which is
//! `cmake/CMakeLists.txt` verbatim, configures, builds `examples/world.c` against the static
//! and the shared library found with `find_path` / `find_library` under a dcr checkout's
//! layout, and the program runs. Fails (never skips) when cmake is missing: CI installs it.
//! Unix (the shared library's name and links); the Windows build of the example is
//! `scripts/windows_check.py`'s.
#![cfg(unix)]

mod common;

use std::path::Path;
use std::process::Command;

use common::{bake_cube, crate_dir, run_ok, run_world, shared_lib, static_lib, workspace};

fn cmake() -> &'static str {
    let ok = Command::new("cmake")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        ok,
        "cmake is not installed: the CMake snippet test needs it (Debian: `apt-get install \
         cmake`; .ci/run installs it)"
    );
    "cmake"
}

#[cfg(unix)]
fn link(src: &Path, dst: &Path) {
    std::os::unix::fs::symlink(src, dst).unwrap();
}

/// The documented snippet is the file the test builds.
#[test]
fn docs_show_the_tested_cmake_snippet() {
    let file = std::fs::read_to_string(crate_dir().join("cmake/CMakeLists.txt")).unwrap();
    let docs = std::fs::read_to_string(workspace().join("docs/engine-integration.md")).unwrap();
    assert!(
        docs.contains(&file),
        "docs/engine-integration.md must quote crates/dcr-capi/cmake/CMakeLists.txt verbatim"
    );
}

/// `cmake -DDCR_ROOT=…` finds the header and the library (static and shared) in a checkout's
/// layout, builds world.c with -Wall -Wextra -Werror, and the program runs the documented
/// steps (one impulse event, at the impact step).
#[test]
fn cmake_snippet_builds_and_runs_the_world_example() {
    let cmake = cmake();
    let dir = tempfile::tempdir().unwrap();
    let base = bake_cube(dir.path());
    // A dcr checkout's layout: crates/dcr-capi/include and target/release with the libraries
    // built with this test.
    let root = dir.path().join("dcr");
    std::fs::create_dir_all(root.join("crates/dcr-capi")).unwrap();
    std::fs::create_dir_all(root.join("target/release")).unwrap();
    link(
        &crate_dir().join("include"),
        &root.join("crates/dcr-capi/include"),
    );
    link(&static_lib(), &root.join("target/release/libdcr_capi.a"));
    link(&shared_lib(), &root.join("target/release/libdcr_capi.so"));
    for static_link in [false, true] {
        let build = dir.path().join(format!("build-static-{static_link}"));
        run_ok(
            Command::new(cmake)
                .arg("-S")
                .arg(crate_dir().join("cmake"))
                .arg("-B")
                .arg(&build)
                .arg(format!("-DDCR_ROOT={}", root.display()))
                .arg(format!(
                    "-DDCR_STATIC={}",
                    if static_link { "ON" } else { "OFF" }
                ))
                .arg("-DCMAKE_BUILD_TYPE=Release"),
        );
        run_ok(Command::new(cmake).arg("--build").arg(&build));
        run_world(
            &build.join("world"),
            &base,
            &format!("static {static_link}"),
        );
        // The shared build really loads the shared library.
        if !static_link {
            let ldd = Command::new("ldd").arg(build.join("world")).output();
            if let Ok(l) = ldd {
                let text = String::from_utf8_lossy(&l.stdout);
                assert!(text.contains("libdcr_capi.so"), "{text}");
            }
        }
    }
}
