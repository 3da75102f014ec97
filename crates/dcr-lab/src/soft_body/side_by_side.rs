//! One scene, side by side: rapier FEM soft bodies at increasing substeps against the distant
//! response (20 modes, the ★ transfer table) on rigid objects and against no response — cost
//! per step, peak memory and the scene's outcome figures.
//!
//! The outcomes (largest lift, tilt) are chaotic — props rattling on a ringing object — so each
//! row can run an ensemble ([`EnsembleParams`]): member 0 is the scene as written, member m > 0
//! starts the projectiles a fixed small distance away across gravity
//! (`dcr_scenes::scene::BuiltWorld::perturb_placement`), and a row reports each outcome's mean
//! and sample standard deviation over the members (`crate::scene_truth::ensemble_stats`). The
//! substep sweep then stops when a doubling moves every mean by less than the tolerance or by
//! less than two standard errors of the difference of the means
//! (`crate::scene_truth::level_change`): converged within the ensemble's noise.
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use dcr_scenes::runner::{run_scene, MethodChoice, RunParams};
use dcr_scenes::scene::{MethodDesc, SceneDesc, TransferDesc};
use serde::{Deserialize, Serialize};

use super::peak_rss::peak_rss_bytes;
use super::soft_scene::{run_soft_scene, SoftSceneParams};
use crate::scene_truth::{ensemble_stats, level_change, TruthLevel};

/// What a row of the comparison runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SideMethod {
    /// The elastic objects as rapier FEM soft bodies (see [`run_soft_scene`]).
    RapierFem {
        /// Substeps per step.
        substeps: usize,
        /// CG iteration cap per substep.
        cg_iterations: usize,
        /// Bodies up to this many degrees of freedom answer their contacts through a direct
        /// factorization (rapier's `max_dense_dofs`), larger ones through the capped CG.
        max_dense_dofs: usize,
        /// Relative residual at which each conjugate gradient stops (rapier's
        /// `linear_tolerance`).
        cg_tolerance: f64,
    },
    /// Rigid objects, the distant response over the 20-mode base (`--method modal`).
    Modal,
    /// Rigid objects, the distant response from the bake-time transfer table (`--method
    /// transfer`; objects without table settings get the accuracy study's region, the faces
    /// within 60° of the mesh's +y).
    Transfer,
    /// Rigid objects, no response.
    Off,
}

impl SideMethod {
    /// A short label for tables (`rapier-fem, 8 substeps`, `dcr, 20 modes (rigid object)`, ...).
    pub fn label(&self) -> String {
        match self {
            SideMethod::RapierFem {
                substeps,
                cg_iterations,
                max_dense_dofs,
                cg_tolerance,
            } => {
                let d = SoftSceneParams::new(PathBuf::new());
                let mut s = format!("rapier-fem, {substeps} substeps");
                if *cg_iterations != d.cg_iterations {
                    s.push_str(&format!(", CG ≤ {cg_iterations}"));
                }
                if *max_dense_dofs != d.max_dense_dofs {
                    s.push_str(&format!(", direct ≤ {max_dense_dofs} dofs"));
                }
                if *cg_tolerance != d.cg_tolerance {
                    s.push_str(&format!(", CG to {cg_tolerance:.0e}"));
                }
                s
            }
            SideMethod::Modal => "dcr, 20 modes (rigid object)".into(),
            SideMethod::Transfer => "dcr, ★ table (rigid object)".into(),
            SideMethod::Off => "no response (rigid object)".into(),
        }
    }
}

/// One row: a method's cost and outcomes on a scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SideRow {
    /// Scene name.
    pub scene: String,
    /// What ran.
    pub method: SideMethod,
    /// Steps (at the scene's h).
    pub steps: usize,
    /// Median and 99th percentile wall time of a whole step (ms): rapier's step, plus the
    /// adapter's calls for the dcr rows.
    pub step_ms_median: f64,
    /// 99th percentile (ms).
    pub step_ms_p99: f64,
    /// The response's own share of a step for the dcr rows: median and 99th percentile of the
    /// adapter's calls (ms); `None` for the others.
    pub response_ms: Option<[f64; 2]>,
    /// Peak resident set size of the process that ran the row (MiB), if the OS says.
    pub peak_rss_mib: Option<f64>,
    /// Wall time of the whole run (s).
    pub wall_s: f64,
    /// Outcome figures, the mean over the members: name → (value, unit).
    pub outcomes: BTreeMap<String, (f64, String)>,
    /// Sample standard deviation of each outcome over the members (the outcome's unit; 0 for
    /// one member).
    #[serde(default)]
    pub spread: BTreeMap<String, f64>,
    /// Members run (see [`EnsembleParams`]); the step times are pooled over all of them.
    #[serde(default = "one")]
    pub members: usize,
    /// Distance the projectiles of members m > 0 start from the scene's placement (m).
    #[serde(default)]
    pub perturbation: f64,
    /// Each member's outcomes, member 0 (the scene as written) first: name → value.
    #[serde(default)]
    pub member_outcomes: Vec<BTreeMap<String, f64>>,
    /// Soft rows: the largest displacement of the soft surface under a watched body over the
    /// members (mm).
    pub surface_peak_mm: Option<f64>,
}

