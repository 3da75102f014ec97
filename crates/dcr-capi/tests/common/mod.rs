//! Shared set-up of the C tests: the C compiler, the freshly built libraries, the modal-bake
//! binary and a small baked base.
//!
//! The tests that need a C compiler fail (they do not skip) when `cc` is missing: CI installs
//! one (`.ci/run`), and a skipped ABI test would pass silently.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// This crate's directory.
pub fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The directory holding this test binary (`target/<profile>/deps`): cargo builds the crate's
/// `libdcr_capi.a` and `libdcr_capi.so` there, in the same compilation as the rlib the test
/// links, so they are never stale.
pub fn deps_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    exe.parent().expect("deps dir").to_path_buf()
}

/// `target/<profile>`.
pub fn profile_dir() -> PathBuf {
    deps_dir().parent().expect("profile dir").to_path_buf()
}

/// The static library built with this test.
pub fn static_lib() -> PathBuf {
    let p = deps_dir().join("libdcr_capi.a");
    assert!(p.is_file(), "{} is missing", p.display());
    p
}

/// The shared library built with this test.
pub fn shared_lib() -> PathBuf {
    let p = deps_dir().join("libdcr_capi.so");
    assert!(p.is_file(), "{} is missing", p.display());
    p
}

/// The system libraries the Rust static library needs (`rustc --print native-static-libs`).
pub const NATIVE_LIBS: [&str; 7] = [
    "-lgcc_s",
    "-lutil",
    "-lrt",
    "-lpthread",
    "-lm",
    "-ldl",
    "-lc",
];

/// `cc` (or `$CC`), which must exist: a missing compiler fails the test with a way to fix it.
pub fn cc() -> String {
    compiler("CC", "cc")
}

/// `c++` (or `$CXX`), which must exist.
pub fn cxx() -> String {
    compiler("CXX", "c++")
}

fn compiler(var: &str, default: &str) -> String {
    let c = std::env::var(var).unwrap_or_else(|_| default.to_string());
    let ok = Command::new(&c)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        ok,
        "no C/C++ compiler `{c}` on PATH: the C ABI tests need one (Debian: `apt-get install \
         build-essential`; .ci/run installs it)"
    );
    c
}

/// Runs `cmd`, panicking with its output when it does not succeed.
pub fn run_ok(cmd: &mut Command) -> Output {
    let o = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    assert!(
        o.status.success(),
        "{cmd:?} failed ({}):\nstdout:\n{}\nstderr:\n{}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// How a C program links the library.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    /// `libdcr_capi.a` and the native libraries.
    Static,
    /// `libdcr_capi.so` with an rpath to its directory.
    Shared,
}

/// Compiles the C sources `srcs` into `out` as C99 with `-Wall -Wextra -Werror -pedantic`,
/// linked against the library; `sanitize` adds AddressSanitizer (with leak detection at run
/// time) and debug info.
pub fn build_c(srcs: &[PathBuf], out: &Path, link: Link, sanitize: bool) {
    let mut cmd = Command::new(cc());
    cmd.args([
        "-std=c99",
        "-Wall",
        "-Wextra",
        "-Werror",
        "-pedantic",
        "-O1",
    ])
    .arg("-I")
    .arg(crate_dir().join("include"))
    .args(srcs)
    .arg("-o")
    .arg(out);
    if sanitize {
        cmd.args(["-g", "-fsanitize=address", "-fno-omit-frame-pointer"]);
    }
    match link {
        Link::Static => {
            cmd.arg(static_lib()).args(NATIVE_LIBS);
        }
        Link::Shared => {
            let lib = shared_lib();
            let dir = lib.parent().unwrap().to_path_buf();
            cmd.arg("-L")
                .arg(&dir)
                .arg("-ldcr_capi")
                .arg(format!("-Wl,-rpath,{}", dir.display()))
                .arg("-lm");
        }
    }
    run_ok(&mut cmd);
}

/// Environment for a sanitized run: leaks and invalid accesses are errors with exit code 23.
pub fn asan_env(cmd: &mut Command) -> &mut Command {
    cmd.env(
        "ASAN_OPTIONS",
        "detect_leaks=1:exitcode=23:abort_on_error=0:halt_on_error=1:detect_stack_use_after_return=1",
    )
    .env("LSAN_OPTIONS", "exitcode=23")
}

/// Asserts a sanitized run reported no AddressSanitizer / LeakSanitizer error.
pub fn assert_clean(o: &Output, what: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.code() != Some(23) && !err.contains("Sanitizer"),
        "{what}: sanitizer report (exit {}):\n{err}",
        o.status
    );
}

