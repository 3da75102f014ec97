//! Progress of long work on stderr: on a terminal an indicatif spinner per stage and a bar for
//! the eigensolve and the transfer table; otherwise (CI logs, redirected stderr) plain lines:
//! one when a stage starts that is still running after [`PLAIN_EVERY`], one every
//! `PLAIN_EVERY` while it runs (with the eigensolver's or table's count when it reports one,
//! else the seconds so far, from a heartbeat thread), and one with its duration when it ends.
//! Short work prints nothing.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use modal_bake::bake::BakeStage;

/// Interval between plain progress lines, and the shortest stage that gets one (seconds;
/// `MODAL_BAKE_PROGRESS_EVERY` overrides it, e.g. 0 for every event).
const PLAIN_EVERY: Duration = Duration::from_secs(5);

/// Progress reporter (see the module doc).
pub struct Progress {
    bar: ProgressBar,
    plain: Option<Arc<Mutex<Plain>>>,
    stop: Arc<AtomicBool>,
    heartbeat: Option<std::thread::JoinHandle<()>>,
}

/// State of the plain-line progress.
struct Plain {
    tool: &'static str,
    every: Duration,
    start: Instant,
    stage: &'static str,
    label: String,
    stage_start: Instant,
    last: Instant,
    /// Whether the current stage has printed a line (a start or heartbeat line).
    announced: bool,
}

impl Plain {
    /// No stage yet; lines every `every`, times from `now`.
    fn new(tool: &'static str, every: Duration, now: Instant) -> Plain {
        Plain {
            tool,
            every,
            start: now,
            stage: "",
            label: String::new(),
            stage_start: now,
            last: now,
            announced: false,
        }
    }

    fn line(&self, text: &str) {
        eprintln!(
            "{} [{:7.1} s] {text}",
            self.tool,
            self.start.elapsed().as_secs_f64()
        );
    }

    /// Ends the current stage (a line with its duration if it was long).
    fn end_stage(&mut self) {
        let took = self.stage_start.elapsed();
        if !self.stage.is_empty() && (took >= self.every || self.announced) {
            self.line(&format!(
                "{}: done in {:.1} s",
                self.label,
                took.as_secs_f64()
            ));
        }
        self.stage = "";
        self.announced = false;
    }

    /// Records progress of `stage` described by `label`.
    fn report(&mut self, stage: &'static str, label: impl FnOnce() -> String) {
        let now = Instant::now();
        if stage != self.stage {
            self.end_stage();
            self.stage = stage;
            self.label = label();
            self.stage_start = now;
            self.last = now;
            if self.every.is_zero() {
                self.line(&self.label);
                self.announced = true;
            }
        } else {
            // Always the latest label: the heartbeat repeats it between reports.
            self.label = label();
            if now.duration_since(self.last) >= self.every {
                self.line(&self.label);
                self.last = now;
                self.announced = true;
            }
        }
    }

    /// A heartbeat: a line for a stage that has run `every` since its last line.
    fn tick(&mut self) {
        let now = Instant::now();
        if self.stage.is_empty() || now.duration_since(self.last) < self.every {
            return;
        }
        self.line(&format!(
            "{} ({:.0} s so far)",
            self.label,
            now.duration_since(self.stage_start).as_secs_f64()
        ));
        self.last = now;
        self.announced = true;
    }
}

