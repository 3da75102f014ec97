//! Windows: a console control handler (`SetConsoleCtrlHandler`). Windows runs the handler on a
//! thread of its own, not by interrupting one, so it may do the clean-up itself and end the
//! process; METIS's SIGTERM handler (see the Unix module) is never run by a console event.
//!
//! A mesher child is ended with `Child::kill` (`TerminateProcess`): there is no process group
//! to end. What the handler cannot see — `modal-bake` itself ended by `TerminateProcess` (Task
//! Manager, a host application closing) — would leave a running mesher behind, so the install
//! also puts the process in a job object that ends every process in it when the job's last
//! handle closes, which is when `modal-bake` ends, however it ends: its children and theirs
//! (a launcher shim's interpreter) are in the job too.
//!
//! Written on `windows-sys` (the maintained binding of the Win32 API; std has no console-event
//! API), one of the modules allowed `unsafe`.
#![allow(unsafe_code)]

use windows_sys::core::BOOL;
use windows_sys::Win32::System::Console::SetConsoleCtrlHandler;
use windows_sys::Win32::System::JobObjects::{
    AssignProcessToJobObject, CreateJobObjectW, JobObjectExtendedLimitInformation,
    SetInformationJobObject, JOBOBJECT_EXTENDED_LIMIT_INFORMATION,
    JOB_OBJECT_LIMIT_KILL_ON_JOB_CLOSE,
};
use windows_sys::Win32::System::Threading::GetCurrentProcess;

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
/// children and ends the process with `STATUS_CONTROL_C_EXIT`, and puts the process in a job
/// object that ends its children when it ends. Call once, early in `main`, before any child
/// starts.
///
/// # Errors
/// When Windows refuses the handler or the job (a job that forbids nested jobs, before
/// Windows 8).
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    // SAFETY: registers a function with the signature `PHANDLER_ROUTINE` requires; it stays
    // valid for the life of the process.
    if unsafe { SetConsoleCtrlHandler(Some(on_console_event), 1) } == 0 {
        return Err(std::io::Error::last_os_error());
    }
    end_children_with_this_process().map_err(|e| {
        std::io::Error::new(
            e.kind(),
            format!("no job object for the meshers, which would outlive a forced end: {e}"),
        )
    })
}

/// Puts this process in a new job object with `JOB_OBJECT_LIMIT_KILL_ON_JOB_CLOSE`. The job's
/// one handle is never closed by this program: Windows closes it when the process ends, and
/// then ends every process left in the job (the children started since, which inherit it).
fn end_children_with_this_process() -> std::io::Result<()> {
    // SAFETY: plain Win32 calls on handles this function owns (the new job) or that are always
    // valid (the current-process pseudo-handle); `info` outlives the call that reads it and has
    // the size passed with it.
    unsafe {
        let job = CreateJobObjectW(std::ptr::null(), std::ptr::null());
        if job.is_null() {
            return Err(std::io::Error::last_os_error());
        }
        let mut info: JOBOBJECT_EXTENDED_LIMIT_INFORMATION = std::mem::zeroed();
        info.BasicLimitInformation.LimitFlags = JOB_OBJECT_LIMIT_KILL_ON_JOB_CLOSE;
        let set = SetInformationJobObject(
            job,
            JobObjectExtendedLimitInformation,
            std::ptr::from_ref(&info).cast(),
            std::mem::size_of::<JOBOBJECT_EXTENDED_LIMIT_INFORMATION>() as u32,
        );
        if set == 0 || AssignProcessToJobObject(job, GetCurrentProcess()) == 0 {
            return Err(std::io::Error::last_os_error());
        }
    }
    Ok(())
}
