//! What a path names, in words for messages, and whether two paths name one file.

use std::fs::FileType;
use std::path::Path;

/// What kind of file system object `t` is, in words for messages ("a directory", "a FIFO", ...).
///
/// ```
/// let t = std::fs::metadata("/").unwrap().file_type();
/// assert_eq!(dcr_files::describe_file_type(t), "a directory");
/// ```
pub fn describe_file_type(t: FileType) -> &'static str {
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

/// Whether `a` and `b` name the same existing file: the same device and inode on Unix, the
/// same volume and file index on Windows (hard links, symbolic links and other spellings of
/// one file count). `false` when either does not exist.
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (file_id(a), file_id(b)) {
        (Some(x), Some(y)) => x == y,
        _ => false,
    }
}

/// The identity of an existing file, links followed: its device and inode on Unix, its
/// volume's serial number and its file index on Windows (other letter case, `8.3` short names
/// and hard links of one file share it), its canonical path elsewhere.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) enum FileId {
    /// (device, inode) on Unix; (volume serial number, file index) on Windows.
    Number(u64, u64),
    /// The canonical path, where the platform numbers no files.
    #[cfg(not(any(unix, windows)))]
    Path(std::path::PathBuf),
}

/// The identity of the file `path` names; `None` when it does not exist or cannot be opened.
pub(crate) fn file_id(path: &Path) -> Option<FileId> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let m = std::fs::metadata(path).ok()?;
        Some(FileId::Number(m.dev(), m.ino()))
    }
    #[cfg(windows)]
    #[allow(unsafe_code)]
    {
        use std::os::windows::fs::OpenOptionsExt;
        use std::os::windows::io::AsRawHandle;
        use windows_sys::Win32::Storage::FileSystem::{
            GetFileInformationByHandle, BY_HANDLE_FILE_INFORMATION, FILE_FLAG_BACKUP_SEMANTICS,
        };
        // No access rights asked: attributes only, as `std::fs::metadata` opens; the backup
        // flag lets a folder be opened too.
        let file = std::fs::OpenOptions::new()
            .access_mode(0)
            .custom_flags(FILE_FLAG_BACKUP_SEMANTICS)
            .open(path)
            .ok()?;
        // SAFETY: an all-zero BY_HANDLE_FILE_INFORMATION is a valid value (integers and
        // FILETIMEs only).
        let mut info: BY_HANDLE_FILE_INFORMATION = unsafe { std::mem::zeroed() };
        // SAFETY: the handle is open for as long as `file` lives; `info` is writable.
        let ok = unsafe { GetFileInformationByHandle(file.as_raw_handle(), &mut info) };
        (ok != 0).then(|| {
            FileId::Number(
                u64::from(info.dwVolumeSerialNumber),
                (u64::from(info.nFileIndexHigh) << 32) | u64::from(info.nFileIndexLow),
            )
        })
    }
    #[cfg(not(any(unix, windows)))]
    {
        path.canonicalize().ok().map(FileId::Path)
    }
}
