//! The coupled elastic–rigid reference of a whole scene: what a plate *should* do when the pot
//! lands on the table, against which the distant response's outcomes are measured.
//!
//! # Model
//! The scene is built exactly as `dcr-scenes run` builds it (`dcr_scenes::scene::build_world`:
//! the same bodies, colliders, masses, friction, restitution, joints and drivers on
//! rapier3d-f64), but stepped at a small coupling step Δt that divides the scene's h. The one
//! elastic object is a linear elastic body (paper Eq. 5, P1 tets, Rayleigh damping) on top of
//! its rigid motion: the sum over *every* elastic mode of the dense generalized eigensolve
//! ([`modal_bake::full_order::ModalAll`]), each mode advanced exactly over Δt under the force
//! held during the step ([`ElasticBody`]), so the elastic side adds no time-discretisation error.
//!
//! # Coupling: penalty contacts, implicit in the forces
//! Rapier still detects the elastic object's contacts (its narrow phase, the scene's colliders)
//! but does not solve them (the object's colliders get empty solver groups). At each coupling
//! step, for every prop collider rapier pairs with the object, the pair's contact manifolds are
//! computed afresh by parry's dispatcher on the same shapes (rapier's narrow phase would reuse
//! a manifold's points while the pair turns by less than 1° and slides by less than 1 mm, so a
//! curved prop's true deepest point — a plate's rim between the four points of its cap's square
//! — could sink unseen and then appear a millimetre deep and pop the prop out). Every point
//! within the prediction distance (2 cm by default, which must exceed the surface's largest
//! elastic displacement) is mapped to the object's surface in
//! the object's frame (closest point, barycentric weights — the mapping the runtime uses), and
//! gets a spring–dashpot normal force of its *end-of-step* gap g (rigid gap along the contact
//! normal minus the elastic surface displacement there, so the surface moves under the
//! contact):
//! f = max(0, −k g − (c/Δt)(g − min(g₀, 0))),
//! k the stiffness per point, g₀ the gap at the start of the step and c the dashpot that gives
//! the scene's restitution e against a rigid surface (c = 2ζ√(k m/points), ζ such that the
//! clamped spring–dashpot rebounds with ratio e). Over one step with the forces held, the
//! end-of-step gaps are affine in the forces, g = g_free + A f: the elastic part of A is the
//! exact step compliance of the modal propagator,
//! C_ab = Σ_j (φ_j·n_a)(φ_j·n_b)(1 − cos ω_jΔt)/ω_j² (its damped form with Rayleigh damping),
//! and the rigid part is Δt² times the prop's (and a dynamic object's) inverse effective mass
//! between the points (Eq. 17; rapier's symplectic Euler moves the prop by Δt v⁺). Each
//! prop's points are solved together ([`solve_penalty_block`]: a small complementarity
//! problem, symmetric positive definite, unique solution); the props are taken one after the
//! other, each seeing the modal load of the ones before (block Gauss–Seidel: the elastic
//! coupling between two props within one step is that of the modes slow enough to carry it,
//! a small fraction of the local compliance). Coulomb friction (the colliders' mean
//! coefficient) is regularised below a slip speed v_s (viscous η = μ f / max(|v_t|, v_s)) and
//! made implicit in the prop's slip only (f_t = −η v_t / (1 + η Δt W_t)), so it never reverses
//! the slip within a step; it acts on the modes explicitly, bounded by μ f. The
//! prop receives f Δt at its contact point; the elastic modes receive −f at the surface point
//! (Eq. 9 with the force), and, for a dynamic object, its rigid body −f Δt. Every other
//! contact (prop on prop) stays rapier's.
//!
//! Why implicit: with the start-of-step gap (the explicit exchange, [`CouplingScheme::Explicit`])
//! the force of a step is answered within that step by the high modes under the point, whose
//! step compliance is large next to 1/k; when k·C_aa is not small the exchange feeds energy to
//! the props and blows up, and near that edge the outcomes depend on Δt, k and the mode count
//! instead of converging. Solving for the end-of-step gap is stable for any k and Δt, costs
//! one small dense solve per prop and step (the C block is a few dot products over the modes),
//! and as k → ∞ tends to rigid contact with a moving surface (g ≥ 0 at the end of each step),
//! so k is a convergence axis like Δt and the modes.
//!
//! Why not rapier's rigid contact with a moving surface (solver hooks setting the contact's
//! target velocity from the surface velocity): that staggers an *explicit* surface velocity
//! against an implicit rigid contact, and the surface's response to the contact impulse within
//! one step is that of the nodal mass under the point — far below a plate's or a pot's mass —
//! so the exchange diverges (the added-mass instability of partitioned schemes). The penalty
//! force's compliance is part of the model (the largest penetration is reported) and its
//! limit for a very stiff object is rigid contact with restitution e (tested).
//!
//! # Convergence: ensembles, because the outcomes are chaotic
//! A plate rattling on a ringing table is a bouncing ball on a vibrating plate, the textbook
//! chaotic system: its largest lift over a scene depends on every detail of the run (a change
//! of the contact stiffness far below its own effect moves the outcomes by tens of percent,
//! `docs/outcomes-analysis.md`), so no single run converges as the step shrinks. Each level is therefore an **ensemble**: member 0 is the
//! scene as written, the others start the projectile a tenth of a millimetre away across
//! gravity ([`dcr_scenes::scene::BuiltWorld::perturb_placement`]); an outcome is the members'
//! mean, with their sample standard deviation. [`scene_truth`] runs the scene at Δt, Δt/2, …
//! until no outcome's mean changes between two successive steps by more than the tolerance
//! (2 %) or by more than two standard errors of the difference of the means
//! ([`level_change`]), then checks the contact stiffness (the same step with k doubled) and,
//! when fewer than every mode is summed, the modes (half the modes), each by the same rule;
//! else the reference is reported as not converged. The estimated error is the largest of the
//! last step change, the checks and the finest level's statistical uncertainty (two standard
//! errors of the means, [`TruthLevel::uncertainty`]), which only more members shrink (as 1/√N).
//! With every mode of the mesh summed there is no truncation and no mode check. The work is bounded
//! before it starts (dense size, steps × modes × bodies per run); the dense eigensolve can be
//! cached on disk ([`read_eigen`]).

