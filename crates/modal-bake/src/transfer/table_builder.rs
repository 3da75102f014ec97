//! [`build_transfer_table`] and the mode sets it takes.

use dcr_runtime::format::{ModesFile, TransferTable, MAX_TRANSFER_POINTS};
use dcr_runtime::{damping_ratio, samples_per_step, ModalModel, ModeFilter, Sampling};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use rayon::prelude::*;

use crate::bake::{bake_mesh, BakeError, BakeParams, ModeRequest};
use crate::full_order::{FullOrderError, FullOrderSystem, ModalAll, SystemParams};
use crate::mesh::TetMesh;

/// Default oversampling of the table's peak search: T = π/(2 ω_max)/2 for its highest mode.
pub const DEFAULT_OVERSAMPLE: f64 = 2.0;

/// Meshes with at most this many free dofs get their table's modes from the dense all-mode
/// eigensolve; larger ones from a Lanczos bake.
pub const DENSE_MAX_DOFS: usize = 6000;

/// Default normal filter for `up`: a vertex is kept when n·û ≥ 0.5 (within 60°), so the edge
/// vertices of a face (normals averaged with the side faces) stay in the region.
pub const UP_MIN_COS: f64 = 0.5;

/// How many modes the table sums.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransferModes {
    /// The lowest n elastic modes.
    Count(usize),
    /// Every elastic mode (dense eigensolve: small meshes only).
    All,
}

/// What to tabulate (SI units, object frame).
#[derive(Clone, Debug, PartialEq)]
pub struct TransferParams {
    /// Rigid-body step h (s) the peaks are taken over; the runtime uses the table only for
    /// this h (relative tolerance 1e-9).
    pub h: f64,
    /// Modes summed. Default 640.
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
}

impl Default for TransferParams {
    fn default() -> Self {
        TransferParams {
            h: 0.01,
            modes: TransferModes::Count(640),
            boxes: Vec::new(),
            up: None,
            up_min_cos: UP_MIN_COS,
            oversample: DEFAULT_OVERSAMPLE,
        }
    }
}

impl TransferParams {
    /// Checks ranges.
    ///
    /// # Errors
    /// [`TransferError::Params`] naming the option.
    pub fn check(&self) -> Result<(), TransferError> {
        let bad = |s: String| Err(TransferError::Params(s));
        if !(self.h.is_finite() && self.h > 0.0) {
            return bad(format!(
                "--transfer-h must be a positive step in seconds, got {}",
                self.h
            ));
        }
        if self.modes == TransferModes::Count(0) {
            return bad("--transfer-modes must be at least 1".into());
        }
        for b in &self.boxes {
            if !b.iter().all(|x| x.is_finite()) || (0..3).any(|k| b[k] > b[k + 3]) {
                return bad(format!(
                    "--transfer-region {b:?}: expected finite xmin,ymin,zmin,xmax,ymax,zmax with min ≤ max"
                ));
            }
        }
        if let Some(u) = self.up {
            let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            if !(l.is_finite() && l > 0.0) {
                return bad(format!(
                    "--transfer-up {u:?}: expected a finite non-zero direction"
                ));
            }
        }
        if !(self.up_min_cos.is_finite() && self.up_min_cos.abs() <= 1.0) {
            return bad(format!(
                "normal-filter cosine {} must be in [-1, 1]",
                self.up_min_cos
            ));
        }
        if !(self.oversample.is_finite() && self.oversample >= 1.0) {
            return bad(format!("oversampling {} must be ≥ 1", self.oversample));
        }
        Ok(())
    }
}

/// Progress of a table build: source rows done of total.
#[derive(Clone, Copy, Debug)]
pub struct TransferProgress {
    /// Rows done.
    pub done: usize,
    /// Rows in all.
    pub total: usize,
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
    /// The Lanczos bake for the table's modes failed.
    #[error("transfer table modes: {0}")]
    Bake(Box<BakeError>),
}

