//! Fitting the spatial attenuation law (paper Eq. 14, §4.4, §5.3 and Fig. 10) to the full-order
//! response of a mesh.
//!
//! # What is measured
//! For a pair of surface vertices (a = impact, b = distant contact) a unit impulse (1 N·s) is
//! applied at a at t = 0 along −n_a (into the surface). Over the window h the *local* peak
//! `d_a = max_k |n_aᵀ u_a(kΔt)|` and the *distant* peak `d_b = max_k |n_bᵀ u_b(kΔt)|`,
//! k = 1 … S, are taken (the same displacement peaks as Eq. 11 and `truth`). The measured
//! attenuation is their ratio
//!
//! `s_ab = d_b / d_a`,
//!
//! exactly the factor the runtime multiplies the local amplitude by (Eq. 15–16: Δv_p = s Δx_c/h),
//! so fitted parameters plug into `AttenuationLaw::Full` unchanged. (The paper's Fig. 10 uses
//! peak *velocities* of a high-resolution FEM run; we use displacements because that is what
//! Eq. 15–16 scale.) The distance r_ab is the heat-method geodesic distance on the surface
//! (Crane et al. 2013, `dcr_runtime::attenuation::HeatGeodesic`) from a to b (Euclidean if the surface's heat
//! operators cannot be built).
//!
//! # Truth
//! u is the sum over elastic modes of the exact damped impulse responses (Rayleigh damping,
//! every damping regime, `dcr_runtime::filter::ModeFilter`), sampled by the exact two-term recursion
//! g_k = a1 g_{k−1} − a2 g_{k−2} of each mode:
//! - [`SurfaceResponse::from_modal_all`]: every mode of a dense eigensolve ([`ModalAll`],
//!   small meshes), or its lowest `modes`;
//! - [`SurfaceResponse::from_base`]: the lowest `modes` of a sparse (Lanczos) bake, for meshes
//!   too large for the dense solve. Full-order Newmark is not offered here: it costs one
//!   full time integration per pair.
//!
//! # Fit
//! In log space Eq. 14 reads `ln s = −α(r − r0) − β ln(r/r0) = c − α r − β ln r` with
//! `c = α r0 + β ln r0`. For α ≥ 0, β > 0 the map (α, β, r0) ↔ (α, β, c) is one-to-one, so the
//! least-squares fit over (α, β, r0) is the *linear* least-squares fit of ln s on [1, −r, −ln r]
//! (Householder-free modified Gram–Schmidt QR, 3 columns); r0 is then recovered from c by
//! bisection on ln r0 (`α e^x + β x = c` is increasing in x). No grid over r0 is needed and the
//! optimum is global. The constraints α ≥ 0, β ≥ 0 (those of `AttenuationLaw::Full`) are
//! enforced by enumerating the faces {free, α = 0, β = 0} and keeping the best feasible one.
//! With r0 given ([`fit_eq14_fixed_r0`]) the fit is linear in (α, β) without intercept.
//! The §4.5 simplified law s = C r^−β is the α = 0 fit with C = e^c ([`fit_simplified`]).
//! Quality: R² = 1 − SS_res/SS_tot and RMS = √(SS_res/n), both of ln s.

mod eq14;
mod surface_response;

use std::time::Instant;

use dcr_runtime::attenuation::HeatGeodesic;
use dcr_runtime::rng::SplitMix64;
use modal_bake::bake::{bake_mesh, BakeError, ModeRequest};
use modal_bake::full_order::{FullOrderError, FullOrderSystem, ModalAll, SystemParams};
use modal_bake::mesh::TetMesh;
use rayon::prelude::*;

pub use eq14::{
    fit_eq14, fit_eq14_fixed_r0, fit_simplified, AttenuationFit, SimplifiedFit, MIN_FIT_SAMPLES,
};
pub use surface_response::SurfaceResponse;

