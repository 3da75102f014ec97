//! `modal-bake bake`.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use modal_bake::bake::{
    self, BakeParams, BakeReport, BakeStage, FixedBelow, ModeRequest, ModesPrecision,
};
use modal_bake::transfer::{TableOrder, TransferModes, TransferParams};

use super::mesh::AssetOptions;
use super::parse;
pub use modal_bake::args::ModelOptions;
use modal_bake::mesh::surface::is_surface_asset;

/// Options that determine a base (shared by `bake` and `check`).
#[derive(Args, Clone, Debug)]
pub struct BakeOptions {
    #[command(flatten)]
    pub model: ModelOptions,
    /// Number of lowest elastic modes to keep [default: 20].
    #[arg(long, value_name = "N", conflicts_with = "max_freq")]
    pub modes: Option<usize>,
    /// Keep every elastic mode below this frequency (Hz) instead of a count.
    #[arg(long, value_name = "HZ")]
    pub max_freq: Option<f64>,
    /// Store the surface mode shapes as 32-bit floats (half the file size).
    #[arg(long)]
    pub f32: bool,
    /// Fix every node at or below a coordinate, e.g. `y=0.01` (m, object frame; repeatable;
    /// combines with --fixed and --fixed-box). A selector that fixes no node is an error.
    #[arg(long, value_name = "AXIS=VALUE", value_parser = parse::axis_value, allow_hyphen_values = true)]
    pub fixed_below: Vec<FixedBelow>,
    /// Fix every node inside a box X0,Y0,Z0,X1,Y1,Z1 (m, object frame, bounds included;
    /// repeatable; combines with --fixed and --fixed-below).
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1", value_parser = parse::aabb, allow_hyphen_values = true)]
    pub fixed_box: Vec<[f64; 6]>,
}

impl BakeOptions {
    pub fn params(&self) -> BakeParams {
        BakeParams {
            material: self.model.material(),
            modes: match self.max_freq {
                Some(f) => ModeRequest::MaxFreqHz(f),
                None => ModeRequest::Count(self.modes.unwrap_or(20)),
            },
            fixed: self.model.fixed.clone(),
            fixed_below: self.fixed_below.clone(),
            fixed_boxes: self.fixed_box.clone(),
            rayleigh: self.model.rayleigh,
            lumped: self.model.lumped,
            precision: if self.f32 {
                ModesPrecision::F32
            } else {
                ModesPrecision::F64
            },
            transfer: None,
        }
    }
}

#[derive(Args)]
pub struct BakeArgs {
    /// Tetrahedral mesh: gmsh .msh (2.2 or 4.1, ASCII or binary, 4- or 10-node tetrahedra) or
    /// meshio-style .json; or a surface asset .obj / .stl / .ply, meshed first as `modal-bake
    /// mesh` does (--mesher, --size, --order, ...). Coordinates in metres unless --units says
    /// otherwise.
    pub mesh: PathBuf,
    /// Output base (written atomically: nothing is left behind on failure).
    #[arg(short = 'o', long = "out", value_name = "OUT.modes")]
    pub out: PathBuf,
    #[command(flatten)]
    pub options: BakeOptions,
    /// Print seconds per stage (read, assemble, factor, eigensolve, write).
    #[arg(long)]
    pub timings: bool,
    /// Print the bake report as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub transfer: TransferOptions,
    #[command(flatten)]
    pub asset: AssetOptions,
    /// Choose the cheapest representation (modes; a transfer table, its modes and order) whose
    /// worst peak error against the bake's own converged full-order truth, at seeded pairs of
    /// the table region (--transfer-up / --transfer-region), is at most PCT percent; needs
    /// --transfer-h (the scene's step). The estimate, query cost and size are stored in the
    /// base (`info` shows them). Overrides --modes and --transfer-modes / --transfer-order.
    #[arg(
        long,
        value_name = "PCT",
        requires = "transfer_h",
        conflicts_with = "max_freq"
    )]
    pub target_error: Option<f64>,
}

/// The tetrahedral mesh of `path`: read, or (a surface asset) meshed by the meshing chain; with the
/// seconds it took. Meshing options given with a volume mesh are an error.
pub fn load_mesh(
    path: &std::path::Path,
    asset: &AssetOptions,
) -> anyhow::Result<(modal_bake::mesh::TetMesh, f64)> {
    let t = std::time::Instant::now();
    if is_surface_asset(path) {
        let out = super::mesh::mesh_asset(path, asset)?;
        return Ok((out.mesh, t.elapsed().as_secs_f64()));
    }
    if asset.any_set() {
        anyhow::bail!(
            "--mesher, --size, --order, --envelope, --gmsh, --ftetwild, --keep-surface and --mesher-timeout apply to surface assets (.obj, .stl, .ply), not to the volume mesh {}",
            path.display()
        );
    }
    let mut mesh = modal_bake::mesh::read_mesh(path).map_err(anyhow::Error::new)?;
    if asset.units != super::mesh::Units::M {
        for p in &mut mesh.nodes {
            for c in p.iter_mut() {
                *c = asset.units.to_metres_of(*c);
            }
        }
    }
    Ok((mesh, t.elapsed().as_secs_f64()))
}

