//! The meshers' child processes and work folders: a time limit on every child, a progress line
//! while it runs, and clean-up on every exit path.
//!
//! Each backend ([`crate::mesh::gmsh`], [`crate::mesh::ftetwild`]) works in a private folder
//! under `$TMPDIR` ([`WorkDir`], prefix `modal-bake-gmsh` or `modal-bake-ftetwild`), removed when
//! it is dropped (success, error, panic unwinding). The folders and the running children are also
//! registered process-wide, so a signal handler can end the children (each with the processes
//! it started: a child leads its own process group) and remove the folders
//! ([`abort_meshing`]; the `modal-bake` binary calls it on SIGINT, SIGTERM and SIGHUP) — the
//! one case dropping cannot cover. SIGKILL cannot be caught.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Default time limit of one mesher run (s).
pub const DEFAULT_TIMEOUT_S: f64 = 600.0;

/// The environment variable naming the Python interpreter that runs gmsh's Python module and
/// pytetwild ([`python_interpreter`]).
pub const PYTHON_ENV: &str = "MODAL_BAKE_PYTHON";

/// The Python interpreter the meshers' Python launchers run: `$MODAL_BAKE_PYTHON` when it is
/// set and not empty (an application's own Python, e.g. Blender's, whose add-on bundles gmsh
/// and pytetwild as wheels and puts them on the child's `PYTHONPATH`), else
/// [`DEFAULT_PYTHON`] on `PATH`.
pub fn python_interpreter() -> PathBuf {
    match std::env::var_os(PYTHON_ENV) {
        Some(p) if !p.is_empty() => PathBuf::from(p),
        _ => PathBuf::from(DEFAULT_PYTHON),
    }
}

/// The interpreter [`python_interpreter`] runs when `MODAL_BAKE_PYTHON` is not set: `python3`,
/// and on Windows `python` (python.org's installer puts `python.exe` on `PATH`, not
/// `python3.exe`).
pub const DEFAULT_PYTHON: &str = if cfg!(windows) { "python" } else { "python3" };

