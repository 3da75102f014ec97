//! `modal_bake::mesh::work::run_child_watched` on real child processes, on every platform: the
//! watcher sees the child's lines as they come and stops it at once, and what the child
//! started ends with the run (Unix: the child's process group; Windows: its job), so nothing
//! keeps the run waiting on an output pipe it holds.
//!
//! The child is this program again, following the script in `DCR_CHILD_SCRIPT` (steps joined
//! by `;`: `out TEXT` and `err TEXT` print a line to stdout or stderr, `sleep S` sleeps S
//! seconds, `spawn S` starts this program again sleeping S seconds with the same stdout and
//! stderr — a grandchild holding the pipes —, `wait` waits for what it spawned, `exit N`
//! exits with N). No shell is needed, so it runs on Windows as on Unix. Without libtest's
//! harness (`harness = false` in Cargo.toml): the child's standard output must hold its
//! script's lines only.

use std::process::{Command, ExitCode};
use std::time::Duration;

use modal_bake::mesh::work::{run_child_watched, ChildOutput};

const SCRIPT: &str = "DCR_CHILD_SCRIPT";

fn main() -> ExitCode {
    if let Ok(script) = std::env::var(SCRIPT) {
        return child(&script);
    }
    the_watcher_stops_the_child_at_the_line_it_waits_for();
    what_the_child_started_ends_with_the_run();
    println!("child_runs: 2 passed");
    ExitCode::SUCCESS
}

/// Follows `script` (see the module docs).
fn child(script: &str) -> ExitCode {
    use std::io::Write;
    let mut spawned = Vec::new();
    for step in script.split(';') {
        let (verb, arg) = step.split_once(' ').unwrap_or((step, ""));
        match verb {
            "out" => {
                let mut o = std::io::stdout().lock();
                writeln!(o, "{arg}").and_then(|()| o.flush()).unwrap();
            }
            "err" => eprintln!("{arg}"),
            "sleep" => std::thread::sleep(Duration::from_secs_f64(arg.parse().unwrap())),
            "spawn" => spawned.push(
                Command::new(std::env::current_exe().unwrap())
                    .env(SCRIPT, format!("sleep {arg}"))
                    .spawn()
                    .unwrap(),
            ),
            "wait" => {
                for mut c in spawned.drain(..) {
                    c.wait().unwrap();
                }
            }
            "exit" => return ExitCode::from(arg.parse::<u8>().unwrap()),
            _ => panic!("unknown step `{step}`"),
        }
    }
    ExitCode::SUCCESS
}

/// Runs this program as a child following `script`, for at most `timeout` seconds.
fn run(script: &str, timeout: f64, stop: &dyn Fn(&str) -> bool) -> ChildOutput {
    let mut cmd = Command::new(std::env::current_exe().unwrap());
    cmd.env(SCRIPT, script);
    run_child_watched(cmd, Duration::from_secs_f64(timeout), &|_| {}, stop).unwrap()
}

// Expectation: the watcher sees the child's lines as they come and stops it at once; a
// watcher that never fires leaves the run as `run_child`'s (status, all the output).
fn the_watcher_stops_the_child_at_the_line_it_waits_for() {
    let seen = std::cell::RefCell::new(Vec::new());
    let out = run("out one;out Info : two 7;sleep 30", 60.0, &|l| {
        seen.borrow_mut().push(l.to_string());
        l.contains("two 7")
    });
    assert!(out.stopped && out.status.is_none());
    assert!(out.seconds < 20.0, "stopped after {} s", out.seconds);
    assert_eq!(*seen.borrow(), ["one", "Info : two 7"]);
    let out = run("out one;err two;exit 3", 60.0, &|_| false);
    assert!(!out.stopped);
    assert_eq!(out.status.and_then(|s| s.code()), Some(3));
    assert_eq!(out.text.replace("\r\n", "\n"), "one\ntwo\n");
}

// Expectation: processes the child started go with it — stopped by the watcher, at the time
// limit, or left running by a child that exited — so none keeps the run waiting on the output
// pipe it holds (each grandchild here would hold it 30 s).
fn what_the_child_started_ends_with_the_run() {
    let out = run("out one;out ready;spawn 30;wait", 60.0, &|l| l == "ready");
    assert!(
        out.stopped && out.seconds < 20.0,
        "stopped after {} s",
        out.seconds
    );
    let out = run("spawn 30;spawn 30;wait", 0.5, &|_| false);
    assert!(out.status.is_none() && !out.stopped);
    assert!(out.seconds < 20.0, "timed out after {} s", out.seconds);
    let out = run("spawn 30;out done", 60.0, &|_| false);
    assert_eq!(out.status.and_then(|s| s.code()), Some(0));
    assert_eq!(out.text.replace("\r\n", "\n"), "done\n");
    assert!(out.seconds < 20.0, "returned after {} s", out.seconds);
}
