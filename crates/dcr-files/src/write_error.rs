//! [`WriteError`]: why a file could not be written.

use std::path::PathBuf;

/// What [`WriteError::InUse`] tells the user to do.
pub const IN_USE_HINT: &str = "another program has it open, or it is read-only; close it there \
                               (or clear its read-only attribute) and run again, or write \
                               elsewhere";

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
    /// Windows: the destination could not be replaced for [`crate::RENAME_PATIENCE`]
    /// because another program holds it open without sharing its deletion (a viewer, an
    /// editor), or it is read-only. The destination is untouched and the temporary removed.
    #[error("{path}: cannot be replaced ({source}): {hint}", hint = IN_USE_HINT)]
    InUse {
        /// The destination.
        path: PathBuf,
        /// The last refusal.
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
