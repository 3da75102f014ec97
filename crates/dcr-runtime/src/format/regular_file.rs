//! Opening files for reading, safely against what a path can name besides a regular file (a
//! directory, a device, a FIFO, a socket).
//!
//! Readers open regular files only: a FIFO blocks until a writer appears and a device such as
//! `/dev/zero` never ends, so neither is opened at all (the type is looked up first, and checked
//! again on the opened handle in case the path changed in between). The writing side (refusing
//! to replace anything but a regular file, or an input) is the tools' `dcr-files` crate, which
//! engines do not compile; its `describe_file_type` uses the same words as the one here.

use std::fs::{File, FileType, Metadata};
use std::path::Path;

/// What kind of file system object `t` is, in words for messages ("a directory", "a FIFO", ...).
pub(crate) fn describe_file_type(t: FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "a character device";
        } else if t.is_block_device() {
            return "a block device";
        } else if t.is_fifo() {
            return "a FIFO";
        } else if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_file() {
        "a regular file"
    } else {
        "a special file"
    }
}

/// Why a path cannot be opened as a regular file for reading.
#[derive(Debug)]
pub enum OpenError {
    /// The path names something other than a regular file (the `describe_file_type` words).
    NotRegular(&'static str),
    /// The operating system refused.
    Io(std::io::Error),
}

impl std::fmt::Display for OpenError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OpenError::NotRegular(what) => write!(f, "not a regular file ({what})"),
            OpenError::Io(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for OpenError {}

/// Opens `path` for reading if it is a regular file (symbolic links followed), returning the
/// file and its length in bytes when opened. Read no more than that length.
///
/// # Errors
/// [`OpenError::NotRegular`] before opening a directory, device, FIFO or socket;
/// [`OpenError::Io`] when it cannot be looked up or opened.
pub fn open_regular_file(path: &Path) -> Result<(File, u64), OpenError> {
    let regular = |meta: &Metadata| {
        if meta.is_file() {
            Ok(())
        } else {
            Err(OpenError::NotRegular(describe_file_type(meta.file_type())))
        }
    };
    regular(&std::fs::metadata(path).map_err(OpenError::Io)?)?;
    let file = File::open(path).map_err(OpenError::Io)?;
    let meta = file.metadata().map_err(OpenError::Io)?;
    regular(&meta)?;
    Ok((file, meta.len()))
}
