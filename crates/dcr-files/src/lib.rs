//! `dcr-files`: the one writer of every file the dcr tools write (bases, meshes, exports, scene
//! outputs, reports), with one policy.
//!
//! 1. [`OutputPlan`]: before anything is written, a command declares its inputs and all of its
//!    outputs; an output that is an input (also through a link or another spelling), exists as
//!    anything but a regular file (a folder, a device, a FIFO, a socket), names no file, or is
//!    shared with another output is refused, naming the option and the path.
//! 2. [`AtomicFile`] / [`write_atomic`]: each file is written under a unique temporary name
//!    beside its destination and renamed over it only when complete; the destination's type is
//!    checked again at the rename, so a device node or a FIFO is never replaced.
//! 3. [`remove_pending_temporaries`]: the temporaries being written are registered
//!    process-wide; a tool's SIGINT/SIGTERM/SIGHUP handler calls it before the process ends.
//!
//! Why a crate of its own: writing files, naming temporaries, checking whether the process that
//! left one still runs and the signal registry are what the tools do, not what an engine does.
//! Engines link `dcr-runtime`, which reads and validates bases and never compiles this crate;
//! the baker (`modal-bake`), `dcr-scenes` and `dcr-lab` write through it, and the runtime's
//! `.modes` encoder (its `write` feature, so that the format stays defined in one place) writes
//! bases through it too. The crate depends on nothing but `thiserror`.
//!
//! ```
//! let dir = tempfile::tempdir()?;
//! let input = dir.path().join("table.modes");
//! std::fs::write(&input, b"base")?;
//! let out = dir.path().join("table.vtu");
//! let mut plan = dcr_files::OutputPlan::new();
//! plan.input("the base", &input);
//! plan.output("--vtu", &out)?;
//! plan.output("--gltf", &input).unwrap_err(); // the input is never an output
//! dcr_files::write_atomic(&out, b"<VTKFile/>")?;
//! assert_eq!(std::fs::read(&out)?, b"<VTKFile/>");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod atomic_file;
mod file_type;
mod output_plan;
mod write_error;

pub use atomic_file::{
    remove_pending_temporaries, write_atomic, AtomicFile, RENAME_PATIENCE, STALE_AFTER,
};
pub use file_type::{describe_file_type, same_file};
pub use output_plan::{OutputError, OutputPlan};
pub use write_error::{WriteError, IN_USE_HINT};
