//! An installed dcr, as a C or C++ engine's build finds it: `cargo cinstall -p dcr-capi`
//! (cargo-c) into a fresh prefix installs
//! - `include/dcr/dcr.h` (the committed header, byte for byte) and `include/dcr/dcr_bullet.hpp`;
//! - `lib/libdcr_capi.so` (SONAME `libdcr_capi.so`) and `lib/libdcr_capi.a`;
//! - `lib/pkgconfig/dcr.pc`: `pkg-config --cflags --libs dcr` is `-I…/include/dcr -L…/lib
//!   -ldcr_capi`, `--static` adds the Rust standard library's system libraries, `--modversion`
//!   is the crate's version;
//!
//! and from that prefix alone `examples/world.c` builds with `-Wall -Wextra -Werror -pedantic`
//! through pkg-config, shared and static (no `libdcr_capi.so` needed at run time), and through
//! `cmake/CMakeLists.txt` without `DCR_ROOT` (its pkg-config route), shared and static; every
//! build runs the documented steps with the same output (one impulse event, at the impact
//! step), and the Bullet adapter compiles from the installed include directory. Without
//! cargo-c the test skips with the command that installs it, and fails instead under
//! `DCR_REQUIRE_CARGO_C=1` (as CI sets it).

mod common;

use std::path::Path;
use std::process::Command;

use common::NATIVE_LIBS;
use common::{bake_cube, cc, crate_dir, cxx, profile_dir, run_ok, run_world, workspace};

/// The pinned cargo-c release: the newest whose embedded cargo builds with Rust 1.95 (the
/// workspace's highest `rust-version`).
const CARGO_C: &str = "0.10.24+cargo-0.98.0";

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}

/// Whether `cargo cinstall` exists; `false` (after saying how to install it) when it does not
/// and `DCR_REQUIRE_CARGO_C` is not 1.
fn have_cargo_c() -> bool {
    let ok = Command::new(cargo())
        .args(["cinstall", "--version"])
        .output()
        .is_ok_and(|o| o.status.success());
    let how = format!(
        "cargo-c is not installed: `cargo install cargo-c --version ={CARGO_C} --locked` \
         (needs libssl-dev and pkg-config; .ci/run installs it)"
    );
    if !ok && std::env::var("DCR_REQUIRE_CARGO_C").as_deref() == Ok("1") {
        panic!("{how} (DCR_REQUIRE_CARGO_C=1)");
    }
    if !ok {
        eprintln!("SKIPPED: {how}");
    }
    ok
}

/// `pkg-config ARGS dcr` against `prefix`'s `dcr.pc` only.
fn pkg_config(prefix: &Path, args: &[&str]) -> String {
    let o = run_ok(
        Command::new("pkg-config")
            .args(args)
            .arg("dcr")
            .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig"))
            .env("PKG_CONFIG_LIBDIR", prefix.join("lib/pkgconfig")),
    );
    String::from_utf8(o.stdout).unwrap().trim().to_string()
}

fn words(s: &str) -> Vec<String> {
    s.split_whitespace().map(str::to_string).collect()
}

