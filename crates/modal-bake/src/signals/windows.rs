//! Windows: a console control handler (`SetConsoleCtrlHandler`). Windows runs the handler on a
//! thread of its own, not by interrupting one, so it may do the clean-up itself and end the
//! process; METIS's SIGTERM handler (see the Unix module) is never run by a console event.
//!
//! A mesher child is one process (gmsh and fTetWild run inside the Python interpreter the
//! launcher starts), ended with `Child::kill` (`TerminateProcess`): there is no process group to
//! end.
//!
//! Written on `windows-sys` (the maintained binding of the Win32 API; std has no console-event
//! API), one of the modules allowed `unsafe`.
#![allow(unsafe_code)]

use windows_sys::core::BOOL;
use windows_sys::Win32::System::Console::SetConsoleCtrlHandler;

/// The exit status of a console process ended by Ctrl-C (`STATUS_CONTROL_C_EXIT`), what
/// Windows reports when the default handler ends it.
const STATUS_CONTROL_C_EXIT: u32 = 0xC000_013A;

/// Runs on the thread Windows starts for a console event (Ctrl-C, Ctrl-Break, close, log-off,
/// shut-down): removes the pending temporaries, ends the mesher children and ends the process.
unsafe extern "system" fn on_console_event(_event: u32) -> BOOL {
    dcr_files::remove_pending_temporaries();
    crate::mesh::work::abort_meshing();
    std::process::exit(STATUS_CONTROL_C_EXIT as i32)
}

/// Installs the console control handler that removes the pending temporaries, ends the mesher
/// children and ends the process with `STATUS_CONTROL_C_EXIT`. Call once, early in `main`.
///
/// # Errors
/// When Windows refuses the handler.
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    // SAFETY: registers a function with the signature `PHANDLER_ROUTINE` requires; it stays
    // valid for the life of the process.
    if unsafe { SetConsoleCtrlHandler(Some(on_console_event), 1) } == 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(())
}