/// Why a fit or a measurement failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// Too few usable samples (finite, r > 0, s > 0).
    #[error("{have} usable samples (finite, r > 0, s > 0); at least {need} are needed")]
    TooFewSamples {
        /// Usable samples.
        have: usize,
        /// Needed.
        need: usize,
    },
    /// No parameter set satisfies α ≥ 0, β ≥ 0, r0 > 0 (e.g. all distances equal).
    #[error("degenerate fit: {0}")]
    Degenerate(String),
    /// Invalid parameters.
    #[error("{0}")]
    Params(String),
    /// The full-order system or dense eigensolve failed.
    #[error(transparent)]
    System(#[from] FullOrderError),
    /// The sparse bake failed.
    #[error(transparent)]
    Bake(#[from] BakeError),
}

/// One measured pair.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AttenuationSample {
    /// Impact surface vertex.
    pub impact_vertex: usize,
    /// Contact surface vertex.
    pub contact_vertex: usize,
    /// Impact position (m).
    pub impact_point: [f64; 3],
    /// Contact position (m).
    pub contact_point: [f64; 3],
    /// Surface distance r (m).
    pub distance_m: f64,
    /// Peak |normal displacement| at the impact per N·s (m).
    pub local_peak_m: f64,
    /// Peak |normal displacement| at the contact per N·s (m).
    pub contact_peak_m: f64,
    /// s = contact / local.
    pub ratio: f64,
}

/// How the truth is computed for the fit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FitTruth {
    /// Dense all-mode sum if free dofs ≤ `max_dense_dofs`, else the sparse bake (default).
    #[default]
    Auto,
    /// Dense eigensolve of every mode (lowest `modes` if given).
    ModalAll,
    /// Sparse Lanczos bake of the lowest `modes` (default [`DEFAULT_SPARSE_MODES`]).
    Modes,
}

/// Modes baked for the sparse truth when `modes` is not given.
pub const DEFAULT_SPARSE_MODES: usize = 200;

/// Parameters of [`fit_attenuation_mesh`] (SI units).
#[derive(Clone, Debug, PartialEq)]
pub struct AttenuationFitParams {
    /// The object: material, fixed-node selectors, Rayleigh damping [α0 (1/s), α1 (s)] and
    /// mass lumping. Default as `bake`: 1.1 GPa, 0.3, 770 kg/m³, free-free, (10, 1e-7),
    /// consistent mass.
    pub system: SystemParams,
    /// Window h (s) of the peaks. Default 0.01.
    pub h: f64,
    /// Sample period (s); `None`: [`SurfaceResponse::default_dt`].
    pub dt: Option<f64>,
    /// Modes used for the truth (`None`: all for modal-all, [`DEFAULT_SPARSE_MODES`] sparse).
    pub modes: Option<usize>,
    /// Truth method. Default [`FitTruth::Auto`].
    pub truth: FitTruth,
    /// Largest free-dof count for the dense eigensolve. Default 6000.
    pub max_dense_dofs: usize,
    /// Random pairs. Default 200.
    pub pairs: usize,
    /// Seed. Default 1.
    pub seed: u64,
    /// Fixed r0 (m); `None`: fitted.
    pub r0: Option<f64>,
}

impl Default for AttenuationFitParams {
    fn default() -> Self {
        AttenuationFitParams {
            system: SystemParams::default(),
            h: 0.01,
            dt: None,
            modes: None,
            truth: FitTruth::Auto,
            max_dense_dofs: 6000,
            pairs: 200,
            seed: 1,
            r0: None,
        }
    }
}

/// What [`fit_attenuation_mesh`] did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct AttenuationFitInfo {
    /// `modal-all` or `modes`.
    pub method: String,
    /// Free dofs of the mesh.
    pub free_dofs: usize,
    /// Modes summed.
    pub modes: usize,
    /// Highest frequency summed (Hz).
    pub max_freq_hz: f64,
    /// Sample period (s).
    pub dt: f64,
    /// Samples over the window.
    pub samples: usize,
    /// Window (s).
    pub h: f64,
    /// `geodesic` or `euclidean`.
    pub distance_kind: String,
    /// Pairs requested / used in the fit.
    pub pairs_requested: usize,
    /// Pairs used.
    pub pairs_used: usize,
    /// Seed.
    pub seed: u64,
    /// Seconds in assembly and the eigensolve (dense or sparse).
    pub eigensolve_s: f64,
    /// Seconds sampling the pairs (geodesics and responses).
    pub response_s: f64,
}

/// Samples, fits and run information.
#[derive(Clone, Debug, serde::Serialize)]
pub struct AttenuationFitReport {
    /// Eq. 14 fit.
    pub fit: AttenuationFit,
    /// §4.5 simplified fit.
    pub simplified: SimplifiedFit,
    /// Run information.
    pub info: AttenuationFitInfo,
    /// Every measured pair.
    pub samples: Vec<AttenuationSample>,
}

/// Most pairs a fit accepts (the samples take ≈ 140 bytes each; a fit needs hundreds).
pub const MAX_FIT_PAIRS: usize = 100_000;

