//! `dcr-scenes`: run a scene headless, or print Table 1 with our numbers beside the paper's.
//!
//! Defines the C library's `rand` and `srand` for the METIS it links through `modal-bake`
//! (`modal_bake::c_rand_symbols!`: the bases it bakes are `modal-bake`'s on every platform).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use dcr_files::OutputPlan;
use dcr_rapier::f64::{ApplyMode, StepGate};
use dcr_runtime::Launch;
use dcr_scenes::export::{side_label, write_outcomes_svg, write_scene_glb, Side};
use dcr_scenes::runner::{
    base_path, run_scene, stress_bench, table1, transfer_base_path, MethodChoice, RunParams,
    RunReport, StressBenchParams, Table1Params, RUN_OUTPUTS,
};
use dcr_scenes::scene::SceneDesc;
use dcr_scenes::{repo_root, SCENES};

#[derive(Parser)]
#[command(
    name = "dcr-scenes",
    version,
    about = "The paper's Table 1 scenes, headless on rapier3d-f64 with dcr-rapier"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Clone, Copy, ValueEnum)]
enum OnOff {
    On,
    Off,
    /// Both runs: files in OUT/on and OUT/off, outcomes.svg and --gltf with both.
    Both,
}

/// A response method for every elastic object of a run.
#[derive(Clone, Copy, ValueEnum)]
enum MethodArg {
    /// The modal filters over the object's base (its `modes`, 20 by default; Eq. 9–13).
    Modal,
    /// Spatial attenuation (Eq. 14–16): the object's own or `attenuation` settings, else C = 1,
    /// β = 1.
    Attenuation,
    /// The bake-time peak-transfer table (many modes, baked for the scene's h into
    /// out/bases/NAME.transfer.modes): the object's `method` or `transfer` settings; objects
    /// without them are refused.
    Transfer,
}

/// How the responses reach the bodies.
#[derive(Clone, Copy, ValueEnum)]
enum ApplyArg {
    /// Explicit impulses right after the step (Eq. 17–18).
    AfterStep,
    /// Replayed through the next step's contact solver (restitution pass; rapier hooks).
    InSolver,
}

impl From<ApplyArg> for ApplyMode {
    fn from(a: ApplyArg) -> ApplyMode {
        match a {
            ApplyArg::AfterStep => ApplyMode::AfterStep,
            ApplyArg::InSolver => ApplyMode::InSolver,
        }
    }
}

/// How long and how large a missing or stale base may be to bake on demand (`run`, `table1`,
/// `bench-stress`): each bake is sized before it starts (the mesh's modes and a transfer
/// table's mode set, then the table once its modes are known) and refused over the budget,
/// as `modal-bake bake --max-memory / --max-time` does.
#[derive(clap::Args, Clone)]
struct BakeBudgetArgs {
    /// Refuse a base whose estimated bake (or transfer table) needs more memory than this
    /// (GB, 1e9 bytes).
    #[arg(long, value_name = "GB", default_value_t = 2.0)]
    max_bake_memory: f64,
    /// Refuse a base whose estimated bake (or transfer table) takes longer than this (s).
    #[arg(long, value_name = "SECONDS", default_value_t = 300.0)]
    max_bake_time: f64,
    /// Bake whatever the estimate says.
    #[arg(long)]
    force_bake: bool,
}

impl BakeBudgetArgs {
    fn budget(&self) -> Result<Option<modal_bake::bake::Budget>> {
        let budget = modal_bake::bake::Budget::from_gb(
            self.max_bake_memory,
            self.max_bake_time,
            ["--max-bake-memory", "--max-bake-time"],
        )
        .map_err(anyhow::Error::msg)?;
        Ok((!self.force_bake).then_some(budget))
    }
}

