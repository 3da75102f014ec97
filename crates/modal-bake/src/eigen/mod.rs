//! Lowest eigenpairs of the generalized symmetric problem K u = λ M u (paper §4.1: the modal
//! basis U = {Ψ₁ … Ψ_m} of the lowest modes). λ = ω² in rad²/s², f = √λ / 2π in Hz.
//!
//! Algorithm: **shift-invert block Lanczos** with thick restart (Wu & Simon 2000; the block
//! form as in Grimes, Lewis & Simon 1994) in the M-inner product:
//!
//! - A = K − σM is factored once by faer's sparse Cholesky (supernodal LLᵀ) under the node
//!   ordering AMD, or METIS nested dissection when it fills less (`ordering.rs`), so
//!   σ must lie strictly below the lowest eigenvalue (free-free objects: σ < 0, see
//!   [`default_shift`]). The operator T = A⁻¹M is M-self-adjoint with eigenvalues
//!   θ = 1/(λ − σ), largest θ ↔ lowest λ.
//! - The Krylov basis grows by a block of b = 8 vectors per step; each step is *one* multi-RHS
//!   solve (the factor is read once for b vectors: our row-major panel sweeps over faer's
//!   supernodal factor, `panel_solve.rs`, on two subtree groups at once when the elimination
//!   tree splits evenly), followed by full M-reorthogonalisation (two passes of block
//!   classical Gram–Schmidt: the first pass always removes more than 1 − 1/√2 of the new
//!   block's M-norm here, measured 0.01–0.61 remaining, so "twice is enough" would never skip
//!   the second) and Cholesky-QR of the block (twice; random replacement on breakdown). The
//!   first pass only runs against the blocks the new one is coupled to in exact arithmetic
//!   (the newest and the one before it; the whole basis right after a thick restart, which
//!   couples it to every kept Ritz vector): those hold the large components, and the second,
//!   full pass removes the rounding-level rest, as a second full pass did (same residuals,
//!   about half the Gram–Schmidt memory traffic). The dense products run sequentially
//!   (faer's parallel path is far slower on these tall-skinny shapes; `kernels.rs`).
//! - Rayleigh–Ritz on the projected H = VᵀMTV with faer's dense symmetric eigensolver.
//!   When the basis reaches its maximum size it is restarted with the best Ritz vectors plus
//!   the newest block (thick restart). Between 1 000 and 20 000 dofs the default basis holds
//!   8 more blocks (128 vectors for 20 pairs in blocks of 8), enough for the bake bench's
//!   beams to converge without a restart (3.5k dofs: 17 block solves instead of 19; 13.5k:
//!   15 either way, without the three restarts' n × 64 × 42 products).
//! - The Rayleigh–Ritz solve (dense, O(k³) in the basis size k) is skipped on steps where no
//!   convergence is expected: after two estimates of the worst wanted residual, the steps
//!   still needed at their geometric rate are extrapolated and 30% of them skipped (Lanczos
//!   converges faster than geometrically, so the next check still comes early; measured
//!   on the bake bench beams: no extra block solve; 8 instead of 16 dense solves of sizes up
//!   to 128 at 3.5k dofs, 7 instead of 14 at 13.5k). Count mode only, never on a step that
//!   must restart.
//! - Convergence is checked on the Lanczos residual estimate, then confirmed on the explicit
//!   relative residual ‖Ku − λMu‖₂ / (‖Ku‖₂ + |σ|·‖Mu‖₂). For elastic modes (λ ≫ |σ|) the
//!   denominator is ‖Ku‖₂ to within |σ|/λ; the |σ| term keeps the rigid modes of a free-free
//!   object (Ku ≈ 0) measurable. Before that check the Ritz vectors whose estimate is within
//!   10³ of the tolerance are *purified* by one more multi-RHS solve (u ← A⁻¹Mu; Nour-Omid,
//!   Parlett, Ericsson & Jensen 1987), which removes the high-frequency rounding noise that K
//!   would otherwise amplify into the residual (≈ 40× the estimate, measured; the others meet
//!   the tolerance without it, and should one fail, all are purified and checked again: 4 of
//!   20 vectors solved instead of 20 on the bake bench beams), then M-orthonormalised by one Cholesky-QR in ascending λ (UᵀMU = I to rounding) with
//!   λᵢ = uᵢᵀKuᵢ. There is deliberately no final Rayleigh–Ritz rotation of (K, M): its dense
//!   eigenvectors are accurate only to ε·λ_max/gap and K amplifies that mixture into the low
//!   modes' residuals (1e-5 measured on the table with 160 modes).
//! - Many modes: one run computes at most 48 pairs (halved on failure); further pairs come from fresh runs in the
//!   M-orthogonal complement of those found (deflation), sharing the factorization. A single
//!   run for hundreds of modes drifts: each thick restart re-injects the ε·θ_max error of the
//!   projected eigensolve, which is large relative to the small θ of the higher modes
//!   (measured: 160 modes in one run ended at residuals 1e-7 after 7 restarts; in runs of 48,
//!   640 modes of the same table converge to ≤ 1e-8). `max_iters` applies per run.
//! - Attainable accuracy: evaluating K u in double precision alone commits a relative error
//!   ≈ ε·λ_max/λ, which exceeds 1e-10 for fine meshes (λ_max/λ₁ ≈ 10⁸ at 10⁵ dofs) and for rigid
//!   modes. Each pair therefore also reports its rounding floor
//!   ([`EigenResult::residual_floors`]) and counts as converged when its residual is ≤ `tol`
//!   **or** within a factor 8 of that floor.
//! - Small problems (at most 2000 free dofs) that want more than a quarter of their modes, or
//!   whose request Lanczos cannot meet (a frequency cap near or beyond the highest mode: the
//!   Krylov basis cannot outgrow the problem), are solved densely (`dense.rs`): every
//!   eigenpair of the dense shift-inverted problem by the tridiagonal QR iteration, checked on
//!   the same explicit residual, failing pairs purified by solves with its Cholesky factor. A
//!   count up to the number of free dofs, or a cap beyond the spectrum, returns every mode.
//! - The start block comes from a fixed-seed splitmix64 generator, mapped once through A⁻¹M;
//!   each eigenvector is signed so its entry of largest magnitude (first on ties) is positive.
//!
//! Determinism: the results are bit-identical across runs and across thread counts. Our own
//! kernels (sparse products, Gram–Schmidt bookkeeping, the panel solves) split work by fixed
//! chunk sizes or by the factor's tree, never by the thread count, and sum in a fixed order.
//! faer 0.24.4's supernodal factorization, solves and dense products were measured to give bit-identical results with `Par::rayon(1)`, `(2)`
//! and `(3)`, equal to `Par::Seq`, on rayon pools of 1 and 2 threads (`tests/fem_eigen.rs`
//! guards Seq = rayon(1) = rayon(2) on both pools);
//! the small dense eigensolves run with `Par::Seq`. Bits may differ between machines with
//! different SIMD support (faer dispatches on CPU features at run time).

