//! SIGINT and SIGTERM to the real `dcr-scenes` binary while it bakes a missing base: the
//! process ends by that signal, and it leaves no `.NAME.modes.tmp-*` beside the base and no
//! half-written output — the base is either absent or a whole, readable base, and the run's
//! output folder holds no file. Without the tools' signal handler in `dcr-scenes`, a signal
//! during the base's write leaves its temporary for ever (the second test fails).

use std::io::{BufRead, BufReader};
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use dcr_scenes::repo_root;

/// Every file under `dir` (relative names), or nothing when it does not exist.
fn names(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd.flatten() {
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                stack.push(e.path());
            } else {
                out.push(e.path().strip_prefix(dir).unwrap().display().to_string());
            }
        }
    }
    out
}

/// `dcr-scenes run SCENE` with empty bases and output folders under `dir` (its elastic
/// object's base is baked first: the roof's in a fifth of a second, the cliff's in most of a
/// second).
fn start(dir: &Path, scene: &str) -> Child {
    Command::new(env!("CARGO_BIN_EXE_dcr-scenes"))
        .args(["run", scene, "--seconds", "0.05", "--dcr", "on", "--out"])
        .arg(dir.join("out"))
        .arg("--bases")
        .arg(dir.join("bases"))
        .env("DCR_ROOT", repo_root())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn kill(child: &Child, signal: &str) {
    let ok = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok, "kill {signal}");
}

/// Checks what a signalled run left in `dir`.
fn check_left(dir: &Path, what: &str) {
    let bases = names(&dir.join("bases"));
    assert!(
        bases.iter().all(|n| !n.contains(".tmp-")),
        "{what}: temporaries left: {bases:?}"
    );
    for n in &bases {
        dcr_runtime::format::ModesFile::read(&dir.join("bases").join(n))
            .unwrap_or_else(|e| panic!("{what}: {n} is not a whole base: {e}"));
    }
    // The run's outputs are written after the bake, through the atomic writer.
    let out = names(&dir.join("out"));
    assert!(
        out.iter().all(|n| !n.contains(".tmp-")),
        "{what}: temporaries among the outputs: {out:?}"
    );
}

#[test]
fn a_signal_during_a_base_bake_leaves_no_temporary_and_no_partial_output() {
    for (signal, number) in [("-INT", 2), ("-TERM", 15)] {
        let dir = tempfile::tempdir().unwrap();
        let mut child = start(dir.path(), "rockfall");
        // Signal as soon as the bake has started.
        let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
        assert!(
            lines.any(|l| l.is_ok_and(|l| l.contains("[dcr-scenes] baking cliff"))),
            "{signal}: the base bake never started"
        );
        kill(&child, signal);
        let status = child.wait().unwrap();
        assert_eq!(
            status.signal(),
            Some(number),
            "{signal}: the run ended by {status:?}, not by the signal"
        );
        check_left(dir.path(), signal);
        // The cliff's bake takes most of a second, the signal milliseconds: it lands in the
        // bake, before the base and any output exist.
        let bases = names(&dir.path().join("bases"));
        let out = names(&dir.path().join("out"));
        assert!(
            bases.is_empty() && out.is_empty(),
            "{signal}: written although the bake was interrupted: {bases:?} {out:?}"
        );
    }
}

// The temporary exists only while the base is written (milliseconds); the signal is sent the
// moment it is seen (up to five tries per signal to see it). Whether the signal lands before
// or after the rename, what is left is a whole base or none, and no temporary. Without the
// handler this leaves `.roof.modes.tmp-HOST-PID-…`.
#[test]
fn a_signal_while_the_base_is_written_leaves_a_whole_base_or_none() {
    let mut caught = 0;
    for signal in ["-INT", "-TERM"] {
        for _attempt in 0..5 {
            let dir = tempfile::tempdir().unwrap();
            let bases = dir.path().join("bases");
            let mut child = start(dir.path(), "roof");
            let stderr = child.stderr.take().unwrap();
            std::thread::spawn(move || {
                std::io::copy(&mut BufReader::new(stderr), &mut std::io::sink())
            });
            let t = Instant::now();
            let mut seen = false;
            while t.elapsed() < Duration::from_secs(120) {
                if names(&bases).iter().any(|n| n.contains(".tmp-")) {
                    kill(&child, signal);
                    seen = true;
                    break;
                }
                if child.try_wait().unwrap().is_some() {
                    break;
                }
            }
            if !seen {
                // The write was too quick to catch: end the run and try again.
                let _ = child.kill();
            }
            child.wait().unwrap();
            let left = names(&bases);
            assert!(
                left.iter().all(|n| !n.contains(".tmp-")),
                "{signal}: temporaries left: {left:?}"
            );
            for n in &left {
                dcr_runtime::format::ModesFile::read(&bases.join(n))
                    .unwrap_or_else(|e| panic!("{signal}: {n} is not a whole base: {e}"));
            }
            if seen {
                caught += 1;
                break;
            }
        }
    }
    assert!(caught > 0, "never signalled while the base was written");
}
