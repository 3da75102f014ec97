//! [`DcrStatus`], the thread-local last-error message and the calls that read it.

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};

/// Outcome of a dcr call. `DCR_STATUS_OK` (0) is success; on any other value the call changed
/// nothing the caller can observe except the out-parameters it documents (a required count),
/// and `dcr_last_error_message` tells what went wrong.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DcrStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument was NULL.
    NullPointer = 1,
    /// An argument failed validation: a value out of range, an unknown enumeration code, a
    /// `struct_size` that is not this library's `sizeof`, a misaligned pointer.
    InvalidArgument = 2,
    /// An elastic-object handle not from this world.
    InvalidHandle = 3,
    /// An output array is too small; the call reported the required count and did nothing else.
    BufferTooSmall = 4,
    /// No result: a point farther from the surface than the allowed distance, a body that
    /// carries no elastic object.
    NotFound = 5,
    /// A file could not be read (missing, permission denied); the message names it.
    Io = 6,
    /// The data is not a valid `.modes` base (corrupt, truncated, wrong version, NaN, a surface
    /// the runtime cannot use); the message names the file (`<memory>` for bytes) and the entry.
    InvalidBase = 7,
    /// The library panicked (a bug): the objects the call mutated must be freed, not used.
    Panic = 8,
}

/// An error on its way to the C caller: the status and the message stored for
/// `dcr_last_error_message`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// Status returned.
    pub status: DcrStatus,
    /// What went wrong (stored as the thread's last error, prefixed with the function name).
    pub message: String,
}

impl Failure {
    /// A failure with `status` and `message`.
    pub fn new(status: DcrStatus, message: impl Into<String>) -> Failure {
        Failure {
            status,
            message: message.into(),
        }
    }

    /// [`DcrStatus::InvalidArgument`] with `message`.
    pub fn invalid(message: impl Into<String>) -> Failure {
        Failure::new(DcrStatus::InvalidArgument, message)
    }
}

