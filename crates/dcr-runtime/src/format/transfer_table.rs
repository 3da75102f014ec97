//! [`TransferTable`]: the optional bake-time peak-transfer table of a `.modes` file.
//!
//! The table's points are the region's surface vertices followed by the midpoints of the
//! region's edges (both ends in the region). `T[p][q]` = peak over one rigid-body step of
//! `|n_qᵀ u_q(t)|` at point q after a unit impulse (1 N·s) at t = 0 at point p along its inward
//! normal `−n_p`, summed over many modes (more than the base keeps for its runtime filters),
//! sampled at `t = k·h/S`, k = 1..S. A midpoint's response row and normal row are the averages
//! of its two vertices' (P1 interpolation). In modal terms `n_qᵀ u_q(t) = −Σ_l w_pl w_ql g_l(t)`
//! with `w_pl = n_pᵀ U_pl`, so the table is exactly symmetric (reciprocity, Maxwell–Betti) and
//! only its upper triangle is stored.
//!
//! Why midpoints: the peak is a convex function of the barycentric weights (a maximum of
//! absolute values of linear functions), so blending the vertex peaks overestimates inside a
//! triangle wherever the vertex responses are out of phase; the runtime interpolates the six
//! P2 nodes of each triangle (vertices and edge midpoints) instead, measured in
//! `docs/accuracy.md`.
//!
//! Units: m per N·s. Normals are the runtime's area-weighted outward vertex normals.

/// Entry names of the optional transfer table in the NPZ archive (all present or all absent).
/// `transfer_edges` (the midpoints) is optional within the group: tables written before it
/// existed have vertex points only and are interpolated linearly.
pub(crate) const TRANSFER_ENTRIES: [&str; 6] = [
    "transfer_vertices",
    "transfer_peaks",
    "transfer_h",
    "transfer_rayleigh",
    "transfer_modes",
    "transfer_samples",
];

/// Optional member of the transfer group: the region edges whose midpoints are table points.
pub(crate) const TRANSFER_EDGES_ENTRY: &str = "transfer_edges";

/// Largest table accepted (points: region vertices + edge midpoints): the packed table then
/// holds ≈ 2·10⁸ f32 (800 MB).
pub const MAX_TRANSFER_POINTS: usize = 20_000;

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
    /// Table points 0..nr.
    pub vertices: Vec<u32>,
    /// Region edges as pairs of region indices (a < b), strictly ascending: their midpoints are
    /// table points nr..nr+ne. Empty for a vertex-only table.
    pub edges: Vec<[u32; 2]>,
    /// Packed upper triangle over the np = nr + ne points, row-major: entry (p, q), p ≤ q at
    /// [`TransferTable::packed_index`]`(p, q)`; m per N·s, finite, ≥ 0.
    pub peaks: Vec<f32>,
}

impl TransferTable {
    /// Region size nr (vertices).
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Number of table points np = nr + ne (vertices, then edge midpoints).
    pub fn num_points(&self) -> usize {
        self.vertices.len() + self.edges.len()
    }

    /// Whether the region is empty.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// The edges whose midpoints a table over `vertices` (ascending surface-vertex indices)
    /// tabulates: every edge of a surface triangle with both ends in the region, as pairs of
    /// region indices (a < b), ascending — the form of [`TransferTable::edges`].
    pub fn region_edges(triangles: &[[u32; 3]], vertices: &[u32]) -> Vec<[u32; 2]> {
        let local = |v: u32| vertices.binary_search(&v).ok().map(|k| k as u32);
        let mut edges: Vec<[u32; 2]> = triangles
            .iter()
            .flat_map(|tri| (0..3).map(move |k| (tri[k], tri[(k + 1) % 3])))
            .filter_map(|(a, b)| {
                let (a, b) = (local(a)?, local(b)?);
                Some([a.min(b), a.max(b)])
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// Number of packed values for `np` points: np(np+1)/2.
    pub fn packed_len(np: usize) -> usize {
        np * (np + 1) / 2
    }

    /// Index of (a, b) in the packed upper triangle (either order; point indices < np).
    #[inline]
    pub fn packed_index(&self, a: usize, b: usize) -> usize {
        let (i, j) = if a <= b { (a, b) } else { (b, a) };
        let np = self.num_points();
        i * (2 * np - i + 1) / 2 + (j - i)
    }

    /// `T[a][b]` (m per N·s) for point indices a, b.
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
        let np = self.num_points();
        if np > MAX_TRANSFER_POINTS {
            return Err(format!(
                "transfer table: {np} points (region vertices and edge midpoints) exceed the limit of {MAX_TRANSFER_POINTS}"
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
        if let Some(k) = (0..self.edges.len()).find(|&k| {
            let [a, b] = self.edges[k];
            a >= b || b as usize >= nr || (k > 0 && self.edges[k - 1] >= self.edges[k])
        }) {
            return Err(format!(
                "transfer_edges row {k} = {:?}: expected region indices a < b < {nr}, rows strictly ascending",
                self.edges[k]
            ));
        }
        if self.peaks.len() != Self::packed_len(np) {
            return Err(format!(
                "transfer_peaks holds {} values, expected np(np+1)/2 = {} for {np} points ({nr} vertices, {} edge midpoints)",
                self.peaks.len(),
                Self::packed_len(np),
                self.edges.len()
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
