//! Signal handling for the command-line tool: on SIGINT, SIGTERM or SIGHUP the temporaries
//! being written ([`dcr_files::AtomicFile`]) are removed, the mesher child processes
//! are ended and their work folders removed ([`crate::mesh::work::abort_meshing`]), then the process ends as
//! the signal's default action would (a shell sees it killed by that signal). Without this the
//! default action would end the process at once and leave a partial `.NAME.tmp-…` beside the
//! output. SIGKILL cannot be caught; the next write of the same output removes what it left.

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// Starts a thread that waits for SIGINT, SIGTERM or SIGHUP, removes the pending temporaries
/// and ends the process by that signal. Call once, early in `main`.
///
/// # Errors
/// When the handlers or the thread cannot be set up.
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    let mut signals = Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(sig) = signals.forever().next() {
                dcr_files::remove_pending_temporaries();
                crate::mesh::work::abort_meshing();
                // Restore the default action and raise the signal again.
                let _ = signal_hook::low_level::emulate_default_handler(sig);
                std::process::exit(128 + sig);
            }
        })?;
    Ok(())
}
