//! `dcr-lab truth`: the full-order reference response to an impulse (see
//! [`dcr_lab::truth`]), in `modal-bake probe`'s JSON shape.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, ValueEnum};
use dcr_lab::truth::{self, CrossCheck, TruthImpact, TruthMethod, TruthParams};
use modal_bake::full_order::RefineParams;

use super::mesh_input::MeshInput;
use super::progress::Progress;
use super::truth_base::BaseUnderTest;
use modal_bake::args::{self as parse, ModelOptions};

/// Truth method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Implicit Newmark average acceleration on the full mesh (any size).
    Newmark,
    /// Sum over every mode with a dense eigensolve (small meshes).
    ModalAll,
}

/// When to run the independent check.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CrossCheckArg {
    /// When cheap (at most 3000 free dofs).
    Auto,
    /// Always.
    On,
    /// Never.
    Off,
}

/// Exit status of a run whose peaks did not converge (the peaks are still printed).
pub const EXIT_NOT_CONVERGED: u8 = 3;

/// Full-order reference response of a mesh to an impulse, with the time step refined until
/// the peaks converge. Exit status: 0 converged, 1 error, 3 not converged (--tol not reached
/// within --max-refinements; the peaks and `"converged": false` are still printed).
#[derive(Args, Clone, Debug)]
pub struct TruthArgs {
    /// Tetrahedral mesh: gmsh .msh (2.0–2.2 or 4.1, ASCII or binary) or meshio-style .json.
    pub mesh: PathBuf,
    /// The base whose object this is: its material, damping and fixed nodes, and how its mesh
    /// file is read (--units, --object, --piece), come from its record; MESH must be the mesh
    /// it was baked from (checked), and the base's own response at the same points (its
    /// transfer table where it serves, else its modes) is printed beside the reference, with
    /// its error.
    #[arg(
        long,
        value_name = "BASE.modes",
        conflicts_with_all = [
            "material", "youngs", "poisson", "density", "fixed", "fixed_below", "fixed_box",
            "fixed_near", "fixed_near_distance", "rayleigh", "lumped", "units", "object", "piece",
        ]
    )]
    pub base: Option<PathBuf>,
    #[command(flatten)]
    pub input: MeshInput,
    #[command(flatten)]
    pub model: ModelOptions,
    /// Impact point (m, object frame), mapped to the closest surface point (refused farther than
    /// 5% of the surface's bounding-box diagonal, as `probe`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse::vec3, allow_hyphen_values = true)]
    pub impact: [f64; 3],
    /// Impulse magnitude (N·s, > 0), applied at t = 0.
    #[arg(long, value_name = "NS", allow_hyphen_values = true)]
    pub impulse: f64,
    /// Impulse direction (normalised); default: into the surface (−normal at the impact).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse::vec3, allow_hyphen_values = true)]
    pub direction: Option<[f64; 3]>,
    /// A distant contact point (m, object frame; repeatable).
    #[arg(
        long = "contact",
        value_name = "X,Y,Z",
        value_parser = parse::vec3,
        required = true,
        allow_hyphen_values = true
    )]
    pub contacts: Vec<[f64; 3]>,
    /// Window h (s) over which the peak displacement is taken.
    #[arg(long, value_name = "S", default_value_t = 0.01)]
    pub h: f64,
    /// First time step / sample period (s; the step used is h/⌈h/dt⌉), halved until every peak
    /// changes by less than --tol.
    #[arg(long, value_name = "S", default_value_t = 1e-5)]
    pub dt: f64,
    /// Convergence tolerance (%): the run stops refining when no peak changes by more.
    #[arg(long, value_name = "PCT", default_value_t = 0.5)]
    pub tol: f64,
    /// Most halvings of the step after the first run (0: a single unchecked run at --dt).
    #[arg(long, value_name = "N", default_value_t = 6)]
    pub max_refinements: usize,
    /// Run the other method at the step reached as an independent check (auto: when the mesh
    /// has at most 3000 free dofs).
    #[arg(long, value_enum, default_value_t = CrossCheckArg::Auto)]
    pub cross_check: CrossCheckArg,
    /// Method.
    #[arg(long, value_enum, default_value_t = MethodArg::Newmark)]
    pub method: MethodArg,
    /// modal-all only: sum the lowest N elastic modes instead of all (to compare with a base).
    #[arg(long, value_name = "N")]
    pub modes: Option<usize>,
    /// modal-all only: largest number of free dofs accepted for the dense eigensolve.
    #[arg(long, value_name = "N", default_value_t = 6000, value_parser = parse_max_dense_dofs)]
    pub max_dense_dofs: usize,
    /// Print one JSON object on stdout (`{"contacts": [...], "info": {...}}`).
    #[arg(long)]
    pub json: bool,
}

