//! [`TablePlan`]: what a table build will compute, known once its mode set is (region, order,
//! points, modes, samples per step), and its estimated wall time and peak memory — so a build
//! that would run for hours or exhaust the memory is refused before it starts, with the
//! parameters that would bring it within the budget.
//!
//! The cost model follows the builder ([`build_transfer_table`](super::build_transfer_table)'s
//! module), with S samples per step, m modes, n_r region vertices, n_b bent points and n_p points,
//! n_c = n_r + n_b series columns, P threads:
//! - time: `(a · S m n_c² + b · S n_p²/2 + c · S n_p n_c/2) / P`: the vertex-series GEMMs (each
//!   source against the ≈ n_c/2 targets still in use), the peak search over every pair's blended
//!   series and the blend of each point's series;
//! - memory: the mode set (the base and the mode set's surface rows, twice: the model keeps a
//!   copy), G in f64 and f32 (12 S m bytes), 1.25 clusters of vertex series (the cluster being
//!   computed and what it keeps of the last; a cluster is the larger of [`CLUSTER_BYTES`] and
//!   four vertices' series, 4 S n_c bytes each — it holds one point at least — and at most all
//!   n_r vertices'),
//!   one point's series per thread and the packed f32 peaks (2 n_p² bytes).
//!
//! Calibration (a, b, c in seconds per flop or per sample-pair of one thread): least squares on
//! table builds of the scaffold and of the npm Stanford bunny at several mode counts and orders
//! (`scripts/calibrate_table_cost.sh`, figures and the estimate's error in docs/benchmarks.md
//! § Transfer-table cost). The samples per step S = ⌈h / T⌉ with T = π/(2 ω_max)/K are what make
//! a build explode: every mode of a mesh with a sliver tetrahedron reaches ω_max ~ 10⁷ rad/s, so
//! S ~ 10⁵ for a 10 ms step. Like [`SizeEstimate`](crate::bake::SizeEstimate), the estimate aims
//! at the order of magnitude a budget needs; it is not a benchmark.

use super::CLUSTER_BYTES;
use crate::bake::{format_bytes, format_seconds, group_digits, Budget};

/// Seconds per modelled flop of the vertex-series GEMMs (f32, one thread; the count S m n_c²
/// overstates the flops run, as series are reused between clusters).
const GEMM_S_PER_FLOP: f64 = 9.3e-12;
/// Seconds per sample of one point pair's peak search (one thread).
const PEAK_S_PER_SAMPLE: f64 = 7.7e-10;
/// Seconds per sample and column of one point's blended series (one thread).
const BLEND_S_PER_SAMPLE: f64 = 4.7e-9;
/// Clusters of vertex series alive at once: the one being computed and the part of the last
/// one it still needs (measured: the beam's 1,676-point table peaks at 487 MB, one cluster
/// 402 MB of it).
const KEPT: f64 = 1.25;
/// Bytes of the process besides the table (the runtime model's tables, allocator slack).
const BASE_BYTES: f64 = 50e6;

/// What a table build computes and its estimated cost (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TablePlan {
    /// Interpolation order (1, 2, 3).
    pub order: u8,
    /// Region vertices n_r.
    pub vertices: usize,
    /// Points n_p (vertices, edge and face points).
    pub points: usize,
    /// Points whose vertices' normals differ (computed from their own rows), n_b.
    pub bent: usize,
    /// Modes summed m.
    pub modes: usize,
    /// Samples per step S.
    pub samples: usize,
    /// The highest mode's angular frequency (rad/s): it sets the sampling period.
    pub omega_max: f64,
    /// The step h (s) the peaks are taken over.
    pub h: f64,
    /// Surface vertices of the mode set (their rows are held in memory).
    pub surface_vertices: usize,
    /// Modes of the mode set (≥ `modes`).
    pub set_modes: usize,
    /// Threads the build runs on (rayon's pool).
    pub threads: usize,
}

impl TablePlan {
    /// Series columns per source vertex n_c = n_r + n_b.
    fn columns(&self) -> f64 {
        (self.vertices + self.bent) as f64
    }

    /// Estimated wall time of the build (s) on `threads` threads.
    pub fn seconds(&self) -> f64 {
        let (s, m, nc, np) = (
            self.samples as f64,
            self.modes as f64,
            self.columns(),
            self.points as f64,
        );
        let gemm = GEMM_S_PER_FLOP * s * m * nc * nc;
        let peaks = PEAK_S_PER_SAMPLE * s * np * np / 2.0;
        let blend = BLEND_S_PER_SAMPLE * s * np * nc / 2.0;
        (gemm + peaks + blend) / self.threads.max(1) as f64
    }

    /// Estimated peak memory of the build (bytes), the mode set included.
    pub fn bytes(&self) -> f64 {
        let (s, m, nc, np) = (
            self.samples as f64,
            self.modes as f64,
            self.columns(),
            self.points as f64,
        );
        let rows = 2.0 * 24.0 * self.surface_vertices as f64 * self.set_modes as f64;
        let g = 12.0 * s * m;
        let per_vertex = 4.0 * s * nc;
        // A cluster holds at most every vertex's series, and one point's vertices at least.
        let cluster = (CLUSTER_BYTES as f64)
            .max(4.0 * per_vertex)
            .min(self.vertices as f64 * per_vertex);
        let threads = self.threads.max(1) as f64 * per_vertex;
        BASE_BYTES + rows + g + KEPT * cluster + threads + 2.0 * np * np + 8.0 * m * nc
    }

    /// Whether the estimate is within `budget`.
    pub fn fits(&self, budget: &Budget) -> bool {
        self.bytes() <= budget.max_bytes && self.seconds() <= budget.max_seconds
    }

    /// One line: `order 3, 5,742 points over 638 region vertices, 4,785 modes, 125,000 samples
    /// per step; about 2.1 h and 11 GB`.
    pub fn describe(&self) -> String {
        format!(
            "order {}, {} points over {} region vertices, {} modes, {} samples per step; about {} and {}",
            self.order,
            group_digits(self.points),
            group_digits(self.vertices),
            group_digits(self.modes),
            group_digits(self.samples),
            format_seconds(self.seconds()),
            format_bytes(self.bytes())
        )
    }
}

/// A table build refused before it started: its plan, the budget and what would fit.
#[derive(Clone, Debug, PartialEq)]
pub struct OverBudget {
    /// The refused plan.
    pub plan: TablePlan,
    /// The budget it is over.
    pub budget: Budget,
    /// The largest table of the same region and order within the budget: the most of the
    /// set's lowest modes that fit, with its plan; `None` when not even one mode fits.
    pub most_modes: Option<TablePlan>,
    /// Changes of the parameters that fit the budget, each with its estimate (may be empty).
    pub fixes: Vec<String>,
}

impl std::fmt::Display for OverBudget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "refused before building: {} — over the budget of {} and {}; the {} samples per step come from the highest mode summed ({:.3e} rad/s: T = π/(2ω) for h = {} s)",
            self.plan.describe(),
            format_seconds(self.budget.max_seconds),
            format_bytes(self.budget.max_bytes),
            group_digits(self.plan.samples),
            self.plan.omega_max,
            self.plan.h,
        )?;
        if self.fixes.is_empty() {
            write!(f, "; no smaller table of this region fits: restrict the region (`transfer.up`, `transfer.boxes`) or raise the budget")
        } else {
            write!(f, "; to lower it: {}", self.fixes.join(", or "))
        }
    }
}
