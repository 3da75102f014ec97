//! The meshers' child processes and work folders: a time limit on every child, a progress line
//! while it runs, and clean-up on every exit path.
//!
//! Each backend ([`crate::mesh::gmsh`], [`crate::mesh::ftetwild`]) works in a private folder
//! under `$TMPDIR` ([`WorkDir`], prefix `modal-bake-gmsh` or `modal-bake-ftetwild`), removed when
//! it is dropped (success, error, panic unwinding). The folders and the running children are also
//! registered process-wide, so a signal handler can end the children and remove the folders
//! ([`abort_meshing`]; the `modal-bake` binary calls it on SIGINT, SIGTERM and SIGHUP) — the
//! one case dropping cannot cover. SIGKILL cannot be caught.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Default time limit of one mesher run (s).
pub const DEFAULT_TIMEOUT_S: f64 = 600.0;

/// Work folders alive in this process.
static DIRS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Mesher children running in this process.
static CHILDREN: Mutex<Vec<Child>> = Mutex::new(Vec::new());

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    match m.lock() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    }
}

/// A private temporary folder, removed (with its content) when dropped or by [`abort_meshing`].
#[derive(Debug)]
pub struct WorkDir {
    dir: Option<tempfile::TempDir>,
}

impl WorkDir {
    /// Creates `$TMPDIR/PREFIX…` and registers it for [`abort_meshing`].
    ///
    /// # Errors
    /// When the folder cannot be created.
    pub fn new(prefix: &str) -> std::io::Result<WorkDir> {
        let dir = tempfile::Builder::new().prefix(prefix).tempdir()?;
        lock(&DIRS).push(dir.path().to_path_buf());
        Ok(WorkDir { dir: Some(dir) })
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        self.dir.as_ref().map_or(Path::new(""), |d| d.path())
    }
}

impl Drop for WorkDir {
    fn drop(&mut self) {
        if let Some(d) = self.dir.take() {
            let p = d.path().to_path_buf();
            let _ = d.close();
            lock(&DIRS).retain(|q| q != &p);
        }
    }
}

/// Ends every running mesher child and removes every work folder of this process; for signal
/// handlers before the process ends. Returns how many folders were removed.
pub fn abort_meshing() -> usize {
    for c in lock(&CHILDREN).iter_mut() {
        let _ = c.kill();
        let _ = c.wait();
    }
    lock(&DIRS)
        .iter()
        .filter(|p| std::fs::remove_dir_all(p).is_ok())
        .count()
}

/// How a child run ended.
#[derive(Debug)]
pub struct ChildOutput {
    /// Exit status; `None` when the time limit ended it.
    pub status: Option<ExitStatus>,
    /// stdout and stderr, joined (lossy UTF-8).
    pub text: String,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Runs `cmd` (stdin closed, stdout and stderr captured) for at most `timeout`, calling
/// `progress(seconds)` about every 15 s while it runs; the child is killed at the limit
/// (`status: None`).
///
/// # Errors
/// When the program cannot be started.
pub fn run_child(
    mut cmd: Command,
    timeout: Duration,
    progress: &dyn Fn(f64),
) -> std::io::Result<ChildOutput> {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let t = Instant::now();
    let mut child = cmd.spawn()?;
    let drain = |r: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(mut r) = r {
                let _ = r.read_to_end(&mut buf);
            }
            buf
        })
    };
    let out = drain(
        child
            .stdout
            .take()
            .map(|s| Box::new(s) as Box<dyn Read + Send>),
    );
    let err = drain(
        child
            .stderr
            .take()
            .map(|s| Box::new(s) as Box<dyn Read + Send>),
    );
    let id = child.id();
    lock(&CHILDREN).push(child);
    let mut next_note = 15.0;
    let status = loop {
        {
            let mut children = lock(&CHILDREN);
            let Some(i) = children.iter().position(|c| c.id() == id) else {
                break None;
            };
            match children[i].try_wait() {
                Ok(Some(s)) => {
                    // Already reaped by try_wait; wait returns its status at once.
                    let _ = children.remove(i).wait();
                    break Some(s);
                }
                Ok(None) if t.elapsed() >= timeout => {
                    let mut c = children.remove(i);
                    let _ = c.kill();
                    let _ = c.wait();
                    break None;
                }
                Ok(None) => {}
                Err(_) => {
                    let mut c = children.remove(i);
                    break c.wait().ok();
                }
            }
        }
        let s = t.elapsed().as_secs_f64();
        if s >= next_note {
            progress(s);
            next_note += 15.0;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut bytes = out.join().unwrap_or_default();
    bytes.extend(err.join().unwrap_or_default());
    Ok(ChildOutput {
        status,
        text: String::from_utf8_lossy(&bytes).into_owned(),
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// A time limit from seconds: finite and positive, else an error naming `--mesher-timeout`.
///
/// # Errors
/// A message naming the option when `seconds` is not a positive finite number.
pub fn timeout_of(seconds: f64) -> Result<Duration, String> {
    if seconds.is_finite() && seconds > 0.0 && seconds < 1e9 {
        Ok(Duration::from_secs_f64(seconds))
    } else {
        Err(format!(
            "--mesher-timeout must be a positive number of seconds below 1e9, got {seconds}"
        ))
    }
}