impl TruthArgs {
    /// The library parameters these options describe.
    pub fn params(&self) -> TruthParams {
        TruthParams {
            system: self.model.system(),
            h: self.h,
            dt: self.dt,
            method: match self.method {
                MethodArg::Newmark => TruthMethod::Newmark,
                MethodArg::ModalAll => TruthMethod::ModalAll,
            },
            modes: self.modes,
            max_dense_dofs: self.max_dense_dofs,
            refine: RefineParams {
                tolerance: self.tol / 100.0,
                max_refinements: self.max_refinements,
                ..RefineParams::default()
            },
            cross_check: match self.cross_check {
                CrossCheckArg::Auto => CrossCheck::Auto,
                CrossCheckArg::On => CrossCheck::On,
                CrossCheckArg::Off => CrossCheck::Off,
            },
        }
    }
}

pub fn run(args: &TruthArgs) -> anyhow::Result<ExitCode> {
    if !(args.tol.is_finite() && args.tol > 0.0) {
        anyhow::bail!("--tol must be a percentage > 0, got {}", args.tol);
    }
    if args.modes.is_some() && args.method != MethodArg::ModalAll {
        anyhow::bail!("--modes truncates the modal sum; it needs --method modal-all");
    }
    if args.modes == Some(0) {
        anyhow::bail!("--modes must be at least 1");
    }
    let mut params = args.params();
    let impact = TruthImpact {
        point: args.impact,
        impulse: args.impulse,
        direction: args.direction,
    };
    let base = args.base.as_deref().map(BaseUnderTest::load).transpose()?;
    let mesh = match &base {
        Some(b) => {
            params.system = b.system();
            let mesh = b.input().read(&args.mesh, "truth")?;
            b.check_mesh(&mesh, &args.mesh.display().to_string())?;
            mesh
        }
        None => args.input.read(&args.mesh, "truth")?,
    };
    let mut progress = Progress::new("truth");
    let res = truth::run_truth(
        mesh,
        &params,
        &impact,
        &args.contacts,
        &args.mesh.display().to_string(),
        &mut |p| progress.count(&format!("step {:.3e} s", p.dt), p.done, p.total),
    );
    progress.finish();
    let res = res.with_context(|| format!("truth for {} failed", args.mesh.display()))?;
    let code = if res.convergence.converged || args.max_refinements == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(EXIT_NOT_CONVERGED)
    };
    let truth_peaks: Vec<f64> = res.contacts.iter().map(|c| c.peak_displacement_m).collect();
    let base_peaks = match &base {
        Some(b) => Some(b.peaks(
            args.h,
            args.impact,
            res.info.impact_direction,
            args.impulse,
            &args.contacts,
            &truth_peaks,
        )?),
        None => None,
    };
    if args.json {
        let mut v = serde_json::to_value(&res)?;
        if let (Some(b), Some(p)) = (&base, &base_peaks) {
            v["base"] = serde_json::json!({
                "file": b.path().display().to_string(),
                "modes": b.modes(),
                "contacts": p,
            });
        }
        super::emit(&format!("{}\n", serde_json::to_string_pretty(&v)?))?;
        return Ok(code);
    }
    let i = &res.info;
    let mut s = format!(
        "{} on {} free dofs ({}), {} samples of {:.3e} s over h = {:.3e} s\n",
        i.method,
        i.free_dofs,
        if i.fixed_nodes == 0 {
            "free-free, rigid motion removed".to_string()
        } else {
            format!("{} fixed nodes", i.fixed_nodes)
        },
        i.samples,
        i.dt,
        i.h
    );
    if i.method == "modal-all" {
        s += &format!("  modes summed: {}\n", i.modes_used);
    }
    s += &format!(
        "  impact at {:?} (triangle {}), direction {:?}\n",
        i.impact_point, i.impact_triangle, i.impact_direction
    );
    s += &format!(
        "  {:>3}  {:>34}  {:>12}  {:>14}  {:>12}\n",
        "#", "point (m)", "distance (m)", "peak disp (m)", "Δv (m/s)"
    );
    for (k, c) in res.contacts.iter().enumerate() {
        s += &format!(
            "  {:>3}  {:>34}  {:>12.5}  {:>14.6e}  {:>12.6e}\n",
            k,
            format!("({:.4}, {:.4}, {:.4})", c.point[0], c.point[1], c.point[2]),
            c.distance_m,
            c.peak_displacement_m,
            c.delta_v_mps
        );
    }
    s += &format!(
        "  seconds: setup {:.3}, eigensolve {:.3}, stepping {:.3} ({} distance)\n",
        i.setup_s, i.solve_s, i.step_s, i.distance_kind
    );
    s += &convergence_lines(&res.convergence, args.max_refinements);
    if let (Some(b), Some(p)) = (&base, &base_peaks) {
        s += &format!(
            "  base {} ({} modes), the same impact:\n",
            b.path().display(),
            b.modes()
        );
        for (k, c) in p.iter().enumerate() {
            s += &format!(
                "  {k:>3}  peak disp {:.6e} m ({}), {}\n",
                c.peak_displacement_m,
                c.served_by,
                c.error_pct.map_or_else(
                    || "the reference is 0 here (a fixed point)".to_string(),
                    |e| format!("error {e:+.2} % against the reference")
                )
            );
        }
    }
    super::emit(&s)?;
    Ok(code)
}

