//! `dcr-lab soft-body`: a scene with its elastic objects as rapier FEM soft bodies, and the
//! side-by-side comparison with dcr (see [`dcr_lab::soft_body`]).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use dcr_lab::soft_body::{
    render_markdown, run_side, sweep_substeps, with_projectiles_advanced, EnsembleParams,
    SceneComparison, SideMethod, SideRow, SoftSceneParams, SweepParams,
};
use dcr_scenes::scene::SceneDesc;

#[derive(Args, Clone, Debug)]
pub struct SoftBodyArgs {
    #[command(subcommand)]
    pub command: SoftBodyCommand,
}

#[derive(Subcommand, Clone, Debug)]
pub enum SoftBodyCommand {
    /// One run of a scene: its elastic objects as rapier FEM soft bodies (`--method
    /// rapier-fem`, the default), or rigid with dcr (`modal`, `transfer`) or without (`off`).
    Run(RunArgs),
    /// Every method side by side on each scene, one process per row (its peak memory is the
    /// row's; its members run one after the other in it): rapier-FEM at 1, 2, 4, … substeps
    /// until the outcomes settle, dcr with 20 modes and with the ★ table, no response. Writes a
    /// markdown table and the rows as JSON.
    Compare(CompareArgs),
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// The elastic objects as rapier FEM soft bodies.
    RapierFem,
    /// Rigid elastic objects, dcr over the 20-mode base.
    Modal,
    /// Rigid elastic objects, dcr from the bake-time transfer table (★).
    Transfer,
    /// Rigid elastic objects, no response.
    Off,
}

#[derive(Args, Clone, Debug)]
pub struct RunArgs {
    /// Scene name (`dinner`, read from ROOT/scenes/dinner.json) or a path to a scene file.
    pub scene: String,
    /// What the elastic objects are.
    #[arg(long, value_enum, default_value = "rapier-fem")]
    pub method: MethodArg,
    /// rapier-fem: solver substeps per step. Default rapier's (4).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=65536))]
    pub substeps: Option<u64>,
    /// rapier-fem: cap on the conjugate-gradient iterations of each substep's elastic solve.
    /// Default rapier's (20).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=100000))]
    pub cg_iterations: Option<u64>,
    /// rapier-fem: soft bodies with at most N degrees of freedom (3 per particle) answer their
    /// contacts through a direct (skyline Cholesky) factorization of the step matrix, exact;
    /// larger ones through the conjugate gradient capped at --cg-iterations. Default rapier's
    /// (600; the dinner table has 3,048).
    #[arg(long, value_name = "N")]
    pub max_dense_dofs: Option<usize>,
    /// rapier-fem: relative residual at which each conjugate gradient stops. Default rapier's
    /// (1e-5).
    #[arg(long, value_name = "TOL")]
    pub cg_tolerance: Option<f64>,
    /// Simulated time (s). Default the scene's `seconds`.
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Start the projectiles (props with an initial velocity) K steps into their free flight:
    /// the same impact, K steps earlier (see `with_projectiles_advanced`). K must end before
    /// the original first contact. Default 0.
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub advance_steps: usize,
    /// Runs per row (an ensemble): member 0 the scene as written, member m > 0 with the
    /// projectiles (bodies with an initial velocity) started --perturbation away across gravity,
    /// each member in its own direction. Outcomes are reported as mean ± sample standard
    /// deviation over the members; step times over all members' steps.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub members: u64,
    /// Distance (m) members m > 0 move the projectiles across gravity.
    #[arg(long, value_name = "M", default_value_t = 1e-4, value_parser = super::parse_perturbation)]
    pub perturbation: f64,
    /// Repository root (scenes, meshes, `out/bases`).
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub root: PathBuf,
    /// Write the row as JSON to FILE (`-`: stdout, instead of the summary line).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Progress lines on stderr every 5 s.
    #[arg(long)]
    pub progress: bool,
}

