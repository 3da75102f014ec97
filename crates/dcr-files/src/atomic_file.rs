//! Atomic file replacement: a file is written under a temporary name beside its destination
//! and renamed over it only when complete, so a reader sees the old file or the new one, never
//! a part, and a failed write leaves nothing behind.
//!
//! Temporary names are `.NAME.tmp-HOST-PID-UNIQUE`: the host (sanitised) and process id of the
//! writer, and 64 random bits, so two writers never collide — not two threads of one process,
//! not two processes with one pid on two hosts sharing a file system. The name says who wrote
//! it, which is how temporaries of writers that died (SIGKILL, power loss) are found: every new
//! [`AtomicFile`] for a destination first removes its stale temporaries — those of a process
//! on this host that no longer runs (Linux: `/proc`; Windows: `OpenProcess`; elsewhere every
//! writer counts as running), and any older than [`STALE_AFTER`] (a writer on another host,
//! whose liveness cannot be seen, or a pid since reused).
//!
//! Signals: the temporaries being written are registered process-wide; a signal handler (the
//! tools install `modal_bake::signals::remove_temporaries_on_signals` for SIGINT, SIGTERM and
//! SIGHUP) calls
//! [`remove_pending_temporaries`] before the process ends. SIGKILL cannot be caught: its
//! temporary is removed by the next write of the same destination.
//!
//! Why not `tempfile::NamedTempFile::persist`: its random names do not say which process wrote
//! them, so temporaries of dead writers could not be told from those being written.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Duration;

use crate::file_type::describe_file_type;
use crate::WriteError;

/// Age after which a temporary is stale whoever wrote it (a write takes seconds, not hours).
pub const STALE_AFTER: Duration = Duration::from_secs(3600);

/// Windows: how long [`AtomicFile::commit`] keeps retrying the rename while the destination is
/// held open by another program (an indexer or a virus scanner opens a new file for a moment
/// after it is written) before it reports [`WriteError::InUse`]: 2 s.
pub const RENAME_PATIENCE: Duration = Duration::from_secs(2);

/// Temporaries being written by this process (removed by [`remove_pending_temporaries`]).
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Per-process counter mixed into the random part of temporary names.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Removes every temporary this process is writing; for signal handlers before the process
/// ends (the writes in progress are lost, their destinations untouched). Returns how many were
/// removed.
pub fn remove_pending_temporaries() -> usize {
    let pending = match PENDING.lock() {
        Ok(p) => p,
        Err(poisoned) => poisoned.into_inner(),
    };
    pending
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}

fn register(path: &Path) {
    if let Ok(mut p) = PENDING.lock() {
        p.push(path.to_path_buf());
    }
}

fn deregister(path: &Path) {
    if let Ok(mut p) = PENDING.lock() {
        p.retain(|q| q != path);
    }
}

fn is_pending(path: &Path) -> bool {
    PENDING.lock().is_ok_and(|p| p.iter().any(|q| q == path))
}

/// This host's name reduced to `[A-Za-z0-9_]` (at most 32 characters; `host` if unknown):
/// Linux's `/proc/sys/kernel/hostname`, else `$HOSTNAME`, else (Windows) `%COMPUTERNAME%`.
fn host_tag() -> String {
    let raw = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::env::var("HOSTNAME"))
        .or_else(|_| std::env::var("COMPUTERNAME"))
        .unwrap_or_default();
    let tag: String = raw
        .trim()
        .chars()
        .take(32)
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if tag.is_empty() {
        "host".into()
    } else {
        tag
    }
}

/// 64 bits that differ between calls and between processes.
fn unique_bits() -> u64 {
    use std::hash::BuildHasher;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64);
    // `RandomState` keys are random per process.
    std::collections::hash_map::RandomState::new().hash_one((n, nanos, std::process::id()))
}

/// The prefix every temporary of `name` starts with.
fn temp_prefix(name: &str) -> String {
    format!(".{name}.tmp-")
}

/// Who wrote a temporary, from its name: (host, pid); the host is `None` in the older
/// `.NAME.tmp-PID` form.
fn parse_temp(suffix: &str) -> Option<(Option<&str>, u32)> {
    let parts: Vec<&str> = suffix.rsplitn(3, '-').collect();
    match parts.as_slice() {
        [pid] => Some((None, pid.parse().ok()?)),
        [_unique, pid, host] => Some((Some(host), pid.parse().ok()?)),
        _ => None,
    }
}

