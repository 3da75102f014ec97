//! The gate of the tests that run the real meshio (PyPI) through `python3`: they skip with a
//! message when meshio is not installed, unless under CI (`CI` set; `.ci/run` installs it),
//! where they fail.
#![allow(dead_code)]

/// Runs the Python `body` after `import json, sys, meshio`, with `args` as `sys.argv[1:]`,
/// and returns what it printed; `None` (the test skips) when meshio is not installed outside
/// CI.
///
/// # Panics
/// When python3 does not run, the script fails, or meshio is missing under CI.
pub fn run_with_meshio(body: &str, args: &[&std::ffi::OsStr]) -> Option<String> {
    let script = format!(
        "import json, sys\ntry:\n    import meshio\nexcept ImportError:\n    \
         print(\"NO_MESHIO\"); sys.exit(0)\n{body}"
    );
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "meshio failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    if text.trim() == "NO_MESHIO" {
        assert!(
            std::env::var_os("CI").is_none(),
            "meshio is not installed under CI"
        );
        eprintln!("SKIPPED: meshio not installed (pip install meshio)");
        return None;
    }
    Some(text)
}
