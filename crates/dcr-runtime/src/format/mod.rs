//! The `.modes` base format, defined once here: the reader and validator every engine uses,
//! and, with the `write` cargo feature, the encoder (`ModesFile::write_atomic`, through the
//! tools' one writer, the `dcr-files` crate) that `modal-bake` writes bases with.

mod modes_file;
mod npy;
mod quadratic_surface;
mod regular_file;
mod transfer_table;

pub use modes_file::{
    AccuracyRecord, FormatError, MaterialSi, ModesFile, ModesMeta, ModesPrecision, FORMAT_VERSION,
    MAX_COORDINATE_M, MIN_EXTENT_M,
};
pub use quadratic_surface::{QuadraticSurface, QUADRATIC_FORMAT_VERSION};
pub use regular_file::{open_regular_file, OpenError};
pub use transfer_table::{TransferTable, MAX_TRANSFER_POINTS};

#[cfg(test)]
mod tests;
