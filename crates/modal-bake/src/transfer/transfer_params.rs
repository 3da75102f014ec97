//! [`TransferParams`]: what a peak-transfer table tabulates, and the errors and progress of a
//! build.

use crate::full_order::FullOrderError;

/// Default oversampling of the table's peak search: T = π/(2 ω_max) for its highest mode (the
/// paper's period; measured against finer sampling in `docs/accuracy.md`).
pub const DEFAULT_OVERSAMPLE: f64 = 1.0;

/// Meshes with at most this many free dofs get their table's modes from the dense all-mode
/// eigensolve; larger ones from a Lanczos bake.
pub const DENSE_MAX_DOFS: usize = 6000;

/// Default normal filter for `up`: a vertex is kept when n·û ≥ 0.5 (within 60°), so the edge
/// vertices of a face (normals averaged with the side faces) stay in the region.
pub const UP_MIN_COS: f64 = 0.5;

/// Tables with at most this many points are cubic under [`TableOrder::Auto`] (≈ 64 MiB of
/// f32 peaks); larger ones quadratic.
pub const AUTO_CUBIC_MAX_POINTS: usize = 5792;

/// Interpolation order of a table over each region triangle (its points; see
/// [`dcr_runtime::format::TransferTable`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TableOrder {
    /// Cubic when the cubic table has at most [`AUTO_CUBIC_MAX_POINTS`] points, else quadratic.
    #[default]
    Auto,
    /// Vertices only (linear blend of vertex peaks).
    Linear,
    /// Vertices and edge midpoints (P2, ≈ 4 points per region vertex).
    Quadratic,
    /// Vertices, two points per edge and face centroids (P3, ≈ 9 points per region vertex).
    Cubic,
}

impl TableOrder {
    /// The order (1, 2, 3) for a region of nr vertices, ne edges and nf faces.
    pub fn resolve(self, nr: usize, ne: usize, nf: usize) -> u8 {
        match self {
            TableOrder::Linear => 1,
            TableOrder::Quadratic => 2,
            TableOrder::Cubic => 3,
            TableOrder::Auto => {
                let cubic = dcr_runtime::format::TransferTable::points_for(3, nr, ne, nf);
                if cubic <= AUTO_CUBIC_MAX_POINTS {
                    3
                } else {
                    2
                }
            }
        }
    }
}

/// Modes of a table under [`TransferModes::Auto`] for meshes too large for the dense solve.
pub const AUTO_LANCZOS_MODES: usize = 640;

/// How many modes the table sums.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransferModes {
    /// The lowest n elastic modes.
    Count(usize),
    /// Every elastic mode (dense eigensolve: small meshes only).
    All,
    /// Every mode when the mesh has at most [`DENSE_MAX_DOFS`] free dofs (the dense solve),
    /// else the lowest [`AUTO_LANCZOS_MODES`] (Lanczos).
    Auto,
}

impl TransferModes {
    /// [`TransferModes::Auto`] resolved for a mesh of `free_dofs` (the others unchanged).
    pub fn resolve(self, free_dofs: usize) -> TransferModes {
        match self {
            TransferModes::Auto if free_dofs <= DENSE_MAX_DOFS => TransferModes::All,
            TransferModes::Auto => TransferModes::Count(AUTO_LANCZOS_MODES),
            m => m,
        }
    }
}

/// What to tabulate (SI units, object frame).
#[derive(Clone, Debug, PartialEq)]
pub struct TransferParams {
    /// Rigid-body step h (s) the peaks are taken over; the runtime uses the table only for
    /// this h (relative tolerance 1e-9).
    pub h: f64,
    /// Modes summed. Default [`TransferModes::Auto`].
    pub modes: TransferModes,
    /// Region boxes (m): vertices inside any of them (empty: no box filter).
    pub boxes: Vec<[f64; 6]>,
    /// Normal filter: keep vertices with n·û ≥ `up_min_cos` (`None`: no filter).
    pub up: Option<[f64; 3]>,
    /// Cosine threshold of the normal filter. Default [`UP_MIN_COS`].
    pub up_min_cos: f64,
    /// Peak-search oversampling K ≥ 1: T = π/(2 ω_max)/K for the table's highest mode.
    /// Default [`DEFAULT_OVERSAMPLE`].
    pub oversample: f64,
    /// Interpolation order. Default [`TableOrder::Auto`].
    pub order: TableOrder,
    /// Refuse the build before it starts when its estimated wall time or peak memory
    /// ([`TablePlan`](super::TablePlan)) is over this budget; `None` (the default): no limit.
    /// Not a table parameter: it changes no peak and is not recorded in the base.
    pub budget: Option<crate::bake::Budget>,
}

impl Default for TransferParams {
    fn default() -> Self {
        TransferParams {
            h: 0.01,
            modes: TransferModes::Auto,
            boxes: Vec::new(),
            up: None,
            up_min_cos: UP_MIN_COS,
            oversample: DEFAULT_OVERSAMPLE,
            order: TableOrder::Auto,
            budget: None,
        }
    }
}

impl TransferParams {
    /// Checks ranges.
    ///
    /// # Errors
    /// [`TransferError::Params`] naming the parameter.
    pub fn check(&self) -> Result<(), TransferError> {
        let bad = |s: String| Err(TransferError::Params(s));
        if !(self.h.is_finite() && self.h > 0.0) {
            return bad(format!(
                "parameter `transfer.h` must be a positive step in seconds, got {}",
                self.h
            ));
        }
        if self.modes == TransferModes::Count(0) {
            return bad("parameter `transfer.modes` must be at least 1".into());
        }
        for b in &self.boxes {
            if !b.iter().all(|x| x.is_finite()) || (0..3).any(|k| b[k] > b[k + 3]) {
                return bad(format!(
                    "parameter `transfer.boxes` = {b:?}: expected finite xmin,ymin,zmin,xmax,ymax,zmax with min ≤ max"
                ));
            }
        }
        if let Some(u) = self.up {
            let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            if !(l.is_finite() && l > 0.0) {
                return bad(format!(
                    "parameter `transfer.up` = {u:?}: expected a finite non-zero direction"
                ));
            }
        }
        if !(self.up_min_cos.is_finite() && self.up_min_cos.abs() <= 1.0) {
            return bad(format!(
                "parameter `transfer.up_min_cos` = {} must be in [-1, 1]",
                self.up_min_cos
            ));
        }
        if !(self.oversample.is_finite() && self.oversample >= 1.0) {
            return bad(format!(
                "parameter `transfer.oversample` = {} must be ≥ 1",
                self.oversample
            ));
        }
        Ok(())
    }
}

/// Progress of a table build: source rows done of total, and the build's plan and estimate.
#[derive(Clone, Copy, Debug)]
pub struct TransferProgress {
    /// Rows done.
    pub done: usize,
    /// Rows in all.
    pub total: usize,
    /// What the build computes and its estimated cost.
    pub plan: super::TablePlan,
}

/// Why a table could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TransferError {
    /// Invalid options or an unusable region.
    #[error("transfer table: {0}")]
    Params(String),
    /// The dense eigensolve for the table's modes failed.
    #[error("transfer table modes: {0}")]
    FullOrder(#[from] FullOrderError),
    /// The build's estimate is over [`TransferParams::budget`]: refused before it started.
    #[error("transfer table: {0}")]
    OverBudget(Box<super::OverBudget>),
}
