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
//! (Crane et al. 2013, `dcr_runtime::HeatGeodesic`) from a to b (Euclidean if the surface's heat
//! operators cannot be built).
//!
//! # Truth
//! u is the sum over elastic modes of the exact damped impulse responses (Rayleigh damping,
//! every damping regime, `dcr_runtime::ModeFilter`), sampled by the exact two-term recursion
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

use std::time::Instant;

use dcr_runtime::{damping_ratio, HeatGeodesic, ModeFilter};
use rayon::prelude::*;

use dcr_runtime::testing::SplitMix64;
use modal_bake::bake::{bake_mesh, BakeError, BakeParams, MaterialSi, ModeRequest, ModesFile};
use modal_bake::full_order::{FullOrderError, FullOrderSystem, ModalAll, SystemParams};
use modal_bake::mesh::TetMesh;

/// Fewest usable pairs accepted by the fits.
pub const MIN_FIT_SAMPLES: usize = 4;

/// Eq. 14 parameters fitted to samples (r in m).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct AttenuationFit {
    /// Material absorption α (1/m), ≥ 0.
    pub alpha: f64,
    /// Geometric spreading exponent β, ≥ 0.
    pub beta: f64,
    /// Minimum distance r0 (m), > 0.
    pub r0: f64,
    /// R² of ln s (1: perfect).
    pub r2_log: f64,
    /// RMS error of ln s (a factor e^rms on s).
    pub rms_log: f64,
    /// Samples used.
    pub n: usize,
    /// Which constraint face the optimum lies on: `free`, `alpha=0`, `beta=0`, `alpha=beta=0`.
    pub active: &'static str,
}

impl AttenuationFit {
    /// s(r) of the fitted law (not clamped at r0).
    pub fn factor(&self, r: f64) -> f64 {
        (-self.alpha * (r - self.r0)).exp() * (r / self.r0).powf(-self.beta)
    }
}

/// §4.5 simplified law s = C r^−β (r in m) fitted to samples.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SimplifiedFit {
    /// C.
    pub c: f64,
    /// β, ≥ 0.
    pub beta: f64,
    /// R² of ln s.
    pub r2_log: f64,
    /// RMS error of ln s.
    pub rms_log: f64,
    /// Samples used.
    pub n: usize,
}

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

/// Least squares of y on the columns of `a` (n × k, k ≤ 3) by modified Gram–Schmidt QR.
/// Returns (coefficients, residual sum of squares) or `None` if the columns are dependent.
fn least_squares(cols: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, f64)> {
    let k = cols.len();
    let mut q: Vec<Vec<f64>> = cols.to_vec();
    let mut rmat = vec![vec![0.0; k]; k];
    for j in 0..k {
        let norm0 = q[j].iter().map(|x| x * x).sum::<f64>().sqrt();
        for i in 0..j {
            let d: f64 = q[i].iter().zip(&q[j]).map(|(a, b)| a * b).sum();
            rmat[i][j] = d;
            let qi = q[i].clone();
            q[j].iter_mut().zip(&qi).for_each(|(x, a)| *x -= d * a);
        }
        let nrm = q[j].iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(nrm > 1e-10 * norm0.max(f64::MIN_POSITIVE)) {
            return None;
        }
        rmat[j][j] = nrm;
        q[j].iter_mut().for_each(|x| *x /= nrm);
    }
    let qty: Vec<f64> = q
        .iter()
        .map(|qj| qj.iter().zip(y).map(|(a, b)| a * b).sum())
        .collect();
    let mut x = vec![0.0; k];
    for j in (0..k).rev() {
        let s: f64 = (j + 1..k).map(|i| rmat[j][i] * x[i]).sum();
        x[j] = (qty[j] - s) / rmat[j][j];
    }
    let rss = y
        .iter()
        .enumerate()
        .map(|(i, yi)| {
            let p: f64 = (0..k).map(|j| cols[j][i] * x[j]).sum();
            (yi - p).powi(2)
        })
        .sum();
    Some((x, rss))
}

