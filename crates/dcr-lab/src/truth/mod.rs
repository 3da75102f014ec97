//! Full-order truth: the exact linear response of a meshed object to an impulse at a surface
//! point, measured as the peak normal displacement at other surface points (the quantity the
//! runtime approximates with a truncated modal base, paper Eq. 9–12).
//!
//! Two independent methods on the same FEM system (paper Eq. 5, M ü + D u̇ + K u = f,
//! D = α0 M + α1 K, every dof of the mesh):
//!
//! - Newmark ([`modal_bake::full_order::newmark_peaks`]): implicit average acceleration
//!   (β = ¼, γ = ½) with a small step, one sparse Cholesky of K_eff, one back-solve per step.
//! - Modal-all ([`modal_bake::full_order::ModalAll`]): dense generalized eigensolve of every mode
//!   and the exact damped impulse response of each (ξ < 1, = 1, > 1) — small meshes only.
//!
//! Conventions (identical to `modal-bake probe` and `dcr_runtime::ModalModel`):
//! - points are mapped to the closest triangle of the extracted boundary surface (brute force,
//!   `modal_bake::full_order::SurfaceMap`) and refused farther than [`MAP_DISTANCE_REL`] × the bounding-box diagonal;
//!   weights in triangle order; normals are area-weighted vertex normals
//!   interpolated with the weights and normalised;
//! - the impulse acts at t = 0 along `direction`, by default *into* the surface (−normal at
//!   the impact), spread to the impact triangle's three nodes by barycentric weights;
//! - a contact's displacement is `nᵀ Σ_i b_i u_i`; its peak is max_k |·| over t = kΔt,
//!   k = 1 … S, S = `samples_per_step(h, dt)` and Δt = h/S (never longer than `dt`);
//!   `delta_v_mps` = peak / h (Eq. 12);
//! - free-free objects: the **elastic** displacement only — the rigid-body part of the motion is
//!   projected out M-orthogonally (`FullOrderSystem::remove_rigid`), which is what the sum
//!   over every elastic mode (a base with all modes) gives. Clamped objects: as is.
//! - `distance_m` is the heat-method geodesic distance on the surface
//!   (`dcr_runtime::attenuation::HeatGeodesic`, Crane et al. 2013) from the impact point, interpolated at the
//!   contact with its barycentric weights; Euclidean if the geodesic solver cannot be built
//!   (reported in [`TruthInfo::distance_kind`]).

use std::time::Instant;

pub use modal_bake::full_order::MaterialSi;
pub use modal_bake::full_order::SystemParams;
use modal_bake::full_order::{
    converged_peaks, FullOrderError, FullOrderSystem, ModalAll, PeakSolver, PeakWindow,
    RefineParams, RefineProgress,
};
use modal_bake::mesh::{MeshError, TetMesh};

use dcr_runtime::attenuation::HeatGeodesic;
use dcr_runtime::filter::samples_per_step;
use dcr_runtime::model::SurfacePoint;

/// Which truth to compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TruthMethod {
    /// Implicit Newmark average acceleration on the full mesh.
    Newmark,
    /// Sum over every mode (dense eigensolve; small meshes).
    ModalAll,
}

/// Parameters of a truth run (SI units).
#[derive(Clone, Debug, PartialEq)]
pub struct TruthParams {
    /// The object's full-order system: material, fixed groups, Rayleigh damping, lumped mass
    /// (defaults as `bake`: 1.1 GPa, 0.3, 770 kg/m³, free-free, (10, 1e-7), consistent mass).
    pub system: SystemParams,
    /// Window h (s) over which the peak is taken. Default 0.01.
    pub h: f64,
    /// First sample/step size Δt (s); the first step used is h/⌈h/Δt⌉, then halved until the
    /// peaks converge ([`TruthParams::refine`]). Default 1e-5.
    pub dt: f64,
    /// Method. Default [`TruthMethod::Newmark`].
    pub method: TruthMethod,
    /// Modal-all only: keep the lowest this-many elastic modes (`None`: all).
    pub modes: Option<usize>,
    /// Modal-all only: refuse meshes with more free dofs than this (dense memory 8n² bytes per
    /// matrix). Default 6000.
    pub max_dense_dofs: usize,
    /// Step refinement: tolerance, halvings, sample budget (`max_refinements = 0`: one run at
    /// `dt`, unchecked). Default [`RefineParams::default`] (0.5 %, 6 halvings).
    pub refine: RefineParams,
    /// Whether the other method is run at the finest step as an independent check. Default
    /// [`CrossCheck::Auto`].
    pub cross_check: CrossCheck,
}

