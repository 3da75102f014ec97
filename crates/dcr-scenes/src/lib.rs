//! `dcr-scenes`: the paper's §5.1 / Table 1 examples, headless on rapier3d-f64 through
//! `dcr-rapier`, with the distant collision response on and off.
//!
//! - [`scene`]: the scene file format (`scenes/*.json`) and the rapier world built from it.
//! - [`runner`]: a headless run (scripted drivers, trajectories, timings, outcome figures) and
//!   the Table 1 report. The response itself is `dcr_rapier::f64::DcrRapier` over
//!   [`dcr_runtime::DcrWorld`].
//! - [`export`]: runs as animated glTF (side by side, response events in `extras`) and the
//!   outcome figures over time as SVG.
//!
//! See docs/scenes.md.

pub mod export;
pub mod runner;
pub mod scene;

use std::path::{Path, PathBuf};

/// The repository root: `$DCR_ROOT`, else the nearest ancestor of the current directory
/// holding `scenes/` and `data/scenes/`, else the workspace this crate was built in.
pub fn repo_root() -> PathBuf {
    if let Ok(r) = std::env::var("DCR_ROOT") {
        return PathBuf::from(r);
    }
    if let Ok(mut d) = std::env::current_dir() {
        loop {
            if d.join("scenes").is_dir() && d.join("data").join("scenes").is_dir() {
                return d;
            }
            if !d.pop() {
                break;
            }
        }
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("..")
}

/// The six scenes of the paper's §5.1, in Table 1 order.
pub const SCENES: [&str; 6] = [
    "dinner", "roof", "scaffold", "lowrider", "rockfall", "washing",
];
