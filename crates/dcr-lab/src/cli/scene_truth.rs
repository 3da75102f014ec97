//! `dcr-lab scene-truth`: the coupled elastic–rigid reference of whole scenes and, with
//! `--page`, the outcomes page comparing the distant response's methods with it (see
//! [`dcr_lab::scene_truth`]).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use dcr_lab::scene_truth::{
    compare_scene, load_scene, plan_truth, run_truth, write_outcomes_page, SceneTruthParams,
};

/// Exit status when a reference did not converge (its outcomes are still printed and written).
pub const EXIT_NOT_CONVERGED: u8 = 3;

/// The coupled elastic–rigid reference of a scene: its one elastic object as every elastic mode
/// of its mesh (dense eigensolve, exact per-mode integration), coupled to the scene's rapier
/// bodies by penalty contacts implicit in the forces at a small step, the step halved until no
/// outcome moves by more than --tol, then checked with the contact stiffness doubled and with
/// half the modes (when --modes truncates them). Exit status: 0 converged, 1 error, 3 not converged (results still printed).
#[derive(Args, Clone, Debug)]
pub struct SceneTruthArgs {
    /// Scene names (scenes/NAME.json) or .json paths relative to the repository root.
    #[arg(required = true)]
    pub scenes: Vec<String>,
    /// First coupling step (s); the scene's h must be a whole multiple of it.
    #[arg(long, value_name = "S", default_value_t = 1e-5)]
    pub dt: f64,
    /// Most halvings of the step.
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub max_halvings: usize,
    /// Convergence tolerance (%) on every outcome between two successive steps.
    #[arg(long, value_name = "PCT", default_value_t = 2.0)]
    pub tol: f64,
    /// Simulated seconds (default: the scene's `seconds`).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Simulated seconds of one scene, named as in SCENES, over --seconds (repeatable; the last
    /// for a scene wins): for a scene whose outcome needs longer than the others', e.g.
    /// `lowrider=1.4` (its truck lands 0.75 s in).
    #[arg(long, value_name = "SCENE=S", value_parser = parse_scene_seconds)]
    pub scene_seconds: Vec<(String, f64)>,
    /// First coupling step of one scene, named as in SCENES, over --dt (repeatable; the last for
    /// a scene wins): for a scene that is long or converges at a coarser step, e.g.
    /// `lowrider=1e-5`.
    #[arg(long, value_name = "SCENE=S", value_parser = parse_scene_seconds)]
    pub scene_dt: Vec<(String, f64)>,
    /// Elastic modes summed (default: every mode).
    #[arg(long, value_name = "N")]
    pub modes: Option<usize>,
    /// Skip the check with half the modes at the finest step (it runs only when --modes sums
    /// fewer than every mode of the mesh).
    #[arg(long)]
    pub no_mode_check: bool,
    /// Skip the check with the contact stiffness doubled at the finest step.
    #[arg(long)]
    pub no_stiffness_check: bool,
    /// Folder caching the dense eigensolve of each object (reused by later levels and runs;
    /// entries are keyed by the object's stiffness and mass matrices).
    #[arg(long, value_name = "DIR")]
    pub eigen_cache: Option<PathBuf>,
    /// Penalty stiffness per contact point (N/m); large is rigid contact (the coupling is
    /// implicit in the forces, stable for any stiffness).
    #[arg(long, value_name = "N_PER_M", default_value_t = 1e9)]
    pub contact_stiffness: f64,
    /// Largest free dofs of the dense eigensolve (memory ~ 3·n²·8 bytes).
    #[arg(long, value_name = "N", default_value_t = 6000)]
    pub max_dense_dofs: usize,
    /// Largest coupling steps × modes × props of one run.
    #[arg(long, value_name = "W", default_value_t = 2e11)]
    pub max_work: f64,
    /// Start every run at t = 0 instead of skipping the projectile's free flight up to three
    /// steps before its first contact (its exact discrete state there).
    #[arg(long)]
    pub no_advance: bool,
    /// Runs per level: member 0 is the scene as written, the others start the scene's
    /// projectile (the bodies launched with a velocity) --perturbation (m) away across gravity; outcomes are the members' mean, and a step or stiffness
    /// change within the members' noise counts as converged (chaotic outcomes such as a
    /// rattling plate's largest lift cannot converge run by run). 1: single runs.
    #[arg(long, value_name = "N", default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub members: u32,
    /// Placement distance of the ensemble's members (m).
    #[arg(long, value_name = "M", default_value_t = 1e-4, value_parser = super::parse_perturbation)]
    pub perturbation: f64,
    /// The props do not load the elastic object: only the launched and driven bodies' contacts
    /// push on its modes, every other prop's see the surface move without pushing back — the
    /// distant response's assumption that resting bodies give the object no feedback, to
    /// measure what it costs against the default two-way reference.
    #[arg(long)]
    pub no_prop_feedback: bool,
    /// Also run the distant response's methods at gain 1 and write DIR/outcomes.md and
    /// DIR/outcomes/SCENE_lift.svg.
    #[arg(long, value_name = "DIR")]
    pub page: Option<PathBuf>,
    /// Line under the page's title (the command, date and load); `scripts/outcomes.sh` sets it.
    #[arg(long, value_name = "TEXT", default_value = "")]
    pub page_header: String,
}

