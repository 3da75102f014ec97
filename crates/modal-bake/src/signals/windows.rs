//! Windows: a console control handler (`SetConsoleCtrlHandler`). Windows runs the handler on a
//! thread of its own, not by interrupting one, so it may do the clean-up itself and end the
//! process; METIS's SIGTERM handler (see the Unix module) is never run by a console event.
//!
//! Windows has no process groups; job objects do their work. A mesher child gets a job of its
//! own ([`ChildJob`]): ending that job ends the child with what it started, as ending its
//! process group does on Unix, so a launcher's interpreter holding the child's output open
//! cannot keep the run waiting. What the handler cannot see — `modal-bake` itself ended by
//! `TerminateProcess` (Task Manager, a host application closing) — would leave a running
//! mesher behind, so the install also puts the process in a job object that ends every
//! process in it when the job's last handle closes, which is when `modal-bake` ends, however
//! it ends: its children and theirs are in that job too (the children's jobs are nested in
//! it).
//!
//! Written on `windows-sys` (the maintained binding of the Win32 API; std has no console-event
//! API), one of the modules allowed `unsafe`.
#![allow(unsafe_code)]

use std::os::windows::io::AsRawHandle;

use windows_sys::core::BOOL;
use windows_sys::Win32::Foundation::{CloseHandle, HANDLE};
use windows_sys::Win32::System::Console::SetConsoleCtrlHandler;
use windows_sys::Win32::System::JobObjects::{
    AssignProcessToJobObject, CreateJobObjectW, JobObjectExtendedLimitInformation,
    SetInformationJobObject, TerminateJobObject, JOBOBJECT_EXTENDED_LIMIT_INFORMATION,
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
    let job = kill_on_close_job()?;
    // SAFETY: `job` is a job handle this function owns (closed again when the assignment
    // fails); the current-process pseudo-handle is always valid.
    unsafe {
        if AssignProcessToJobObject(job, GetCurrentProcess()) == 0 {
            let e = std::io::Error::last_os_error();
            CloseHandle(job);
            return Err(e);
        }
    }
    Ok(())
}

/// A new job object with `JOB_OBJECT_LIMIT_KILL_ON_JOB_CLOSE` (every process in it ends when
/// its last handle closes); the caller owns the handle.
fn kill_on_close_job() -> std::io::Result<HANDLE> {
    // SAFETY: plain Win32 calls on the handle created here (closed again on failure); `info`
    // outlives the call that reads it and has the size passed with it.
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
        if set == 0 {
            let e = std::io::Error::last_os_error();
            CloseHandle(job);
            return Err(e);
        }
        Ok(job)
    }
}

/// A job object holding one mesher child and every process it starts, nested in the
/// program's own job (Windows 8 and later): [`ChildJob::end`] ends them all, and so does
/// dropping it (the job ends its processes when its handle closes). A process the child
/// starts in the moment between its start and [`ChildJob::for_child`] stays outside (the
/// program's own job still ends it when the program ends).
#[derive(Debug)]
pub struct ChildJob(HANDLE);

// SAFETY: a job handle may be used and closed from any thread; `ChildJob` owns its handle.
unsafe impl Send for ChildJob {}

impl ChildJob {
    /// Puts `child` (just started) in a job of its own.
    ///
    /// # Errors
    /// When Windows refuses the job or the assignment (no nested jobs before Windows 8, or a
    /// job that forbids them).
    pub fn for_child(child: &std::process::Child) -> std::io::Result<ChildJob> {
        let job = ChildJob(kill_on_close_job()?);
        // SAFETY: both handles are open: the job owned by `job`, the process by `child`.
        if unsafe { AssignProcessToJobObject(job.0, child.as_raw_handle()) } == 0 {
            return Err(std::io::Error::last_os_error());
        }
        Ok(job)
    }

    /// Ends every process in the job (exit code 1).
    pub fn end(&self) {
        // SAFETY: the handle is open for as long as `self` lives.
        unsafe { TerminateJobObject(self.0, 1) };
    }
}

impl Drop for ChildJob {
    fn drop(&mut self) {
        // SAFETY: closes the handle this value owns, once.
        unsafe { CloseHandle(self.0) };
    }
}
