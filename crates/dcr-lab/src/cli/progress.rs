//! Progress on stderr: a bar on a terminal; otherwise plain lines (CI logs), one when a stage
//! starts and then at most one every [`PLAIN_EVERY`] while it counts.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Interval between plain progress lines of one counting stage.
pub const PLAIN_EVERY: Duration = Duration::from_secs(5);

/// A progress reporter for one command.
pub struct Progress {
    /// Prefix of plain lines (the command name).
    name: &'static str,
    bar: Option<ProgressBar>,
    stage: String,
    last_line: Option<Instant>,
}

impl Progress {
    /// A bar when stderr is a terminal, plain lines otherwise.
    pub fn new(name: &'static str) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::new_spinner();
            b.enable_steady_tick(Duration::from_millis(120));
            b
        });
        Progress {
            name,
            bar,
            stage: String::new(),
            last_line: None,
        }
    }

    /// A stage without a count (e.g. "eigensolve").
    pub fn stage(&mut self, what: &str) {
        if self.stage == what {
            return;
        }
        self.stage = what.to_string();
        match &self.bar {
            Some(b) => {
                b.set_style(ProgressStyle::default_spinner());
                b.set_length(0);
                b.set_message(what.to_string());
            }
            None => eprintln!("{}: {what}", self.name),
        }
    }

    /// A counting stage: `done` of `total` `what`.
    pub fn count(&mut self, what: &str, done: usize, total: usize) {
        let new_stage = self.stage != what;
        if new_stage {
            self.stage = what.to_string();
            self.last_line = None;
        }
        match &self.bar {
            Some(b) => {
                if new_stage {
                    b.set_style(
                        ProgressStyle::with_template(
                            "{spinner} {msg} [{bar:30}] {pos}/{len} ({eta} left)",
                        )
                        .unwrap_or_else(|_| ProgressStyle::default_bar())
                        .progress_chars("=> "),
                    );
                    b.set_message(what.to_string());
                }
                b.set_length(total as u64);
                b.set_position(done as u64);
            }
            None => {
                let due = self.last_line.is_none_or(|t| t.elapsed() >= PLAIN_EVERY);
                if due || done == total {
                    eprintln!("{}: {what} {done}/{total}", self.name);
                    self.last_line = Some(Instant::now());
                }
            }
        }
    }

    /// Clears the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
