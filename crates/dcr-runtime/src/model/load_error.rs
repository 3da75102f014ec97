//! Errors raised while loading or validating a modal base.

use std::path::PathBuf;

use crate::format::FormatError;

/// Why a modal base could not be turned into a [`crate::ModalModel`]; every variant names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LoadError {
    /// The `.modes` file is unreadable, truncated, mismatched or holds NaN (see [`FormatError`];
    /// its message starts with the file path).
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The base is readable but unusable at run time (e.g. a degenerate surface the BVH refuses).
    #[error("{path}: {detail}")]
    Invalid {
        /// File concerned (`<memory>` for [`crate::ModalModel::from_base`]).
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
}
