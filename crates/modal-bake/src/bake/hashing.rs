//! The geometry hash stored in every base (`meta.source_hash`): SHA-256 of the canonical
//! geometry, independent of the mesh file's format and bytes.

use sha2::{Digest, Sha256};

use crate::mesh::TetMesh;

/// `sha256:<hex>` of the canonical geometry: node positions rounded to 16 significant
/// digits, tetrahedra (after orientation) and the sorted fixed-node set. Independent of the
/// file's format and bytes.
///
/// Why 16 digits: gmsh prints ASCII MSH coordinates with `%.16g`, which does not round-trip
/// every `f64`, so its ASCII and binary files of one mesh can differ by an ulp per coordinate.
/// Rounding is idempotent on what gmsh prints (x and the double nearest its 16-digit decimal
/// round alike), so every form gmsh writes of one mesh — MSH 2.2 or 4.1, ASCII or binary —
/// and a meshio JSON of it hash alike. Two meshes whose coordinates differ only beyond the
/// 16th significant digit (relative change below ~5e-16) share a hash; their bases differ by
/// rounding only.
pub fn geometry_hash(mesh: &TetMesh, fixed: &[usize]) -> String {
    let mut h = Sha256::new();
    h.update(b"dcr-geometry-v2");
    h.update((mesh.nodes.len() as u64).to_le_bytes());
    for p in &mesh.nodes {
        for &x in p {
            h.update(round_16_digits(x).to_bits().to_le_bytes());
        }
    }
    h.update((mesh.tets.len() as u64).to_le_bytes());
    for t in &mesh.tets {
        for &v in t {
            h.update((v as u64).to_le_bytes());
        }
    }
    h.update((fixed.len() as u64).to_le_bytes());
    for &v in fixed {
        h.update((v as u64).to_le_bytes());
    }
    // Second-order meshes only, so linear meshes keep their hash.
    if mesh.is_quadratic() {
        h.update(b"tet10");
        for e in &mesh.mid_edges {
            for &v in e {
                h.update((v as u64).to_le_bytes());
            }
        }
    }
    format!("sha256:{:x}", h.finalize())
}

/// `x` rounded to 16 significant decimal digits (the double nearest `%.16g` of `x`); non-finite
/// values unchanged.
pub fn round_16_digits(x: f64) -> f64 {
    use std::io::Write;
    if !x.is_finite() {
        return x;
    }
    // "-d.ddddddddddddddde-308" is 23 bytes.
    let mut buf = [0u8; 32];
    let mut w = &mut buf[..];
    let _ = write!(w, "{x:.15e}");
    let n = 32 - w.len();
    std::str::from_utf8(&buf[..n])
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rounding to 16 digits is idempotent (the geometry hash relies on it: a coordinate and
    /// its `%.16g` print round alike), exact where 16 digits suffice, and moves a value by at
    /// most half a unit of its 16th digit (plus the parse's half ulp). Random bit patterns over
    /// the whole finite range.
    #[test]
    fn rounding_to_16_digits_is_idempotent() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut checked = 0;
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = f64::from_bits(state);
            if !x.is_finite() {
                continue;
            }
            let r = round_16_digits(x);
            let printed: f64 = format!("{x:.15e}").parse().unwrap();
            assert_eq!(r.to_bits(), printed.to_bits(), "{x:e}");
            assert_eq!(round_16_digits(r).to_bits(), r.to_bits(), "{x:e}");
            assert!((r - x).abs() <= 6.2e-16 * x.abs(), "{x:e} → {r:e}");
            checked += 1;
        }
        assert!(checked > 190_000);
        for x in [0.0, -0.0, 1.0, 0.1, 0.3, -2.5e-7, 1e300, 5e-324] {
            assert_eq!(round_16_digits(x).to_bits(), x.to_bits(), "{x:e}");
        }
    }
}
