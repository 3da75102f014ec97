//! [`TransferTable`]: the optional bake-time peak-transfer table of a `.modes` file.
//!
//! `T[i][j]` = peak over one rigid-body step of `|n_jᵀ u_j(t)|` at region vertex j after a unit
//! impulse (1 N·s) at t = 0 at region vertex i along its inward normal `−n_i`, summed over many
//! modes (more than the base keeps for its runtime filters), sampled at `t = k·h/S`, k = 1..S.
//! In modal terms `n_jᵀ u_j(t) = −Σ_l w_il w_jl g_l(t)` with `w_il = n_iᵀ U_il`, so the table is
//! exactly symmetric (reciprocity, Maxwell–Betti) and only its upper triangle is stored.
//!
//! Units: m per N·s. Normals are the runtime's area-weighted outward vertex normals.

/// Entry names of the optional transfer table in the NPZ archive (all present or all absent).
pub(crate) const TRANSFER_ENTRIES: [&str; 6] = [
    "transfer_vertices",
    "transfer_peaks",
    "transfer_h",
    "transfer_rayleigh",
    "transfer_modes",
    "transfer_samples",
];

/// Largest region accepted (vertices): the packed table then holds ≈ 2·10⁸ f32 (800 MB).
pub const MAX_TRANSFER_VERTICES: usize = 20_000;

/// A symmetric single-impact peak-transfer table over a region of surface vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferTable {
    /// Rigid-body step h (s) the peaks were taken over.
    pub h: f64,
    /// Rayleigh damping used [α0 (1/s), α1 (s)].
    pub rayleigh: [f64; 2],
    /// Number of elastic modes summed.
    pub modes: u32,
    /// Samples per step S (peaks taken at t = k·h/S, k = 1..S).
    pub samples: u32,
    /// Region: surface-vertex indices (into `ModesFile::surface_vertices`), strictly ascending.
    pub vertices: Vec<u32>,
    /// Packed upper triangle, row-major: entry (a, b), a ≤ b (region indices) at
    /// [`TransferTable::packed_index`]`(a, b)`; m per N·s, finite, ≥ 0.
    pub peaks: Vec<f32>,
}

impl TransferTable {
    /// Region size nr.
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Whether the region is empty.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// Number of packed values for a region of `nr` vertices: nr(nr+1)/2.
    pub fn packed_len(nr: usize) -> usize {
        nr * (nr + 1) / 2
    }

    /// Index of (a, b) in the packed upper triangle (either order; region indices < nr).
    #[inline]
    pub fn packed_index(&self, a: usize, b: usize) -> usize {
        let (i, j) = if a <= b { (a, b) } else { (b, a) };
        let nr = self.vertices.len();
        i * (2 * nr - i + 1) / 2 + (j - i)
    }

    /// `T[a][b]` (m per N·s) for region indices a, b.
    #[inline]
    pub fn peak(&self, a: usize, b: usize) -> f64 {
        f64::from(self.peaks[self.packed_index(a, b)])
    }

    /// Checks shapes and values against a base with `ns` surface vertices.
    ///
    /// # Errors
    /// A one-line description of the first problem found.
    pub fn check(&self, ns: usize) -> Result<(), String> {
        let nr = self.vertices.len();
        if nr == 0 {
            return Err("transfer table: empty region".into());
        }
        if nr > MAX_TRANSFER_VERTICES {
            return Err(format!(
                "transfer table: {nr} region vertices exceed the limit of {MAX_TRANSFER_VERTICES}"
            ));
        }
        if let Some(&v) = self.vertices.iter().find(|&&v| v as usize >= ns) {
            return Err(format!(
                "transfer_vertices names vertex {v} ≥ {ns} surface vertices"
            ));
        }
        if let Some(k) = (1..nr).find(|&k| self.vertices[k] <= self.vertices[k - 1]) {
            return Err(format!(
                "transfer_vertices not strictly ascending at position {k}"
            ));
        }
        if self.peaks.len() != Self::packed_len(nr) {
            return Err(format!(
                "transfer_peaks holds {} values, expected nr(nr+1)/2 = {} for {nr} region vertices",
                self.peaks.len(),
                Self::packed_len(nr)
            ));
        }
        if let Some(k) = self
            .peaks
            .iter()
            .position(|x| !(x.is_finite() && *x >= 0.0))
        {
            return Err(format!(
                "transfer_peaks[{k}] = {} (must be finite and ≥ 0)",
                self.peaks[k]
            ));
        }
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(format!(
                "transfer_h = {} s (must be finite and > 0)",
                self.h
            ));
        }
        if !self.rayleigh.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(format!(
                "transfer_rayleigh {:?} must be finite and ≥ 0",
                self.rayleigh
            ));
        }
        if self.modes == 0 || self.samples == 0 {
            return Err(format!(
                "transfer_modes = {} and transfer_samples = {} must be ≥ 1",
                self.modes, self.samples
            ));
        }
        Ok(())
    }
}