/// The optional bake-time peak-transfer table (`dcr_runtime::Method::Transfer`).
#[derive(Args, Clone, Debug)]
pub struct TransferOptions {
    /// Also store a peak-transfer table for this rigid-body step h (s): the peak normal
    /// displacement at every region vertex and edge midpoint per unit normal impulse at every
    /// other, with many modes (size ≈ (4 × region vertices)²/2 f32). The runtime uses it only
    /// for this h and the base's Rayleigh damping.
    #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
    pub transfer_h: Option<f64>,
    /// Modes the table sums: a count, `all` (dense eigensolve; small meshes) or `auto` (all up
    /// to 6000 free dofs, else 640) [default: auto].
    #[arg(long, value_name = "N|all|auto", requires = "transfer_h", value_parser = parse_modes)]
    pub transfer_modes: Option<TransferModes>,
    /// Region box (m, object frame), repeatable: surface vertices inside any box [default: the
    /// whole surface].
    #[arg(long, value_name = "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX", requires = "transfer_h", value_parser = parse::aabb, allow_hyphen_values = true)]
    pub transfer_region: Vec<[f64; 6]>,
    /// Keep only region vertices whose outward normal is within 60° of this direction (e.g.
    /// `0,0,1` for the top faces).
    #[arg(long, value_name = "DX,DY,DZ", requires = "transfer_h", value_parser = parse::vec3, allow_hyphen_values = true)]
    pub transfer_up: Option<[f64; 3]>,
    /// Peak-search oversampling of the table: T = π/(2 ω_max)/K for its highest mode [default: 1].
    #[arg(long, value_name = "K", requires = "transfer_h")]
    pub transfer_oversample: Option<f64>,
    /// Interpolation order over each region triangle: 1 (vertices), 2 (+ edge midpoints), 3
    /// (+ two points per edge and face centroids, ≈ 5× the size of 2), or auto (3 when its
    /// table has at most 5792 points, else 2).
    #[arg(long, value_name = "auto|1|2|3", requires = "transfer_h", value_parser = parse_order)]
    pub transfer_order: Option<TableOrder>,
}

fn parse_order(s: &str) -> Result<TableOrder, String> {
    match s.trim() {
        "auto" => Ok(TableOrder::Auto),
        "1" => Ok(TableOrder::Linear),
        "2" => Ok(TableOrder::Quadratic),
        "3" => Ok(TableOrder::Cubic),
        _ => Err(format!("expected auto, 1, 2 or 3, got `{s}`")),
    }
}

fn parse_modes(s: &str) -> Result<TransferModes, String> {
    if s.eq_ignore_ascii_case("all") {
        return Ok(TransferModes::All);
    }
    if s.eq_ignore_ascii_case("auto") {
        return Ok(TransferModes::Auto);
    }
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(TransferModes::Count(n)),
        _ => Err(format!(
            "expected a mode count ≥ 1, `all` or `auto`, got `{s}`"
        )),
    }
}

impl TransferOptions {
    /// The table's parameters, `None` without `--transfer-h`.
    pub fn params(&self) -> Option<TransferParams> {
        let h = self.transfer_h?;
        let d = TransferParams::default();
        Some(TransferParams {
            h,
            modes: self.transfer_modes.unwrap_or(d.modes),
            boxes: self.transfer_region.clone(),
            up: self.transfer_up,
            oversample: self.transfer_oversample.unwrap_or(d.oversample),
            order: self.transfer_order.unwrap_or(d.order),
            ..d
        })
    }
}

/// Progress of a bake on stderr: on a terminal a spinner per stage and a bar for the
/// eigensolve and the transfer table; otherwise (CI logs, redirected stderr) plain lines for the
/// stages longer than [`PLAIN_EVERY`]: one every `PLAIN_EVERY` while a stage that reports
/// progress runs, and one with its duration when it ends. Short bakes print nothing.
pub(super) struct Progress {
    pub(super) bar: ProgressBar,
    pub(super) plain: Option<Plain>,
}

/// Interval between plain progress lines, and the shortest stage that gets one (seconds;
/// `MODAL_BAKE_PROGRESS_EVERY` overrides it, e.g. 0 for every event).
const PLAIN_EVERY: Duration = Duration::from_secs(5);

/// State of the plain-line progress.
pub(super) struct Plain {
    every: Duration,
    start: std::time::Instant,
    stage: &'static str,
    label: String,
    stage_start: std::time::Instant,
    last: std::time::Instant,
}