/// Whether process `pid` runs on this host (unknown: assumed running): on Linux whether
/// `/proc/PID` exists, on Windows whether the process can be opened and has no exit code yet.
fn process_alive(pid: u32) -> bool {
    #[cfg(windows)]
    {
        use windows_sys::Win32::Foundation::{
            CloseHandle, GetLastError, ERROR_INVALID_PARAMETER, STILL_ACTIVE,
        };
        use windows_sys::Win32::System::Threading::{
            GetExitCodeProcess, OpenProcess, PROCESS_QUERY_LIMITED_INFORMATION,
        };
        // SAFETY: plain Win32 calls; the handle is closed once, the exit code is writable.
        #[allow(unsafe_code)]
        unsafe {
            let handle = OpenProcess(PROCESS_QUERY_LIMITED_INFORMATION, 0, pid);
            if handle.is_null() {
                // No such process; anything else (access denied) means one runs.
                return GetLastError() != ERROR_INVALID_PARAMETER;
            }
            let mut code = 0u32;
            let answered = GetExitCodeProcess(handle, &mut code) != 0;
            CloseHandle(handle);
            !answered || code == STILL_ACTIVE as u32
        }
    }
    #[cfg(not(windows))]
    {
        let proc = Path::new("/proc");
        if proc.join("self").exists() {
            proc.join(pid.to_string()).exists()
        } else {
            true
        }
    }
}

/// Removes the stale temporaries of `name` in `dir` (see the module docs); returns how many.
fn remove_stale(dir: &Path, name: &str) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let prefix = temp_prefix(name);
    let host = host_tag();
    let me = std::process::id();
    let mut removed = 0;
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(suffix) = file_name.to_str().and_then(|f| f.strip_prefix(&prefix)) else {
            continue;
        };
        let path = entry.path();
        if is_pending(&path) {
            continue;
        }
        let dead_here = match parse_temp(suffix) {
            Some((h, pid)) if h.is_none_or(|h| h == host) => pid == me || !process_alive(pid),
            _ => false,
        };
        let old = entry
            .metadata()
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age > STALE_AFTER);
        if (dead_here || old) && std::fs::remove_file(&path).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// A file being written under a temporary name beside `dest`; [`AtomicFile::commit`] renames
/// it over `dest`, dropping it uncommitted removes it.
///
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let dest = dir.path().join("out.bin");
/// let mut f = dcr_files::AtomicFile::create(&dest).unwrap();
/// f.write_all(b"complete").unwrap();
/// f.commit().unwrap();
/// assert_eq!(std::fs::read(&dest).unwrap(), b"complete");
/// ```
#[derive(Debug)]
pub struct AtomicFile {
    file: Option<File>,
    tmp: PathBuf,
    dest: PathBuf,
}

impl AtomicFile {
    /// Starts writing `dest`: removes its stale temporaries, then creates a new temporary
    /// beside it (never an existing file).
    ///
    /// # Errors
    /// [`WriteError::Clobber`] when `dest` exists and is not a regular file (a directory,
    /// device, FIFO or socket: renaming over it would replace it); [`WriteError::Io`] when
    /// the temporary cannot be created (missing folder, permissions, ...).
    pub fn create(dest: &Path) -> Result<AtomicFile, WriteError> {
        let io = |source| WriteError::Io {
            path: dest.to_path_buf(),
            source,
        };
        check_replaceable(dest)?;
        let dir = dest
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let name = dest
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .ok_or_else(|| {
                io(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "the path names no file",
                ))
            })?;
        remove_stale(dir, &name);
        let tmp = dir.join(format!(
            "{}{}-{}-{:016x}",
            temp_prefix(&name),
            host_tag(),
            std::process::id(),
            unique_bits()
        ));
        register(&tmp);
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => Ok(AtomicFile {
                file: Some(file),
                tmp,
                dest: dest.to_path_buf(),
            }),
            Err(e) => {
                deregister(&tmp);
                Err(io(e))
            }
        }
    }

    /// The temporary's path (for tests and messages).
    pub fn temporary_path(&self) -> &Path {
        &self.tmp
    }

    /// Syncs the temporary to disk and renames it over the destination.
    ///
    /// # Errors
    /// [`WriteError::Io`]; the temporary is removed and the destination left untouched.
    pub fn commit(mut self) -> Result<(), WriteError> {
        let result = (|| {
            let file = self
                .file
                .take()
                .ok_or_else(|| std::io::Error::other("the temporary was already closed"))?;
            file.sync_all()?;
            drop(file);
            check_replaceable(&self.dest).map_err(|e| std::io::Error::other(e.to_string()))?;
            rename_patiently(&self.tmp, &self.dest)
        })();
        match result {
            Ok(()) => {
                deregister(&self.tmp);
                // Make the rename itself durable (best effort: not every platform can).
                if let Some(dir) = self.dest.parent().filter(|d| !d.as_os_str().is_empty()) {
                    let _ = File::open(dir).and_then(|d| d.sync_all());
                }
                Ok(())
            }
            Err(source) if held_open(&source) => Err(WriteError::InUse {
                path: self.dest.clone(),
                source,
            }),
            Err(source) => Err(WriteError::Io {
                path: self.dest.clone(),
                source,
            }),
        }
    }
}

