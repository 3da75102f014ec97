//! A file cache of the elastic object's dense eigensolve ([`ModalAll`]), so the levels of a
//! reference and later runs on the same object do not repeat it (minutes at 3000 dofs).
//!
//! The key is the SHA-256 of the free-dof stiffness and mass matrices (structure and values,
//! exact bit patterns): a changed mesh, material, fixed group or Young's scale is a different
//! key. An entry is `MAGIC`, the key, then n, m and the rigid modes dropped (u64 little
//! endian), the m eigenvalues and the n × m vectors (column-major) as f64 little endian, so a
//! cached solve is bit-identical to the computed one. The reader checks the file's length
//! against the header before it allocates; an unreadable or mismatched entry is reported and
//! recomputed. Files are written with the project's atomic writer.

use std::path::{Path, PathBuf};

use faer::Mat;
use modal_bake::full_order::{FullOrderSystem, ModalAll};
use sha2::{Digest, Sha256};

use crate::accuracy::truth_cache::hash_sparse;

/// Version of the entry layout and key recipe.
const MAGIC: &[u8; 16] = b"dcr-modalall-v2\n";

/// The cache key of `sys`'s eigensolve (hex SHA-256).
pub fn eigen_key(sys: &FullOrderSystem) -> String {
    let mut h = Sha256::new();
    h.update(MAGIC);
    hash_sparse(&mut h, &sys.k);
    hash_sparse(&mut h, &sys.m);
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The entry's path in `dir` for `key`.
pub fn eigen_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("{}.modall", &key[..32]))
}

/// Reads the entry for `key` from `dir`: `Ok(None)` if there is none.
///
/// # Errors
/// A file that is there but unreadable, of another key, or of the wrong length (the message
/// names it; the caller recomputes and replaces it).
pub fn read_eigen(dir: &Path, key: &str) -> Result<Option<ModalAll>, String> {
    let p = eigen_path(dir, key);
    let bytes = match std::fs::read(&p) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("{}: {e}", p.display())),
    };
    let head = MAGIC.len() + 64 + 24;
    if bytes.len() < head || &bytes[..MAGIC.len()] != MAGIC {
        return Err(format!("{}: not an eigensolve cache entry", p.display()));
    }
    if &bytes[MAGIC.len()..MAGIC.len() + 64] != key.as_bytes() {
        return Err(format!("{}: entry of another key", p.display()));
    }
    let u = |i: usize| {
        let o = MAGIC.len() + 64 + 8 * i;
        u64::from_le_bytes(bytes[o..o + 8].try_into().expect("8 bytes"))
    };
    let (n, m, rigid) = (u(0), u(1), u(2));
    let want = (m as u128) * (n as u128 + 1) * 8 + head as u128;
    if want != bytes.len() as u128 {
        return Err(format!(
            "{}: {} bytes, the header says {want} (truncated entry)",
            p.display(),
            bytes.len()
        ));
    }
    let (n, m) = (n as usize, m as usize);
    let f = |i: usize| {
        let o = head + 8 * i;
        f64::from_le_bytes(bytes[o..o + 8].try_into().expect("8 bytes"))
    };
    let eigenvalues = (0..m).map(f).collect();
    let vectors = Mat::from_fn(n, m, |i, j| f(m + j * n + i));
    Ok(Some(ModalAll {
        eigenvalues,
        vectors,
        rigid_dropped: rigid as usize,
        solve_s: 0.0,
    }))
}

/// Writes `all` as the entry for `key` in `dir` (created if missing).
///
/// # Errors
/// The folder cannot be created or the file cannot be written.
pub fn write_eigen(dir: &Path, key: &str, all: &ModalAll) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow::anyhow!("eigensolve cache {}: {e}", dir.display()))?;
    let (n, m) = (all.vectors.nrows(), all.vectors.ncols());
    let mut bytes = Vec::with_capacity(MAGIC.len() + 64 + 24 + 8 * m * (n + 1));
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(key.as_bytes());
    for x in [n as u64, m as u64, all.rigid_dropped as u64] {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    for x in &all.eigenvalues {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    for j in 0..m {
        for i in 0..n {
            bytes.extend_from_slice(&all.vectors[(i, j)].to_le_bytes());
        }
    }
    dcr_files::write_atomic(&eigen_path(dir, key), &bytes)?;
    Ok(())
}