mod dense;
mod kernels;
mod lanczos;
mod ordering;
mod panel_solve;
mod ritz;
mod shift_invert;

use faer::sparse::SparseColMat;
use faer::{Mat, Par};

use crate::fem::Material;
use crate::mesh::TetMesh;

pub use kernels::SplitMix64;
/// A pair counts as converged within this factor of its double-precision residual floor.
pub use ritz::FLOOR_FACTOR;
pub(crate) use shift_invert::{lin_comb, ShiftInvert};

/// Parameters of [`solve_lowest`].
#[derive(Clone, Debug, PartialEq)]
pub struct EigenParams {
    /// Number of lowest eigenpairs wanted. With [`EigenParams::max_freq_hz`] it is a minimum.
    pub nev: usize,
    /// If set: return every mode with frequency f = √λ/2π (Hz) below this limit (and at least
    /// `nev` modes), at most [`EigenParams::max_modes`].
    pub max_freq_hz: Option<f64>,
    /// Shift σ (rad²/s²); must be strictly below the lowest eigenvalue so that K − σM is
    /// positive definite. 0 suits clamped objects; free-free objects need σ < 0
    /// ([`default_shift`]).
    pub shift: f64,
    /// Block size b: right-hand sides per factor solve (default 8). With the block solves of
    /// `panel_solve.rs` a block of 8 costs about what a block of 6 does once the factor no
    /// longer fits in cache, and the larger block converges in fewer solves (bake bench, 20
    /// modes: 3.5k 19 vs 22, 13.5k 15 vs 18, 109k 11 vs 13; timings in
    /// docs/benchmarks.md, "Design measurements").
    pub block: usize,
    /// Maximum Krylov basis size before a thick restart; `None`: nev + max(nev, 4b) + b, plus
    /// 8b between 1 000 and 20 000 dofs, rounded up to a multiple of b (grown automatically in
    /// max-frequency mode); 64 (128 between 1 000 and 20 000 dofs) for 20 pairs in blocks of 8.
    pub krylov_dim: Option<usize>,
    /// Tolerance on the relative residual (see the module docs), default 1e-10.
    pub tol: f64,
    /// Maximum number of block solves (Lanczos steps), default 300.
    pub max_iters: usize,
    /// Cap on the number of modes returned in max-frequency mode (default 2000).
    pub max_modes: usize,
    /// Threads given to faer's factorization (and to its solves of single vectors or blocks
    /// wider than 8) as `Par::rayon(n)`; 0 (default): sequential below 20 000 dofs, else the
    /// current rayon pool's size. The Lanczos block solves and the split panel sweeps use the
    /// current rayon pool; dense products are sequential. Results do not depend on it
    /// (bit-identical for 1, 2 and 3 threads on faer 0.24.4; `tests/fem_eigen.rs` guards it).
    pub threads: usize,
    /// Seed of the start block.
    pub seed: u64,
}