impl Plain {
    fn line(&self, text: &str) {
        eprintln!("bake [{:7.1} s] {text}", self.start.elapsed().as_secs_f64());
    }

    /// Ends the current stage (a line with its duration if it was long).
    pub(super) fn end_stage(&mut self) {
        let took = self.stage_start.elapsed();
        if !self.stage.is_empty() && took >= self.every {
            self.line(&format!(
                "{}: done in {:.1} s",
                self.label,
                took.as_secs_f64()
            ));
        }
    }

    /// Records progress of `stage` described by `label`.
    fn report(&mut self, stage: &'static str, label: impl FnOnce() -> String) {
        let now = std::time::Instant::now();
        if stage != self.stage {
            self.end_stage();
            self.stage = stage;
            self.label = label();
            self.stage_start = now;
            self.last = now;
        } else if now.duration_since(self.last) >= self.every {
            self.label = label();
            self.line(&self.label);
            self.last = now;
        }
    }
}

impl Progress {
    pub(super) fn new() -> Progress {
        use std::io::IsTerminal;
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new_spinner();
            bar.enable_steady_tick(Duration::from_millis(120));
            Progress { bar, plain: None }
        } else {
            let now = std::time::Instant::now();
            Progress {
                bar: ProgressBar::hidden(),
                plain: Some(Plain {
                    every: std::env::var("MODAL_BAKE_PROGRESS_EVERY")
                        .ok()
                        .and_then(|s| s.parse::<f64>().ok())
                        .filter(|s| s.is_finite() && *s >= 0.0)
                        .map_or(PLAIN_EVERY, Duration::from_secs_f64),
                    start: now,
                    stage: "",
                    label: String::new(),
                    stage_start: now,
                    last: now,
                }),
            }
        }
    }

    pub(super) fn update(&mut self, stage: BakeStage) {
        if let Some(plain) = &mut self.plain {
            match stage {
                BakeStage::Read => plain.report("read", || "reading mesh".into()),
                BakeStage::Assemble => plain.report("assemble", || "assembling K and M".into()),
                BakeStage::Factor => plain.report("factor", || "factoring K − σM".into()),
                BakeStage::Eigensolve(p) => plain.report("eigensolve", || {
                    format!(
                        "eigensolve: {}/{} modes converged, Lanczos step {}",
                        p.converged.min(p.requested),
                        p.requested,
                        p.iteration
                    )
                }),
                BakeStage::TransferModes => plain.report("transfer modes", || {
                    "solving for the transfer table's modes".into()
                }),
                BakeStage::Transfer(p) => plain.report("transfer", || {
                    format!("transfer table: {}/{} rows", p.done, p.total)
                }),
                BakeStage::Write => plain.report("write", || "writing".into()),
            }
            return;
        }
        match stage {
            BakeStage::Read => self.bar.set_message("reading mesh"),
            BakeStage::Assemble => self.bar.set_message("assembling K and M"),
            BakeStage::Factor => self.bar.set_message("factoring K − σM"),
            BakeStage::Eigensolve(p) => {
                if self.bar.length().is_none() {
                    self.bar.set_style(
                        ProgressStyle::with_template(
                            "{spinner} eigensolve [{bar:30}] {pos}/{len} modes converged ({msg})",
                        )
                        .unwrap_or_else(|_| ProgressStyle::default_bar())
                        .progress_chars("=> "),
                    );
                    self.bar.set_length(p.requested as u64);
                }
                self.bar.set_length(p.requested as u64);
                self.bar.set_position(p.converged.min(p.requested) as u64);
                self.bar
                    .set_message(format!("Lanczos step {}", p.iteration));
            }
            BakeStage::TransferModes => {
                self.bar.set_style(ProgressStyle::default_spinner());
                self.bar
                    .set_message("solving for the transfer table's modes");
            }
            BakeStage::Transfer(p) => {
                if self.bar.length() != Some(p.total as u64) {
                    self.bar.set_style(
                        ProgressStyle::with_template(
                            "{spinner} transfer table [{bar:30}] {pos}/{len} rows ({eta} left)",
                        )
                        .unwrap_or_else(|_| ProgressStyle::default_bar())
                        .progress_chars("=> "),
                    );
                    self.bar.set_length(p.total as u64);
                }
                self.bar.set_position(p.done as u64);
            }
            BakeStage::Write => {
                self.bar.set_style(ProgressStyle::default_spinner());
                self.bar.set_message("writing");
            }
        }
    }
}