#[derive(Args, Clone, Debug)]
pub struct CompareArgs {
    /// Scene names (or paths). Scenes with scripted drivers or dynamic elastic objects are
    /// refused by the soft-body run.
    #[arg(required = true)]
    pub scenes: Vec<String>,
    /// Wall-time budget of each scene's substep sweep (minutes): no row starts that would
    /// likely end past it (estimated as twice the previous row).
    #[arg(long, value_name = "MIN", default_value_t = 20.0)]
    pub budget_min: f64,
    /// First substep count of the sweep (doubled each row).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub first_substeps: u64,
    /// Largest substep count of the sweep.
    #[arg(long, value_name = "N", default_value_t = 256)]
    pub max_substeps: usize,
    /// Tolerance of the sweep (%): it stops once doubling the substeps moves every outcome by
    /// less than this, or (with --members ≥ 2) every outcome's mean by less than max(this, two
    /// standard errors of the difference of the means): converged within the ensembles' noise.
    #[arg(long, value_name = "PCT", default_value_t = 2.0)]
    pub tolerance_pct: f64,
    /// CG iteration cap of the sweep's rows (rapier's `SoftFemParameters::max_linear_iterations`).
    /// Default rapier's (20).
    #[arg(long, value_name = "N")]
    pub cg_iterations: Option<usize>,
    /// Direct-factorization limit of the sweep's rows (rapier's `SoftFemParameters::max_dense_dofs`,
    /// dofs). Default rapier's (600).
    #[arg(long, value_name = "N")]
    pub max_dense_dofs: Option<usize>,
    /// Extra rapier-fem rows after the sweep, SUBSTEPS:CG[:DENSE] (repeatable), e.g. `4:1000` for
    /// rapier's default substeps with a conjugate gradient run to its tolerance, `8:1000:4000`
    /// for 8 substeps with the contact responses from a direct factorization as well.
    #[arg(long, value_name = "SUBSTEPS:CG[:DENSE]", value_parser = parse_extra)]
    pub extra: Vec<(usize, usize, usize)>,
    /// Simulated time of every row (s). Default each scene's `seconds`.
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Every row: start the projectiles K steps into their free flight (the same impact, K steps
    /// earlier; see `soft-body run --advance-steps`).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub advance_steps: usize,
    /// Runs per row (an ensemble): member 0 the scene as written, member m > 0 with the
    /// projectiles (bodies with an initial velocity) started --perturbation away across gravity,
    /// each member in its own direction. Outcomes are reported as mean ± sample standard
    /// deviation over the members; step times over all members' steps.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub members: u64,
    /// Distance (m) members m > 0 move the projectiles across gravity.
    #[arg(long, value_name = "M", default_value_t = 1e-4, value_parser = super::parse_perturbation)]
    pub perturbation: f64,
    /// Repository root.
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub root: PathBuf,
    /// Markdown table output.
    #[arg(long, value_name = "FILE", default_value = "out/soft_body/compare.md")]
    pub md: PathBuf,
    /// JSON output (every row, every scene).
    #[arg(
        long,
        value_name = "FILE",
        default_value = "out/soft_body/compare.json"
    )]
    pub json: PathBuf,
}

/// `SUBSTEPS:CG[:DENSE]`, SUBSTEPS and CG at least 1; DENSE defaults to rapier's.
fn parse_extra(s: &str) -> Result<(usize, usize, usize), String> {
    let parts: Vec<&str> = s.split(':').collect();
    if !(2..=3).contains(&parts.len()) {
        return Err(format!(
            "{s:?}: expected SUBSTEPS:CG[:DENSE], e.g. 4:1000 or 8:1000:4000"
        ));
    }
    let n = |x: &str, min: usize| -> Result<usize, String> {
        x.trim()
            .parse::<usize>()
            .ok()
            .filter(|&v| v >= min)
            .ok_or_else(|| {
                format!("{s:?}: SUBSTEPS and CG must be whole numbers ≥ 1, DENSE a whole number")
            })
    };
    let dense = match parts.get(2) {
        Some(d) => n(d, 0)?,
        None => SoftSceneParams::new(PathBuf::new()).max_dense_dofs,
    };
    Ok((n(parts[0], 1)?, n(parts[1], 1)?, dense))
}