/// The independent check of a truth run: the other method at the step the run reached.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CrossCheck {
    /// When cheap: free dofs ≤ [`CROSS_CHECK_AUTO_DOFS`] (a dense solve of at most that size).
    #[default]
    Auto,
    /// Always (modal-all needs free dofs ≤ `max_dense_dofs`).
    On,
    /// Never.
    Off,
}

/// [`CrossCheck::Auto`] runs the check up to this many free dofs.
pub const CROSS_CHECK_AUTO_DOFS: usize = 3000;

/// How a truth run converged (percentages of each peak).
#[derive(Clone, Debug, serde::Serialize)]
pub struct TruthConvergence {
    /// Whether every peak changed by less than the tolerance over the last two halvings.
    pub converged: bool,
    /// Tolerance (%).
    pub tolerance_pct: f64,
    /// Step reached (s).
    pub dt_reached: f64,
    /// Largest change of a peak between the last two steps (%; null with one step).
    pub last_change_pct: Option<f64>,
    /// Estimated error of the reported peaks: the larger of the last two changes (%; null with
    /// fewer than three steps).
    pub estimated_error_pct: Option<f64>,
    /// Every step tried, coarsest first: `dt`, `samples`, `change_pct`, `seconds`.
    pub history: Vec<TruthLevel>,
    /// The other method at the step reached, if run.
    pub cross_check: Option<TruthCrossCheck>,
}

/// One step of the refinement.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TruthLevel {
    /// Step (s).
    pub dt: f64,
    /// Samples over the window.
    pub samples: usize,
    /// Largest change of a peak from the previous step (%; null first).
    pub change_pct: Option<f64>,
    /// Wall seconds.
    pub seconds: f64,
}

/// The independent check.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TruthCrossCheck {
    /// `newmark` or `modal-all`.
    pub method: String,
    /// Its step (s).
    pub dt: f64,
    /// Largest relative difference of a peak from the reported one (%).
    pub max_diff_pct: f64,
}

impl Default for TruthParams {
    fn default() -> Self {
        TruthParams {
            system: SystemParams::default(),
            h: 0.01,
            dt: 1e-5,
            method: TruthMethod::Newmark,
            modes: None,
            max_dense_dofs: 6000,
            refine: RefineParams::default(),
            cross_check: CrossCheck::Auto,
        }
    }
}

/// Points farther than this fraction of the surface's bounding-box diagonal are refused (as
/// `modal-bake probe` and `DistantResponse` do by default).
pub const MAP_DISTANCE_REL: f64 = 0.05;

/// An impulse applied at t = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthImpact {
    /// Point (m, object frame); mapped to the closest surface point.
    pub point: [f64; 3],
    /// Impulse magnitude (N·s).
    pub impulse: f64,
    /// Direction (normalised here); `None`: into the surface, −normal at the impact.
    pub direction: Option<[f64; 3]>,
}

/// One contact's truth, in `modal-bake probe`'s JSON shape.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TruthContact {
    /// The contact mapped onto the surface (m).
    pub point: [f64; 3],
    /// Surface triangle index (as in a baked base).
    pub triangle: u32,
    /// Barycentric weights in triangle order.
    pub bary: [f64; 3],
    /// Distance from the impact along the surface (m), see the module docs.
    pub distance_m: f64,
    /// Peak |normal displacement| over the window (m).
    pub peak_displacement_m: f64,
    /// peak / h (m/s), paper Eq. 12.
    pub delta_v_mps: f64,
}