fn one() -> usize {
    1
}

/// The ensemble every row of a comparison runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnsembleParams {
    /// Members (at least 1). Default 1: the scene as written only.
    pub members: usize,
    /// Distance (m) across gravity by which members m > 0 start their projectiles away from the
    /// scene's placement, each member in its own direction. Default 1e-4 (0.1 mm).
    pub perturbation: f64,
}

impl Default for EnsembleParams {
    fn default() -> Self {
        EnsembleParams {
            members: 1,
            perturbation: 1e-4,
        }
    }
}

fn percentile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let i = ((p / 100.0) * (s.len() - 1) as f64).round() as usize;
    s[i.min(s.len() - 1)]
}

/// `desc` with every elastic object that has no transfer-table settings given the accuracy
/// study's region (faces within 60° of the mesh's +y, defaults otherwise), so `--method
/// transfer` runs on it.
pub fn with_transfer_region(desc: &SceneDesc) -> SceneDesc {
    let mut d = desc.clone();
    for e in &mut d.elastic {
        if e.transfer.is_none() && !matches!(e.method, MethodDesc::Transfer(_)) {
            e.transfer = Some(TransferDesc {
                up: Some([0.0, 1.0, 0.0]),
                ..TransferDesc::default()
            });
        }
    }
    d
}

/// `desc` with its projectiles (props with a non-zero initial velocity) started `steps` steps
/// into their free flight in a world of `substeps` substeps per step: with `m = steps ·
/// substeps` substeps of `δ = h / substeps`, translation `x + m δ v + ½ g δ² m (m + 1)` and
/// velocity `v + m δ g`, which is where and how fast rapier's symplectic Euler (velocity first,
/// then position, once per substep) carries them. The impact then happens `steps` steps earlier,
/// at the same place, with the same velocity, as in the whole scene run with the same substeps;
/// what rests on the scene has `steps · h` seconds less to settle before it. Used to shorten the
/// costly soft rows (and every other row of the same comparison). `steps` must end before the
/// first contact of the original flight (the caller's choice: the flight is not checked against
/// the scene).
///
/// # Errors
/// A projectile that spins (`angvel`), is damped or is placed relative to an elastic object (the
/// shift is written for plain translation in the world frame); `substeps` 0.
pub fn with_projectiles_advanced(
    desc: &SceneDesc,
    steps: usize,
    substeps: usize,
) -> Result<SceneDesc> {
    if substeps == 0 {
        anyhow::bail!("substeps must be at least 1");
    }
    let mut d = desc.clone();
    if steps == 0 {
        return Ok(d);
    }
    let m = (steps * substeps) as f64;
    let (dt, g) = (desc.h / substeps as f64, desc.gravity);
    for p in &mut d.props {
        if p.fixed || p.linvel == [0.0; 3] {
            continue;
        }
        if p.angvel != [0.0; 3] || p.linear_damping != 0.0 || p.relative_to.is_some() {
            anyhow::bail!(
                "scene {}: prop {} is a projectile that spins, is damped or is placed relative \
                 to an elastic object; advancing its flight is only written for plain \
                 translation (run this scene without --advance-steps)",
                desc.name,
                p.name
            );
        }
        let t = &mut p.pose.translation;
        for a in 0..3 {
            t[a] += m * dt * p.linvel[a] + 0.5 * g[a] * dt * dt * m * (m + 1.0);
            p.linvel[a] += m * dt * g[a];
        }
    }
    Ok(d)
}