/// The `modal-bake` binary of this workspace: `target/<profile>/modal-bake` when it is newer
/// than every source it is built from (as after `cargo test --workspace`, which builds it for
/// modal-bake's own tests), else built (once per test binary) by a nested `cargo build`.
pub fn modal_bake() -> PathBuf {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        let bin = profile_dir().join("modal-bake");
        if is_fresh(&bin) {
            return bin;
        }
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut cmd = Command::new(cargo);
        cmd.current_dir(workspace()).args([
            "build",
            "-q",
            "-p",
            "modal-bake",
            "--bin",
            "modal-bake",
        ]);
        if profile_dir().file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        run_ok(&mut cmd);
        assert!(bin.is_file(), "{} is missing", bin.display());
        bin
    })
    .clone()
}

/// Whether `bin` exists and is newer than modal-bake's and dcr-runtime's sources, manifests
/// and the lock file.
fn is_fresh(bin: &Path) -> bool {
    fn newest(p: &Path, t: &mut std::time::SystemTime) {
        let Ok(meta) = std::fs::metadata(p) else {
            return;
        };
        if meta.is_dir() {
            for e in std::fs::read_dir(p).into_iter().flatten().flatten() {
                newest(&e.path(), t);
            }
        } else if let Ok(m) = meta.modified() {
            *t = (*t).max(m);
        }
    }
    let Ok(built) = std::fs::metadata(bin).and_then(|m| m.modified()) else {
        return false;
    };
    let mut t = std::time::SystemTime::UNIX_EPOCH;
    let w = workspace();
    for p in [
        "crates/modal-bake/src",
        "crates/modal-bake/Cargo.toml",
        "crates/dcr-runtime/src",
        "crates/dcr-runtime/Cargo.toml",
        "Cargo.lock",
    ] {
        newest(&w.join(p), &mut t);
    }
    built > t
}

/// Runs the world example `bin` (`examples/world.c` built) on `base` (a [`bake_cube`] base)
/// for 10 steps and checks the documented outcome: 10 step lines and one impulse event, at the
/// impact step 7. Returns its output; `what` names the build in a failure.
pub fn run_world(bin: &Path, base: &Path, what: &str) -> String {
    let o = run_ok(
        Command::new(bin)
            .arg(base)
            .arg("10")
            .env_remove("LD_LIBRARY_PATH"),
    );
    let out = String::from_utf8(o.stdout).unwrap();
    let steps = out.lines().filter(|l| l.starts_with("step ")).count();
    let events: Vec<&str> = out.lines().filter(|l| l.starts_with("event ")).collect();
    assert_eq!(steps, 10, "{what}: {out}");
    assert_eq!(events.len(), 1, "{what}: {out}");
    assert!(events[0].starts_with("event 7 "), "{what}: {}", events[0]);
    out
}

/// A small free-free base baked from `data/meshes/cube_v41.msh` (unit cube, 8 modes) into
/// `dir`.
pub fn bake_cube(dir: &Path) -> PathBuf {
    let out = dir.join("cube.modes");
    let mesh = workspace().join("data/meshes/cube_v41.msh");
    run_ok(
        Command::new(modal_bake())
            .arg("bake")
            .arg(&mesh)
            .arg("-o")
            .arg(&out)
            .args(["--modes", "8"]),
    );
    out
}
