//! [`WriteError`]: why a file could not be written.

use std::path::PathBuf;

/// Why [`crate::AtomicFile`] or [`crate::write_atomic`] could not write a file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// Operating-system I/O error (missing folder, permissions, full disk, ...).
    #[error("{path}: {source}")]
    Io {
        /// The destination.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The destination exists and is not a regular file: renaming over it would replace it.
    #[error("{path}: is {what}; refusing to replace it with a file (give the path of a file)")]
    Clobber {
        /// The destination.
        path: PathBuf,
        /// What it is ("a directory", "a character device", ...).
        what: &'static str,
    },
}