/// The usable (r, ln s) pairs.
fn usable(r: &[f64], s: &[f64]) -> Result<(Vec<f64>, Vec<f64>), FitError> {
    let (rr, ls): (Vec<f64>, Vec<f64>) = r
        .iter()
        .zip(s)
        .filter(|(r, s)| r.is_finite() && **r > 0.0 && s.is_finite() && **s > 0.0)
        .map(|(r, s)| (*r, s.ln()))
        .unzip();
    if rr.len() < MIN_FIT_SAMPLES {
        return Err(FitError::TooFewSamples {
            have: rr.len(),
            need: MIN_FIT_SAMPLES,
        });
    }
    Ok((rr, ls))
}

fn quality(ls: &[f64], rss: f64) -> (f64, f64) {
    let n = ls.len() as f64;
    let mean = ls.iter().sum::<f64>() / n;
    let tot: f64 = ls.iter().map(|y| (y - mean).powi(2)).sum();
    let r2 = if tot > 0.0 { 1.0 - rss / tot } else { 1.0 };
    (r2, (rss / n).sqrt())
}

/// r0 > 0 with α r0 + β ln r0 = c (α, β ≥ 0), or `None`.
fn solve_r0(alpha: f64, beta: f64, c: f64) -> Option<f64> {
    if beta > 0.0 {
        // g(x) = α e^x + β x − c, increasing in x = ln r0.
        let g = |x: f64| alpha * x.min(700.0).exp() + beta * x - c;
        let (mut lo, mut hi) = (-1.0f64, 1.0f64);
        while g(lo) > 0.0 {
            lo *= 2.0;
            if lo < -1e6 {
                return None;
            }
        }
        while g(hi) < 0.0 {
            hi *= 2.0;
            if hi > 1e6 {
                return None;
            }
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if g(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let r0 = (0.5 * (lo + hi)).exp();
        (r0.is_finite() && r0 > 0.0).then_some(r0)
    } else if alpha > 0.0 && c > 0.0 {
        Some(c / alpha)
    } else {
        None
    }
}

/// Least-squares fit of Eq. 14, s = exp(−α(r − r0)) (r/r0)^−β, to samples (r in m, s > 0);
/// r0 is fitted too (see the module docs). Samples with r ≤ 0, s ≤ 0 or non-finite values are
/// ignored.
///
/// # Errors
/// [`FitError::TooFewSamples`] below [`MIN_FIT_SAMPLES`] usable samples;
/// [`FitError::Degenerate`] if no α ≥ 0, β ≥ 0, r0 > 0 fits (e.g. a single distance).
///
/// ```
/// use dcr_lab::attenuation_fit::fit_eq14;
/// let r: Vec<f64> = (1..40).map(|i| 0.05 * i as f64).collect();
/// let s: Vec<f64> = r.iter().map(|r| (-0.5 * (r - 0.03)).exp() * (r / 0.03).powf(-0.8)).collect();
/// let f = fit_eq14(&r, &s).unwrap();
/// assert!((f.alpha - 0.5).abs() < 1e-8 && (f.beta - 0.8).abs() < 1e-8);
/// assert!((f.r0 - 0.03).abs() < 1e-9);
/// ```
pub fn fit_eq14(r: &[f64], s: &[f64]) -> Result<AttenuationFit, FitError> {
    let (rr, ls) = usable(r, s)?;
    let one = vec![1.0; rr.len()];
    let mr: Vec<f64> = rr.iter().map(|r| -r).collect();
    let ml: Vec<f64> = rr.iter().map(|r| -r.ln()).collect();
    let mut best: Option<(f64, AttenuationFit)> = None;
    let faces: [(&'static str, bool, bool); 3] = [
        ("free", true, true),
        ("alpha=0", false, true),
        ("beta=0", true, false),
    ];
    for (name, use_a, use_b) in faces {
        let mut cols = vec![one.clone()];
        if use_a {
            cols.push(mr.clone());
        }
        if use_b {
            cols.push(ml.clone());
        }
        let Some((x, rss)) = least_squares(&cols, &ls) else {
            continue;
        };
        let c = x[0];
        let alpha = if use_a { x[1] } else { 0.0 };
        let beta = if use_b { x[cols.len() - 1] } else { 0.0 };
        if alpha < 0.0 || beta < 0.0 {
            continue;
        }
        let Some(r0) = solve_r0(alpha, beta, c) else {
            continue;
        };
        if best.as_ref().is_none_or(|(b, _)| rss < *b) {
            let (r2_log, rms_log) = quality(&ls, rss);
            best = Some((
                rss,
                AttenuationFit {
                    alpha,
                    beta,
                    r0,
                    r2_log,
                    rms_log,
                    n: rr.len(),
                    active: name,
                },
            ));
        }
    }
    best.map(|(_, f)| f)
        .ok_or_else(|| FitError::Degenerate("no α ≥ 0, β ≥ 0, r0 > 0 fits the samples".into()))
}

/// As [`fit_eq14`] with r0 (m) given: ln s = −α(r − r0) − β ln(r/r0), linear in (α, β).
///
/// # Errors
/// As [`fit_eq14`]; [`FitError::Params`] if r0 is not finite and > 0.
pub fn fit_eq14_fixed_r0(r: &[f64], s: &[f64], r0: f64) -> Result<AttenuationFit, FitError> {
    if !(r0.is_finite() && r0 > 0.0) {
        return Err(FitError::Params(format!(
            "r0 must be finite and > 0 m, got {r0}"
        )));
    }
    let (rr, ls) = usable(r, s)?;
    let ma: Vec<f64> = rr.iter().map(|r| -(r - r0)).collect();
    let mb: Vec<f64> = rr.iter().map(|r| -(r / r0).ln()).collect();
    let mut best: Option<(f64, AttenuationFit)> = None;
    let faces: [(&'static str, bool, bool); 4] = [
        ("free", true, true),
        ("alpha=0", false, true),
        ("beta=0", true, false),
        ("alpha=beta=0", false, false),
    ];
    for (name, use_a, use_b) in faces {
        let mut cols = Vec::new();
        if use_a {
            cols.push(ma.clone());
        }
        if use_b {
            cols.push(mb.clone());
        }
        let (x, rss) = if cols.is_empty() {
            (vec![], ls.iter().map(|y| y * y).sum())
        } else {
            match least_squares(&cols, &ls) {
                Some(v) => v,
                None => continue,
            }
        };
        let alpha = if use_a { x[0] } else { 0.0 };
        let beta = if use_b { x[x.len() - 1] } else { 0.0 };
        if alpha < 0.0 || beta < 0.0 {
            continue;
        }
        if best.as_ref().is_none_or(|(b, _)| rss < *b) {
            let (r2_log, rms_log) = quality(&ls, rss);
            best = Some((
                rss,
                AttenuationFit {
                    alpha,
                    beta,
                    r0,
                    r2_log,
                    rms_log,
                    n: rr.len(),
                    active: name,
                },
            ));
        }
    }
    best.map(|(_, f)| f)
        .ok_or_else(|| FitError::Degenerate("no α ≥ 0, β ≥ 0 fits the samples".into()))
}

/// Least-squares fit of the §4.5 law s = C r^−β (r in m): ln s = ln C − β ln r, β ≥ 0.
///
/// # Errors
/// [`FitError::TooFewSamples`]; [`FitError::Degenerate`] if every r is the same.
pub fn fit_simplified(r: &[f64], s: &[f64]) -> Result<SimplifiedFit, FitError> {
    let (rr, ls) = usable(r, s)?;
    let one = vec![1.0; rr.len()];
    let ml: Vec<f64> = rr.iter().map(|r| -r.ln()).collect();
    let (c, beta, rss) = match least_squares(&[one.clone(), ml], &ls) {
        Some((x, rss)) if x[1] >= 0.0 => (x[0], x[1], rss),
        Some(_) => {
            let (x, rss) = least_squares(&[one], &ls).expect("a column of ones");
            (x[0], 0.0, rss)
        }
        None => return Err(FitError::Degenerate("every distance is the same".into())),
    };
    let (r2_log, rms_log) = quality(&ls, rss);
    Ok(SimplifiedFit {
        c: c.exp(),
        beta,
        r2_log,
        rms_log,
        n: rr.len(),
    })
}

/// The normal-displacement rows of every surface vertex in modal coordinates, with the modes'
/// eigenvalues: enough to evaluate the response at any surface vertex to an impulse at any
/// other.
#[derive(Clone, Debug)]
pub struct SurfaceResponse {
    /// λ_j = ω_j² (rad²/s²) of the modes used, ascending.
    pub eigenvalues: Vec<f64>,
    /// Row-major (ns × m): `rows[v * m + j] = n_vᵀ U_v,j` (m·kg^-1/2), n_v the area-weighted
    /// outward vertex normal.
    pub rows: Vec<f64>,
    /// Surface vertex positions (m).
    pub vertices: Vec<[f64; 3]>,
    /// Outward surface triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Vertices that can be struck and measured (not fixed; non-zero row).
    pub eligible: Vec<bool>,
}

/// Area-weighted outward unit vertex normals (as `SurfaceMap` and `ModalModel`).
fn vertex_normals(v: &[[f64; 3]], t: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let mut n = vec![[0.0; 3]; v.len()];
    for tri in t {
        let [a, b, c] = tri.map(|i| i as usize);
        let (e1, e2) = (sub(v[b], v[a]), sub(v[c], v[a]));
        let x = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        for k in [a, b, c] {
            for ax in 0..3 {
                n[k][ax] += x[ax];
            }
        }
    }
    for x in &mut n {
        let l = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        if l > 0.0 {
            x.iter_mut().for_each(|c| *c /= l);
        }
    }
    n
}

impl SurfaceResponse {
    fn finish(
        eigenvalues: Vec<f64>,
        rows: Vec<f64>,
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        fixed: &[bool],
    ) -> SurfaceResponse {
        let m = eigenvalues.len();
        let eligible = (0..vertices.len())
            .map(|v| !fixed[v] && rows[v * m..(v + 1) * m].iter().any(|x| *x != 0.0))
            .collect();
        SurfaceResponse {
            eigenvalues,
            rows,
            vertices,
            triangles,
            eligible,
        }
    }

    /// From a dense all-mode solve of `sys`, keeping the lowest `modes` (`None`: all).
    pub fn from_modal_all(sys: &FullOrderSystem, ma: &ModalAll, modes: Option<usize>) -> Self {
        let m = modes.unwrap_or(usize::MAX).min(ma.eigenvalues.len());
        let s = &sys.surface;
        let ns = s.vertices.len();
        let mut rows = vec![0.0; ns * m];
        let mut fixed = vec![false; ns];
        rows.par_chunks_mut(m.max(1))
            .enumerate()
            .for_each(|(v, row)| {
                let vol = s.surface_to_volume[v];
                for ax in 0..3 {
                    if let Some(i) = sys.map.free_index(3 * vol + ax) {
                        let n = s.normals[v][ax];
                        for (j, x) in row.iter_mut().enumerate() {
                            *x += n * ma.vectors[(i, j)];
                        }
                    }
                }
            });
        for (v, f) in fixed.iter_mut().enumerate() {
            *f = sys.map.free_index(3 * s.surface_to_volume[v]).is_none();
        }
        Self::finish(
            ma.eigenvalues[..m].to_vec(),
            rows,
            s.vertices.clone(),
            s.triangles.clone(),
            &fixed,
        )
    }

    /// From a baked base (its surface rows of U).
    pub fn from_base(base: &ModesFile) -> Self {
        let m = base.eigenvalues.len();
        let ns = base.surface_vertices.len();
        let normals = vertex_normals(&base.surface_vertices, &base.surface_triangles);
        let mut rows = vec![0.0; ns * m];
        for v in 0..ns {
            for ax in 0..3 {
                let n = normals[v][ax];
                let src = &base.modes[(v * 3 + ax) * m..(v * 3 + ax + 1) * m];
                for (x, u) in rows[v * m..(v + 1) * m].iter_mut().zip(src) {
                    *x += n * u;
                }
            }
        }
        let mut is_fixed = vec![false; ns];
        let fixed: std::collections::HashSet<u32> = base.fixed_nodes.iter().copied().collect();
        for (v, f) in is_fixed.iter_mut().enumerate() {
            *f = fixed.contains(&base.surface_to_volume[v]);
        }
        Self::finish(
            base.eigenvalues.clone(),
            rows,
            base.surface_vertices.clone(),
            base.surface_triangles.clone(),
            &is_fixed,
        )
    }

    /// Number of modes.
    pub fn num_modes(&self) -> usize {
        self.eigenvalues.len()
    }

    /// The default sample period: a quarter of the paper's T = π/(2ω_max) (16 samples per
    /// period of the highest mode used), in s.
    pub fn default_dt(&self) -> f64 {
        let wmax = self.eigenvalues.last().copied().unwrap_or(1.0).sqrt();
        std::f64::consts::FRAC_PI_2 / wmax / 4.0
    }

    /// Per-mode sampled impulse-response recursions (g(Δt), a1, a2).
    fn filters(&self, rayleigh: [f64; 2], dt: f64) -> Vec<(f64, f64, f64)> {
        self.eigenvalues
            .iter()
            .map(|&lam| {
                if !(lam > 0.0) {
                    return (0.0, 0.0, 0.0);
                }
                let w = lam.sqrt();
                let f = ModeFilter::new(w, damping_ratio(w, rayleigh), dt);
                (f.g, f.a1, f.a2)
            })
            .collect()
    }

    /// (local peak at `a`, peak at each of `contacts`) (m) of the normal displacement over
    /// k = 1 … `steps` samples of `dt` (s) after a unit impulse (1 N·s) at surface vertex `a`
    /// along −n_a.
    fn pair_peaks(
        &self,
        filters: &[(f64, f64, f64)],
        a: usize,
        contacts: &[usize],
        steps: usize,
    ) -> (f64, Vec<f64>) {
        let m = self.num_modes();
        let ra = &self.rows[a * m..(a + 1) * m];
        let nc = contacts.len() + 1;
        let mut y = vec![0.0; nc * steps];
        let mut coef = vec![0.0; nc];
        for (j, &(g1, a1, a2)) in filters.iter().enumerate() {
            // Load r_j = −ra_j (1 N·s along −n_a); measured n_bᵀ u_b = Σ_j rb_j r_j g_j(t).
            let r = -ra[j];
            if r == 0.0 || g1 == 0.0 {
                continue;
            }
            coef[0] = ra[j] * r;
            for (c, &b) in contacts.iter().enumerate() {
                coef[c + 1] = self.rows[b * m + j] * r;
            }
            let (mut gm2, mut gm1) = (0.0, 0.0);
            for k in 0..steps {
                let g = if k == 0 { g1 } else { a1 * gm1 - a2 * gm2 };
                gm2 = gm1;
                gm1 = g;
                for (c, cf) in coef.iter().enumerate() {
                    y[c * steps + k] += cf * g;
                }
            }
        }
        let peak = |c: usize| {
            y[c * steps..(c + 1) * steps]
                .iter()
                .fold(0.0f64, |p, v| p.max(v.abs()))
        };
        (peak(0), (1..nc).map(peak).collect())
    }
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
    /// Isotropic material (E in Pa, ν, ρ in kg/m³). Default as `bake`: 1.1 GPa, 0.3, 770.
    pub material: MaterialSi,
    /// Fixed physical groups (empty: free-free).
    pub fixed: Vec<String>,
    /// Rayleigh damping [α0 (1/s), α1 (s)]. Default (10, 1e-7).
    pub rayleigh: [f64; 2],
    /// Lumped mass.
    pub lumped: bool,
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
        let t = SystemParams::default();
        AttenuationFitParams {
            material: t.material,
            fixed: Vec::new(),
            rayleigh: t.rayleigh,
            lumped: false,
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

/// Measures `pairs` random (impact, contact) vertex pairs of `resp` (seeded), see the module
/// docs; returns the samples, the distance kind and (dt, samples) used.
///
/// # Errors
/// [`FitError::Params`] for fewer than two eligible vertices or a bad h / dt.
pub fn sample_attenuation(
    resp: &SurfaceResponse,
    rayleigh: [f64; 2],
    h: f64,
    dt: Option<f64>,
    pairs: usize,
    seed: u64,
) -> Result<(Vec<AttenuationSample>, String, f64, usize), FitError> {
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
    let steps = dcr_runtime::samples_per_step(h, dt_req);
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
    for &(a, b) in &pairs_v {
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
    let filters = resp.filters(rayleigh, dt);
    let samples = pairs_v
        .par_iter()
        .zip(r.par_iter())
        .map(|(&(a, b), &d)| {
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
        })
        .collect();
    Ok((samples, kind.into(), dt, steps))
}

/// Bakes the truth for `mesh`, measures random pairs and fits Eq. 14 and the §4.5 law.
/// `file` names the mesh in messages.
///
/// # Errors
/// [`FitError`] naming what failed (mesh, material, eigensolve, too few samples, degenerate).
///
/// ```
/// use dcr_lab::attenuation_fit::*;
/// use modal_bake::mesh::TetMesh;
/// let mesh = TetMesh::structured_box([6, 2, 2], [1.0, 0.2, 0.2]);
/// let p = AttenuationFitParams { fixed: vec!["xmin".into()], h: 2e-3, pairs: 20, ..Default::default() };
/// let rep = fit_attenuation_mesh(mesh, &p, "box").unwrap();
/// assert!(rep.fit.alpha.is_finite() && rep.fit.beta.is_finite() && rep.fit.r0 > 0.0);
/// ```
pub fn fit_attenuation_mesh(
    mesh: TetMesh,
    params: &AttenuationFitParams,
    file: &str,
) -> Result<AttenuationFitReport, FitError> {
    if params.pairs < MIN_FIT_SAMPLES {
        return Err(FitError::Params(format!(
            "the number of pairs must be at least {MIN_FIT_SAMPLES}, got {}",
            params.pairs
        )));
    }
    if params.modes == Some(0) {
        return Err(FitError::Params(
            "the number of modes must be at least 1".into(),
        ));
    }
    let tp = SystemParams {
        material: params.material,
        fixed: params.fixed.clone(),
        rayleigh: params.rayleigh,
        lumped: params.lumped,
    };
    let t = Instant::now();
    let free_dofs;
    let (resp, method) = {
        let sys = FullOrderSystem::new(mesh.clone(), &tp, file)?;
        free_dofs = sys.n();
        let dense = match params.truth {
            FitTruth::Auto => free_dofs <= params.max_dense_dofs,
            FitTruth::ModalAll => true,
            FitTruth::Modes => false,
        };
        if dense {
            let ma = ModalAll::new(&sys, params.max_dense_dofs)?;
            (
                SurfaceResponse::from_modal_all(&sys, &ma, params.modes),
                "modal-all",
            )
        } else {
            drop(sys);
            let bp = BakeParams {
                material: params.material,
                modes: ModeRequest::Count(params.modes.unwrap_or(DEFAULT_SPARSE_MODES)),
                fixed: params.fixed.clone(),
                rayleigh: params.rayleigh,
                lumped: params.lumped,
                ..Default::default()
            };
            let (base, _) = bake_mesh(mesh, &bp, file, &mut |_| {})?;
            (SurfaceResponse::from_base(&base), "modes")
        }
    };
    let eigensolve_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (samples, kind, dt, steps) = sample_attenuation(
        &resp,
        params.rayleigh,
        params.h,
        params.dt,
        params.pairs,
        params.seed,
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
