//! Unix: the three signals are blocked in the thread that installs this (and so in every
//! thread it starts afterwards) and taken by one thread with `sigwait`, so no signal handler
//! runs for them in those threads. A handler would not be safe: METIS (the bake's
//! fill-reducing ordering) installs its own process-wide SIGTERM handler while it orders a
//! matrix, one that `longjmp`s into the ordering thread's stack, and a SIGTERM that ran it on
//! another thread crashed a terminated batch with SIGSEGV (two of 40 runs under load). Threads
//! started before the install (a test harness's main thread) keep the signals unblocked; a
//! small handler there forwards them to the waiting thread.
//!
//! [`kill_process_group`] ends a mesher child with the processes it started: each child leads
//! its own process group (`crate::mesh::work`), and std signals single processes only.
//!
//! Written on `libc` (its signal mask, `sigwait`, `sigaction`, `pthread_kill`, `kill`), one of
//! the modules allowed `unsafe`: std has no signal API, and signal-hook delivers through a
//! handler, which is what METIS replaces.
#![allow(unsafe_code)]

use std::mem::MaybeUninit;
use std::sync::atomic::{AtomicU64, Ordering};

use libc::{c_int, sigset_t, SIGHUP, SIGINT, SIGTERM};

/// The signals that end the tool after its clean-up.
const SIGNALS: [c_int; 3] = [SIGINT, SIGTERM, SIGHUP];

/// The waiting thread (`pthread_t`), for the forwarding handler; 0 until it runs.
static WAITER: AtomicU64 = AtomicU64::new(0);

/// A signal set holding `signals`.
fn set_of(signals: &[c_int]) -> sigset_t {
    let mut set = MaybeUninit::<sigset_t>::uninit();
    // SAFETY: sigemptyset initialises the set; sigaddset only sets bits of valid signals.
    unsafe {
        libc::sigemptyset(set.as_mut_ptr());
        for &s in signals {
            libc::sigaddset(set.as_mut_ptr(), s);
        }
        set.assume_init()
    }
}

/// Runs on a thread that started before the install and has the signals unblocked: hands the
/// signal to the waiting thread (`pthread_kill` is async-signal-safe; the signal stays pending
/// there, blocked, until its `sigwait` takes it).
extern "C" fn forward(sig: c_int) {
    let waiter = WAITER.load(Ordering::Acquire);
    if waiter != 0 {
        // SAFETY: `waiter` is the pthread_t of the waiting thread, which never exits before
        // the process does.
        unsafe {
            libc::pthread_kill(waiter as libc::pthread_t, sig);
        }
    }
}

/// Blocks SIGINT, SIGTERM and SIGHUP in the calling thread (and every thread it starts from
/// now on), starts a thread that waits for them, removes the pending temporaries, ends the
/// mesher children and ends the process by that signal. Call once, early in `main`, before
/// any other thread starts.
///
/// # Errors
/// When the signal mask, the forwarding handler or the thread cannot be set up.
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    let set = set_of(&SIGNALS);
    // SAFETY: a valid set; the old mask is not needed.
    let rc = unsafe { libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) };
    if rc != 0 {
        return Err(std::io::Error::from_raw_os_error(rc));
    }
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            // SAFETY: pthread_self is always valid for the calling thread.
            WAITER.store(unsafe { libc::pthread_self() } as u64, Ordering::Release);
            let _ = ready_tx.send(());
            let mut sig: c_int = 0;
            // SAFETY: a valid set, all of whose signals are blocked in this thread.
            while unsafe { libc::sigwait(&set, &mut sig) } != 0 {}
            dcr_files::remove_pending_temporaries();
            crate::mesh::work::abort_meshing();
            end_by(sig);
        })?;
    let _ = ready_rx.recv();
    for sig in SIGNALS {
        // SAFETY: a plain handler that only loads an atomic and calls pthread_kill; the
        // signals are blocked while it runs.
        let rc = unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = forward as extern "C" fn(c_int) as usize;
            action.sa_mask = set;
            action.sa_flags = libc::SA_RESTART;
            libc::sigaction(sig, &action, std::ptr::null_mut())
        };
        if rc != 0 {
            return Err(std::io::Error::last_os_error());
        }
    }
    Ok(())
}

/// Sends SIGKILL to every process of process group `pgid` (a child spawned as the leader of its
/// own group); nothing happens when the group no longer exists. Group numbers 0 and 1 (this
/// process's own group, every process) are never signalled.
pub fn kill_process_group(pgid: u32) {
    if let Ok(pid) = libc::pid_t::try_from(pgid) {
        if pid > 1 {
            // SAFETY: kill(2) with a negative pid signals that process group; no memory is
            // shared with it.
            unsafe {
                libc::kill(-pid, libc::SIGKILL);
            }
        }
    }
}

/// Ends the process as `sig`'s default action does: the default action restored and the
/// signal raised with it unblocked in this thread only; `exit(128 + sig)` if that returns.
fn end_by(sig: c_int) -> ! {
    let one = set_of(&[sig]);
    // SAFETY: restoring the default disposition and raising a signal the process may receive.
    unsafe {
        libc::signal(sig, libc::SIG_DFL);
        libc::pthread_sigmask(libc::SIG_UNBLOCK, &one, std::ptr::null_mut());
        libc::raise(sig);
    }
    std::process::exit(128 + sig);
}
