//! The `.modes` base format (read and write), defined once here; `modal-bake` writes through it.

mod modes_file;

pub use modes_file::{
    FormatError, MaterialSi, ModesFile, ModesMeta, ModesPrecision, FORMAT_VERSION,
};

#[cfg(test)]
mod tests;