/// Where a fit is (reported to the caller's progress callback).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum FitProgress {
    /// Assembling and solving for the modes (`modal-all` or `modes`).
    Solve {
        /// `modal-all` (dense) or `modes` (Lanczos bake).
        method: &'static str,
    },
    /// Geodesic distances: pairs done of total.
    Distances {
        /// Done.
        done: usize,
        /// Total.
        total: usize,
    },
    /// Peak responses: pairs done of total.
    Pairs {
        /// Done.
        done: usize,
        /// Total.
        total: usize,
    },
}

fn check_pairs(pairs: usize) -> Result<(), FitError> {
    if !(MIN_FIT_SAMPLES..=MAX_FIT_PAIRS).contains(&pairs) {
        return Err(FitError::Params(format!(
            "the number of pairs must be in {MIN_FIT_SAMPLES} … {MAX_FIT_PAIRS}, got {pairs}"
        )));
    }
    Ok(())
}

/// Measures `pairs` random (impact, contact) vertex pairs of `resp` (seeded), see the module
/// docs; returns the samples, the distance kind and (dt, samples) used.
///
/// # Errors
/// [`FitError::Params`] for fewer than two eligible vertices, a bad h / dt, or `pairs` outside
/// [`MIN_FIT_SAMPLES`] … [`MAX_FIT_PAIRS`].
pub fn sample_attenuation(
    resp: &SurfaceResponse,
    rayleigh: [f64; 2],
    h: f64,
    dt: Option<f64>,
    pairs: usize,
    seed: u64,
    progress: &mut dyn FnMut(FitProgress),
) -> Result<(Vec<AttenuationSample>, String, f64, usize), FitError> {
    check_pairs(pairs)?;
    let dt_req = dt.unwrap_or_else(|| resp.default_dt());
    if !(h.is_finite() && h > 0.0 && dt_req.is_finite() && dt_req > 0.0) {
        return Err(FitError::Params(format!(
            "the window h and sample period dt must be finite and > 0 s, got h = {h}, dt = {dt_req}"
        )));
    }
    if h / dt_req > 1e7 {
        return Err(FitError::Params(format!(
            "h/dt = {:.2e} samples is too many (limit 1e7)",
            h / dt_req
        )));
    }
    let steps = dcr_runtime::filter::samples_per_step(h, dt_req);
    let dt = h / steps as f64;
    let cand: Vec<usize> = (0..resp.vertices.len())
        .filter(|&v| resp.eligible[v])
        .collect();
    if cand.len() < 2 {
        return Err(FitError::Params(format!(
            "the surface has {} free vertices; at least 2 are needed",
            cand.len()
        )));
    }
    let mut rng = SplitMix64(seed);
    let pairs_v: Vec<(usize, usize)> = (0..pairs)
        .map(|_| {
            let a = cand[rng.below(cand.len())];
            let mut b = a;
            while b == a {
                b = cand[rng.below(cand.len())];
            }
            (a, b)
        })
        .collect();
    // Distances: one heat solve per impact vertex.
    let heat = HeatGeodesic::new(&resp.vertices, &resp.triangles).ok();
    let mut kind = if heat.is_some() {
        "geodesic"
    } else {
        "euclidean"
    };
    let mut dist = vec![0.0; resp.vertices.len()];
    let mut r = Vec::with_capacity(pairs);
    for (i, &(a, b)) in pairs_v.iter().enumerate() {
        progress(FitProgress::Distances {
            done: i,
            total: pairs,
        });
        let eu = {
            let (p, q) = (resp.vertices[a], resp.vertices[b]);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let d = match &heat {
            Some(hg) => {
                hg.distances_from_vertex(a, &mut dist);
                if dist[b].is_finite() {
                    dist[b]
                } else {
                    kind = "euclidean";
                    eu
                }
            }
            None => eu,
        };
        r.push(d);
    }
    progress(FitProgress::Distances {
        done: pairs,
        total: pairs,
    });
    let filters = resp.filters(rayleigh, dt);
    let mut samples = Vec::with_capacity(pairs);
    // Blocks of pairs in parallel, progress between blocks.
    const BLOCK: usize = 32;
    for (start, (pv, rv)) in pairs_v
        .chunks(BLOCK)
        .zip(r.chunks(BLOCK))
        .enumerate()
        .map(|(k, x)| (k * BLOCK, x))
    {
        progress(FitProgress::Pairs {
            done: start,
            total: pairs,
        });
        samples.par_extend(pv.par_iter().zip(rv.par_iter()).map(|(&(a, b), &d)| {
            let (la, cb) = resp.pair_peaks(&filters, a, &[b], steps);
            AttenuationSample {
                impact_vertex: a,
                contact_vertex: b,
                impact_point: resp.vertices[a],
                contact_point: resp.vertices[b],
                distance_m: d,
                local_peak_m: la,
                contact_peak_m: cb[0],
                ratio: cb[0] / la,
            }
        }));
    }
    progress(FitProgress::Pairs {
        done: pairs,
        total: pairs,
    });
    Ok((samples, kind.into(), dt, steps))
}

/// Bakes the truth for `mesh`, measures random pairs and fits Eq. 14 and the §4.5 law.
/// `file` names the mesh in messages; `progress` hears where the run is.
///
/// # Errors
/// [`FitError`] naming what failed (mesh, material, eigensolve, too few samples, degenerate).
///
/// ```
/// use dcr_lab::attenuation_fit::*;
/// use modal_bake::full_order::SystemParams;
/// use modal_bake::mesh::TetMesh;
/// let mesh = TetMesh::structured_box([6, 2, 2], [1.0, 0.2, 0.2]);
/// let system = SystemParams { fixed: vec!["xmin".into()], ..Default::default() };
/// let p = AttenuationFitParams { system, h: 2e-3, pairs: 20, ..Default::default() };
/// let rep = fit_attenuation_mesh(mesh, &p, "box", &mut |_| {}).unwrap();
/// assert!(rep.fit.alpha.is_finite() && rep.fit.beta.is_finite() && rep.fit.r0 > 0.0);
/// ```
pub fn fit_attenuation_mesh(
    mesh: TetMesh,
    params: &AttenuationFitParams,
    file: &str,
    progress: &mut dyn FnMut(FitProgress),
) -> Result<AttenuationFitReport, FitError> {
    check_pairs(params.pairs)?;
    if params.modes == Some(0) {
        return Err(FitError::Params(
            "the number of modes must be at least 1".into(),
        ));
    }
    let tp = &params.system;
    let t = Instant::now();
    let free_dofs;
    let (resp, method) = {
        let sys = FullOrderSystem::new(mesh.clone(), tp, file)?;
        free_dofs = sys.n();
        let dense = match params.truth {
            FitTruth::Auto => free_dofs <= params.max_dense_dofs,
            FitTruth::ModalAll => true,
            FitTruth::Modes => false,
        };
        progress(FitProgress::Solve {
            method: if dense { "modal-all" } else { "modes" },
        });
        if dense {
            let ma = ModalAll::new(&sys, params.max_dense_dofs)?;
            (
                SurfaceResponse::from_modal_all(&sys, &ma, params.modes),
                "modal-all",
            )
        } else {
            drop(sys);
            let bp = tp.bake_params(ModeRequest::Count(
                params.modes.unwrap_or(DEFAULT_SPARSE_MODES),
            ));
            let (base, _) = bake_mesh(mesh, &bp, file, &mut |_| {})?;
            (SurfaceResponse::from_base(&base), "modes")
        }
    };
    let eigensolve_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (samples, kind, dt, steps) = sample_attenuation(
        &resp,
        params.system.rayleigh,
        params.h,
        params.dt,
        params.pairs,
        params.seed,
        progress,
    )?;
    let response_s = t.elapsed().as_secs_f64();
    let r: Vec<f64> = samples.iter().map(|s| s.distance_m).collect();
    let s: Vec<f64> = samples.iter().map(|s| s.ratio).collect();
    let fit = match params.r0 {
        Some(r0) => fit_eq14_fixed_r0(&r, &s, r0)?,
        None => fit_eq14(&r, &s)?,
    };
    let simplified = fit_simplified(&r, &s)?;
    let info = AttenuationFitInfo {
        method: method.into(),
        free_dofs,
        modes: resp.num_modes(),
        max_freq_hz: resp.eigenvalues.last().copied().unwrap_or(0.0).sqrt() / std::f64::consts::TAU,
        dt,
        samples: steps,
        h: params.h,
        distance_kind: kind,
        pairs_requested: params.pairs,
        pairs_used: fit.n,
        seed: params.seed,
        eigensolve_s,
        response_s,
    };
    Ok(AttenuationFitReport {
        fit,
        simplified,
        info,
        samples,
    })
}