/// The `NEEDED` entries of an ELF file (`readelf -d`).
fn needed(bin: &Path) -> String {
    let o = run_ok(Command::new("readelf").arg("-d").arg(bin));
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter(|l| l.contains("(NEEDED)") || l.contains("(SONAME)"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn cargo_c_installs_a_prefix_that_pkg_config_and_cmake_build_against() {
    if !have_cargo_c() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("prefix");
    // cargo-c builds for an explicit target triple with flags of its own: a target directory
    // of its own beside this profile's, kept across runs so that a rerun only relinks.
    let target = profile_dir().parent().unwrap().join("cargo-c");
    let mut install = Command::new(cargo());
    install
        .current_dir(workspace())
        .args(["cinstall", "-p", "dcr-capi"])
        .arg("--prefix")
        .arg(&prefix)
        .arg("--libdir")
        .arg(prefix.join("lib"))
        .arg("--target-dir")
        .arg(&target);
    if profile_dir().file_name().is_some_and(|n| n == "release") {
        install.arg("--release");
    }
    run_ok(&mut install);

    // What is installed.
    let inc = prefix.join("include/dcr");
    let lib = prefix.join("lib");
    for (installed, source) in [
        (inc.join("dcr.h"), crate_dir().join("include/dcr.h")),
        (
            inc.join("dcr_bullet.hpp"),
            crate_dir().join("integrations/bullet/dcr_bullet.hpp"),
        ),
    ] {
        assert_eq!(
            std::fs::read(&installed).unwrap_or_else(|e| panic!("{}: {e}", installed.display())),
            std::fs::read(&source).unwrap(),
            "{} differs from {}",
            installed.display(),
            source.display()
        );
    }
    assert!(lib.join("libdcr_capi.a").is_file());
    let so = lib.join("libdcr_capi.so");
    assert!(
        needed(&so).contains("Library soname: [libdcr_capi.so]"),
        "{}",
        needed(&so)
    );

    // dcr.pc.
    assert_eq!(
        pkg_config(&prefix, &["--cflags", "--libs"]),
        format!("-I{} -L{} -ldcr_capi", inc.display(), lib.display())
    );
    assert_eq!(
        pkg_config(&prefix, &["--modversion"]),
        env!("CARGO_PKG_VERSION")
    );
    let static_libs = words(&pkg_config(&prefix, &["--static", "--libs"]));
    for l in NATIVE_LIBS {
        assert!(
            static_libs.iter().any(|w| w == l),
            "{l} not in {static_libs:?}"
        );
    }

    // world.c through pkg-config: shared, then static.
    let base = bake_cube(dir.path());
    let src = crate_dir().join("examples/world.c");
    let cflags = words(&pkg_config(&prefix, &["--cflags"]));
    let strict = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"];
    let shared = dir.path().join("world_shared");
    run_ok(
        Command::new(cc())
            .args(strict)
            .args(&cflags)
            .arg(&src)
            .args(words(&pkg_config(&prefix, &["--libs"])))
            .arg(format!("-Wl,-rpath,{}", lib.display()))
            .arg("-o")
            .arg(&shared),
    );
    assert!(
        needed(&shared).contains("libdcr_capi.so"),
        "{}",
        needed(&shared)
    );
    let reference = run_world(&shared, &base, "pkg-config, shared");
    let fixed = dir.path().join("world_static");
    run_ok(
        Command::new(cc())
            .args(strict)
            .args(&cflags)
            .arg(&src)
            .args(["-Wl,-Bstatic", "-ldcr_capi", "-Wl,-Bdynamic"])
            .args(&static_libs)
            .arg("-o")
            .arg(&fixed),
    );
    assert!(
        !needed(&fixed).contains("libdcr_capi"),
        "{}",
        needed(&fixed)
    );
    assert_eq!(run_world(&fixed, &base, "pkg-config, static"), reference);

    // cmake/CMakeLists.txt without DCR_ROOT: its pkg-config route.
    for static_link in [false, true] {
        let build = dir.path().join(format!("cmake-static-{static_link}"));
        let env = prefix.join("lib/pkgconfig");
        run_ok(
            Command::new("cmake")
                .arg("-S")
                .arg(crate_dir().join("cmake"))
                .arg("-B")
                .arg(&build)
                .arg(format!(
                    "-DDCR_STATIC={}",
                    if static_link { "ON" } else { "OFF" }
                ))
                .arg("-DCMAKE_BUILD_TYPE=Release")
                .env("PKG_CONFIG_PATH", &env)
                .env("PKG_CONFIG_LIBDIR", &env),
        );
        run_ok(Command::new("cmake").arg("--build").arg(&build));
        let bin = build.join("world");
        assert_eq!(
            needed(&bin).contains("libdcr_capi.so"),
            !static_link,
            "{}",
            needed(&bin)
        );
        let what = format!("CMake, static {static_link}");
        assert_eq!(run_world(&bin, &base, &what), reference, "{what}");
    }

    // The Bullet adapter from the installed include directory (with Bullet's own flags).
    let bullet = Command::new("pkg-config")
        .args(["--cflags", "bullet"])
        .output();
    match bullet {
        Ok(o) if o.status.success() => {
            let tu = dir.path().join("adapter.cpp");
            std::fs::write(
                &tu,
                "#include \"dcr_bullet.hpp\"\nint main() { return 0; }\n",
            )
            .unwrap();
            run_ok(
                Command::new(cxx())
                    .args(["-std=c++17", "-Wall", "-Wextra", "-Werror", "-pedantic"])
                    .args(["-fsyntax-only"])
                    .args(&cflags)
                    .args(words(&String::from_utf8_lossy(&o.stdout)))
                    .arg(&tu),
            );
        }
        _ if std::env::var("DCR_REQUIRE_BULLET").as_deref() == Ok("1") => {
            panic!("Bullet is missing (`apt-get install libbullet-dev`; DCR_REQUIRE_BULLET=1)")
        }
        _ => eprintln!("Bullet is missing: the installed adapter is not compiled"),
    }
}