/// Whether a refused rename means the destination is held open by another program (or is
/// read-only): Windows' access-denied, sharing-violation and lock-violation errors; never
/// elsewhere, where a rename replaces an open file.
fn held_open(e: &std::io::Error) -> bool {
    cfg!(windows)
        && (e.kind() == std::io::ErrorKind::PermissionDenied
            || matches!(e.raw_os_error(), Some(32 | 33)))
}

/// `std::fs::rename`, retried while [`held_open`] refuses it, for up to [`RENAME_PATIENCE`]
/// (waits of 10 ms doubling to 200 ms); returns the last result.
fn rename_patiently(from: &Path, to: &Path) -> std::io::Result<()> {
    let start = std::time::Instant::now();
    let mut wait = Duration::from_millis(10);
    loop {
        match std::fs::rename(from, to) {
            Err(e) if held_open(&e) && start.elapsed() < RENAME_PATIENCE => {
                std::thread::sleep(wait);
                wait = (wait * 2).min(Duration::from_millis(200));
            }
            result => return result,
        }
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.file {
            Some(f) => f.write(buf),
            None => Err(std::io::Error::other("the temporary was already closed")),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.file {
            Some(f) => f.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Uncommitted (or a failed commit): the temporary goes.
        drop(self.file.take());
        if is_pending(&self.tmp) {
            let _ = std::fs::remove_file(&self.tmp);
            deregister(&self.tmp);
        }
    }
}

/// `dest` may be replaced by a file: it does not exist or is a regular file (a symbolic link
/// to one is replaced by the file).
fn check_replaceable(dest: &Path) -> Result<(), WriteError> {
    match std::fs::metadata(dest) {
        Ok(meta) if !meta.is_file() => Err(WriteError::Clobber {
            path: dest.to_path_buf(),
            what: describe_file_type(meta.file_type()),
        }),
        _ => Ok(()),
    }
}

/// Writes `bytes` to `dest` atomically ([`AtomicFile`]).
///
/// # Errors
/// As [`AtomicFile::create`] and [`AtomicFile::commit`].
pub fn write_atomic(dest: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    let mut f = AtomicFile::create(dest)?;
    f.write_all(bytes).map_err(|source| WriteError::Io {
        path: dest.to_path_buf(),
        source,
    })?;
    f.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    // Regression: temporaries were named `.NAME.tmp-PID` — two writers with one pid on hosts
    // sharing a file system collided, and a temporary left by a killed writer stayed for ever.
    // Names carry host, pid and random bits; a new write removes the temporaries of writers
    // that are gone.
    #[test]
    fn temporaries_are_unique_and_stale_ones_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("x.modes");
        let a = AtomicFile::create(&dest).unwrap();
        let b = AtomicFile::create(&dest).unwrap();
        assert_ne!(a.temporary_path(), b.temporary_path());
        let name = a
            .temporary_path()
            .file_name()
            .unwrap()
            .to_str()
            .unwrap()
            .to_string();
        let host = host_tag();
        let me = std::process::id();
        assert!(
            name.starts_with(&format!(".x.modes.tmp-{host}-{me}-")),
            "{name}"
        );
        // Writers in progress are never stale; dropping one removes its temporary.
        assert_eq!(remove_stale(dir.path(), "x.modes"), 0);
        drop(a);
        drop(b);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

        // A process that has exited (this test program, asked to run no test): its pid names
        // a dead writer on this host; one still running (the same program waiting on its
        // standard input) a live one.
        let this = std::env::current_exe().unwrap();
        let mut child = std::process::Command::new(&this)
            .args(["--exact", "no test has this name"])
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let mut waiting = std::process::Command::new(&this)
            .args([
                "--exact",
                "atomic_file::tests::waits_for_stdin",
                "--ignored",
            ])
            .env("DCR_FILES_TEST_WAIT", "1")
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let alive = waiting.id();
        let touch = |n: &str| {
            let p = dir.path().join(n);
            std::fs::write(&p, b"partial").unwrap();
            p
        };
        let stale = [
            touch(&format!(".x.modes.tmp-{host}-{dead}-0123456789abcdef")),
            touch(&format!(".x.modes.tmp-{dead}")),
        ];
        let live = touch(&format!(".x.modes.tmp-{host}-{alive}-0123456789abcdef"));
        let foreign = touch(".x.modes.tmp-otherhost-1-0123456789abcdef");
        let old_foreign = touch(".x.modes.tmp-otherhost-2-0123456789abcdef");
        std::fs::File::options()
            .write(true)
            .open(&old_foreign)
            .unwrap()
            .set_modified(std::time::SystemTime::now() - 2 * STALE_AFTER)
            .unwrap();
        let other = touch(".y.modes.tmp-h-1-0");
        write_atomic(&dest, b"complete").unwrap();
        for p in stale.iter().chain([&old_foreign]) {
            assert!(!p.exists(), "{} should be removed", p.display());
        }
        for p in [&live, &foreign, &other] {
            assert!(p.exists(), "{} should stay", p.display());
        }
        assert_eq!(std::fs::read(&dest).unwrap(), b"complete");
        drop(waiting.stdin.take());
        assert!(waiting.wait().unwrap().success());
        // Once it has ended, its temporary is stale too.
        write_atomic(&dest, b"again").unwrap();
        assert!(!live.exists(), "{} should be removed", live.display());
    }

    /// The live writer of `temporaries_are_unique_and_stale_ones_are_removed`: with
    /// `DCR_FILES_TEST_WAIT` set it runs until its standard input closes.
    #[test]
    #[ignore = "a helper process, started by temporaries_are_unique_and_stale_ones_are_removed"]
    fn waits_for_stdin() {
        if std::env::var_os("DCR_FILES_TEST_WAIT").is_some() {
            std::io::copy(&mut std::io::stdin(), &mut std::io::sink()).unwrap();
        }
    }

    // Regression: `-o` onto a character device replaced the device node with the base (as
    // root, exit 0). Writes replace regular files only; a symbolic link to `/dev/null` is
    // refused as the device it names, and the link and the device survive.
    #[test]
    #[cfg(unix)]
    fn writes_never_replace_what_is_not_a_regular_file() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.modes");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        let sub = dir.path().join("sub.modes");
        std::fs::create_dir(&sub).unwrap();
        let null = dir.path().join("null.modes");
        std::os::unix::fs::symlink("/dev/null", &null).unwrap();
        for (path, what) in [
            (&fifo, "a FIFO"),
            (&sub, "a directory"),
            (&null, "a character device"),
        ] {
            let err = write_atomic(path, b"bytes").unwrap_err();
            assert!(
                matches!(&err, WriteError::Clobber { what: w, .. } if *w == what),
                "{err}"
            );
        }
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert!(sub.is_dir());
        assert!(std::fs::symlink_metadata(&null)
            .unwrap()
            .file_type()
            .is_symlink());
        assert!(std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device());
        // Only the FIFO, the folder, the link and nothing else: no temporary left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
    }

    // Windows: a destination another program holds open (no delete sharing) is waited for
    // while it is released within RENAME_PATIENCE; held throughout, the write fails naming it,
    // the destination keeps its bytes and no temporary is left.
    #[test]
    #[cfg(windows)]
    fn a_destination_held_open_is_waited_for_then_named() {
        use std::os::windows::fs::OpenOptionsExt;
        const FILE_SHARE_READ: u32 = 1;
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("x.modes");
        std::fs::write(&dest, b"old").unwrap();
        let hold = || {
            std::fs::OpenOptions::new()
                .read(true)
                .share_mode(FILE_SHARE_READ)
                .open(&dest)
                .unwrap()
        };
        let held = hold();
        let release = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(300));
            drop(held);
        });
        let start = std::time::Instant::now();
        write_atomic(&dest, b"new").unwrap();
        release.join().unwrap();
        assert!(start.elapsed() >= Duration::from_millis(250));
        assert_eq!(std::fs::read(&dest).unwrap(), b"new");

        let held = hold();
        let err = write_atomic(&dest, b"newer").unwrap_err();
        assert!(matches!(err, WriteError::InUse { .. }), "{err}");
        assert!(
            err.to_string().contains("another program has it open"),
            "{err}"
        );
        drop(held);
        assert_eq!(std::fs::read(&dest).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    // A folder where the file would go is refused on every platform, and nothing is left.
    #[test]
    fn writes_never_replace_a_folder() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub.modes");
        std::fs::create_dir(&sub).unwrap();
        let err = write_atomic(&sub, b"bytes").unwrap_err();
        assert!(
            matches!(&err, WriteError::Clobber { what, .. } if *what == "a directory"),
            "{err}"
        );
        assert!(sub.is_dir());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