impl Default for EigenParams {
    fn default() -> Self {
        EigenParams {
            nev: 20,
            max_freq_hz: None,
            shift: 0.0,
            block: 8,
            krylov_dim: None,
            tol: 1e-10,
            max_iters: 300,
            max_modes: 2000,
            threads: 0,
            seed: 0x5EED_0DC2,
        }
    }
}

/// Progress report passed to the callback once per Lanczos step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EigenProgress {
    /// Wanted eigenpairs whose residual estimate meets the tolerance.
    pub converged: usize,
    /// Eigenpairs wanted (grows in max-frequency mode as modes below the limit appear).
    pub requested: usize,
    /// Lanczos steps (block solves) so far.
    pub iteration: usize,
}

/// What the solver did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EigenInfo {
    /// Wall time (s) of the symbolic + numeric factorization of K − σM.
    pub factor_seconds: f64,
    /// Wall time (s) of the Lanczos iteration (solves, orthogonalisation, Rayleigh–Ritz).
    pub solve_seconds: f64,
    /// Lanczos steps taken.
    pub iterations: usize,
    /// Block solves with the factor (each with `block` right-hand sides).
    pub block_solves: usize,
    /// Thick restarts.
    pub restarts: usize,
    /// Explicit residual checks (each costs one purification solve of the wanted vectors whose
    /// estimate is near the tolerance).
    pub residual_checks: usize,
    /// Ritz vectors purified by an extra solve before the residual checks (summed over the
    /// checks; see the module docs).
    pub purified: usize,
    /// Largest Krylov basis size used.
    pub krylov_dim: usize,
    /// Stored entries of the Cholesky factor (0 for the dense path).
    pub factor_nnz: usize,
    /// The shift σ used (rad²/s²).
    pub shift: f64,
    /// Max-frequency mode hit [`EigenParams::max_modes`].
    pub capped: bool,
    /// The problem was solved by the dense path (small, and wanting much of its spectrum or
    /// beyond Lanczos's reach; see the module docs).
    pub dense: bool,
}

/// Lowest eigenpairs of K u = λ M u.
#[derive(Clone, Debug)]
pub struct EigenResult {
    /// Eigenvalues λ = ω² (rad²/s²), ascending.
    pub eigenvalues: Vec<f64>,
    /// Eigenvectors as columns (n × m), M-orthonormal (UᵀMU = I), sign-normalised.
    pub vectors: Mat<f64>,
    /// Relative residual of each pair, ‖Ku − λMu‖₂ / (‖Ku‖₂ + |σ|‖Mu‖₂).
    pub residuals: Vec<f64>,
    /// Rounding floor of each residual: ε·(‖|K||u|‖ + |λ|‖|M||u|‖) / (‖Ku‖ + |σ|‖Mu‖), the
    /// relative error committed just by evaluating K u in double precision. A pair also counts
    /// as converged when its residual is within a small factor (8) of this floor, which for
    /// fine meshes (λ_max/λ ≳ 10⁶) or rigid modes can exceed `tol`.
    pub residual_floors: Vec<f64>,
    /// What the solver did.
    pub info: EigenInfo,
}

impl EigenResult {
    /// Frequencies f = √max(λ, 0) / 2π (Hz), ascending.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues
            .iter()
            .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect()
    }
}