mod contact_solve;
mod coupled_run;
mod eigen_cache;
mod elastic_body;
mod outcomes_page;

pub use contact_solve::{solve_penalty_block, BlockSolveInfo};
pub use coupled_run::{
    run_coupled, CoupledParams, CoupledRun, CouplingScheme, ElasticPrep, START_OVERLAP_FLOOR_M,
    START_OVERLAP_RISE_M,
};
pub use eigen_cache::{eigen_key, eigen_path, read_eigen, write_eigen};
pub use elastic_body::ElasticBody;
pub use outcomes_page::{
    compare_scene, method_ensemble, methods_desc, write_outcomes_page, EnsembleSpec, MethodOutcome,
    SceneComparison,
};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use dcr_scenes::scene::{build_world, SceneDesc};
use modal_bake::full_order::{FullOrderSystem, MaterialSi, ModalAll, SystemParams};
use rapier3d_f64::prelude::{ColliderHandle, PairContacts};
use rayon::prelude::*;

/// Settings of [`scene_truth`] (defaults in [`SceneTruthParams::default`]).
#[derive(Clone, Debug)]
pub struct SceneTruthParams {
    /// First coupling step (s). Default 1e-5 s (the scene's h must be a whole multiple).
    pub dt: f64,
    /// Largest number of halvings of the step. Default 3.
    pub max_halvings: usize,
    /// Largest change of an outcome between two successive steps (fraction). Default 0.02.
    pub tolerance: f64,
    /// Simulated time (s); `None`: the scene's `seconds`.
    pub seconds: Option<f64>,
    /// Modes summed (`None`: every mode).
    pub modes: Option<usize>,
    /// Check the modes (the converged step with half the modes) when fewer than every mode is
    /// summed. Default true.
    pub check_modes: bool,
    /// Penalty stiffness per contact point (N/m). Default 1e9: near rigid contact (sub-0.1 mm
    /// penetrations under the scenes' props), which the implicit coupling keeps stable.
    pub contact_stiffness: f64,
    /// Slip speed of the friction regularisation (m/s). Default 1e-3.
    pub friction_velocity: f64,
    /// Scale on the elastic object's Young's modulus (1 = the scene's). Default 1.
    pub youngs_scale: f64,
    /// Rayleigh damping override [α0, α1] (`None`: the scene's).
    pub rayleigh: Option<[f64; 2]>,
    /// Largest free dofs of the dense eigensolve. Default 6000.
    pub max_dense_dofs: usize,
    /// Largest coupling steps × modes × bodies of one run. Default 2e11.
    pub max_work: f64,
    /// Check the contact stiffness (the finest step with k doubled). Default true.
    pub check_stiffness: bool,
    /// Folder of the eigensolve cache (`None`: no cache).
    pub eigen_cache: Option<PathBuf>,
    /// Start every run with the projectile advanced along its exact discrete free flight to
    /// [`ADVANCE_MARGIN_STEPS`] steps before its first contact ([`advance_steps`]): the quiet
    /// fall costs nothing then. Default true.
    pub advance: bool,
    /// Runs per level (members of the ensemble; member 0 is the scene as written). Default 6.
    pub members: usize,
    /// Placement distance of the ensemble's members (m). Default 1e-4.
    pub perturbation: f64,
    /// Whether the props load the elastic object ([`CoupledParams::prop_feedback`]). Default
    /// true (the reference); false measures the distant response's no-feedback assumption.
    pub prop_feedback: bool,
    /// Progress on stderr.
    pub progress: bool,
}

