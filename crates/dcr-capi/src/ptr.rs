//! Checked conversions of the caller's pointers: NULL → [`DcrStatus::NullPointer`], misaligned
//! or oversized → [`DcrStatus::InvalidArgument`], each naming the argument.
//!
//! The checks cannot prove a pointer valid (no C API can); they turn the mistakes a caller can
//! make without undefined behaviour on its own side into errors instead of crashes.

use std::mem::{align_of, size_of};

use crate::status::{DcrStatus, Failure};

/// Checks that `p` is non-null and aligned for `T`.
pub(crate) fn check_ptr<T>(p: *const T, name: &str) -> Result<(), Failure> {
    if p.is_null() {
        return Err(Failure::new(
            DcrStatus::NullPointer,
            format!("`{name}` is NULL"),
        ));
    }
    if !(p as usize).is_multiple_of(align_of::<T>()) {
        return Err(Failure::invalid(format!(
            "`{name}` ({p:p}) is not aligned to {} bytes",
            align_of::<T>()
        )));
    }
    Ok(())
}

/// Checks that `n` elements of `T` fit in `isize::MAX` bytes (the limit of a Rust slice).
pub(crate) fn check_len<T>(n: usize, name: &str) -> Result<(), Failure> {
    if n.checked_mul(size_of::<T>().max(1))
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Failure::invalid(format!(
            "`{name}`: {n} elements of {} bytes exceed the address space",
            size_of::<T>()
        )));
    }
    Ok(())
}

/// `&T` from a caller pointer.
///
/// # Safety
/// When non-null and aligned, `p` must point to a valid, initialised `T` that is not mutated
/// during `'a`.
pub(crate) unsafe fn arg_ref<'a, T>(p: *const T, name: &str) -> Result<&'a T, Failure> {
    check_ptr(p, name)?;
    // SAFETY: non-null and aligned (checked); validity is the caller's contract.
    Ok(unsafe { &*p })
}

/// `&mut T` from a caller pointer to an initialised `T` (handles).
///
/// # Safety
/// When non-null and aligned, `p` must point to a valid `T` not aliased during `'a`.
pub(crate) unsafe fn arg_mut<'a, T>(p: *mut T, name: &str) -> Result<&'a mut T, Failure> {
    check_ptr(p, name)?;
    // SAFETY: non-null and aligned (checked); validity and exclusivity are the caller's contract.
    Ok(unsafe { &mut *p })
}

/// A slice of `n` caller elements; `p` may be NULL (or dangling) when `n` is 0.
///
/// # Safety
/// When `n` > 0, `p` must point to `n` valid, initialised `T` not mutated during `'a`.
pub(crate) unsafe fn arg_slice<'a, T>(
    p: *const T,
    n: usize,
    name: &str,
) -> Result<&'a [T], Failure> {
    if n == 0 {
        return Ok(&[]);
    }
    check_ptr(p, name)?;
    check_len::<T>(n, name)?;
    // SAFETY: non-null, aligned, size within isize::MAX (checked); the caller guarantees `n`
    // valid elements that nothing mutates meanwhile.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// Writes `value` to the caller's out-parameter `p` (which may be uninitialised memory).
///
/// # Safety
/// When non-null and aligned, `p` must be valid for a write of `T`.
pub(crate) unsafe fn write_out<T>(p: *mut T, value: T, name: &str) -> Result<(), Failure> {
    check_ptr(p, name)?;
    // SAFETY: non-null and aligned (checked); writable per the caller's contract. `write`
    // does not read or drop the old contents, so uninitialised memory is fine.
    unsafe { p.write(value) };
    Ok(())
}

/// Reads a 3-vector from the caller's pointer to 3 doubles.
///
/// # Safety
/// When non-null and aligned, `p` must point to 3 readable `f64`.
pub(crate) unsafe fn read_vec3(p: *const f64, name: &str) -> Result<[f64; 3], Failure> {
    // SAFETY: forwarded caller contract (3 readable doubles).
    let s = unsafe { arg_slice(p, 3, name)? };
    Ok([s[0], s[1], s[2]])
}

/// The `struct_size` a set-up struct starts with must equal this library's `sizeof`.
pub(crate) fn check_struct_size<T>(found: u32, name: &str, type_name: &str) -> Result<(), Failure> {
    let expected = size_of::<T>();
    if found as usize != expected {
        return Err(Failure::invalid(format!(
            "`{name}.struct_size` is {found}, but this library's sizeof({type_name}) is \
             {expected}: fill the struct with its `*_default` function, and build against the \
             dcr.h that ships with this library"
        )));
    }
    Ok(())
}

/// The first `bool` field (of those at byte offsets `fields`) of the caller's struct at `p` that
/// holds neither 0 nor 1, with the byte found; read as raw bytes before any reference to the
/// struct exists. A C or C++ `bool` is always 0 or 1 unless its memory was never initialised;
/// Rust may not read another value as `bool`. Does not allocate.
///
/// # Safety
/// `p` must be non-null, aligned and point to a readable `T` (each offset inside it).
unsafe fn bad_bool<'f, T>(p: *const T, fields: &[(usize, &'f str)]) -> Option<(&'f str, u8)> {
    fields.iter().find_map(|&(offset, field)| {
        debug_assert!(offset < size_of::<T>());
        // SAFETY: `offset` lies inside the readable `T` at `p` (caller contract); a byte read
        // has no alignment or validity requirement.
        let b = unsafe { p.cast::<u8>().add(offset).read() };
        (b > 1).then_some((field, b))
    })
}

fn not_a_bool(name: &str, field: &str, b: u8) -> Failure {
    Failure::invalid(format!(
        "`{name}.{field}` holds {b}, not a bool (0 or 1): initialise every field (the \
         `*_default` functions do)"
    ))
}

/// Checks that the `bool` fields at byte offsets `fields` of the caller's struct at `p` hold 0
/// or 1 (see `bad_bool`).
///
/// # Safety
/// `p` must be non-null, aligned and point to a readable `T` (each offset inside it).
pub(crate) unsafe fn check_bools<T>(
    p: *const T,
    fields: &[(usize, &str)],
    name: &str,
) -> Result<(), Failure> {
    // SAFETY: forwarded caller contract.
    match unsafe { bad_bool(p, fields) } {
        Some((field, b)) => Err(not_a_bool(name, field, b)),
        None => Ok(()),
    }
}

/// [`check_bools`] over each of the `n` elements of the caller's array at `p` (no allocation
/// unless one is bad).
///
/// # Safety
/// When `n` > 0, `p` must be non-null, aligned and point to `n` readable `T`.
pub(crate) unsafe fn check_bools_in_array<T>(
    p: *const T,
    n: usize,
    fields: &[(usize, &str)],
    name: &str,
) -> Result<(), Failure> {
    for i in 0..n {
        // SAFETY: element i of the caller's array (caller contract).
        if let Some((field, b)) = unsafe { bad_bool(p.add(i), fields) } {
            return Err(not_a_bool(&format!("{name}[{i}]"), field, b));
        }
    }
    Ok(())
}