/// A base-shaped mode set (surface rows of U) of the lowest `modes` dense eigenpairs, in the
/// layout of `template` (a base baked from the same mesh and options: same surface order).
///
/// # Errors
/// [`TransferError::FullOrder`] when the system cannot be built or the dense eigensolve fails
/// (including more than [`DENSE_MAX_DOFS`] free dofs).
pub fn mode_set_dense(
    template: &ModesFile,
    mesh: &TetMesh,
    params: &BakeParams,
    modes: TransferModes,
    file: &str,
) -> Result<ModesFile, TransferError> {
    let tp = SystemParams {
        material: params.material,
        fixed: params.fixed.clone(),
        rayleigh: params.rayleigh,
        lumped: params.lumped,
    };
    let sys = FullOrderSystem::new(mesh.clone(), &tp, file)?;
    let ma = ModalAll::new(&sys, DENSE_MAX_DOFS)?;
    let m = match modes {
        TransferModes::All => ma.eigenvalues.len(),
        TransferModes::Count(n) => n.min(ma.eigenvalues.len()),
    };
    Ok(mode_set_from_dense(template, &sys, &ma, m))
}

/// The lowest `m` eigenpairs of a dense all-mode solve `ma` of `sys` as a base-shaped mode set
/// in the layout of `template` (surface rows of U; fixed dofs zero; no table).
pub fn mode_set_from_dense(
    template: &ModesFile,
    sys: &FullOrderSystem,
    ma: &ModalAll,
    m: usize,
) -> ModesFile {
    let mut b = template.clone();
    let mut rows = Vec::with_capacity(b.surface_to_volume.len() * 3 * m);
    for &v in &b.surface_to_volume {
        for ax in 0..3 {
            match sys.map.free_index(3 * v as usize + ax) {
                Some(i) => rows.extend((0..m).map(|j| ma.vectors[(i, j)])),
                None => rows.extend(std::iter::repeat_n(0.0, m)),
            }
        }
    }
    b.modes = rows;
    b.eigenvalues = ma.eigenvalues[..m].to_vec();
    b.residuals = vec![0.0; m];
    b.transfer = None;
    b
}

/// A mode set of the lowest `n` modes from a Lanczos bake of `mesh` with `params`.
///
/// # Errors
/// [`TransferError::Bake`] when that bake fails (e.g. the eigensolver does not converge).
pub fn mode_set_lanczos(
    mesh: &TetMesh,
    params: &BakeParams,
    n: usize,
    file: &str,
) -> Result<ModesFile, TransferError> {
    let p = BakeParams {
        modes: ModeRequest::Count(n),
        ..params.clone()
    };
    bake_mesh(mesh.clone(), &p, file, &mut |_| {})
        .map(|(b, _)| b)
        .map_err(|e| TransferError::Bake(Box::new(e)))
}