fn scene_path(root: &Path, s: &str) -> PathBuf {
    if s.ends_with(".json") {
        PathBuf::from(s)
    } else {
        root.join("scenes").join(format!("{s}.json"))
    }
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    dcr_files::write_atomic(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// The ensemble of `--members` and `--perturbation` (both checked by their parsers).
fn ensemble(members: u64, perturbation: f64) -> EnsembleParams {
    EnsembleParams {
        members: members as usize,
        perturbation,
    }
}

fn side_method(a: &RunArgs) -> SideMethod {
    let d = SoftSceneParams::new(PathBuf::new());
    match a.method {
        MethodArg::RapierFem => SideMethod::RapierFem {
            substeps: a.substeps.map_or(d.substeps, |n| n as usize),
            cg_iterations: a.cg_iterations.map_or(d.cg_iterations, |n| n as usize),
            max_dense_dofs: a.max_dense_dofs.unwrap_or(d.max_dense_dofs),
            cg_tolerance: a.cg_tolerance.unwrap_or(d.cg_tolerance),
        },
        MethodArg::Modal => SideMethod::Modal,
        MethodArg::Transfer => SideMethod::Transfer,
        MethodArg::Off => SideMethod::Off,
    }
}

fn run_one(a: &RunArgs) -> Result<()> {
    if a.method != MethodArg::RapierFem
        && (a.substeps.is_some()
            || a.cg_iterations.is_some()
            || a.max_dense_dofs.is_some()
            || a.cg_tolerance.is_some())
    {
        bail!(
            "--substeps, --cg-iterations, --max-dense-dofs and --cg-tolerance apply to --method \
             rapier-fem only"
        );
    }
    if let Some(t) = a.cg_tolerance {
        if !(t > 0.0 && t < 1.0) {
            bail!("--cg-tolerance {t}: must be a relative residual in (0, 1), e.g. 1e-8");
        }
    }
    if let Some(s) = a.seconds {
        if !(s > 0.0 && s.is_finite()) {
            bail!("--seconds {s}: must be a positive number of seconds");
        }
    }
    let ensemble = ensemble(a.members, a.perturbation);
    let path = scene_path(&a.root, &a.scene);
    let method = side_method(a);
    let substeps = match method {
        SideMethod::RapierFem { substeps, .. } => substeps,
        // `dcr-scenes` runs rapier's default substeps.
        _ => rapier3d_f64::prelude::IntegrationParameters::default().num_solver_iterations,
    };
    let desc = with_projectiles_advanced(&SceneDesc::read(&path)?, a.advance_steps, substeps)?;
    let row = run_side(
        &desc,
        &method,
        a.root.clone(),
        a.seconds,
        &ensemble,
        a.progress,
    )?;
    let json = serde_json::to_string_pretty(&row)? + "\n";
    match &a.json {
        Some(p) if p.as_os_str() == "-" => crate::cli::emit(&json)?,
        Some(p) => {
            write_file(p, &json)?;
            crate::cli::emit(&summary(&row))?;
        }
        None => crate::cli::emit(&summary(&row))?,
    }
    Ok(())
}

fn summary(r: &SideRow) -> String {
    let outcomes: Vec<String> = r
        .outcomes
        .iter()
        .map(|(n, (v, u))| match r.spread.get(n) {
            Some(sd) if r.members > 1 => format!("{n} {v:.4} ± {sd:.4} {u}"),
            _ => format!("{n} {v:.4} {u}"),
        })
        .collect();
    format!(
        "{} {}: {} member(s) of {} steps, step median {:.3} ms, p99 {:.3} ms, peak RSS {} MiB, \
         {:.1} s; {}\n",
        r.scene,
        r.method.label(),
        r.members,
        r.steps,
        r.step_ms_median,
        r.step_ms_p99,
        r.peak_rss_mib.map_or("?".into(), |m| format!("{m:.0}")),
        r.wall_s,
        outcomes.join(", ")
    )
}

/// Runs one row in a child process of this binary (`soft-body run … --json -`).
fn run_child(
    root: &Path,
    scene: &str,
    method: &SideMethod,
    seconds: Option<f64>,
    advance_steps: usize,
    ensemble: &EnsembleParams,
) -> Result<SideRow> {
    let exe = std::env::current_exe().context("locating the dcr-lab binary")?;
    let mut cmd = Command::new(exe);
    cmd.arg("soft-body")
        .arg("run")
        .arg(scene)
        .arg("--root")
        .arg(root)
        .arg("--json")
        .arg("-")
        .arg("--progress");
    match method {
        SideMethod::RapierFem {
            substeps,
            cg_iterations,
            max_dense_dofs,
            cg_tolerance,
        } => {
            cmd.args(["--method", "rapier-fem", "--substeps"])
                .arg(substeps.to_string())
                .arg("--cg-iterations")
                .arg(cg_iterations.to_string())
                .arg("--max-dense-dofs")
                .arg(max_dense_dofs.to_string())
                .arg("--cg-tolerance")
                .arg(cg_tolerance.to_string());
        }
        SideMethod::Modal => {
            cmd.args(["--method", "modal"]);
        }
        SideMethod::Transfer => {
            cmd.args(["--method", "transfer"]);
        }
        SideMethod::Off => {
            cmd.args(["--method", "off"]);
        }
    }
    if let Some(s) = seconds {
        cmd.arg("--seconds").arg(s.to_string());
    }
    cmd.arg("--advance-steps").arg(advance_steps.to_string());
    cmd.arg("--members")
        .arg(ensemble.members.to_string())
        .arg("--perturbation")
        .arg(ensemble.perturbation.to_string());
    eprintln!("[dcr-lab] {scene}: {} …", method.label());
    let out = cmd
        .stderr(Stdio::inherit())
        .output()
        .context("running a dcr-lab soft-body child")?;
    if !out.status.success() {
        bail!(
            "{scene}: the {} run failed ({})",
            method.label(),
            out.status
        );
    }
    let row: SideRow = serde_json::from_slice(&out.stdout)
        .with_context(|| format!("{scene}: reading the {} row", method.label()))?;
    eprint!("[dcr-lab]   {}", summary(&row));
    Ok(row)
}

fn compare(a: &CompareArgs) -> Result<()> {
    if !(a.budget_min > 0.0) {
        bail!("--budget-min {}: must be positive", a.budget_min);
    }
    if !(a.tolerance_pct > 0.0) {
        bail!("--tolerance-pct {}: must be positive", a.tolerance_pct);
    }
    if a.first_substeps as usize > a.max_substeps {
        bail!(
            "--first-substeps {} is above --max-substeps {}: the sweep would run no row",
            a.first_substeps,
            a.max_substeps
        );
    }
    let ens = ensemble(a.members, a.perturbation);
    let mut out = Vec::new();
    for scene in &a.scenes {
        // Read (and check) the scene and the advance before spending minutes on it.
        with_projectiles_advanced(
            &SceneDesc::read(&scene_path(&a.root, scene))?,
            a.advance_steps,
            1,
        )?;
        // Bake the bases first, in a row of their own that is not kept: a row whose process
        // bakes would report the eigensolver's memory and time, not the run's.
        for m in [SideMethod::Modal, SideMethod::Transfer] {
            run_child(
                &a.root,
                scene,
                &m,
                Some(0.01),
                0,
                &EnsembleParams::default(),
            )?;
        }
        let mut rows = Vec::new();
        for m in [SideMethod::Off, SideMethod::Modal, SideMethod::Transfer] {
            rows.push(run_child(
                &a.root,
                scene,
                &m,
                a.seconds,
                a.advance_steps,
                &ens,
            )?);
        }
        let params = SweepParams {
            first: a.first_substeps as usize,
            budget_s: a.budget_min * 60.0,
            max_substeps: a.max_substeps,
            tolerance: a.tolerance_pct / 100.0,
            ..SweepParams::default()
        };
        let params = SweepParams {
            cg_iterations: a.cg_iterations.unwrap_or(params.cg_iterations),
            max_dense_dofs: a.max_dense_dofs.unwrap_or(params.max_dense_dofs),
            ..params
        };
        let (soft, end) = sweep_substeps(&params, |m| {
            run_child(&a.root, scene, m, a.seconds, a.advance_steps, &ens)
        })?;
        let mut all = soft;
        for &(substeps, cg_iterations, max_dense_dofs) in &a.extra {
            let m = SideMethod::RapierFem {
                substeps,
                cg_iterations,
                max_dense_dofs,
                cg_tolerance: params.cg_tolerance,
            };
            all.push(run_child(
                &a.root,
                scene,
                &m,
                a.seconds,
                a.advance_steps,
                &ens,
            )?);
        }
        all.extend(rows);
        out.push(SceneComparison {
            scene: all[0].scene.clone(),
            default_substeps: SoftSceneParams::new(PathBuf::new()).substeps,
            rows: all,
            sweep: end,
        });
    }
    write_file(&a.md, &render_markdown(&out))?;
    write_file(&a.json, &(serde_json::to_string_pretty(&out)? + "\n"))?;
    crate::cli::emit(&format!(
        "wrote {} and {}\n",
        a.md.display(),
        a.json.display()
    ))?;
    Ok(())
}

pub fn run(a: &SoftBodyArgs) -> Result<()> {
    match &a.command {
        SoftBodyCommand::Run(r) => run_one(r),
        SoftBodyCommand::Compare(c) => compare(c),
    }
}