impl Progress {
    /// A reporter whose plain lines start with `tool` (`bake`, `mesh`).
    pub fn new(tool: &'static str) -> Progress {
        use std::io::IsTerminal;
        let stop = Arc::new(AtomicBool::new(false));
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new_spinner();
            bar.enable_steady_tick(Duration::from_millis(120));
            return Progress {
                bar,
                plain: None,
                stop,
                heartbeat: None,
            };
        }
        let now = Instant::now();
        let every = std::env::var("MODAL_BAKE_PROGRESS_EVERY")
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0)
            .map_or(PLAIN_EVERY, Duration::from_secs_f64);
        let plain = Arc::new(Mutex::new(Plain::new(tool, every, now)));
        let heartbeat = (!every.is_zero()).then(|| {
            let (plain, stop) = (plain.clone(), stop.clone());
            let nap = every.min(Duration::from_millis(500));
            std::thread::spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    std::thread::park_timeout(nap);
                    if stop.load(Ordering::Relaxed) {
                        break;
                    }
                    if let Ok(mut p) = plain.lock() {
                        p.tick();
                    }
                }
            })
        });
        Progress {
            bar: ProgressBar::hidden(),
            plain: Some(plain),
            stop,
            heartbeat,
        }
    }

    fn plain(&self, f: impl FnOnce(&mut Plain)) -> bool {
        match &self.plain {
            Some(p) => {
                if let Ok(mut p) = p.lock() {
                    f(&mut p);
                }
                true
            }
            None => false,
        }
    }

    /// Starts (or continues) a stage without a count: `stage` identifies it, `label` says what
    /// runs (`meshing chair.obj with gmsh`).
    pub fn stage(&mut self, stage: &'static str, label: &str) {
        if !self.plain(|p| p.report(stage, || label.to_string())) {
            self.bar.set_style(ProgressStyle::default_spinner());
            self.bar.set_message(label.to_string());
        }
    }

    /// Ends the current stage and the reporter (clears the bar, stops the heartbeat).
    pub fn finish(&mut self) {
        self.bar.finish_and_clear();
        self.plain(|p| p.end_stage());
        self.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.heartbeat.take() {
            h.thread().unpark();
            let _ = h.join();
        }
    }

    /// Reports a bake stage.
    pub fn update(&mut self, stage: BakeStage) {
        let plain = self.plain(|plain| match stage {
            BakeStage::Read => plain.report("read", || stage.label().into()),
            BakeStage::Assemble => plain.report("assemble", || stage.label().into()),
            BakeStage::Factor => plain.report("factor", || stage.label().into()),
            BakeStage::Eigensolve(p) => plain.report("eigensolve", || {
                format!(
                    "eigensolve: {}/{} modes converged, Lanczos step {}",
                    p.converged.min(p.requested),
                    p.requested,
                    p.iteration
                )
            }),
            BakeStage::TransferModes => plain.report("transfer modes", || stage.label().into()),
            BakeStage::Transfer(p) => plain.report("transfer", || {
                format!(
                    "transfer table: {}/{} rows ({})",
                    p.done,
                    p.total,
                    p.plan.describe()
                )
            }),
            BakeStage::Truth(_) => plain.report("truth", || detailed(stage)),
            BakeStage::Write => plain.report("write", || stage.label().into()),
        });
        if plain {
            return;
        }
        match stage {
            BakeStage::Read | BakeStage::Assemble | BakeStage::Factor => {
                self.bar.set_message(stage.label())
            }
            BakeStage::Eigensolve(p) => {
                if self.bar.length().is_none() {
                    self.bar.set_style(
                        ProgressStyle::with_template(
                            "{spinner} eigensolve [{bar:30}] {pos}/{len} modes converged ({msg})",
                        )
                        .unwrap_or_else(|_| ProgressStyle::default_bar())
                        .progress_chars("=> "),
                    );
                }
                self.bar.set_length(p.requested as u64);
                self.bar.set_position(p.converged.min(p.requested) as u64);
                self.bar
                    .set_message(format!("Lanczos step {}", p.iteration));
            }
            BakeStage::TransferModes | BakeStage::Truth(_) | BakeStage::Write => {
                self.bar.set_style(ProgressStyle::default_spinner());
                self.bar.set_message(detailed(stage));
            }
            BakeStage::Transfer(p) => {
                if self.bar.length() != Some(p.total as u64) {
                    self.bar.set_style(
                        ProgressStyle::with_template(
                            "{spinner} transfer table [{bar:30}] {pos}/{len} rows ({eta} left)",
                        )
                        .unwrap_or_else(|_| ProgressStyle::default_bar())
                        .progress_chars("=> "),
                    );
                    self.bar.set_length(p.total as u64);
                    self.bar
                        .println(format!("transfer table: {}", p.plan.describe()));
                }
                self.bar.set_position(p.done as u64);
            }
        }
    }
}

/// A stage's label with its counts where a spinner shows them (the truth's level and samples).
fn detailed(stage: BakeStage) -> String {
    match stage {
        BakeStage::Truth(p) => format!(
            "{}: level {} (dt {:.2e} s), {}/{} samples",
            stage.label(),
            p.level,
            p.dt,
            p.done,
            p.total
        ),
        _ => stage.label().into(),
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The heartbeat repeats the latest count, not the stage's first: a report between two
    // heartbeat lines (too soon for a line of its own) still updates the label.
    #[test]
    fn the_heartbeat_repeats_the_latest_report() {
        let mut p = Plain::new("test", Duration::from_secs(3600), Instant::now());
        p.report("transfer", || "transfer table: 0/10 rows".into());
        p.report("transfer", || "transfer table: 4/10 rows".into());
        assert_eq!(p.label, "transfer table: 4/10 rows");
        p.report("write", || "writing".into());
        assert_eq!((p.stage, p.label.as_str()), ("write", "writing"));
    }
}
