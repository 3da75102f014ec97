//! Library version and ABI revision.

use std::ffi::c_char;

use crate::guard::guard;
use crate::ptr::write_out;
use crate::status::DcrStatus;

/// Revision of the C ABI this header describes: bumped whenever a struct layout, a function
/// signature or an enumeration code changes. Compare it with `DcrVersion.abi` from
/// `dcr_version` at start-up to catch a header and a library that do not belong together.
pub const DCR_ABI_VERSION: u32 = 3;

/// The library's version (semantic versioning of the dcr crates) and ABI revision.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DcrVersion {
    /// Major version.
    pub major: u32,
    /// Minor version.
    pub minor: u32,
    /// Patch version.
    pub patch: u32,
    /// The library's `DCR_ABI_VERSION`.
    pub abi: u32,
}

/// Fills `out` with the library's version and ABI revision.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` when `out` is NULL.
///
/// # Safety
/// `out` must be NULL or valid for a write of a `DcrVersion`.
#[no_mangle]
pub unsafe extern "C" fn dcr_version(out: *mut DcrVersion) -> DcrStatus {
    guard("dcr_version", || {
        let v = DcrVersion {
            major: env!("CARGO_PKG_VERSION_MAJOR").parse().unwrap_or(0),
            minor: env!("CARGO_PKG_VERSION_MINOR").parse().unwrap_or(0),
            patch: env!("CARGO_PKG_VERSION_PATCH").parse().unwrap_or(0),
            abi: DCR_ABI_VERSION,
        };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, v, "out") }
    })
}

/// The library's version as a static NUL-terminated string, e.g. `"0.1.0"`. Do not free it.
#[no_mangle]
pub extern "C" fn dcr_version_string() -> *const c_char {
    const V: &str = concat!(env!("CARGO_PKG_VERSION"), "\0");
    V.as_ptr().cast()
}
