//! `dcr-lab fit-gain`: the response gain at which a method's ensemble mean of one outcome equals
//! a target (the coupled reference's, `docs/outcomes.md`), and every outcome at that gain — the
//! per-object calibration of the paper's rule against the reference.

use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use dcr_lab::scene_truth::{
    advance_steps, load_scene, method_ensemble, methods_desc, EnsembleSpec, MethodOutcome,
};
use dcr_runtime::Launch;
use dcr_scenes::runner::MethodChoice;

/// The methods a gain is fitted for.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FitMethod {
    /// The bake-time peak-transfer table (★).
    Transfer,
    /// The modal filters over 20 modes (Eq. 9–13).
    Modal,
    /// Spatial attenuation (Eq. 14–16).
    Attenuation,
}

/// Find the gain (the scale on the response's Δv, 1 = Eq. 12 unscaled) at which the method's
/// ensemble mean of one outcome equals a target, by bisection on log gain; then print every
/// outcome at that gain. The runs are those of `scene-truth --page`: the same ensemble
/// (member 0 the scene as written, the others with the projectile started --perturbation away)
/// and the same advanced start.
#[derive(Args, Clone, Debug)]
pub struct FitGainArgs {
    /// Scene name (scenes/NAME.json) or .json path relative to the repository root.
    pub scene: String,
    /// The target: OUTCOME=VALUE in the outcome's unit (mm, deg), e.g. plates_max_lift=20.3.
    #[arg(long, value_name = "NAME=VALUE")]
    pub target: String,
    /// The method whose gain is fitted.
    #[arg(long, value_enum, default_value_t = FitMethod::Transfer)]
    pub method: FitMethod,
    /// Run the method under the response option `Launch::SustainedPeak` (d/h of the
    /// carried-over filters as a target on every step the object rings) instead of the
    /// paper's rule.
    #[arg(long)]
    pub sustained: bool,
    /// Members of each ensemble.
    #[arg(long, value_name = "N", default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub members: u32,
    /// Placement distance of the members (m).
    #[arg(long, value_name = "M", default_value_t = 1e-4, value_parser = super::parse_perturbation)]
    pub perturbation: f64,
    /// Simulated seconds from the scene's t = 0, as `scene-truth --seconds` (default: the
    /// scene's `seconds`).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Start at t = 0 instead of the projectile advanced to three steps before its first
    /// contact (as `scene-truth --no-advance`).
    #[arg(long)]
    pub no_advance: bool,
    /// Smallest gain searched.
    #[arg(long, value_name = "G", default_value_t = 0.25)]
    pub min_gain: f64,
    /// Largest gain searched.
    #[arg(long, value_name = "G", default_value_t = 16.0)]
    pub max_gain: f64,
    /// Bisection steps on log gain.
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub iterations: u32,
}

fn describe(m: &MethodOutcome) -> String {
    m.outcomes
        .iter()
        .map(|(k, (v, u))| {
            format!(
                "{k} {v:.3} ± {:.3} {u}",
                m.spread.get(k).copied().unwrap_or(0.0)
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Runs `dcr-lab fit-gain`.
///
/// # Errors
/// Invalid options, an unknown scene or outcome, a failed run, a target outside the range.
pub fn run(a: &FitGainArgs) -> Result<ExitCode> {
    let Some((name, value)) = a.target.split_once('=') else {
        bail!(
            "--target {}: expected OUTCOME=VALUE, e.g. plates_max_lift=20.3",
            a.target
        );
    };
    let target: f64 = value
        .trim()
        .parse()
        .with_context(|| format!("--target {}: {value} is not a number", a.target))?;
    if !(0.0 < a.min_gain && a.min_gain < a.max_gain && a.max_gain.is_finite()) {
        bail!(
            "--min-gain {} and --max-gain {} must satisfy 0 < min < max",
            a.min_gain,
            a.max_gain
        );
    }
    let root = dcr_scenes::repo_root();
    let desc = load_scene(&root, &a.scene)?;
    let name = name.trim();
    if !desc.outcomes.iter().any(|o| o.name == name) {
        bail!(
            "scene {}: no outcome {name} (it has {})",
            desc.name,
            desc.outcomes
                .iter()
                .map(|o| o.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let advanced = if a.no_advance {
        None
    } else {
        advance_steps(&desc, &root)?.ok()
    };
    let seconds = a.seconds.unwrap_or(desc.seconds) - advanced.unwrap_or(0) as f64 * desc.h;
    if seconds <= 0.0 {
        bail!("--seconds ends before the projectile's first contact; raise it");
    }
    let mdesc = methods_desc(&desc, advanced)?;
    let (method, label) = match a.method {
        FitMethod::Transfer => (MethodChoice::Transfer, "★ transfer table"),
        FitMethod::Modal => (MethodChoice::Modal, "modal, 20 modes"),
        FitMethod::Attenuation => (MethodChoice::Attenuation, "attenuation"),
    };
    let (launch, label) = if a.sustained {
        (Launch::SustainedPeak, format!("{label}, sustained d/h"))
    } else {
        (Launch::PeakOverStep, label.to_string())
    };
    let ens = EnsembleSpec {
        members: a.members as usize,
        perturbation: a.perturbation,
        seconds,
    };
    eprintln!(
        "[fit-gain] {}: {label}, {} members, {seconds:.3} s from {:.3} s; target {name} = {target}",
        desc.name,
        ens.members,
        advanced.unwrap_or(0) as f64 * desc.h
    );
    let eval = |g: f64| -> Result<(f64, MethodOutcome)> {
        let m = method_ensemble(
            &mdesc,
            &root,
            &label,
            Some(g),
            (method.clone(), launch),
            &ens,
        )?;
        let v = m.outcomes.get(name).map_or(0.0, |x| x.0);
        eprintln!("[fit-gain] gain {g:.4}: {}", describe(&m));
        Ok((v - target, m))
    };
    let (mut lo, mut hi) = (a.min_gain, a.max_gain);
    let (f_lo, m_lo) = eval(lo)?;
    let (f_hi, m_hi) = eval(hi)?;
    let mut best = if f_lo.abs() < f_hi.abs() {
        (lo, f_lo, m_lo)
    } else {
        (hi, f_hi, m_hi)
    };
    if f_lo.signum() == f_hi.signum() {
        bail!(
            "{name} does not cross {target} between gains {lo} and {hi} (means {:.4} and {:.4}); \
             widen --min-gain/--max-gain",
            f_lo + target,
            f_hi + target
        );
    }
    let rising = f_hi > f_lo;
    for _ in 0..a.iterations {
        let mid = (lo * hi).sqrt();
        let (f, m) = eval(mid)?;
        if f.abs() < best.1.abs() {
            best = (mid, f, m.clone());
        }
        if (f > 0.0) == rising {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let out = format!(
        "{}: {label}, gain {:.4} gives {name} {:.4} (target {target}); at that gain: {}\n",
        desc.name,
        best.0,
        best.1 + target,
        describe(&best.2)
    );
    super::emit(&out)?;
    Ok(ExitCode::SUCCESS)
}