/// What a truth run did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct TruthInfo {
    /// `newmark` or `modal-all`.
    pub method: String,
    /// Free degrees of freedom.
    pub free_dofs: usize,
    /// Fixed nodes (0: free-free, rigid motion removed).
    pub fixed_nodes: usize,
    /// Samples S over the window (= Newmark steps).
    pub samples: usize,
    /// Step/sample period used (s).
    pub dt: f64,
    /// Window (s).
    pub h: f64,
    /// Modal-all: elastic modes summed.
    pub modes_used: usize,
    /// Modal-all: rigid modes dropped.
    pub rigid_modes_dropped: usize,
    /// The impact mapped onto the surface (m), its triangle, weights and unit direction.
    pub impact_point: [f64; 3],
    /// Impact triangle.
    pub impact_triangle: u32,
    /// Impact weights.
    pub impact_bary: [f64; 3],
    /// Unit impulse direction used.
    pub impact_direction: [f64; 3],
    /// `geodesic` or `euclidean`.
    pub distance_kind: String,
    /// Wall time (s) of set-up (assembly), solve (factor/eigensolve) and time stepping.
    pub setup_s: f64,
    /// Factor or eigensolve seconds.
    pub solve_s: f64,
    /// Stepping / summation seconds.
    pub step_s: f64,
}

/// Truth for every contact plus what the run did.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TruthResult {
    /// One entry per requested contact, in order.
    pub contacts: Vec<TruthContact>,
    /// Run information.
    pub info: TruthInfo,
    /// How the step was refined and whether the peaks converged.
    pub convergence: TruthConvergence,
}

/// Why a truth run failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TruthError {
    /// The mesh could not be read.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The full-order system or its solve failed (mesh, material, factorization, size).
    #[error(transparent)]
    System(#[from] FullOrderError),
    /// Invalid parameters or inputs (the message names which).
    #[error("{0}")]
    Params(String),
}

impl TruthParams {
    /// (samples S, step h/S).
    ///
    /// # Errors
    /// [`TruthError::Params`] for non-positive h or dt or more than the refinement's sample
    /// budget ([`RefineParams::max_samples`]).
    pub fn sampling(&self) -> Result<(usize, f64), TruthError> {
        if !(self.h.is_finite() && self.h > 0.0 && self.dt.is_finite() && self.dt > 0.0) {
            return Err(TruthError::Params(format!(
                "the window h and step dt must be finite and > 0 s, got h = {}, dt = {}",
                self.h, self.dt
            )));
        }
        if !(self.h / self.dt <= self.refine.max_samples as f64) {
            return Err(TruthError::Params(format!(
                "h/dt = {:.3e} steps exceeds the limit {}",
                self.h / self.dt,
                self.refine.max_samples
            )));
        }
        let s = samples_per_step(self.h, self.dt);
        Ok((s, self.h / s as f64))
    }
}

/// Maps the impact and contacts onto the surface and returns (impact point, unit direction,
/// contact points).
fn map_points(
    sys: &FullOrderSystem,
    impact: &TruthImpact,
    contacts: &[[f64; 3]],
) -> Result<(SurfacePoint, [f64; 3], Vec<SurfacePoint>), TruthError> {
    if !(impact.impulse.is_finite() && impact.impulse > 0.0) {
        return Err(TruthError::Params(format!(
            "the impulse must be a finite number > 0 (N·s), got {}",
            impact.impulse
        )));
    }
    let max_map = MAP_DISTANCE_REL * sys.surface.bounding_box_diagonal();
    let map = |p: [f64; 3], what: &str| {
        sys.surface
            .project(p)
            .filter(|sp| sp.distance <= max_map)
            .ok_or_else(|| {
                TruthError::Params(format!(
                    "{what} at {p:?} is farther than {max_map:.4} m from the surface"
                ))
            })
    };
    let isp = map(impact.point, "impact point")?;
    let dir = match impact.direction {
        Some(d) => {
            let n = normalize(d);
            if n == [0.0; 3] {
                return Err(TruthError::Params(format!(
                    "the impulse direction must be a non-zero finite vector, got {d:?}"
                )));
            }
            n
        }
        None => isp.normal.map(|x| -x),
    };
    let csp = contacts
        .iter()
        .enumerate()
        .map(|(i, &p)| map(p, &format!("contact {}", i + 1)))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((isp, dir, csp))
}

