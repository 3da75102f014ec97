//! `dcr-lab fit-attenuation`: fit the spatial attenuation law (paper Eq. 14) to the
//! full-order response of a mesh at random surface vertex pairs (see
//! [`dcr_lab::attenuation_fit::fit_eq14`] and the `attenuation_fit` module docs).

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, ValueEnum};
use dcr_lab::attenuation_fit::{self, AttenuationFitParams, FitProgress, FitTruth};
use modal_bake::args::ModelOptions;

use super::mesh_input::MeshInput;
use super::progress::Progress;

/// Truth used for the pairs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FitTruthArg {
    /// modal-all when the free dofs fit --max-dense-dofs, else modes.
    Auto,
    /// Dense eigensolve, sum over every elastic mode (or the lowest --modes).
    ModalAll,
    /// Sparse bake of the lowest --modes (default 200) elastic modes.
    Modes,
}

#[derive(Args, Clone, Debug)]
pub struct FitAttenuationArgs {
    /// Tetrahedral mesh: gmsh .msh (2.0–2.2 or 4.1, ASCII or binary) or meshio-style .json.
    pub mesh: PathBuf,
    #[command(flatten)]
    pub input: MeshInput,
    #[command(flatten)]
    pub model: ModelOptions,
    /// Random (impact, contact) surface vertex pairs.
    #[arg(long, value_name = "N", default_value_t = 200)]
    pub pairs: usize,
    /// Seed of the pair sampler.
    #[arg(long, value_name = "U64", default_value_t = 1)]
    pub seed: u64,
    /// Window h (s) over which the peaks are taken.
    #[arg(long, value_name = "S", default_value_t = 0.01)]
    pub h: f64,
    /// Sample period (s) [default: π/(2ω_max)/4 of the modes used].
    #[arg(long, value_name = "S")]
    pub dt: Option<f64>,
    /// Modes summed for the truth [default: all (modal-all) or 200 (modes)].
    #[arg(long, value_name = "N")]
    pub modes: Option<usize>,
    /// Truth method.
    #[arg(long, value_enum, default_value_t = FitTruthArg::Auto)]
    pub truth: FitTruthArg,
    /// Largest number of free dofs for the dense eigensolve.
    #[arg(long, value_name = "N", default_value_t = 6000, value_parser = super::truth::parse_max_dense_dofs)]
    pub max_dense_dofs: usize,
    /// Fix r0 (m) instead of fitting it.
    #[arg(long, value_name = "M")]
    pub r0: Option<f64>,
    /// Print one JSON object (`{"fit", "simplified", "info", "samples"}`) on stdout.
    #[arg(long)]
    pub json: bool,
}

impl FitAttenuationArgs {
    /// The library parameters these options describe.
    pub fn params(&self) -> AttenuationFitParams {
        AttenuationFitParams {
            system: self.model.system(),
            h: self.h,
            dt: self.dt,
            modes: self.modes,
            truth: match self.truth {
                FitTruthArg::Auto => FitTruth::Auto,
                FitTruthArg::ModalAll => FitTruth::ModalAll,
                FitTruthArg::Modes => FitTruth::Modes,
            },
            max_dense_dofs: self.max_dense_dofs,
            pairs: self.pairs,
            seed: self.seed,
            r0: self.r0,
        }
    }
}

pub fn run(args: &FitAttenuationArgs) -> anyhow::Result<()> {
    let mesh = args.input.read(&args.mesh, "fit-attenuation")?;
    let mut progress = Progress::new("fit-attenuation");
    let rep = attenuation_fit::fit_attenuation_mesh(
        mesh,
        &args.params(),
        &args.mesh.display().to_string(),
        &mut |p| match p {
            FitProgress::Solve { method } => {
                progress.stage(&format!("solving for the modes ({method})"))
            }
            FitProgress::Distances { done, total } => {
                progress.count("geodesic distances", done, total)
            }
            FitProgress::Pairs { done, total } => progress.count("pair responses", done, total),
            _ => {}
        },
    );
    progress.finish();
    let rep = rep.with_context(|| format!("fit-attenuation for {} failed", args.mesh.display()))?;
    if args.json {
        return super::emit(&format!("{}\n", serde_json::to_string_pretty(&rep)?));
    }
    let (i, f, s) = (&rep.info, &rep.fit, &rep.simplified);
    let (rmin, rmax) = rep
        .samples
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), x| {
            (a.min(x.distance_m), b.max(x.distance_m))
        });
    let mut out = format!(
        "{} truth: {} modes (≤ {:.0} Hz) on {} free dofs; {} samples of {:.3e} s over h = {} s\n",
        i.method, i.modes, i.max_freq_hz, i.free_dofs, i.samples, i.dt, i.h
    );
    out += &format!(
        "  {} of {} pairs used (seed {}), {} distances {:.4} … {:.4} m\n",
        i.pairs_used, i.pairs_requested, i.seed, i.distance_kind, rmin, rmax
    );
    out += &format!(
        "  Eq. 14: alpha = {:.6} 1/m, beta = {:.6}, r0 = {:.6} m ({}{})\n",
        f.alpha,
        f.beta,
        f.r0,
        if args.r0.is_some() { "r0 given, " } else { "" },
        if f.active == "free" {
            "unconstrained".to_string()
        } else {
            format!("constrained: {}", f.active)
        }
    );
    out += &format!(
        "          R² (ln s) = {:.4}, RMS ln error = {:.4} (factor {:.3})\n",
        f.r2_log,
        f.rms_log,
        f.rms_log.exp()
    );
    if args.r0.is_none() && !(f.r0 >= 0.01 * rmin && f.r0 <= rmax) {
        out += &format!(
            "  note: r0 is outside [{:.2e}, {:.4}] m (β ≈ 0 makes r0 ill-conditioned); \
             the law is still the least-squares optimum; consider --r0 or the §4.5 fit\n",
            0.01 * rmin,
            rmax
        );
    }
    out += &format!(
        "  §4.5 s = C r^-beta: C = {:.6}, beta = {:.6}; R² (ln s) = {:.4}, RMS ln error = {:.4}\n",
        s.c, s.beta, s.r2_log, s.rms_log
    );
    out += &format!(
        "  seconds: eigensolve {:.3}, pairs {:.3}\n",
        i.eigensolve_s, i.response_s
    );
    super::emit(&out)
}
