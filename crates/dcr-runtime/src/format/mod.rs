//! The `.modes` base format (read and write), defined once here; `modal-bake` writes through it.
//! Beside it the one writer of every file the tools write: [`OutputPlan`] (the output policy,
//! checked before anything is written) and [`AtomicFile`] / [`write_atomic`].

mod atomic_file;
mod modes_file;
mod npy;
mod output_plan;
mod quadratic_surface;
mod regular_file;
mod transfer_table;

pub use atomic_file::{remove_pending_temporaries, write_atomic, AtomicFile, STALE_AFTER};
pub use modes_file::{
    AccuracyRecord, FormatError, MaterialSi, ModesFile, ModesMeta, ModesPrecision, FORMAT_VERSION,
    MAX_COORDINATE_M, MIN_EXTENT_M,
};
pub use output_plan::{OutputError, OutputPlan};
pub use quadratic_surface::{QuadraticSurface, QUADRATIC_FORMAT_VERSION};
pub use regular_file::{describe_file_type, open_regular_file, same_file, OpenError};
pub use transfer_table::{TransferTable, MAX_TRANSFER_POINTS};

#[cfg(test)]
mod tests;