impl Default for SceneTruthParams {
    fn default() -> Self {
        SceneTruthParams {
            dt: 1e-5,
            max_halvings: 3,
            tolerance: 0.02,
            seconds: None,
            modes: None,
            check_modes: true,
            contact_stiffness: 1e9,
            friction_velocity: 1e-3,
            youngs_scale: 1.0,
            rayleigh: None,
            max_dense_dofs: 6000,
            max_work: 2e11,
            check_stiffness: true,
            eigen_cache: None,
            advance: true,
            members: 6,
            perturbation: 1e-4,
            prop_feedback: true,
            progress: false,
        }
    }
}

/// One level of the refinement: its step, modes and outcomes.
#[derive(Clone, Debug)]
pub struct TruthLevel {
    /// Coupling step (s).
    pub dt: f64,
    /// Modes summed.
    pub modes: usize,
    /// Penalty stiffness per contact point (N/m).
    pub contact_stiffness: f64,
    /// Outcomes, the mean over the members: name → (value, unit).
    pub outcomes: BTreeMap<String, (f64, String)>,
    /// Sample standard deviation of each outcome over the members (the outcome's unit; 0 for
    /// one member).
    pub spread: BTreeMap<String, f64>,
    /// Members run.
    pub members: usize,
    /// Largest relative change of an outcome's mean from the level it is compared with (the
    /// previous step, or the finest step for a check; `None` for the first level).
    pub change: Option<f64>,
    /// Whether every outcome's change is within the tolerance or within the two members'
    /// statistical noise (two standard errors of the difference of the means); `None` for the
    /// first level.
    pub within_noise: Option<bool>,
    /// Largest penetration over the members (m).
    pub max_penetration: f64,
    /// Wall time of the level (s; members run side by side).
    pub wall_s: f64,
}

impl TruthLevel {
    /// Two standard errors of each outcome's mean, relative to max(|mean|, 1 unit): the
    /// ensemble's statistical uncertainty at 95 %; the largest over the outcomes.
    pub fn uncertainty(&self) -> f64 {
        self.outcomes
            .iter()
            .map(|(k, (m, _))| {
                two_standard_errors(self.spread.get(k).copied().unwrap_or(0.0), self.members)
                    / m.abs().max(1.0)
            })
            .fold(0.0, f64::max)
    }
}

/// Two standard errors of an ensemble mean (95 %): `2 s / √N` for the members' sample standard
/// deviation `s` (the outcome's unit) over `N` members.
pub(crate) fn two_standard_errors(spread: f64, members: usize) -> f64 {
    2.0 * spread / (members.max(1) as f64).sqrt()
}