pub fn run(args: &BakeArgs) -> anyhow::Result<()> {
    super::check_output(&args.out, "-o", &[&args.mesh])?;
    args.options.model.check_ranges()?;
    if let Some(target) = args.target_error {
        return super::target::run(args, target);
    }
    let params = BakeParams {
        transfer: args.transfer.params(),
        ..args.options.params()
    };
    let mut progress = Progress::new();
    let units = args.asset.units;
    let report =
        if is_surface_asset(&args.mesh) || args.asset.any_set() || units != super::mesh::Units::M {
            progress.bar.finish_and_clear();
            let (mesh, read_s) = load_mesh(&args.mesh, &args.asset)?;
            progress = Progress::new();
            let file = args.mesh.display().to_string();
            bake::bake_mesh(mesh, &params, &file, &mut |s| progress.update(s))
                .map_err(anyhow::Error::new)
                .and_then(|(base, mut report)| {
                    report.read_s = read_s;
                    progress.update(BakeStage::Write);
                    let t = std::time::Instant::now();
                    super::create_parent(&args.out)?;
                    base.write_atomic(&args.out)?;
                    report.write_s = t.elapsed().as_secs_f64();
                    Ok(report)
                })
        } else {
            bake::bake_file(&args.mesh, &params, &args.out, &mut |s| progress.update(s))
                .map_err(anyhow::Error::new)
        };
    progress.bar.finish_and_clear();
    if let Some(plain) = &mut progress.plain {
        plain.end_stage();
    }
    let report = report
        .with_context(|| format!("baking {} failed; nothing was written", args.mesh.display()))?;
    if let Some(dir) = &report.created_folder {
        eprintln!("note: created folder {dir}");
    }
    if !is_surface_asset(&args.mesh) {
        super::mesh::warn_extent(
            &args.mesh.display().to_string(),
            report.extent_m,
            units,
            &format!(" and weighs {:.4e} kg", report.mass_kg),
        );
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&args.out, &report);
    }
    if args.timings {
        let (transfer_modes_s, transfer_s) = report
            .transfer
            .as_ref()
            .map_or((0.0, 0.0), |t| (t.modes_s, t.build_s));
        eprintln!(
            "timings (s): read {:.3}  assemble {:.3}  factor {:.3}  eigensolve {:.3}  transfer modes {:.3}  transfer table {:.3}  write {:.3}  total {:.3}",
            report.read_s,
            report.assemble_s,
            report.factor_s,
            report.eigensolve_s,
            transfer_modes_s,
            transfer_s,
            report.write_s,
            report.read_s
                + report.assemble_s
                + report.factor_s
                + report.eigensolve_s
                + transfer_modes_s
                + transfer_s
                + report.write_s
        );
    }
    Ok(())
}

pub(super) fn print_report(out: &std::path::Path, r: &BakeReport) {
    outln!("wrote {}", out.display());
    outln!(
        "  mesh: {} nodes, {} {}-node tets, {} free dofs, mass {:.6} kg",
        r.nodes,
        r.tets,
        if r.order == 2 { 10 } else { 4 },
        r.free_dofs,
        r.mass_kg
    );
    for n in &r.notes {
        outln!("  note: {n}");
    }
    if r.reoriented_tets > 0 {
        outln!("  reoriented {} inverted tetrahedra", r.reoriented_tets);
    }
    if r.rigid_modes_excluded > 0 {
        outln!(
            "  free-free: {} rigid-body modes detected (|λ| ≤ {:.2e} rad²/s²) and excluded",
            r.rigid_modes_excluded,
            r.rigid_eigenvalues
                .iter()
                .fold(0.0f64, |a, l| a.max(l.abs()))
        );
    } else {
        outln!("  fixed nodes: {}", r.fixed_nodes);
        for (what, n) in &r.fixed_by {
            outln!("    {what}: {n} nodes");
        }
    }
    if r.surface_edge_nodes > 0 {
        outln!(
            "  surface: {} vertices + {} mid-edge nodes, {} 6-node triangles",
            r.surface_vertices,
            r.surface_edge_nodes,
            r.surface_triangles
        );
    } else {
        outln!(
            "  surface: {} vertices, {} triangles",
            r.surface_vertices,
            r.surface_triangles
        );
    }
    let worst = r.residuals.iter().fold(0.0f64, |a, &b| a.max(b));
    outln!(
        "  {} modes, {:.3} Hz … {:.3} Hz, worst relative residual {:.1e}",
        r.modes,
        r.frequencies_hz.first().copied().unwrap_or(0.0),
        r.frequencies_hz.last().copied().unwrap_or(0.0),
        worst
    );
    if let Some(t) = &r.transfer {
        outln!(
            "  transfer table: order {}, {} points ({} region vertices, {} edges), {} modes ({}), {} samples per step, built in {:.2} s",
            t.order,
            t.points,
            t.vertices,
            t.edges,
            t.modes,
            t.mode_source,
            t.samples,
            t.modes_s + t.build_s
        );
    }
}
