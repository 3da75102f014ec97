//! [`TransferTable`]: the optional bake-time peak-transfer table of a `.modes` file.
//!
//! The table's points are the nodes of a Lagrange interpolant of order k = [`TransferTable::order`]
//! on each region triangle: the region's surface vertices (k = 1), then one point per region
//! edge (k = 2: its midpoint) or two (k = 3: at 1/3 and 2/3 of the edge), then (k = 3) the
//! centroid of every region face (a surface triangle with its three corners in the region);
//! [`TransferTable::point_support`] gives each point's position as barycentric weights of
//! region vertices. `T[p][q]` = peak over one rigid-body step of
//! `|n_qᵀ u_q(t)|` at point q after a unit impulse (1 N·s) at t = 0 at point p along its inward
//! normal `−n_p`, summed over many modes (more than the base keeps for its runtime filters),
//! sampled at `t = k·h/S`, k = 1..S. A point's response row and normal row are the
//! barycentric blends of its vertices' (P1 interpolation of the FEM field). In modal terms `n_qᵀ u_q(t) = −Σ_l w_pl w_ql g_l(t)`
//! with `w_pl = n_pᵀ U_pl`, so the table is exactly symmetric (reciprocity, Maxwell–Betti) and
//! only its upper triangle is stored.
//!
//! Why more points than vertices: the peak is a convex function of the barycentric weights (a
//! maximum of absolute values of linear functions), so blending the vertex peaks overestimates
//! inside a triangle wherever the vertex responses are out of phase (waves whose length is a
//! few triangles: terrain); the runtime interpolates the P2 (6) or P3 (10) nodes of each
//! triangle instead, measured in `docs/accuracy.md`.
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

/// Optional member of the transfer group: the region edges whose points are table points.
pub(crate) const TRANSFER_EDGES_ENTRY: &str = "transfer_edges";

/// Optional member of the transfer group: the interpolation order (1, 2 or 3); absent: 2 when
/// `transfer_edges` is present, else 1.
pub(crate) const TRANSFER_ORDER_ENTRY: &str = "transfer_order";

/// Optional member of the transfer group (order 3): the region faces whose centroids are table
/// points.
pub(crate) const TRANSFER_FACES_ENTRY: &str = "transfer_faces";

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
    /// Interpolation order k ∈ {1, 2, 3}: vertices only, + edge midpoints (P2), + two points
    /// per edge and face centroids (P3).
    pub order: u8,
    /// Region edges as pairs of region indices (a < b), strictly ascending: edge e carries table
    /// point nr + e (order 2: its midpoint) or points nr + 2e, nr + 2e + 1 (order 3: at 1/3 of
    /// the way from a, and from b). Empty for order 1.
    pub edges: Vec<[u32; 2]>,
    /// Order 3: region faces as sorted triples of region indices (a < b < c), strictly
    /// ascending; face f carries table point nr + 2ne + f, its centroid. Empty otherwise.
    pub faces: Vec<[u32; 3]>,
    /// Packed upper triangle over the np = nr + ne points, row-major: entry (p, q), p ≤ q at
    /// [`TransferTable::packed_index`]`(p, q)`; m per N·s, finite, ≥ 0.
    pub peaks: Vec<f32>,
}

impl TransferTable {
    /// Region size nr (vertices).
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Number of table points np (vertices, edge points, face centroids).
    pub fn num_points(&self) -> usize {
        Self::points_for(
            self.order,
            self.vertices.len(),
            self.edges.len(),
            self.faces.len(),
        )
    }

    /// Points of a table of `order` over nr vertices, ne edges and nf faces.
    pub fn points_for(order: u8, nr: usize, ne: usize, nf: usize) -> usize {
        match order {
            1 => nr,
            2 => nr + ne,
            _ => nr + 2 * ne + nf,
        }
    }

    /// Table point `p` as barycentric weights of up to three region vertices (region indices;
    /// unused slots have weight 0). Panics for p ≥ [`TransferTable::num_points`].
    pub fn point_support(&self, p: usize) -> ([u32; 3], [f64; 3]) {
        let nr = self.vertices.len();
        let ne = self.edges.len();
        if p < nr {
            return ([p as u32, 0, 0], [1.0, 0.0, 0.0]);
        }
        let q = p - nr;
        match self.order {
            2 => {
                let [a, b] = self.edges[q];
                ([a, b, 0], [0.5, 0.5, 0.0])
            }
            _ if q < 2 * ne => {
                let [a, b] = self.edges[q / 2];
                let w = if q.is_multiple_of(2) {
                    [2.0 / 3.0, 1.0 / 3.0, 0.0]
                } else {
                    [1.0 / 3.0, 2.0 / 3.0, 0.0]
                };
                ([a, b, 0], w)
            }
            _ => (self.faces[q - 2 * ne], [1.0 / 3.0; 3]),
        }
    }

    /// The faces whose centroids an order-3 table over `vertices` (ascending surface-vertex
    /// indices) tabulates: every surface triangle with its three corners in the region, as
    /// sorted triples of region indices, ascending — the form of [`TransferTable::faces`].
    pub fn region_faces(triangles: &[[u32; 3]], vertices: &[u32]) -> Vec<[u32; 3]> {
        let local = |v: u32| vertices.binary_search(&v).ok().map(|k| k as u32);
        let mut faces: Vec<[u32; 3]> = triangles
            .iter()
            .filter_map(|t| {
                let mut f = [local(t[0])?, local(t[1])?, local(t[2])?];
                f.sort_unstable();
                Some(f)
            })
            .collect();
        faces.sort_unstable();
        faces.dedup();
        faces
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
                "transfer table: {np} points (region vertices, edge and face points) exceed the limit of {MAX_TRANSFER_POINTS}"
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
        if !(1..=3).contains(&self.order) {
            return Err(format!(
                "transfer_order = {} (must be 1, 2 or 3)",
                self.order
            ));
        }
        if self.order == 1 && !self.edges.is_empty() {
            return Err("transfer_order = 1 but transfer_edges is not empty".into());
        }
        if self.order != 3 && !self.faces.is_empty() {
            return Err(format!(
                "transfer_order = {} but transfer_faces is not empty",
                self.order
            ));
        }
        if let Some(k) = (0..self.faces.len()).find(|&k| {
            let [a, b, c] = self.faces[k];
            a >= b || b >= c || c as usize >= nr || (k > 0 && self.faces[k - 1] >= self.faces[k])
        }) {
            return Err(format!(
                "transfer_faces row {k} = {:?}: expected region indices a < b < c < {nr}, rows strictly ascending",
                self.faces[k]
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
                "transfer_peaks holds {} values, expected np(np+1)/2 = {} for {np} points (order {}: {nr} vertices, {} edges, {} faces)",
                self.peaks.len(),
                Self::packed_len(np),
                self.order,
                self.edges.len(),
                self.faces.len()
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