/// Options shared by `run` and `table1`: how the response is applied and bounded.
#[derive(clap::Args, Clone)]
struct ResponseArgs {
    /// Energy bound η in [0, 1] (per object and step, the responses inject at most η × what
    /// the step's impacts dissipated), or `off` for no bound. Default: the world's (1).
    #[arg(long, value_name = "ETA|off", value_parser = parse_eta)]
    energy_eta: Option<Eta>,
    /// How the responses reach the bodies.
    #[arg(long, value_enum, default_value = "after-step")]
    apply: ApplyArg,
    /// Lateral kick (paper §5.4): the tangential peak displacement also pushes sideways.
    #[arg(long)]
    lateral_kick: bool,
    /// Turn rapier's contact recycling off on the elastic objects (as the in-solver path
    /// must), to compare the two paths under the same contact generation.
    #[arg(long)]
    no_contact_recycling: bool,
    /// On which steps the contacts are read in full and the world stepped: only the steps
    /// with an impact (default), or every step.
    #[arg(long, value_enum, default_value = "impact-steps")]
    gate: GateArg,
    /// How the resting bodies are launched: the paper's Δv = d/h added on the impact's step
    /// (default), or d/h of the carried-over filters as a target for the body's normal velocity
    /// on every step the object rings (turns carry-over on; with the transfer table, the larger
    /// of its peak and the filters'). docs/outcomes-analysis.md measures both.
    #[arg(long, value_enum, default_value = "peak-over-step")]
    launch: LaunchArg,
}

/// A launch rule (`--launch`).
#[derive(Clone, Copy, ValueEnum)]
enum LaunchArg {
    /// Eq. 12: Δv = d/h added to the body on the steps with impacts.
    PeakOverStep,
    /// d/h of the carried-over filters, a target on every step the object rings.
    SustainedPeak,
}

impl From<LaunchArg> for Launch {
    fn from(l: LaunchArg) -> Launch {
        match l {
            LaunchArg::PeakOverStep => Launch::PeakOverStep,
            LaunchArg::SustainedPeak => Launch::SustainedPeak,
        }
    }
}

/// On which steps the adapter reads the contacts.
#[derive(Clone, Copy, ValueEnum)]
enum GateArg {
    /// Steps with an impact, found by a light pass over the contacts' impulses
    /// (engine-newness classification).
    ImpactSteps,
    /// Every step (the world's age-based classification).
    EveryStep,
}

impl From<GateArg> for StepGate {
    fn from(g: GateArg) -> StepGate {
        match g {
            GateArg::ImpactSteps => StepGate::ImpactSteps,
            GateArg::EveryStep => StepGate::EveryStep,
        }
    }
}

/// A parsed `--energy-eta`.
#[derive(Clone, Copy)]
struct Eta(Option<f64>);

fn parse_gain(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .parse()
        .map_err(|_| format!("{s:?} is not a number (a scale ≥ 0 on the response Δv)"))?;
    if !(v.is_finite() && v >= 0.0) {
        return Err(format!("{v} is not a finite scale ≥ 0"));
    }
    Ok(v)
}

fn parse_eta(s: &str) -> Result<Eta, String> {
    if s.eq_ignore_ascii_case("off") || s.eq_ignore_ascii_case("none") {
        return Ok(Eta(None));
    }
    let v: f64 = s
        .parse()
        .map_err(|_| format!("{s:?} is not a number in [0, 1] or `off`"))?;
    if !(0.0..=1.0).contains(&v) {
        return Err(format!("{v} is outside [0, 1]"));
    }
    Ok(Eta(Some(v)))
}

impl ResponseArgs {
    fn eta(&self) -> Option<f64> {
        self.energy_eta
            .map_or(dcr_rapier::WorldParams::default().energy_eta, |e| e.0)
    }
}