/// Distances (m) from the impact to each contact, and the kind used.
fn distances(
    sys: &FullOrderSystem,
    isp: &SurfacePoint,
    csp: &[SurfacePoint],
) -> (Vec<f64>, String) {
    if let Ok(heat) = HeatGeodesic::new(&sys.surface.vertices, &sys.surface.triangles) {
        let mut d = vec![0.0; sys.surface.vertices.len()];
        heat.distances_from_point(isp, &mut d);
        if d.iter().all(|x| x.is_finite()) {
            let out = csp
                .iter()
                .map(|c| {
                    let t = sys.surface.triangles[c.triangle as usize];
                    (0..3)
                        .map(|i| c.bary[i] * d[t[i] as usize])
                        .sum::<f64>()
                        .max(0.0)
                })
                .collect();
            return (out, "geodesic".into());
        }
    }
    let out = csp.iter().map(|c| dist(c.point, isp.point)).collect();
    (out, "euclidean".into())
}

/// Truth for an in-memory mesh: impulse `impact` at t = 0, peaks at `contacts` (m), with the
/// step refined until the peaks converge (`params.refine`; the result says whether they did).
/// `file` names the source in messages; `progress` hears each refinement level and step.
///
/// # Errors
/// [`TruthError`] naming what failed (material, mesh, mapping, factorization, size). A run that
/// does not converge is not an error: [`TruthConvergence::converged`] is false.
///
/// ```
/// use dcr_lab::truth::*;
/// use modal_bake::mesh::TetMesh;
/// let mesh = TetMesh::structured_box([4, 1, 1], [1.0, 0.2, 0.2]);
/// let params = TruthParams {
///     system: SystemParams { fixed: vec!["xmin".into()], ..Default::default() },
///     h: 2e-3,
///     dt: 1e-5,
///     method: TruthMethod::ModalAll,
///     ..Default::default()
/// };
/// let impact = TruthImpact { point: [1.0, 0.1, 0.2], impulse: 1.0, direction: None };
/// let res = run_truth(mesh, &params, &impact, &[[0.5, 0.1, 0.2]], "box", &mut |_| {}).unwrap();
/// assert!(res.contacts[0].peak_displacement_m > 0.0 && res.convergence.converged);
/// ```
pub fn run_truth(
    mesh: TetMesh,
    params: &TruthParams,
    impact: &TruthImpact,
    contacts: &[[f64; 3]],
    file: &str,
    progress: &mut dyn FnMut(RefineProgress),
) -> Result<TruthResult, TruthError> {
    let (_, dt0) = params.sampling()?;
    let t = Instant::now();
    let sys = FullOrderSystem::new(mesh, &params.system, file)?;
    let (isp, dir, csp) = map_points(&sys, impact, contacts)?;
    let f = sys.load_vector(&isp, dir, impact.impulse);
    let rows: Vec<Vec<f64>> = csp.iter().map(|c| sys.contact_row(c)).collect();
    let (dist, distance_kind) = distances(&sys, &isp, &csp);
    let mut info = TruthInfo {
        free_dofs: sys.n(),
        fixed_nodes: sys.fixed_nodes,
        h: params.h,
        impact_point: isp.point,
        impact_triangle: isp.triangle,
        impact_bary: isp.bary,
        impact_direction: dir,
        distance_kind,
        setup_s: t.elapsed().as_secs_f64(),
        ..Default::default()
    };
    let loads = [f];
    let dense_ok = sys.n() <= params.max_dense_dofs;
    let check = match params.cross_check {
        CrossCheck::Off => false,
        CrossCheck::On => true,
        CrossCheck::Auto => sys.n() <= CROSS_CHECK_AUTO_DOFS.min(params.max_dense_dofs),
    };
    let need_dense = params.method == TruthMethod::ModalAll || (check && dense_ok);
    let t = Instant::now();
    let ma = if need_dense {
        let ma = ModalAll::new(&sys, params.max_dense_dofs)?;
        info.rigid_modes_dropped = ma.rigid_dropped;
        Some(ma)
    } else {
        None
    };
    let dense_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (solver, other) = match (params.method, &ma) {
        (TruthMethod::ModalAll, Some(ma)) => {
            info.method = "modal-all".into();
            // A truncated sum is not the full-order response: nothing to check it against.
            let check = check && params.modes.is_none();
            info.modes_used = params.modes.unwrap_or(usize::MAX).min(ma.eigenvalues.len());
            info.solve_s = dense_s;
            (
                PeakSolver::ModalAll(ma, params.modes),
                check.then_some(PeakSolver::Newmark),
            )
        }
        (_, ma) => {
            info.method = "newmark".into();
            let other = ma
                .as_ref()
                .filter(|_| check)
                .map(|m| PeakSolver::ModalAll(m, None));
            (PeakSolver::Newmark, other)
        }
    };
    let conv = converged_peaks(
        &sys,
        solver,
        &loads,
        &rows,
        PeakWindow {
            h: params.h,
            dt: dt0,
        },
        &params.refine,
        progress,
    )?;
    info.step_s = t.elapsed().as_secs_f64();
    info.samples = conv.samples;
    info.dt = conv.dt;
    let peaks = conv.peaks[0].clone();
    if !peaks.iter().all(|p| p.is_finite()) {
        return Err(TruthError::Params(
            "the response is not finite (overflow: impulse or material out of range)".into(),
        ));
    }
    let cross_check = match other {
        Some(o) => {
            let single = RefineParams {
                max_refinements: 0,
                ..params.refine
            };
            let c = converged_peaks(
                &sys,
                o,
                &loads,
                &rows,
                PeakWindow {
                    h: params.h,
                    dt: conv.dt,
                },
                &single,
                &mut |_| {},
            )?;
            let diff = peaks
                .iter()
                .zip(&c.peaks[0])
                .filter(|(p, _)| **p > 1e-12 * peaks.iter().fold(0.0f64, |a, b| a.max(*b)))
                .fold(0.0f64, |m, (p, q)| m.max(((q - p) / p).abs()));
            Some(TruthCrossCheck {
                method: match o {
                    PeakSolver::Newmark => "newmark".into(),
                    PeakSolver::ModalAll(..) => "modal-all".into(),
                },
                dt: c.dt,
                max_diff_pct: 100.0 * diff,
            })
        }
        None => None,
    };
    let pct = |x: f64| x.is_finite().then_some(100.0 * x);
    let convergence = TruthConvergence {
        converged: conv.converged,
        tolerance_pct: 100.0 * conv.tolerance,
        dt_reached: conv.dt,
        last_change_pct: pct(conv.last_change),
        estimated_error_pct: pct(conv.estimated_error),
        history: conv
            .history
            .iter()
            .map(|l| TruthLevel {
                dt: l.dt,
                samples: l.samples,
                change_pct: pct(l.change),
                seconds: l.seconds,
            })
            .collect(),
        cross_check,
    };
    let contacts = csp
        .iter()
        .zip(peaks)
        .zip(dist)
        .map(|((c, p), d)| TruthContact {
            point: c.point,
            triangle: c.triangle,
            bary: c.bary,
            distance_m: d,
            peak_displacement_m: p,
            delta_v_mps: p / params.h,
        })
        .collect();
    Ok(TruthResult {
        contacts,
        info,
        convergence,
    })
}

/// `a/|a|`, or zero for a zero or non-finite vector.
fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    if n > 0.0 && n.is_finite() {
        a.map(|x| x / n)
    } else {
        [0.0; 3]
    }
}

/// Euclidean distance (m).
fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}
