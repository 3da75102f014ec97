//! Interruption handling for the command-line tool: when the user or the system ends
//! `modal-bake` (Unix: SIGINT, SIGTERM or SIGHUP; Windows: Ctrl-C, Ctrl-Break, the console
//! closing, log-off or shut-down) the temporaries being written ([`dcr_files::AtomicFile`]) are
//! removed, the mesher child processes are ended and their work folders removed
//! ([`crate::mesh::work::abort_meshing`]), then the process ends as the interruption's default
//! action would (Unix: killed by that signal; Windows: exit status `0xC000013A`,
//! `STATUS_CONTROL_C_EXIT`). Without this the default action would end the process at once and
//! leave a partial `.NAME.tmp-…` beside the output. What cannot be caught (SIGKILL, Windows'
//! `TerminateProcess`) leaves it; on Unix the next write of the same output removes it.

#[cfg(unix)]
mod unix;
#[cfg(unix)]
pub use unix::{kill_process_group, remove_temporaries_on_signals};

#[cfg(windows)]
mod windows;
#[cfg(windows)]
pub use windows::{remove_temporaries_on_signals, ChildJob};

/// Nothing to install on a platform that is neither Unix nor Windows.
///
/// # Errors
/// Always: interruptions are not watched there.
#[cfg(not(any(unix, windows)))]
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    Err(std::io::Error::new(
        std::io::ErrorKind::Unsupported,
        "interruptions are watched on Unix and Windows only",
    ))
}