#[derive(Subcommand)]
enum Cmd {
    /// Run one scene (a name in scenes/ or a path to a scene JSON file).
    Run {
        /// Scene name (dinner, roof, scaffold, lowrider, rockfall, washing) or JSON path.
        scene: String,
        /// Simulated seconds (default: the scene's).
        #[arg(long)]
        seconds: Option<f64>,
        /// Distant collision response on or off.
        #[arg(long, value_enum, default_value = "on")]
        dcr: OnOff,
        /// Response method for every elastic object (default: each object's own).
        #[arg(long, value_enum)]
        method: Option<MethodArg>,
        /// Attenuation exponent β (implies --method attenuation).
        #[arg(long)]
        beta: Option<f64>,
        /// Scale on every elastic object's response Δv, replacing the objects' own `gain`
        /// (1 = the paper's Eq. 12/18 unscaled). Default: each object's `gain`.
        #[arg(long, value_name = "G", value_parser = parse_gain, allow_hyphen_values = true)]
        gain: Option<f64>,
        /// Output directory (default out/SCENE). Without --out the runs go to out/SCENE/on
        /// and out/SCENE/off (as with --dcr both), so an on and an off run never overwrite
        /// each other; with --out a single run writes there.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Bases directory (default out/bases).
        #[arg(long)]
        bases: Option<PathBuf>,
        /// Also write the run(s) as animated glTF here (side by side with --dcr both; the
        /// response events in the file's extras). Open it with scripts/view.sh.
        #[arg(long, value_name = "OUT.glb")]
        gltf: Option<PathBuf>,
        #[command(flatten)]
        response: ResponseArgs,
        #[command(flatten)]
        budget: BakeBudgetArgs,
    },
    /// Bake missing/stale bases, run every scene on and off, print Table 1.
    Table1 {
        /// One JSON object instead of the text table.
        #[arg(long)]
        json: bool,
        /// Override every scene's length (s).
        #[arg(long)]
        seconds: Option<f64>,
        /// Only these scenes (comma separated).
        #[arg(long, value_delimiter = ',')]
        scenes: Option<Vec<String>>,
        /// Bases directory (default out/bases).
        #[arg(long)]
        bases: Option<PathBuf>,
        /// Also write every scene's on and off runs side by side as DIR/SCENE.glb.
        #[arg(long, value_name = "DIR")]
        gltf: Option<PathBuf>,
        #[command(flatten)]
        response: ResponseArgs,
        /// Energy-bound sweep: also run each scene unbounded and at each η (comma separated,
        /// e.g. 1,0.5,0.1) and report which outcomes move by more than 5 %.
        #[arg(long, value_delimiter = ',', value_name = "ETAS")]
        energy_sweep: Vec<f64>,
        #[command(flatten)]
        budget: BakeBudgetArgs,
    },
    /// The adapter's per-step cost against the number of resting contacts: scenes/stress.json
    /// cut to its first N boxes, one JSON object on stdout (wall-clock medians).
    BenchStress {
        /// Numbers of boxes (comma separated).
        #[arg(long, value_delimiter = ',', default_value = "100,300,1000")]
        props: Vec<usize>,
        /// Simulated seconds per run (default: the scene's).
        #[arg(long)]
        seconds: Option<f64>,
        /// Bases directory (default out/bases).
        #[arg(long)]
        bases: Option<PathBuf>,
        #[command(flatten)]
        budget: BakeBudgetArgs,
    },
}

fn scene_path(root: &std::path::Path, s: &str) -> PathBuf {
    if s.ends_with(".json") {
        PathBuf::from(s)
    } else {
        root.join("scenes").join(format!("{s}.json"))
    }
}

fn print_report(report: &RunReport, out_dir: &std::path::Path) {
    println!(
        "{} dcr {} ({} steps): {}",
        report.scene,
        if report.dcr { "on" } else { "off" },
        report.steps,
        out_dir.display()
    );
    for (k, (v, u)) in &report.outcomes {
        println!("  {k:28} {v:10.3} {u}");
    }
    for m in &report.models {
        println!(
            "  model {:8} impacts {:4} queries {:4} distant contacts (max) {:3} query µs median {} p99 {}",
            m.model,
            m.stats.impacts,
            m.queries,
            m.distant_contacts,
            m.query_us_median.map_or("-".into(), |v| format!("{v:.1}")),
            m.query_us_p99.map_or("-".into(), |v| format!("{v:.1}"))
        );
        if m.method.starts_with("transfer") {
            println!(
                "  model {:8} {} ({}): {} of {} events from the table; {} contacts served by the modal base outside its region",
                m.model,
                m.method,
                m.base,
                m.stats.events_by_table,
                m.stats.responses_applied,
                m.stats.contacts_table_fallback
            );
        }
    }
    println!(
        "  rapier {:.1} ms, dcr {:.1} ms ({:.2}% of step); energy injected {:.4e} J, dissipated {:.4e} J",
        report.rapier_ms,
        report.adapter_ms,
        100.0 * report.dcr_share_of_step,
        report.injected_ke,
        report.dissipated
    );
    println!(
        "  world stepped on {} of {} steps ({})",
        report.world_steps, report.steps, report.gate
    );
    println!("  trajectory {}", report.trajectory_hash);
}

