//! The `.modes` base format (read and write), defined once here; `modal-bake` writes through it.

mod modes_file;
mod transfer_table;

pub use modes_file::{
    AccuracyRecord, FormatError, MaterialSi, ModesFile, ModesMeta, ModesPrecision, FORMAT_VERSION,
};
pub use transfer_table::{TransferTable, MAX_TRANSFER_POINTS};

#[cfg(test)]
mod tests;