/// Builds the table over the region selected by `params` from the mode set `modes` (a base
/// with many modes; its own Rayleigh damping is ignored in favour of `rayleigh`).
///
/// # Errors
/// [`TransferError::Params`] for invalid parameters, an empty region, or one whose vertices
/// and edge midpoints exceed [`MAX_TRANSFER_POINTS`].
pub fn build_transfer_table(
    modes: &ModesFile,
    params: &TransferParams,
    rayleigh: [f64; 2],
    progress: &mut dyn FnMut(TransferProgress),
) -> Result<TransferTable, TransferError> {
    params.check()?;
    let m = match params.modes {
        TransferModes::All => modes.num_modes(),
        TransferModes::Count(n) => n.min(modes.num_modes()),
    };
    let mut set = modes.clone();
    set.transfer = None;
    let model =
        ModalModel::from_base(set).map_err(|e| TransferError::Params(format!("mode set: {e}")))?;
    let region = super::select_region(&model, &params.boxes, params.up, params.up_min_cos);
    let nr = region.len();
    if nr == 0 {
        return Err(TransferError::Params(
            "the region (--transfer-region / --transfer-up) selects no surface vertex".into(),
        ));
    }
    let edges = TransferTable::region_edges(&model.base().surface_triangles, &region);
    let np = nr + edges.len();
    if np > MAX_TRANSFER_POINTS {
        return Err(TransferError::Params(format!(
            "the region selects {nr} surface vertices and {} edges, more than the {MAX_TRANSFER_POINTS} table points supported; restrict it with --transfer-region / --transfer-up",
            edges.len()
        )));
    }
    let mm = model.num_modes();
    let omega = &model.omega()[..m];
    let t_req = Sampling::Oversample(params.oversample).period(omega[m - 1]);
    if params.h / t_req > 1e7 {
        return Err(TransferError::Params(format!(
            "{:.0} samples per step (h/T) exceed the limit of 1e7; lower --transfer-modes or --transfer-h",
            params.h / t_req
        )));
    }
    let s = samples_per_step(params.h, t_req);
    let period = params.h / s as f64;
    // G (S × m): g_l(kT), the exact impulse response the runtime uses.
    let filters: Vec<ModeFilter> = omega
        .iter()
        .map(|&w| ModeFilter::new(w, damping_ratio(w, rayleigh), period))
        .collect();
    let g = Mat::from_fn(s, m, |k, l| {
        filters[l].impulse_response((k + 1) as f64 * period)
    });
    // W (m × nr): normal rows of the region vertices, one column per vertex; a midpoint's row
    // is the average of its two vertices' (P1).
    let rows = model.normal_mode_rows();
    let w = Mat::from_fn(m, nr, |l, c| rows[region[c] as usize * mm + l]);
    let point_row = |p: usize, l: usize| -> f64 {
        if p < nr {
            w[(l, p)]
        } else {
            let [a, b] = edges[p - nr];
            0.5 * (w[(l, a as usize)] + w[(l, b as usize)])
        }
    };

    // Row p: Y = (G ∘ w_p) W (S × nr), the signals at every region vertex; a midpoint column is
    // the average of two vertex columns, so one GEMM against the vertices serves all np points.
    let mut peaks = vec![0.0f32; TransferTable::packed_len(np)];
    let chunk = 16usize;
    let mut done = 0;
    progress(TransferProgress { done, total: np });
    for start in (0..np).step_by(chunk) {
        let end = (start + chunk).min(np);
        let block: Vec<Vec<f32>> = (start..end)
            .into_par_iter()
            .map_init(
                || (Mat::<f64>::zeros(s, m), Mat::<f64>::zeros(s, nr)),
                |(a, y), p| {
                    for l in 0..m {
                        let wp = point_row(p, l);
                        for k in 0..s {
                            a[(k, l)] = g[(k, l)] * wp;
                        }
                    }
                    matmul(
                        y.as_mut(),
                        Accum::Replace,
                        a.as_ref(),
                        w.as_ref(),
                        1.0,
                        Par::Seq,
                    );
                    (p..np)
                        .map(|q| {
                            let peak = if q < nr {
                                let col = y.col(q);
                                (0..s).fold(0.0f64, |pk, k| pk.max(col[k].abs()))
                            } else {
                                let [ea, eb] = edges[q - nr];
                                let (ca, cb) = (y.col(ea as usize), y.col(eb as usize));
                                (0..s).fold(0.0f64, |pk, k| pk.max((0.5 * (ca[k] + cb[k])).abs()))
                            };
                            peak as f32
                        })
                        .collect()
                },
            )
            .collect();
        for (p, row) in (start..end).zip(block) {
            let at = p * (2 * np - p + 1) / 2;
            peaks[at..at + row.len()].copy_from_slice(&row);
        }
        done = end;
        progress(TransferProgress { done, total: np });
    }
    let table = TransferTable {
        h: params.h,
        rayleigh,
        modes: m as u32,
        samples: s as u32,
        vertices: region,
        edges,
        peaks,
    };
    table
        .check(modes.num_surface_vertices())
        .map_err(TransferError::Params)?;
    Ok(table)
}