fn real_main() -> Result<()> {
    let cli = Cli::parse_from(modal_bake::args::join_negative_values(std::env::args_os()));
    let root = repo_root();
    match cli.cmd {
        Cmd::Run {
            scene,
            seconds,
            dcr,
            method,
            beta,
            gain,
            out,
            bases,
            gltf,
            response,
            budget,
        } => {
            let bake_budget = budget.budget()?;
            let path = scene_path(&root, &scene);
            if std::fs::symlink_metadata(&path).is_err() {
                bail!(
                    "no scene {scene:?} ({} does not exist; scenes: {})",
                    path.display(),
                    SCENES.join(", ")
                );
            }
            let desc = SceneDesc::read(&path)?;
            if let Some(b) = beta {
                if !(b.is_finite() && (0.0..=10.0).contains(&b)) {
                    bail!("--beta {b}: the attenuation exponent β must be in [0, 10]");
                }
            }
            let method = match (method, beta) {
                (Some(MethodArg::Modal | MethodArg::Transfer), Some(_)) => {
                    bail!("--beta is the attenuation exponent: use it without --method or with --method attenuation")
                }
                (_, Some(b)) => MethodChoice::AttenuationBeta(b),
                (Some(MethodArg::Attenuation), None) => MethodChoice::Attenuation,
                (Some(MethodArg::Modal), None) => MethodChoice::Modal,
                (Some(MethodArg::Transfer), None) => MethodChoice::Transfer,
                (None, None) => MethodChoice::Scene,
            };
            if matches!(response.launch, LaunchArg::SustainedPeak)
                && matches!(
                    method,
                    MethodChoice::Attenuation | MethodChoice::AttenuationBeta(_)
                )
            {
                bail!(
                    "--launch sustained-peak reads the modal filters, which spatial attenuation \
                     does not have: use it with --method modal or --method transfer"
                );
            }
            desc.run_steps(seconds)
                .map_err(|e| anyhow::anyhow!("scene {}: {e}", path.display()))?;
            let split = out.is_none() || matches!(dcr, OnOff::Both);
            let out_dir = out.unwrap_or_else(|| root.join("out").join(&desc.name));
            let bases_dir = bases.unwrap_or_else(|| root.join("out").join("bases"));
            let runs: &[bool] = match dcr {
                OnOff::On => &[true],
                OnOff::Off => &[false],
                OnOff::Both => &[true, false],
            };
            // Every output is checked against the inputs and the others before anything runs.
            let mut plan = OutputPlan::new();
            plan.input("the scene file", &path);
            for e in &desc.elastic {
                plan.input("the mesh", &root.join(&e.mesh));
            }
            plan.output_folder("--bases", &bases_dir)?;
            for e in &desc.elastic {
                plan.output("--bases", &base_path(&bases_dir, e))?;
                plan.output("--bases", &transfer_base_path(&bases_dir, e))?;
            }
            plan.output_folder("--out", &out_dir)?;
            for &on in runs {
                let dir = if split {
                    out_dir.join(if on { "on" } else { "off" })
                } else {
                    out_dir.clone()
                };
                plan.output_folder("--out", &dir)?;
                for name in RUN_OUTPUTS {
                    plan.output("--out", &dir.join(name))?;
                }
            }
            if !desc.outcomes.is_empty() {
                plan.output("--out", &out_dir.join("outcomes.svg"))?;
            }
            if let Some(path) = &gltf {
                plan.output("--gltf", path)?;
            }
            let mut reports = Vec::new();
            for &on in runs {
                let dir = if split {
                    out_dir.join(if on { "on" } else { "off" })
                } else {
                    out_dir.clone()
                };
                let report = run_scene(
                    &desc,
                    &RunParams {
                        seconds,
                        method: method.clone(),
                        gain,
                        bases_dir: bases_dir.clone(),
                        out_dir: Some(dir.clone()),
                        progress: true,
                        apply: response.apply.into(),
                        energy_eta: response.eta(),
                        lateral_kick: response.lateral_kick,
                        launch: response.launch.into(),
                        contact_recycling: !response.no_contact_recycling,
                        gate: response.gate.into(),
                        bake_budget,
                        ..RunParams::new(root.clone(), on)
                    },
                )?;
                print_report(&report, &dir);
                reports.push(report);
            }
            let refs: Vec<&RunReport> = reports.iter().collect();
            if !desc.outcomes.is_empty() {
                let svg = out_dir.join("outcomes.svg");
                let t = std::time::Instant::now();
                write_outcomes_svg(&desc, &refs, &svg)?;
                println!(
                    "  outcomes over time: {} ({:.1} KiB, {:.3} s)",
                    svg.display(),
                    std::fs::metadata(&svg).map_or(0, |m| m.len()) as f64 / 1024.0,
                    t.elapsed().as_secs_f64()
                );
            }
            if let Some(path) = gltf {
                let sides: Vec<Side> = reports
                    .iter()
                    .map(|r| Side {
                        label: side_label(r),
                        report: r,
                    })
                    .collect();
                let t = std::time::Instant::now();
                let info = write_scene_glb(&desc, &root, &bases_dir, &sides, &path)
                    .with_context(|| format!("writing {}", path.display()))?;
                println!(
                    "  glTF: {} ({:.1} KiB, {} body nodes, {} keyframes, {} response events, {:.3} s)",
                    path.display(),
                    info.bytes as f64 / 1024.0,
                    info.body_nodes,
                    info.keyframes,
                    info.events,
                    t.elapsed().as_secs_f64()
                );
            }
        }
        Cmd::Table1 {
            json,
            seconds,
            scenes,
            bases,
            gltf,
            response,
            energy_sweep,
            budget,
        } => {
            let bake_budget = budget.budget()?;
            for &e in &energy_sweep {
                if !(0.0..=1.0).contains(&e) {
                    bail!("--energy-sweep: {e} is outside [0, 1]");
                }
            }
            let scenes = scenes.unwrap_or_else(|| SCENES.iter().map(|s| s.to_string()).collect());
            for s in &scenes {
                if !SCENES.contains(&s.as_str()) {
                    bail!("unknown scene {s:?} (scenes: {})", SCENES.join(", "));
                }
            }
            if let Some(dir) = &gltf {
                let mut plan = OutputPlan::new();
                plan.output_folder("--gltf", dir)?;
                for s in &scenes {
                    plan.output("--gltf", &dir.join(format!("{s}.glb")))?;
                }
            }
            let (text, value) = table1(&Table1Params {
                scenes,
                seconds,
                root: root.clone(),
                bases_dir: bases.unwrap_or_else(|| root.join("out").join("bases")),
                scaffold_betas: vec![0.5, 1.0, 2.0],
                apply: response.apply.into(),
                energy_eta: response.eta(),
                lateral_kick: response.lateral_kick,
                launch: response.launch.into(),
                contact_recycling: !response.no_contact_recycling,
                gate: response.gate.into(),
                eta_sweep: energy_sweep,
                gltf_dir: gltf,
                bake_budget,
            })
            .context("table1")?;
            if json {
                println!("{}", serde_json::to_string_pretty(&value)?);
            } else {
                print!("{text}");
            }
        }
        Cmd::BenchStress {
            props,
            seconds,
            bases,
            budget,
        } => {
            let bake_budget = budget.budget()?;
            if let Some(s) = seconds {
                if !(s.is_finite() && s > 0.0) {
                    bail!("--seconds must be positive, got {s}");
                }
            }
            let value = stress_bench(&StressBenchParams {
                props,
                seconds,
                root: root.clone(),
                bases_dir: bases.unwrap_or_else(|| root.join("out").join("bases")),
                progress: true,
                bake_budget,
            })
            .context("bench-stress")?;
            println!("{}", serde_json::to_string_pretty(&value)?);
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    if let Err(e) = modal_bake::signals::remove_temporaries_on_signals() {
        eprintln!("dcr-scenes: warning: cannot watch for signals ({e}); an interrupted write may leave a temporary file");
    }
    match real_main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("dcr-scenes: error: {}", modal_bake::args::error_line(&e));
            ExitCode::FAILURE
        }
    }
}

modal_bake::c_rand_symbols!();