thread_local! {
    /// The last failure's message on this thread (empty before the first failure).
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Stores `function: message` as this thread's last error (interior NULs become `?`).
pub(crate) fn set_last_error(function: &str, message: &str) {
    let text = format!("{function}: {message}").replace('\0', "?");
    let c = CString::new(text).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Copies this thread's last error message into `buf` (NUL-terminated, UTF-8).
///
/// The message is that of the last call on this thread that did not return `DCR_STATUS_OK`
/// (successful calls leave it unchanged; empty before the first failure). It names the
/// function, then what failed as the Rust error says it: the file and the entry, line or value
/// at fault, or the argument and its value.
///
/// `required` (may be NULL) receives the buffer size the whole message needs, terminating NUL
/// included. `buf` may be NULL when `len` is 0 (a size query).
///
/// # Errors
/// `DCR_STATUS_BUFFER_TOO_SMALL` when `len` < the required size: `buf` then holds the first
/// `len − 1` bytes and a NUL (when `len` > 0). `DCR_STATUS_NULL_POINTER` when `buf` is NULL and
/// `len` > 0. These two do not replace the stored message.
///
/// # Safety
/// `buf` must be NULL or point to `len` writable bytes; `required` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_last_error_message(
    buf: *mut c_char,
    len: usize,
    required: *mut usize,
) -> DcrStatus {
    let run = std::panic::catch_unwind(|| {
        LAST_ERROR.with(|e| {
            let e = e.borrow();
            let bytes = e.as_bytes_with_nul();
            if !required.is_null() {
                // SAFETY: non-null, and the caller guarantees it is valid for a write.
                unsafe { required.write_unaligned(bytes.len()) };
            }
            if len == 0 {
                return if bytes.len() > 1 {
                    DcrStatus::BufferTooSmall
                } else {
                    DcrStatus::Ok
                };
            }
            if buf.is_null() {
                return DcrStatus::NullPointer;
            }
            let n = bytes.len().min(len);
            // SAFETY: `buf` is non-null and points to `len` ≥ n writable bytes (caller
            // contract); the source is our own buffer, which cannot overlap the caller's.
            unsafe {
                std::ptr::copy_nonoverlapping(bytes.as_ptr().cast::<c_char>(), buf, n);
                *buf.add(n - 1) = 0;
            }
            if n < bytes.len() {
                DcrStatus::BufferTooSmall
            } else {
                DcrStatus::Ok
            }
        })
    });
    run.unwrap_or(DcrStatus::Panic)
}

/// This thread's last error message (see `dcr_last_error_message`) as a NUL-terminated string
/// owned by the library: valid until the next failing dcr call on this thread, or the thread's
/// exit. Never NULL (empty before the first failure). Do not free it.
#[no_mangle]
pub extern "C" fn dcr_last_error() -> *const c_char {
    std::panic::catch_unwind(|| LAST_ERROR.with(|e| e.borrow().as_ptr())).unwrap_or(c"".as_ptr())
}

/// The status's name as a static NUL-terminated string (`"DCR_STATUS_OK"`, …;
/// `"DCR_STATUS_UNKNOWN"` for a value this library does not define). Do not free it.
#[no_mangle]
pub extern "C" fn dcr_status_name(status: i32) -> *const c_char {
    let name: &'static CStr = match status {
        0 => c"DCR_STATUS_OK",
        1 => c"DCR_STATUS_NULL_POINTER",
        2 => c"DCR_STATUS_INVALID_ARGUMENT",
        3 => c"DCR_STATUS_INVALID_HANDLE",
        4 => c"DCR_STATUS_BUFFER_TOO_SMALL",
        5 => c"DCR_STATUS_NOT_FOUND",
        6 => c"DCR_STATUS_IO",
        7 => c"DCR_STATUS_INVALID_BASE",
        8 => c"DCR_STATUS_PANIC",
        _ => c"DCR_STATUS_UNKNOWN",
    };
    name.as_ptr()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::guard::guard;

    /// Every status has its own name, and the name is the C constant's spelling.
    #[test]
    fn status_names_match_the_constants() {
        use DcrStatus::*;
        let all = [
            Ok,
            NullPointer,
            InvalidArgument,
            InvalidHandle,
            BufferTooSmall,
            NotFound,
            Io,
            InvalidBase,
            Panic,
        ];
        let mut seen = std::collections::HashSet::new();
        for s in all {
            // SAFETY: dcr_status_name returns a pointer to a static NUL-terminated string.
            let name = unsafe { CStr::from_ptr(dcr_status_name(s as i32)) };
            let name = name.to_str().unwrap();
            let snake: String = format!("{s:?}")
                .chars()
                .flat_map(|c| {
                    if c.is_uppercase() {
                        vec!['_', c]
                    } else {
                        vec![c.to_ascii_uppercase()]
                    }
                })
                .collect();
            assert_eq!(name, format!("DCR_STATUS{snake}"));
            assert!(seen.insert(name));
        }
        // SAFETY: as above.
        let unknown = unsafe { CStr::from_ptr(dcr_status_name(99)) };
        assert_eq!(unknown.to_str().unwrap(), "DCR_STATUS_UNKNOWN");
    }

    /// A guarded failure stores `function: message`, and a later success leaves it.
    #[test]
    fn last_error_names_the_function_and_survives_success() {
        let st = guard("dcr_example", || Err(Failure::invalid("bad h: -1 s")));
        assert_eq!(st, DcrStatus::InvalidArgument);
        assert_eq!(guard("dcr_other", || Ok(())), DcrStatus::Ok);
        // SAFETY: never NULL, valid until the next failing call on this thread.
        let msg = unsafe { CStr::from_ptr(dcr_last_error()) };
        assert_eq!(msg.to_str().unwrap(), "dcr_example: bad h: -1 s");
    }
}