/// Why [`solve_lowest`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EigenError {
    /// The iteration limit was reached before every wanted pair met the tolerance.
    #[error("eigensolver did not converge: {converged} of {requested} modes, worst relative residual {worst_residual:.3e}")]
    NotConverged {
        /// Pairs meeting the tolerance.
        converged: usize,
        /// Pairs wanted.
        requested: usize,
        /// Largest relative residual among the wanted pairs.
        worst_residual: f64,
    },
    /// K − σM could not be factored (typically: σ not below the lowest eigenvalue).
    #[error("factorization failed: {0}")]
    Factorization(String),
    /// Inconsistent input (sizes, nev larger than the problem, zero block, ...).
    #[error("invalid eigenproblem input: {0}")]
    InvalidInput(String),
    /// The small dense eigensolver failed.
    #[error("{0}")]
    Dense(String),
}

/// The `nev` lowest eigenpairs (or all below `max_freq_hz`) of K u = λ M u by shift-invert
/// block Lanczos; K (N/m) and M (kg) symmetric with both triangles stored, M positive definite,
/// K − σM positive definite.
///
/// `progress` is called once per Lanczos step.
///
/// # Errors
/// [`EigenError::Factorization`] if K − σM is not positive definite,
/// [`EigenError::NotConverged`] if the tolerance is not met within `max_iters` steps,
/// [`EigenError::InvalidInput`] on inconsistent sizes or parameters.
///
/// ```
/// use modal_bake::{eigen::{solve_lowest, EigenParams}, fem::*, mesh::TetMesh};
/// let mesh = TetMesh::structured_box([6, 2, 2], [1.0, 0.2, 0.2]);
/// let mat = Material::new(1e9, 0.3, 1000.0).unwrap();
/// let (k, m) = (assemble_stiffness(&mesh, &mat), assemble_mass(&mesh, &mat, false));
/// let (map, k, m) = reduce_fixed(&k, &m, &mesh.groups["xmin"]).unwrap();
/// let params = EigenParams { nev: 4, ..Default::default() };
/// let res = solve_lowest(&k, &m, &params, &mut |_| {}).unwrap();
/// assert_eq!(res.eigenvalues.len(), 4);
/// assert!(res.residuals.iter().all(|&r| r <= 1e-10));
/// let full = map.expand(res.vectors.as_ref());
/// assert_eq!(full.nrows(), mesh.dofs());
/// ```
pub fn solve_lowest(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    params: &EigenParams,
    progress: &mut dyn FnMut(EigenProgress),
) -> Result<EigenResult, EigenError> {
    let n = k.nrows();
    check_input(k, m, params)?;
    let sigma = params.shift;
    let lam_lim = params
        .max_freq_hz
        .map(|f| (2.0 * std::f64::consts::PI * f).powi(2));
    let par = match params.threads {
        0 if n < AUTO_SEQ_BELOW => Par::Seq,
        t => Par::rayon(t),
    };
    let info = EigenInfo {
        shift: sigma,
        ..Default::default()
    };
    if params.nev == 0 && lam_lim.is_none() {
        return Ok(EigenResult {
            eigenvalues: vec![],
            vectors: Mat::zeros(n, 0),
            residuals: vec![],
            residual_floors: vec![],
            info,
        });
    }
    let b = params.block.min(n).max(1);
    let ncv0 = lanczos::krylov_dim(params, params.nev.max(1), b, n);
    let small = n <= DENSE_MAX_DOFS;
    if n <= ncv0 + b + DENSE_MARGIN || (small && params.nev * DENSE_FRACTION_INV > n) {
        return dense::solve(k, m, params, lam_lim, info, progress);
    }
    match lanczos::solve_lanczos(k, m, params, lam_lim, par, info.clone(), progress) {
        // A small problem whose request Lanczos cannot meet (a frequency cap near or beyond
        // the highest mode; the Krylov basis cannot outgrow the problem) is solved densely.
        Err(EigenError::NotConverged { .. } | EigenError::InvalidInput(_)) if small => {
            dense::solve(k, m, params, lam_lim, info, progress)
        }
        other => other,
    }
}

/// Problems with at most this many dofs beyond the Krylov basis size are solved densely.
const DENSE_MARGIN: usize = 16;

/// Problems with at most this many free dofs are solved densely (`dense.rs`) when more than
/// n / [`DENSE_FRACTION_INV`] pairs are wanted, or when Lanczos fails on them (a frequency cap
/// near or beyond the highest mode). The dense path costs O(n³) whatever is wanted; measured
/// with `examples/dense_timing` (clamped beams, every mode, on 2 cores at load 10):
/// 750 dofs 0.7 s, 1512 dofs 5.2 s, 2646 dofs 38–46 s, 2940 dofs 80 s, against 2.6 s and
/// 4 s for Lanczos's n/10 lowest at 2646 and 2940 dofs. 2000 keeps the dense bake within
/// about 15 s there.
pub(super) const DENSE_MAX_DOFS: usize = 2000;

