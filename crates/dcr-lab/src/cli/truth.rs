//! `dcr-lab truth`: the full-order reference response to an impulse (see
//! [`dcr_lab::truth`]), in `modal-bake probe`'s JSON shape.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, ValueEnum};
use dcr_lab::truth::{self, TruthImpact, TruthMethod, TruthParams};
use modal_bake::args::{self as parse, ModelOptions};

/// Truth method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Implicit Newmark average acceleration on the full mesh (any size).
    Newmark,
    /// Sum over every mode with a dense eigensolve (small meshes).
    ModalAll,
}

#[derive(Args, Clone, Debug)]
pub struct TruthArgs {
    /// Tetrahedral mesh: gmsh .msh (2.2 or 4.1, ASCII or binary) or meshio-style .json.
    pub mesh: PathBuf,
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
    /// Time step / sample period (s); the step used is h/⌈h/dt⌉.
    #[arg(long, value_name = "S", default_value_t = 1e-6)]
    pub dt: f64,
    /// Method.
    #[arg(long, value_enum, default_value_t = MethodArg::Newmark)]
    pub method: MethodArg,
    /// modal-all only: sum the lowest N elastic modes instead of all (to compare with a base).
    #[arg(long, value_name = "N")]
    pub modes: Option<usize>,
    /// modal-all only: largest number of free dofs accepted for the dense eigensolve.
    #[arg(long, value_name = "N", default_value_t = 6000)]
    pub max_dense_dofs: usize,
    /// Print one JSON object on stdout (`{"contacts": [...], "info": {...}}`).
    #[arg(long)]
    pub json: bool,
}

impl TruthArgs {
    /// The library parameters these options describe.
    pub fn params(&self) -> TruthParams {
        TruthParams {
            material: self.model.material(),
            fixed: self.model.fixed.clone(),
            rayleigh: self.model.rayleigh,
            lumped: self.model.lumped,
            h: self.h,
            dt: self.dt,
            method: match self.method {
                MethodArg::Newmark => TruthMethod::Newmark,
                MethodArg::ModalAll => TruthMethod::ModalAll,
            },
            modes: self.modes,
            max_dense_dofs: self.max_dense_dofs,
        }
    }
}

pub fn run(args: &TruthArgs) -> anyhow::Result<()> {
    if args.modes.is_some() && args.method != MethodArg::ModalAll {
        anyhow::bail!("--modes truncates the modal sum; it needs --method modal-all");
    }
    if args.modes == Some(0) {
        anyhow::bail!("--modes must be at least 1");
    }
    let params = args.params();
    let impact = TruthImpact {
        point: args.impact,
        impulse: args.impulse,
        direction: args.direction,
    };
    let res = truth::truth_file(&args.mesh, &params, &impact, &args.contacts)
        .with_context(|| format!("truth for {} failed", args.mesh.display()))?;
    if args.json {
        return super::emit(&format!("{}\n", serde_json::to_string_pretty(&res)?));
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
        "  seconds: setup {:.3}, factor/eigensolve {:.3}, stepping {:.3} ({} distance)\n",
        i.setup_s, i.solve_s, i.step_s, i.distance_kind
    );
    super::emit(&s)
}
