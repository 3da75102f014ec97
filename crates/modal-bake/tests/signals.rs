//! Signals during a write: SIGINT and SIGTERM remove the temporary being written and end the
//! process by that signal; after SIGKILL (which cannot be caught) the next write of the same
//! destination removes the dead writer's temporary.
//!
//! The writer is this test binary run again as a child (`child_writer` with
//! `DCR_SIGNAL_CHILD_DIR` set): it installs the CLI's handler, starts an atomic write, prints
//! `ready` and waits to be signalled.
//!
//! Unix signals only: Windows' console events and forced ends are checked on the Windows build
//! under Wine by `scripts/windows_check.py`.
#![cfg(unix)]

use std::io::{BufRead, BufReader, Write};
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, Stdio};

const CHILD_ENV: &str = "DCR_SIGNAL_CHILD_DIR";

/// In the child: a write in progress that never finishes. In a normal test run: nothing.
#[test]
fn child_writer() {
    let Ok(dir) = std::env::var(CHILD_ENV) else {
        return;
    };
    modal_bake::signals::remove_temporaries_on_signals().unwrap();
    let dest = Path::new(&dir).join("out.modes");
    let mut f = dcr_files::AtomicFile::create(&dest).unwrap();
    f.write_all(&[7u8; 1 << 20]).unwrap();
    f.flush().unwrap();
    println!("ready");
    std::io::stdout().flush().unwrap();
    std::thread::sleep(std::time::Duration::from_secs(60));
}

/// Runs the child writer in `dir`, sends `signal` once it is writing, returns its exit status
/// and the names left in `dir`.
fn signal_writer(dir: &Path, signal: &str) -> (std::process::ExitStatus, Vec<String>) {
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "child_writer", "--nocapture", "--test-threads=1"])
        .env(CHILD_ENV, dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    assert!(
        lines.any(|l| l.is_ok_and(|l| l.trim_end().ends_with("ready"))),
        "the child never started writing"
    );
    let names = |d: &Path| -> Vec<String> {
        std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect()
    };
    assert_eq!(names(dir).len(), 1, "a temporary while writing");
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    (status, names(dir))
}

// Regression: SIGINT or SIGTERM during a write left `.NAME.tmp-PID` (2–23 MB) for ever.
#[test]
fn sigint_and_sigterm_remove_the_temporary() {
    for (signal, number) in [("-INT", 2), ("-TERM", 15), ("-HUP", 1)] {
        let dir = tempfile::tempdir().unwrap();
        let (status, left) = signal_writer(dir.path(), signal);
        assert_eq!(status.signal(), Some(number), "{signal}: {status:?}");
        assert!(left.is_empty(), "{signal}: left {left:?}");
    }
}

// SIGKILL cannot be caught: the temporary stays until the next write of that destination, which
// removes it (its writer is gone) and writes the file.
#[test]
fn sigkill_leftovers_are_removed_by_the_next_write() {
    let dir = tempfile::tempdir().unwrap();
    let (status, left) = signal_writer(dir.path(), "-KILL");
    assert_eq!(status.signal(), Some(9));
    assert_eq!(left.len(), 1, "{left:?}");
    assert!(left[0].starts_with(".out.modes.tmp-"), "{left:?}");
    dcr_files::write_atomic(&dir.path().join("out.modes"), b"next").unwrap();
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("out.modes")]);
}