/// Count requests for more than n / this many pairs of a small problem go straight to the
/// dense path (Lanczos failed on 250 of the 570 dofs of the free-free beam).
pub(super) const DENSE_FRACTION_INV: usize = 4;

/// With `threads == 0`, problems below this many dofs run sequentially: thread
/// synchronisation costs more than it saves there (measured on 2 cores).
pub(super) const AUTO_SEQ_BELOW: usize = 20_000;

fn check_input(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    params: &EigenParams,
) -> Result<(), EigenError> {
    let n = k.nrows();
    let bad = |s: String| Err(EigenError::InvalidInput(s));
    if k.ncols() != n || m.nrows() != n || m.ncols() != n {
        return bad(format!(
            "K is {}x{}, M is {}x{}; both must be square and equal",
            k.nrows(),
            k.ncols(),
            m.nrows(),
            m.ncols()
        ));
    }
    if params.nev > n {
        return bad(format!("nev = {} exceeds the problem size {n}", params.nev));
    }
    if params.block == 0 {
        return bad("block size must be at least 1".into());
    }
    if !(params.tol > 0.0 && params.tol.is_finite()) {
        return bad(format!("tolerance must be positive, got {}", params.tol));
    }
    if !params.shift.is_finite() {
        return bad(format!("shift must be finite, got {}", params.shift));
    }
    if let Some(f) = params.max_freq_hz {
        if !(f > 0.0 && f.is_finite()) {
            return bad(format!("max frequency must be positive, got {f} Hz"));
        }
    }
    Ok(())
}

/// Coefficient c of [`default_shift`]: σ = −c·(E/ρ)·t²/L⁴.
const SHIFT_COEFF: f64 = 0.5;

/// A robust shift σ (rad²/s²) for a free-free object: σ = −0.5·(E/ρ)·t²/L⁴, with L the largest
/// and t the smallest side of the mesh's axis-aligned bounding box (m).
///
/// Rationale: the first elastic eigenvalue λ₇ scales like (E/ρ)/L² for a compact object
/// (≈ 5–10·(E/ρ)/L² for a cube) and like (E/ρ)·t²/L⁴ for a slender beam or thin plate in
/// bending (free-free Euler–Bernoulli beam of square section: (4.730⁴/12)·(E/ρ)·t²/L⁴ ≈
/// 41.7·(E/ρ)·t²/L⁴); the formula sits roughly 10–100× below λ₇ in both regimes (P1 meshes are
/// stiff, which only widens the gap). Trade-off, measured on boxes and beams: the six rigid
/// modes (θ = 1/|σ|) must be well separated from λ₇ to converge first (they are, by that
/// factor), while a |σ| that is *too small* makes the rounding errors of each solve leak into
/// the elastic Ritz vectors along the rigid directions, in proportion to λ_max/|σ|: with
/// σ = −10⁻⁴·(E/ρ)/L² the elastic residuals stalled near 10⁻⁸, with this shift they reach
/// 10⁻¹¹–10⁻¹². Any σ < 0 keeps K − σM positive definite, so a shift that is too large in
/// magnitude (e.g. a thin curved shell whose bounding box overestimates t) only slows
/// convergence; pass an explicit shift if needed.
///
/// ```
/// use modal_bake::{eigen::default_shift, fem::Material, mesh::TetMesh};
/// let mesh = TetMesh::structured_box([2, 2, 2], [1.0, 1.0, 1.0]);
/// let s = default_shift(&mesh, &Material::new(1e9, 0.3, 1000.0).unwrap());
/// assert!((s + 0.5 * 1e6).abs() < 1e-6);
/// ```
pub fn default_shift(mesh: &TetMesh, mat: &Material) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.nodes {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let ext: Vec<f64> = (0..3).map(|a| (hi[a] - lo[a]).max(0.0)).collect();
    let l = ext.iter().cloned().fold(0.0, f64::max);
    let t = ext
        .iter()
        .cloned()
        .filter(|&e| e > 0.0)
        .fold(f64::INFINITY, f64::min);
    let usable = l > 0.0 && t.is_finite();
    if !usable {
        return -SHIFT_COEFF * mat.bar_speed_squared();
    }
    -SHIFT_COEFF * mat.bar_speed_squared() * t * t / (l * l * l * l)
}
