//! The workspace's small `[f64; 3]` vector kit (plain data, as at the engine boundary), shared
//! by the runtime, the rapier adapter and the baker so that every crate does the same operations
//! in the same order (bit-identical results). Units are the caller's (m, m/s, N·s, ...); the
//! frame is whatever frame the arguments share.
//!
//! ```
//! use dcr_runtime::math::{cross, dot, norm, normalize, sub};
//! let e = sub([1.0, 2.0, 3.0], [1.0, 2.0, 2.0]);
//! assert_eq!(e, [0.0, 0.0, 1.0]);
//! assert_eq!(cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), e);
//! assert_eq!(dot(e, [4.0, 5.0, 6.0]), 6.0);
//! assert_eq!(norm(normalize([3.0, 0.0, 4.0])), 1.0);
//! assert_eq!(normalize([0.0; 3]), [0.0; 3]);
//! ```

/// `a + b`.
#[inline]
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
#[inline]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s a`.
#[inline]
pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `a · b`, summed in axis order.
#[inline]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b` (right-handed).
#[inline]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a|²`.
#[inline]
pub fn norm2(a: [f64; 3]) -> f64 {
    dot(a, a)
}

/// `|a|`.
#[inline]
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Unit vector along `a`, or `[0, 0, 0]` for a zero (or non-finite) vector.
#[inline]
pub fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = norm(a);
    if n > 0.0 && n.is_finite() {
        scale(a, 1.0 / n)
    } else {
        [0.0; 3]
    }
}

/// `M v` for a row-major 3 × 3 matrix (`m[row][column]`): each row dotted with `v`.
#[inline]
pub fn mat_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `a·b + c`: one fused multiply-add when `FMA` (callers compile that path with FMA enabled,
/// e.g. under `pulp` dispatch), else a separate multiply and add.
#[inline(always)]
pub(crate) fn fmadd<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA {
        a.mul_add(b, c)
    } else {
        c + a * b
    }
}
