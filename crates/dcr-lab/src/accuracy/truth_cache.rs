//! A file cache of converged full-order truths ([`converged_peaks`] results), so a rerun of the
//! report does not repeat the Newmark refinement of the large objects (tens of minutes each).
//!
//! The key is the SHA-256 of everything the result depends on: the solver (Newmark, or the
//! dense sum and its mode count), the free-dof stiffness and mass matrices (structure and
//! values), Rayleigh damping, every load and measurement row, the window, the first step and
//! the refinement settings, all as exact bit patterns. A changed mesh, material, point, or
//! setting is a different key; the solver's code is not in the key, so after changing how the
//! truth is computed, delete the folder. Entries store every `f64` as its bit pattern, so a
//! cached truth is bit-identical to the computed one. Files are written atomically (temporary
//! file, then rename); an unreadable entry is recomputed and replaced.

use std::path::{Path, PathBuf};

use faer::sparse::SparseColMat;
use modal_bake::full_order::{
    converged_peaks, ConvergedPeaks, FullOrderError, FullOrderSystem, PeakSolver, RefineProgress,
    Refinement,
};
use modal_bake::target_error::TruthProblem;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// Version of the entry layout and key recipe.
const VERSION: &[u8] = b"dcr-truth-cache-v1";

/// Feeds a sparse matrix to `h`: its size, structure and the exact bit patterns of its values
/// (the part of a cache key that names a stiffness or mass matrix).
pub(crate) fn hash_sparse(h: &mut Sha256, a: &SparseColMat<usize, f64>) {
    let s = a.symbolic();
    h.update((s.nrows() as u64).to_le_bytes());
    for &p in s.col_ptr() {
        h.update((p as u64).to_le_bytes());
    }
    for &r in s.row_idx() {
        h.update((r as u64).to_le_bytes());
    }
    for &v in a.val() {
        h.update(v.to_bits().to_le_bytes());
    }
}

/// The cache key of `t` on `sys` (hex SHA-256).
pub fn key(sys: &FullOrderSystem, t: &TruthProblem) -> String {
    let mut h = Sha256::new();
    h.update(VERSION);
    match t.solver {
        PeakSolver::Newmark => h.update(b"newmark"),
        PeakSolver::ModalAll(_, m) => {
            h.update(b"modal-all");
            h.update((m.unwrap_or(usize::MAX) as u64).to_le_bytes());
        }
    }
    hash_sparse(&mut h, &sys.k);
    hash_sparse(&mut h, &sys.m);
    let floats = |h: &mut Sha256, xs: &[f64]| {
        h.update((xs.len() as u64).to_le_bytes());
        for x in xs {
            h.update(x.to_bits().to_le_bytes());
        }
    };
    floats(&mut h, &sys.rayleigh);
    for (group, vs) in [(b"loads", t.loads), (b"rows.", t.rows)] {
        h.update(group);
        h.update((vs.len() as u64).to_le_bytes());
        for v in vs {
            floats(&mut h, v);
        }
    }
    floats(&mut h, &[t.window.h, t.window.dt, t.refine.tolerance]);
    h.update((t.refine.max_refinements as u64).to_le_bytes());
    h.update((t.refine.max_samples as u64).to_le_bytes());
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// One cached result; every `f64` as its bit pattern (NaN-safe, exact).
#[derive(Serialize, Deserialize)]
struct Entry {
    key: String,
    peaks: Vec<Vec<u64>>,
    dt: u64,
    samples: usize,
    converged: bool,
    tolerance: u64,
    last_change: u64,
    estimated_error: u64,
    /// (dt, samples, change, seconds) per level.
    history: Vec<(u64, usize, u64, u64)>,
}

impl Entry {
    fn of(key: &str, c: &ConvergedPeaks) -> Entry {
        Entry {
            key: key.into(),
            peaks: c
                .peaks
                .iter()
                .map(|r| r.iter().map(|x| x.to_bits()).collect())
                .collect(),
            dt: c.dt.to_bits(),
            samples: c.samples,
            converged: c.converged,
            tolerance: c.tolerance.to_bits(),
            last_change: c.last_change.to_bits(),
            estimated_error: c.estimated_error.to_bits(),
            history: c
                .history
                .iter()
                .map(|l| {
                    (
                        l.dt.to_bits(),
                        l.samples,
                        l.change.to_bits(),
                        l.seconds.to_bits(),
                    )
                })
                .collect(),
        }
    }

    fn peaks(&self) -> ConvergedPeaks {
        let f = f64::from_bits;
        ConvergedPeaks {
            peaks: self
                .peaks
                .iter()
                .map(|r| r.iter().map(|&x| f(x)).collect())
                .collect(),
            dt: f(self.dt),
            samples: self.samples,
            converged: self.converged,
            tolerance: f(self.tolerance),
            last_change: f(self.last_change),
            estimated_error: f(self.estimated_error),
            history: self
                .history
                .iter()
                .map(|&(dt, samples, change, seconds)| Refinement {
                    dt: f(dt),
                    samples,
                    change: f(change),
                    seconds: f(seconds),
                })
                .collect(),
        }
    }
}

/// Where the entry of `key` lives in `dir`.
fn entry_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("{key}.json"))
}

/// The cached truth of `t` in `dir` if there is a readable entry with the same key and shape,
/// else [`converged_peaks`] (stored in `dir` afterwards; a failed write is reported on stderr
/// and otherwise ignored: the cache only saves time). `dir = None`: no cache. `hit` is set when
/// the result came from the cache.
///
/// # Errors
/// Those of [`converged_peaks`].
pub fn cached_converged_peaks(
    dir: Option<&Path>,
    sys: &FullOrderSystem,
    t: &TruthProblem,
    progress: &mut dyn FnMut(RefineProgress),
    hit: &mut bool,
) -> Result<ConvergedPeaks, FullOrderError> {
    *hit = false;
    let Some(dir) = dir else {
        return converged_peaks(sys, t.solver, t.loads, t.rows, t.window, t.refine, progress);
    };
    let key = key(sys, t);
    let path = entry_path(dir, &key);
    if let Ok(text) = std::fs::read_to_string(&path) {
        match serde_json::from_str::<Entry>(&text) {
            Ok(e)
                if e.key == key
                    && e.peaks.len() == t.loads.len()
                    && e.peaks.iter().all(|r| r.len() == t.rows.len()) =>
            {
                *hit = true;
                return Ok(e.peaks());
            }
            _ => eprintln!(
                "truth cache: {} is unreadable or stale; recomputing",
                path.display()
            ),
        }
    }
    let c = converged_peaks(sys, t.solver, t.loads, t.rows, t.window, t.refine, progress)?;
    if let Err(e) = store(dir, &path, &Entry::of(&key, &c)) {
        eprintln!("truth cache: could not write {}: {e}", path.display());
    }
    Ok(c)
}

fn store(dir: &Path, path: &Path, e: &Entry) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let bytes = serde_json::to_vec(e).map_err(std::io::Error::other)?;
    dcr_files::write_atomic(path, &bytes).map_err(std::io::Error::other)
}