/// The convergence summary of the text output.
fn convergence_lines(c: &truth::TruthConvergence, max_refinements: usize) -> String {
    let steps: Vec<String> = c
        .history
        .iter()
        .map(|l| match l.change_pct {
            Some(d) => format!("{:.2e} s ({d:.3} %)", l.dt),
            None => format!("{:.2e} s", l.dt),
        })
        .collect();
    let mut s = format!(
        "  steps tried (largest peak change): {}\n",
        steps.join(", ")
    );
    s += &match (c.converged, c.estimated_error_pct) {
        (true, Some(e)) => format!(
            "  converged at dt = {:.3e} s: last two changes ≤ {e:.3} % < {} % (last {:.3} %)\n",
            c.dt_reached,
            c.tolerance_pct,
            c.last_change_pct.unwrap_or(f64::NAN),
        ),
        _ if max_refinements == 0 => "  single run (--max-refinements 0): convergence not checked\n".into(),
        _ => format!(
            "  NOT CONVERGED at dt = {:.3e} s: last two changes up to {:.3} %, tolerance {} % (raise --max-refinements or lower --dt)\n",
            c.dt_reached,
            c.estimated_error_pct.or(c.last_change_pct).unwrap_or(f64::NAN),
            c.tolerance_pct
        ),
    };
    if let Some(x) = &c.cross_check {
        s += &format!(
            "  cross-check: {} at dt = {:.3e} s differs by at most {:.3} %\n",
            x.method, x.dt, x.max_diff_pct
        );
    }
    s
}

/// Largest `--max-dense-dofs`: a dense eigensolve of N free dofs holds several N × N `f64`
/// matrices (K, M, the eigenvectors and the solver's workspace), about 2 GB at this N.
pub const MAX_DENSE_DOFS_LIMIT: usize = 8000;

/// `--max-dense-dofs N` with 1 ≤ N ≤ [`MAX_DENSE_DOFS_LIMIT`].
pub fn parse_max_dense_dofs(s: &str) -> Result<usize, String> {
    let n: usize = s.trim().parse().map_err(|_| {
        format!("{s:?} is not a whole number of free dofs (1 to {MAX_DENSE_DOFS_LIMIT})")
    })?;
    if !(1..=MAX_DENSE_DOFS_LIMIT).contains(&n) {
        return Err(format!(
            "{n} is outside 1 to {MAX_DENSE_DOFS_LIMIT}: a dense eigensolve of N dofs holds several \
             N × N matrices (about 2 GB at {MAX_DENSE_DOFS_LIMIT}); larger meshes take the \
             Newmark truth (--method newmark)"
        ));
    }
    Ok(n)
}