/// Runs one row in this process, every member of `ensemble` one after the other (the peak
/// memory is this process's): outcomes as mean and sample standard deviation over the members,
/// the step times pooled over all members' steps.
///
/// # Errors
/// What [`run_soft_scene`] or `dcr_scenes::runner::run_scene` report; no member.
pub fn run_side(
    desc: &SceneDesc,
    method: &SideMethod,
    root: PathBuf,
    seconds: Option<f64>,
    ensemble: &EnsembleParams,
    progress: bool,
) -> Result<SideRow> {
    if ensemble.members == 0 {
        anyhow::bail!("members must be at least 1");
    }
    let wall = Instant::now();
    let mut whole: Vec<f64> = Vec::new();
    let mut adapter: Vec<f64> = Vec::new();
    let mut runs: Vec<BTreeMap<String, (f64, String)>> = Vec::new();
    let mut surface_peak_mm: Option<f64> = None;
    let mut steps = 0;
    let dcr = matches!(method, SideMethod::Modal | SideMethod::Transfer);
    for member in 0..ensemble.members {
        let perturbation = (member, ensemble.perturbation);
        match method {
            SideMethod::RapierFem {
                substeps,
                cg_iterations,
                max_dense_dofs,
                cg_tolerance,
            } => {
                let mut p = SoftSceneParams::new(root.clone());
                p.cg_tolerance = *cg_tolerance;
                p.substeps = *substeps;
                p.cg_iterations = *cg_iterations;
                p.max_dense_dofs = *max_dense_dofs;
                p.seconds = seconds;
                p.perturbation = perturbation;
                p.progress = progress;
                let r = run_soft_scene(desc, &p)?;
                steps = r.steps;
                whole.extend(&r.step_ms);
                if let Some(peak) = r.surface_peak_mm.values().copied().reduce(f64::max) {
                    surface_peak_mm = Some(surface_peak_mm.map_or(peak, |s| s.max(peak)));
                }
                runs.push(r.outcomes);
            }
            SideMethod::Modal | SideMethod::Transfer | SideMethod::Off => {
                let mut p = RunParams::new(root.clone(), dcr);
                p.seconds = seconds;
                p.progress = progress;
                p.perturbation = perturbation;
                let desc = if *method == SideMethod::Transfer {
                    p.method = MethodChoice::Transfer;
                    with_transfer_region(desc)
                } else {
                    p.method = MethodChoice::Modal;
                    desc.clone()
                };
                let r = run_scene(&desc, &p)?;
                steps = r.steps;
                whole.extend(
                    r.step_times
                        .iter()
                        .map(|t| (t.rapier_us + if dcr { t.adapter_us } else { 0.0 }) / 1e3),
                );
                adapter.extend(r.step_times.iter().map(|t| t.adapter_us / 1e3));
                runs.push(r.outcomes.into_iter().collect());
            }
        }
    }
    let (outcomes, spread) = ensemble_stats(&runs.iter().collect::<Vec<_>>());
    Ok(SideRow {
        scene: desc.name.clone(),
        method: method.clone(),
        steps,
        step_ms_median: percentile(&whole, 50.0),
        step_ms_p99: percentile(&whole, 99.0),
        response_ms: dcr.then(|| [percentile(&adapter, 50.0), percentile(&adapter, 99.0)]),
        peak_rss_mib: peak_rss_bytes().map(|b| b as f64 / (1024.0 * 1024.0)),
        wall_s: wall.elapsed().as_secs_f64(),
        outcomes,
        spread,
        members: ensemble.members,
        perturbation: ensemble.perturbation,
        member_outcomes: runs
            .iter()
            .map(|r| r.iter().map(|(k, v)| (k.clone(), v.0)).collect())
            .collect(),
        surface_peak_mm,
    })
}

/// The largest relative change of the outcome figures between two rows:
/// `|a − b| / max(|a|, |b|)` over the outcomes, a pair both below `floor` counting as no change
/// (figures that small — 1 µm of lift, 0.001° of tilt — are at rapier's contact noise).
pub fn outcome_change(a: &SideRow, b: &SideRow, floor: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for (name, (va, _)) in &a.outcomes {
        let Some((vb, _)) = b.outcomes.get(name) else {
            return f64::INFINITY;
        };
        let scale = va.abs().max(vb.abs());
        if scale < floor {
            continue;
        }
        worst = worst.max((va - vb).abs() / scale);
    }
    worst
}

/// How the substep sweep of the soft rows ends.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SweepEnd {
    /// Substeps of the last row run.
    pub last_substeps: usize,
    /// Whether the last doubling moved every outcome (its mean, for ensembles) by less than
    /// the tolerance or, for ensembles, by less than two standard errors of the difference.
    pub converged: bool,
    /// Whether the sweep converged only by the second test: some mean moved by the tolerance or
    /// more, but by less than the ensembles' noise.
    #[serde(default)]
    pub within_noise: bool,
    /// The largest outcome change of the last doubling (fraction).
    pub last_change: f64,
    /// Why the sweep stopped (`converged`, `converged within noise`, `time budget`, `substep
    /// cap`).
    pub reason: String,
}