/// Work folders alive in this process.
static DIRS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Mesher children running in this process, and whether [`abort_meshing`] has run (no child
/// is started after it). A child is spawned and registered under this lock, so the abort sees
/// every child that exists.
static CHILDREN: Mutex<Children> = Mutex::new(Children {
    running: Vec::new(),
    aborted: false,
});

/// The contents of [`CHILDREN`].
struct Children {
    running: Vec<Running>,
    aborted: bool,
}

/// A mesher child and, on Windows, the job holding it and what it starts
/// ([`crate::signals::ChildJob`]; `None` when Windows refused one, said once on stderr).
struct Running {
    child: Child,
    #[cfg(windows)]
    job: Option<crate::signals::ChildJob>,
}

impl Running {
    fn new(child: Child) -> Running {
        #[cfg(windows)]
        let job = match crate::signals::ChildJob::for_child(&child) {
            Ok(job) => Some(job),
            Err(e) => {
                static SAID: std::sync::Once = std::sync::Once::new();
                SAID.call_once(|| {
                    eprintln!(
                        "warning: no job object for the mesher ({e}): a process it starts \
                         may outlive it until modal-bake ends"
                    );
                });
                None
            }
        };
        Running {
            child,
            #[cfg(windows)]
            job,
        }
    }
}

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

/// Ends every running mesher child (with the processes it started) and removes every work
/// folder of this process; for signal handlers before the process ends. Returns how many
/// folders were removed.
pub fn abort_meshing() -> usize {
    let mut children = lock(&CHILDREN);
    children.aborted = true;
    for c in children.running.iter_mut() {
        kill_group(c);
        let _ = c.child.wait();
    }
    lock(&DIRS)
        .iter()
        .filter(|p| std::fs::remove_dir_all(p).is_ok())
        .count()
}

/// Kills a mesher child and every process in its process group (Unix: each mesher child
/// leads its own group, [`run_child_watched`]) or its job (Windows), so a process it started
/// cannot outlive it holding its output open. After the child has been reaped the group may
/// be empty (nothing is signalled) or hold what it left running (ended too); its number is not
/// reused while any member lives.
fn kill_group(running: &mut Running) {
    #[cfg(unix)]
    crate::signals::kill_process_group(running.child.id());
    #[cfg(windows)]
    if let Some(job) = &running.job {
        job.end();
    }
    let _ = running.child.kill();
}

/// How a child run ended.
#[derive(Debug)]
pub struct ChildOutput {
    /// Exit status; `None` when the time limit ended it, or the watcher ([`run_child_watched`]).
    pub status: Option<ExitStatus>,
    /// Whether the watcher stopped it (then `status` is `None`).
    pub stopped: bool,
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
    cmd: Command,
    timeout: Duration,
    progress: &dyn Fn(f64),
) -> std::io::Result<ChildOutput> {
    run_child_watched(cmd, timeout, progress, &|_| false)
}

/// [`run_child`], also showing each complete line of the child's stdout to `stop` as it
/// arrives (within about 20 ms): the child is killed as soon as `stop` returns true
/// (`stopped`, `status: None`).
///
/// The child leads its own process group (Unix) or job (Windows), and whenever the run ends —
/// at `stop`, at the time limit or when the child exits — what is left of it is killed, so a
/// process the child started (a launcher's interpreter, a background helper) neither outlives
/// the run nor keeps it waiting on an output pipe it holds open. The group also means a
/// terminal's Ctrl-C reaches the child through the `modal-bake` binary's handler
/// ([`abort_meshing`]).
///
/// # Errors
/// When the program cannot be started.
pub fn run_child_watched(
    mut cmd: Command,
    timeout: Duration,
    progress: &dyn Fn(f64),
    stop: &dyn Fn(&str) -> bool,
) -> std::io::Result<ChildOutput> {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(&mut cmd, 0);
    let t = Instant::now();
    // Spawned and registered in one step, so `abort_meshing` cannot miss it.
    let (id, child_out, child_err) = {
        let mut children = lock(&CHILDREN);
        if children.aborted {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "meshing was interrupted by a signal",
            ));
        }
        let mut child = cmd.spawn()?;
        let pipes = (child.stdout.take(), child.stderr.take());
        let id = child.id();
        children.running.push(Running::new(child));
        (id, pipes.0, pipes.1)
    };
    let drain = |r: Option<Box<dyn Read + Send>>, into: std::sync::Arc<Mutex<Vec<u8>>>| {
        std::thread::spawn(move || {
            let Some(mut r) = r else { return };
            let mut buf = [0u8; 8192];
            loop {
                match r.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => lock(&into).extend_from_slice(&buf[..n]),
                }
            }
        })
    };
    let stdout = std::sync::Arc::new(Mutex::new(Vec::new()));
    let stderr = std::sync::Arc::new(Mutex::new(Vec::new()));
    let out = drain(
        child_out.map(|s| Box::new(s) as Box<dyn Read + Send>),
        stdout.clone(),
    );
    let err = drain(
        child_err.map(|s| Box::new(s) as Box<dyn Read + Send>),
        stderr.clone(),
    );
    let mut next_note = 15.0;
    let mut scanned = 0;
    let mut stopped = false;
    let status = loop {
        // The complete lines the child has written since the last look.
        {
            let bytes = lock(&stdout);
            while let Some(n) = bytes[scanned..].iter().position(|&b| b == b'\n') {
                let line = String::from_utf8_lossy(&bytes[scanned..scanned + n]);
                scanned += n + 1;
                if stop(&line) {
                    stopped = true;
                    break;
                }
            }
        }
        {
            let mut children = lock(&CHILDREN);
            let Some(i) = children.running.iter().position(|c| c.child.id() == id) else {
                break None;
            };
            match children.running[i].child.try_wait() {
                Ok(Some(s)) if !stopped => {
                    // Already reaped by try_wait; wait returns its status at once.
                    let mut c = children.running.remove(i);
                    kill_group(&mut c);
                    let _ = c.child.wait();
                    break Some(s);
                }
                Ok(_) if stopped || t.elapsed() >= timeout => {
                    let mut c = children.running.remove(i);
                    kill_group(&mut c);
                    let _ = c.child.wait();
                    break None;
                }
                Ok(_) => {}
                Err(_) => {
                    let mut c = children.running.remove(i);
                    let status = c.child.wait().ok();
                    kill_group(&mut c);
                    break status;
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
    let _ = out.join();
    let _ = err.join();
    let mut bytes = std::mem::take(&mut *lock(&stdout));
    bytes.extend(std::mem::take(&mut *lock(&stderr)));
    Ok(ChildOutput {
        status,
        stopped,
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