/// The converged (or not) coupled reference of a scene.
pub struct SceneTruth {
    /// Scene name.
    pub scene: String,
    /// Free dofs and elastic modes of the object, and the eigensolve's wall time (s).
    pub free_dofs: usize,
    /// Elastic modes available.
    pub modes_available: usize,
    /// Dense eigensolve wall time (s).
    pub eigen_s: f64,
    /// Levels, coarse to fine.
    pub levels: Vec<TruthLevel>,
    /// The half-mode check at the finest step (its change from the full run), if run.
    pub half_modes: Option<TruthLevel>,
    /// The stiffness check at the finest step: k doubled (its change from the full run), if run.
    pub double_k: Option<TruthLevel>,
    /// Whether the step and the stiffness converged: their last changes within the tolerance
    /// or within the ensemble's statistical noise.
    pub converged: bool,
    /// The finest level's runs, member 0 (the scene as written) first.
    pub runs: Vec<CoupledRun>,
    /// Simulated seconds.
    pub seconds: f64,
    /// The settings.
    pub params: SceneTruthParams,
    /// Steps of h the projectile was advanced before every run (0: runs start at t = 0), or
    /// why it was not.
    pub advanced: std::result::Result<usize, String>,
}

impl SceneTruth {
    /// Member 0 of the finest level: the scene as written.
    pub fn run(&self) -> &CoupledRun {
        &self.runs[0]
    }

    /// The finest level.
    pub fn finest(&self) -> &TruthLevel {
        self.levels
            .last()
            .expect("a reference has at least one level")
    }

    /// Whether the mode check counts: only when fewer than every mode is summed (with every
    /// mode of the mesh there is no truncation; the half-mode run then shows how much the
    /// upper half of the spectrum matters, reported beside).
    pub fn modes_truncated(&self) -> bool {
        self.finest().modes < self.modes_available
    }

    /// The estimated error: the largest of the last change between two successive steps, the
    /// stiffness check, the mode check (when modes are truncated) and the ensemble's
    /// statistical uncertainty ([`TruthLevel::uncertainty`]).
    pub fn estimated_error(&self) -> f64 {
        let step = self
            .levels
            .last()
            .and_then(|l| l.change)
            .unwrap_or(f64::NAN);
        let modes = if self.modes_truncated() {
            self.half_modes.as_ref()
        } else {
            None
        };
        [modes, self.double_k.as_ref()]
            .into_iter()
            .flatten()
            .fold(step, |e, h| e.max(h.change.unwrap_or(0.0)))
            .max(self.finest().uncertainty())
    }
}