/// A row's outcomes as a level of the coupled reference's refinement, for
/// [`crate::scene_truth::level_change`] (only outcomes, spread and members are read).
fn as_level(r: &SideRow) -> TruthLevel {
    TruthLevel {
        dt: 0.0,
        modes: 0,
        contact_stiffness: 0.0,
        outcomes: r.outcomes.clone(),
        spread: r.spread.clone(),
        members: r.members,
        change: None,
        within_noise: None,
        max_penetration: 0.0,
        wall_s: r.wall_s,
    }
}

/// Whether row `b` agrees with row `a` within the ensembles' noise: every outcome's mean moved
/// by at most max(`tolerance` · max(|b|, 1 unit), two standard errors of the difference of the
/// means) — `crate::scene_truth::level_change`, the coupled reference's test. Rows of one
/// member have no noise estimate: `false` unless both have at least two members.
pub fn within_noise(a: &SideRow, b: &SideRow, tolerance: f64) -> bool {
    a.members > 1 && b.members > 1 && level_change(&as_level(a), &as_level(b), tolerance).1
}

/// Settings of the substep sweep.
#[derive(Clone, Debug)]
pub struct SweepParams {
    /// First substep count (doubled each row). Default 1.
    pub first: usize,
    /// Largest substep count. Default 256.
    pub max_substeps: usize,
    /// The sweep stops once a doubling changes every outcome by less than this (fraction).
    /// Default 0.02.
    pub tolerance: f64,
    /// Outcomes below this in both rows count as unchanged (mm or deg). Default 0.001.
    pub floor: f64,
    /// Wall-time budget of the sweep (s): no row starts whose estimated time (twice the last
    /// row's) would end past it. Default 1200.
    pub budget_s: f64,
    /// CG iteration cap of the sweep's rows. Default rapier's (20).
    pub cg_iterations: usize,
    /// Direct-factorization limit of the sweep's rows (dofs). Default rapier's (600).
    pub max_dense_dofs: usize,
    /// Relative residual of the sweep's conjugate gradients. Default rapier's (1e-5).
    pub cg_tolerance: f64,
}

impl Default for SweepParams {
    fn default() -> Self {
        SweepParams {
            first: 1,
            max_substeps: 256,
            tolerance: 0.02,
            floor: 1e-3,
            budget_s: 1200.0,
            cg_iterations: SoftSceneParams::new(PathBuf::new()).cg_iterations,
            max_dense_dofs: SoftSceneParams::new(PathBuf::new()).max_dense_dofs,
            cg_tolerance: SoftSceneParams::new(PathBuf::new()).cg_tolerance,
        }
    }
}

/// Runs rapier-FEM rows at `first`, 2·`first`, 4·`first`, … substeps with `run` until a
/// doubling changes every outcome by less than the tolerance ([`outcome_change`]) or, for
/// ensembles, moves every mean within the noise ([`within_noise`]), the budget would be
/// exceeded or the cap is reached. Returns the rows in order and how the sweep ended.
///
/// # Errors
/// The first error `run` returns.
pub fn sweep_substeps(
    params: &SweepParams,
    mut run: impl FnMut(&SideMethod) -> Result<SideRow>,
) -> Result<(Vec<SideRow>, SweepEnd)> {
    let start = Instant::now();
    let mut rows: Vec<SideRow> = Vec::new();
    let mut n = params.first.max(1);
    let mut end = SweepEnd {
        last_substeps: n,
        converged: false,
        within_noise: false,
        last_change: f64::INFINITY,
        reason: "substep cap".into(),
    };
    loop {
        let row = run(&SideMethod::RapierFem {
            substeps: n,
            cg_iterations: params.cg_iterations,
            max_dense_dofs: params.max_dense_dofs,
            cg_tolerance: params.cg_tolerance,
        })?;
        let mut noise = false;
        if let Some(prev) = rows.last() {
            end.last_change = outcome_change(prev, &row, params.floor);
            noise = within_noise(prev, &row, params.tolerance);
        }
        end.last_substeps = n;
        let wall = row.wall_s;
        rows.push(row);
        if end.last_change < params.tolerance {
            end.converged = true;
            end.reason = "converged".into();
            break;
        }
        if noise {
            end.converged = true;
            end.within_noise = true;
            end.reason = "converged within noise".into();
            break;
        }
        if n * 2 > params.max_substeps {
            end.reason = "substep cap".into();
            break;
        }
        if start.elapsed().as_secs_f64() + 2.0 * wall > params.budget_s {
            end.reason = "time budget".into();
            break;
        }
        n *= 2;
    }
    Ok((rows, end))
}
