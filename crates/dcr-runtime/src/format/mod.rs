//! The `.modes` base format (read and write), defined once here; `modal-bake` writes through it.

mod modes_file;
mod quadratic_surface;
mod transfer_table;

pub use modes_file::{
    FormatError, MaterialSi, ModesFile, ModesMeta, ModesPrecision, FORMAT_VERSION,
};
pub use quadratic_surface::{QuadraticSurface, QUADRATIC_FORMAT_VERSION};
pub use transfer_table::{TransferTable, MAX_TRANSFER_POINTS};

#[cfg(test)]
mod tests;