/// The mean and sample standard deviation of every outcome over `runs`.
pub fn ensemble_stats(
    runs: &[&BTreeMap<String, (f64, String)>],
) -> (BTreeMap<String, (f64, String)>, BTreeMap<String, f64>) {
    let mut mean = BTreeMap::new();
    let mut spread = BTreeMap::new();
    let Some(first) = runs.first() else {
        return (mean, spread);
    };
    let n = runs.len() as f64;
    for (k, (_, unit)) in first.iter() {
        let vals: Vec<f64> = runs.iter().map(|r| r.get(k).map_or(0.0, |x| x.0)).collect();
        let m = vals.iter().sum::<f64>() / n;
        let var = if runs.len() > 1 {
            vals.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        mean.insert(k.clone(), (m, unit.clone()));
        spread.insert(k.clone(), var.sqrt());
    }
    (mean, spread)
}

/// Compares level `b` with level `a`: the largest relative change of an outcome's mean
/// ([`outcome_change`]) and whether every outcome's change is within `tol` or within two
/// standard errors of the difference of the two means (the ensembles' noise).
pub fn level_change(a: &TruthLevel, b: &TruthLevel, tol: f64) -> (f64, bool) {
    let change = outcome_change(&a.outcomes, &b.outcomes);
    let mut within = true;
    for (k, (vb, _)) in &b.outcomes {
        let va = a.outcomes.get(k).map_or(0.0, |x| x.0);
        let scale = vb.abs().max(1.0);
        let sa = a.spread.get(k).copied().unwrap_or(0.0);
        let sb = b.spread.get(k).copied().unwrap_or(0.0);
        let noise =
            2.0 * (sa * sa / a.members.max(1) as f64 + sb * sb / b.members.max(1) as f64).sqrt();
        if (va - vb).abs() > (tol * scale).max(noise) {
            within = false;
        }
    }
    (change, within)
}

/// Steps of h kept between the advanced start and the projectile's first contact.
pub const ADVANCE_MARGIN_STEPS: usize = 3;

/// The step (0-based, of h) after which a launched body (a dynamic body with a non-zero
/// initial velocity) first has a contact point within 5 mm in the rigid scene run at h;
/// `None` when none has one over the scene's `seconds`.
///
/// # Errors
/// The world cannot be built.
pub fn first_contact_step(desc: &SceneDesc, root: &Path) -> Result<Option<usize>> {
    let mut built = build_world(desc, root)?;
    let launched: Vec<ColliderHandle> = built
        .collider_body
        .iter()
        .filter(|(_, &b)| {
            let rb = &built.world.bodies[built.bodies[b].handle];
            rb.is_dynamic() && rb.linvel().length() > 0.0
        })
        .map(|(&c, _)| c)
        .collect();
    if launched.is_empty() {
        return Ok(None);
    }
    let steps = (desc.seconds / desc.h).round() as usize;
    for k in 0..steps {
        built.world.step_with_events(&(), &());
        for &c in &launched {
            for pair in built.world.narrow_phase.contact_pairs_with(c) {
                let PairContacts::Rigid(rc) = &pair.contacts else {
                    continue;
                };
                if rc
                    .manifolds
                    .iter()
                    .any(|m| m.points.iter().any(|p| p.dist < 5e-3))
                {
                    return Ok(Some(k));
                }
            }
        }
    }
    Ok(None)
}

/// How many steps of h every run of the reference (and of the methods beside it) skips: the
/// projectile's free flight up to [`ADVANCE_MARGIN_STEPS`] steps before its first contact,
/// replaced by its exact discrete state there
/// ([`crate::soft_body::with_projectiles_advanced`]); `Err` says why the scene cannot be
/// advanced (no launched body, drivers, a projectile placed relative to the object).
///
/// # Errors
/// The world cannot be built.
pub fn advance_steps(desc: &SceneDesc, root: &Path) -> Result<std::result::Result<usize, String>> {
    if !desc.drivers.is_empty() {
        return Ok(Err("the scene has drivers (timed impulses)".into()));
    }
    let Some(k) = first_contact_step(desc, root)? else {
        return Ok(Err("no launched body touches anything".into()));
    };
    let steps = k.saturating_sub(ADVANCE_MARGIN_STEPS);
    Ok(
        match crate::soft_body::with_projectiles_advanced(desc, steps, 1) {
            Ok(_) => Ok(steps),
            Err(_) => Err(
                "a projectile spins, is damped or is placed relative to the elastic \
                 object; its advanced flight is written for plain translation only"
                    .into(),
            ),
        },
    )
}

/// Loads `scenes/NAME.json` (or a path) under `root`.
///
/// # Errors
/// Unknown scene or unreadable file.
pub fn load_scene(root: &Path, scene: &str) -> Result<SceneDesc> {
    let p = if scene.ends_with(".json") {
        root.join(scene)
    } else {
        root.join("scenes").join(format!("{scene}.json"))
    };
    if !p.is_file() {
        bail!(
            "scene {scene}: no file {} (give a scene name of scenes/ or a .json path)",
            p.display()
        );
    }
    SceneDesc::read(&p)
}

/// The full-order system and every mode of the scene's one elastic object (Young's modulus
/// scaled by `youngs_scale`); the eigensolve is read from / written to `cache` when given
/// ([`read_eigen`]).
///
/// # Errors
/// No or several elastic objects, a mesh error, more free dofs than `max_dense_dofs`, a cache
/// entry that cannot be written.
pub fn prepare_elastic(
    desc: &SceneDesc,
    root: &Path,
    youngs_scale: f64,
    max_dense_dofs: usize,
    cache: Option<&Path>,
) -> Result<ElasticPrep> {
    if desc.elastic.len() != 1 {
        bail!(
            "scene {}: the coupled reference takes exactly one elastic object, the scene has {}",
            desc.name,
            desc.elastic.len()
        );
    }
    let e = &desc.elastic[0];
    let path = root.join(&e.mesh);
    let mesh = modal_bake::mesh::read_mesh(&path)
        .with_context(|| format!("reading mesh {}", path.display()))?;
    let params = SystemParams {
        material: MaterialSi {
            youngs: e.material.youngs * youngs_scale,
            poisson: e.material.poisson,
            density: e.material.density,
        },
        fixed: e.fixed.clone(),
        fixed_below: e.fixed_below(),
        fixed_boxes: e.fixed_boxes.clone(),
        fixed_near: Vec::new(),
        rayleigh: e.rayleigh,
        lumped: false,
    };
    let sys = FullOrderSystem::new(mesh, &params, &path.display().to_string())?;
    if sys.n() > max_dense_dofs {
        bail!(
            "elastic object {}: {} free dofs, above the dense limit {max_dense_dofs} of the \
             coupled reference (raise --max-dense-dofs if the machine has the memory: the \
             solve needs about 3·n²·8 bytes and O(n³) time)",
            e.name,
            sys.n()
        );
    }
    let key = eigen_key(&sys);
    let cached = match cache.map(|dir| read_eigen(dir, &key)) {
        Some(Ok(Some(all))) if all.vectors.nrows() == sys.n() => Some(all),
        Some(Err(msg)) => {
            eprintln!("[scene-truth] eigensolve cache: {msg}; solving again and replacing it");
            None
        }
        _ => None,
    };
    let all = match cached {
        Some(all) => all,
        None => {
            let all = ModalAll::new(&sys, max_dense_dofs)?;
            if let Some(dir) = cache {
                write_eigen(dir, &key, &all).with_context(|| {
                    format!("writing the eigensolve cache in {}", dir.display())
                })?;
            }
            all
        }
    };
    // Every elastic eigenvalue must be positive; a non-positive one is a lost mode (the dense
    // solve at an extreme stiffness or a mesh with a mechanism), which would let the surface
    // drift under a held load.
    if let Some(l) = all.eigenvalues.iter().find(|l| **l <= 0.0) {
        bail!(
            "elastic object {}: the dense eigensolve returned a non-positive elastic eigenvalue \
             {l:.3e} rad²/s² (largest {:.3e}); the object is too stiff for a dense solve in double precision or has a mechanism (lower --youngs-scale or check the fixed nodes)",
            e.name,
            all.eigenvalues.last().copied().unwrap_or(0.0)
        );
    }
    Ok(ElasticPrep { sys, all })
}

/// The largest relative change between two outcome sets: |a − b| / max(|b|, 1 unit). The
/// floor of one unit (1 mm of lift or slide, 1° of tilt) compares figures below it absolutely,
/// so a sub-millimetre lift that flickers between 0 and 0.5 mm does not dominate.
pub fn outcome_change(
    a: &BTreeMap<String, (f64, String)>,
    b: &BTreeMap<String, (f64, String)>,
) -> f64 {
    let mut worst = 0.0f64;
    for (k, (vb, _)) in b {
        let va = a.get(k).map_or(0.0, |x| x.0);
        worst = worst.max((va - vb).abs() / vb.abs().max(1.0));
    }
    worst
}

/// Runs the coupled reference of `desc` with its step halved until converged (module doc):
/// [`plan_truth`] then [`run_truth`].
///
/// # Errors
/// As [`plan_truth`] and [`run_truth`].
pub fn scene_truth(desc: &SceneDesc, root: &Path, params: &SceneTruthParams) -> Result<SceneTruth> {
    run_truth(desc, root, params, plan_truth(desc, root, params)?)
}

/// What a scene's reference needs before its first run: the elastic object's every mode, the
/// projectile's advanced start and the simulated seconds, checked against the dense limit and
/// the work budget. [`plan_truth`] makes it in seconds (minutes for an uncached eigensolve of
/// a large object), so a command running several scenes can refuse a bad setting for any of
/// them before the long runs start.
pub struct TruthPlan {
    prep: ElasticPrep,
    eigen_s: f64,
    advanced: std::result::Result<usize, String>,
    seconds: f64,
    modes: usize,
}

/// Plans the reference of `desc` (see [`TruthPlan`]).
///
/// # Errors
/// As [`prepare_elastic`]; a projectile that cannot be advanced; a first contact after the
/// simulated time; a run over the work budget.
pub fn plan_truth(desc: &SceneDesc, root: &Path, params: &SceneTruthParams) -> Result<TruthPlan> {
    let t0 = Instant::now();
    let prep = prepare_elastic(
        desc,
        root,
        params.youngs_scale,
        params.max_dense_dofs,
        params.eigen_cache.as_deref(),
    )?;
    let eigen_s = t0.elapsed().as_secs_f64();
    let advanced = if params.advance {
        advance_steps(desc, root)?
    } else {
        Err("not asked for".into())
    };
    let skip = *advanced.as_ref().unwrap_or(&0);
    let seconds = params.seconds.unwrap_or(desc.seconds) - skip as f64 * desc.h;
    if seconds <= 0.0 {
        bail!(
            "scene {}: the projectile's first contact comes after the {} s simulated (raise --seconds)",
            desc.name,
            params.seconds.unwrap_or(desc.seconds)
        );
    }
    if params.progress {
        match &advanced {
            Ok(k) => eprintln!(
                "[scene-truth] {}: every run starts with the projectile {k} steps ({:.3} s) into its free flight, {} steps before its first contact",
                desc.name,
                *k as f64 * desc.h,
                ADVANCE_MARGIN_STEPS
            ),
            Err(why) => eprintln!("[scene-truth] {}: runs start at t = 0 ({why})", desc.name),
        }
    }
    let modes = params
        .modes
        .unwrap_or(usize::MAX)
        .min(prep.all.eigenvalues.len());
    let bodies = desc.props.len().max(1) as f64;
    let finest = params.dt / 2f64.powi(params.max_halvings as i32);
    let work = seconds / finest * modes as f64 * bodies;
    if work > params.max_work {
        bail!(
            "scene {}: the finest run would take {:.2e} steps × {modes} modes × {bodies} prop \
             descriptions = {work:.2e}, above the budget {:.2e} (lower --seconds, \
             --max-halvings or --modes, or raise --max-work)",
            desc.name,
            seconds / finest,
            params.max_work
        );
    }
    if params.progress {
        eprintln!(
            "[scene-truth] {}: {} free dofs, {} elastic modes, eigensolve {:.1} s",
            desc.name,
            prep.sys.n(),
            prep.all.eigenvalues.len(),
            eigen_s
        );
    }
    Ok(TruthPlan {
        prep,
        eigen_s,
        advanced,
        seconds,
        modes,
    })
}

/// Runs the reference `plan` was made for (`desc` and `params` as given to [`plan_truth`]).
///
/// # Errors
/// As [`run_coupled`].
pub fn run_truth(
    desc: &SceneDesc,
    root: &Path,
    params: &SceneTruthParams,
    plan: TruthPlan,
) -> Result<SceneTruth> {
    let TruthPlan {
        prep,
        eigen_s,
        advanced,
        seconds,
        modes,
    } = plan;
    let skip = *advanced.as_ref().unwrap_or(&0);
    // The scene each run of step `dt` starts from.
    let start_desc = |dt: f64| -> Result<SceneDesc> {
        let sub = (desc.h / dt).round().max(1.0) as usize;
        crate::soft_body::with_projectiles_advanced(desc, skip, sub)
    };
    let coupled = |dt: f64, modes: usize, k: f64| CoupledParams {
        dt,
        seconds,
        modes: Some(modes),
        contact_stiffness: k,
        friction_velocity: params.friction_velocity,
        rayleigh: params.rayleigh.unwrap_or(desc.elastic[0].rayleigh),
        restitution: desc.restitution,
        progress: params.progress,
        scheme: CouplingScheme::Implicit,
        perturbation: (0, 0.0),
        prop_feedback: params.prop_feedback,
    };
    let members = params.members.max(1);
    // One level: every member, side by side (one rayon task each; member 0 reports progress).
    let ensemble = |dt: f64, modes: usize, k: f64| -> Result<(TruthLevel, Vec<CoupledRun>)> {
        let t = Instant::now();
        let runs = (0..members)
            .into_par_iter()
            .map(|m| {
                let mut p = coupled(dt, modes, k);
                p.perturbation = (m, params.perturbation);
                p.progress = params.progress && m == 0;
                run_coupled(&start_desc(dt)?, root, &prep, &p)
            })
            .collect::<Result<Vec<_>>>()?;
        let (outcomes, spread) =
            ensemble_stats(&runs.iter().map(|r| &r.outcomes).collect::<Vec<_>>());
        let level = TruthLevel {
            dt,
            modes,
            contact_stiffness: k,
            outcomes,
            spread,
            members,
            change: None,
            within_noise: None,
            max_penetration: runs.iter().map(|r| r.max_penetration).fold(0.0, f64::max),
            wall_s: t.elapsed().as_secs_f64(),
        };
        Ok((level, runs))
    };
    let describe = |l: &TruthLevel| -> String {
        l.outcomes
            .iter()
            .map(|(k, v)| {
                format!(
                    "{k} {:.4} ± {:.4}",
                    v.0,
                    l.spread.get(k).copied().unwrap_or(0.0)
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut levels: Vec<TruthLevel> = Vec::new();
    let mut dt = params.dt;
    let mut runs;
    let mut converged = false;
    loop {
        let (mut level, r) = ensemble(dt, modes, params.contact_stiffness)?;
        runs = r;
        if let Some(prev) = levels.last() {
            let (change, within) = level_change(prev, &level, params.tolerance);
            level.change = Some(change);
            level.within_noise = Some(within);
        }
        if params.progress {
            eprintln!(
                "[scene-truth] {}: dt {:.3e} s, {} modes, {} members: {} (change {}) in {:.0} s",
                desc.name,
                dt,
                modes,
                members,
                describe(&level),
                level
                    .change
                    .map_or("–".into(), |c| format!("{:.2} %", 100.0 * c)),
                level.wall_s
            );
        }
        let done = level.within_noise == Some(true);
        levels.push(level);
        if done {
            converged = true;
            break;
        }
        if levels.len() > params.max_halvings {
            break;
        }
        dt /= 2.0;
    }
    let finest = levels.last().expect("one level at least").clone();
    let check = |name: &str, m: usize, k: f64| -> Result<TruthLevel> {
        let (mut h, _) = ensemble(dt, m, k)?;
        let (change, within) = level_change(&finest, &h, params.tolerance);
        h.change = Some(change);
        h.within_noise = Some(within);
        if params.progress {
            eprintln!(
                "[scene-truth] {}: {name} (dt {dt:.3e} s, {m} modes, k {k:.2e} N/m): {} (change {:.2} %{}) in {:.0} s",
                desc.name,
                describe(&h),
                100.0 * change,
                if within { ", within noise" } else { "" },
                h.wall_s
            );
        }
        Ok(h)
    };
    let double_k = if params.check_stiffness {
        let h = check("k doubled", modes, 2.0 * params.contact_stiffness)?;
        converged &= h.within_noise == Some(true);
        Some(h)
    } else {
        None
    };
    // With every mode of the mesh summed there is nothing to add: the check runs only when the
    // modes are truncated.
    let half_modes = if params.check_modes && modes >= 2 && modes < prep.all.eigenvalues.len() {
        let h = check("half the modes", modes / 2, params.contact_stiffness)?;
        converged &= h.within_noise == Some(true);
        Some(h)
    } else {
        None
    };
    Ok(SceneTruth {
        scene: desc.name.clone(),
        free_dofs: prep.sys.n(),
        modes_available: prep.all.eigenvalues.len(),
        eigen_s,
        levels,
        half_modes,
        double_k,
        converged,
        runs,
        seconds,
        params: params.clone(),
        advanced,
    })
}