/// Runs `dcr-lab scene-truth`.
///
/// # Errors
/// Invalid options, an unknown scene, a failed run.
pub fn run(a: &SceneTruthArgs) -> anyhow::Result<ExitCode> {
    if !(a.dt > 0.0 && a.dt.is_finite()) {
        anyhow::bail!("--dt must be a positive step in seconds, got {}", a.dt);
    }
    if !(a.tol > 0.0 && a.contact_stiffness > 0.0) {
        anyhow::bail!("--tol and --contact-stiffness must be positive");
    }
    if let Some(s) = a.seconds {
        if !(s > 0.0 && s.is_finite()) {
            anyhow::bail!("--seconds must be positive, got {s}");
        }
    }
    if a.no_prop_feedback && a.page.is_some() {
        anyhow::bail!(
            "--no-prop-feedback measures the no-feedback assumption; the outcomes page (--page) \
             compares the methods with the two-way reference: run them separately"
        );
    }
    for (flag, list) in [
        ("--scene-seconds", &a.scene_seconds),
        ("--scene-dt", &a.scene_dt),
    ] {
        if let Some((name, _)) = list.iter().find(|(n, _)| !a.scenes.contains(n)) {
            anyhow::bail!(
                "{flag} names {name:?}, which is not among the scenes run ({})",
                a.scenes.join(", ")
            );
        }
    }
    let root = dcr_scenes::repo_root();
    let params = SceneTruthParams {
        dt: a.dt,
        max_halvings: a.max_halvings,
        tolerance: a.tol / 100.0,
        seconds: a.seconds,
        modes: a.modes,
        check_modes: !a.no_mode_check,
        check_stiffness: !a.no_stiffness_check,
        prop_feedback: !a.no_prop_feedback,
        eigen_cache: a.eigen_cache.clone(),
        contact_stiffness: a.contact_stiffness,
        max_dense_dofs: a.max_dense_dofs,
        max_work: a.max_work,
        members: a.members as usize,
        advance: !a.no_advance,
        perturbation: a.perturbation,
        progress: true,
        ..SceneTruthParams::default()
    };
    let scene_params = |s: &String| {
        let mut params = params.clone();
        if let Some(&(_, t)) = a.scene_seconds.iter().rev().find(|(n, _)| n == s) {
            params.seconds = Some(t);
        }
        if let Some(&(_, dt)) = a.scene_dt.iter().rev().find(|(n, _)| n == s) {
            params.dt = dt;
        }
        params
    };
    // Every scene is planned first (side by side: the scene, its modes, the budget), so a bad
    // setting for any of them is refused before the long runs; each error is also printed
    // the moment it happens.
    let plans: Vec<anyhow::Result<_>> = std::thread::scope(|scope| {
        let jobs: Vec<_> = a
            .scenes
            .iter()
            .map(|s| {
                let (root, params) = (&root, scene_params(s));
                scope.spawn(move || {
                    let r = load_scene(root, s).and_then(|desc| {
                        let plan = plan_truth(&desc, root, &params)?;
                        Ok((desc, plan))
                    });
                    if let Err(e) = &r {
                        eprintln!("[scene-truth] {s}: error: {e:#}");
                    }
                    r
                })
            })
            .collect();
        jobs.into_iter()
            .map(|j| {
                j.join()
                    .unwrap_or_else(|_| Err(anyhow::anyhow!("a scene's plan panicked")))
            })
            .collect()
    });
    let failed: Vec<String> = plans
        .iter()
        .zip(&a.scenes)
        .filter_map(|(p, s)| p.as_ref().err().map(|e| format!("{s}: {e:#}")))
        .collect();
    if !failed.is_empty() {
        anyhow::bail!(
            "nothing was run; {} of {} scenes cannot be:\n  {}",
            failed.len(),
            a.scenes.len(),
            failed.join("\n  ")
        );
    }
    // The scenes run side by side (one thread each); results are reported in the given order.
    let results: Vec<anyhow::Result<(bool, String, Option<_>)>> = std::thread::scope(|scope| {
        let jobs: Vec<_> = a
            .scenes
            .iter()
            .zip(plans.into_iter().flatten())
            .map(|(s, (desc, plan))| {
                let (root, params) = (&root, scene_params(s));
                scope.spawn(move || -> anyhow::Result<(bool, String, Option<_>)> {
                    let params = &params;
                    let truth = run_truth(&desc, root, params, plan)?;
                    let ok = truth.converged && truth.estimated_error() < params.tolerance;
                    let last = truth.levels.last().map_or(f64::NAN, |l| l.dt);
                    let mut out = format!(
                        "{}: {} at dt {:.3e} s, {} modes, estimated error {:.2} %\n",
                        truth.scene,
                        if ok { "converged" } else { "NOT converged" },
                        last,
                        truth.levels.last().map_or(0, |l| l.modes),
                        100.0 * truth.estimated_error()
                    );
                    for (k, (v, u)) in &truth.finest().outcomes {
                        out.push_str(&format!("  {k}: {v:.4} {u}\n"));
                    }
                    let cmp = if a.page.is_some() {
                        Some(compare_scene(&desc, root, truth, true)?)
                    } else {
                        None
                    };
                    Ok((ok, out, cmp))
                })
            })
            .collect();
        jobs.into_iter()
            .map(|j| {
                j.join()
                    .unwrap_or_else(|_| Err(anyhow::anyhow!("a scene's run panicked")))
            })
            .collect()
    });
    let mut all_converged = true;
    let mut comparisons = Vec::new();
    for r in results {
        let (ok, out, cmp) = r?;
        all_converged &= ok;
        super::emit(&out)?;
        comparisons.extend(cmp);
    }
    if let Some(dir) = &a.page {
        write_outcomes_page(dir, &comparisons, &a.page_header)?;
        eprintln!("[scene-truth] wrote {}", dir.join("outcomes.md").display());
    }
    Ok(if all_converged {
        ExitCode::SUCCESS
    } else {
        eprintln!("error: a reference did not converge within --max-halvings (see above)");
        ExitCode::from(EXIT_NOT_CONVERGED)
    })
}

/// Parses `SCENE=S` (S in seconds, positive and finite): `--scene-seconds`, `--scene-dt`.
fn parse_scene_seconds(v: &str) -> Result<(String, f64), String> {
    let (name, t) = v
        .split_once('=')
        .ok_or_else(|| format!("expected SCENE=SECONDS (e.g. lowrider=1.4), got {v:?}"))?;
    let t: f64 = t
        .trim()
        .parse()
        .map_err(|e| format!("{t:?} in {v:?} is not a number of seconds: {e}"))?;
    if name.is_empty() || !(t > 0.0 && t.is_finite()) {
        return Err(format!(
            "expected a scene name and positive seconds, got {v:?}"
        ));
    }
    Ok((name.to_string(), t))
}
