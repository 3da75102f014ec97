//! `modal-bake bake`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use modal_bake::bake::{
    self, BakeParams, BakeReport, BakeStage, BaseStatus, ModeRequest, ModesPrecision,
};
use modal_bake::transfer::{TableOrder, TransferModes, TransferParams};

use super::bake_options::{meshing_pairs, options_line, selection_pairs};
use super::budget::BudgetOptions;
use super::mesh::AssetOptions;
use super::parse;
pub use super::progress::Progress;
use dcr_runtime::format::ModesFile;
pub use modal_bake::args::ModelOptions;
use modal_bake::mesh::surface::is_surface_asset;
use modal_bake::mesh::AssetKey;

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
            fixed_below: self.model.fixed_below.clone(),
            fixed_boxes: self.model.fixed_box.clone(),
            fixed_near: self.model.fixed_near(),
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
    /// meshio-style .json; or a surface asset .obj / .stl / .ply / .glb / .gltf, meshed first
    /// as `modal-bake mesh` does (--mesher, --size, --order, ...). Coordinates in metres unless
    /// --units says otherwise.
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
    #[command(flatten)]
    pub budget: BudgetOptions,
    /// With --transfer-h (the scene's step): choose the cheapest representation (modes; a
    /// transfer table, its modes and order) whose worst peak error against the bake's own
    /// converged full-order truth, at seeded pairs of the table region (--transfer-up /
    /// --transfer-region), is at most PCT percent; the estimate, query cost and size are stored
    /// in the base (`info` shows them); overrides --modes and --transfer-modes /
    /// --transfer-order. Each candidate table is held to --max-memory / --max-time (one over
    /// them is cut to the most modes that fit, or skipped and listed; --force builds it); the
    /// truth the candidates are scored against is not estimated (minutes on a mesh of a few
    /// thousand dofs). Without --transfer-h, for a surface asset: choose the mesh, refining
    /// --size (from its default) until the lowest five modes move by less than PCT percent
    /// between successive meshes, within the budget.
    #[arg(long, value_name = "PCT", conflicts_with = "max_freq")]
    pub target_error: Option<f64>,
}

impl BakeArgs {
    /// The modes of the transfer table this bake builds (`None` without `--transfer-h`).
    pub fn table_modes(&self) -> Option<TransferModes> {
        self.transfer.params().map(|t| t.modes)
    }
}

/// A mesh loaded for a bake or a check, and what its base records of how it was made.
pub struct Loaded {
    /// The tetrahedral mesh (m).
    pub mesh: modal_bake::mesh::TetMesh,
    /// Seconds reading or meshing took.
    pub seconds: f64,
    /// The key of a surface asset whose mesh is reproducible ([`AssetKey::of`]).
    pub asset_key: Option<AssetKey>,
}

/// The tetrahedral mesh of `path`: read (its `--object` physical volume, its `--piece`
/// connected piece, `--straighten`ed), or (a surface asset) meshed by the meshing chain, with
/// its [`AssetKey`]. Meshing options given with a volume mesh are an error.
pub fn load_mesh(path: &std::path::Path, asset: &AssetOptions) -> anyhow::Result<Loaded> {
    let t = std::time::Instant::now();
    if is_surface_asset(path) {
        let out = super::mesh::mesh_asset(path, asset)?;
        let asset_key = AssetKey::of(path, &asset.params()?, &out.report);
        return Ok(Loaded {
            mesh: out.mesh,
            seconds: t.elapsed().as_secs_f64(),
            asset_key,
        });
    }
    if asset.any_meshing_set() {
        anyhow::bail!(
            "--mesher, --size, --order, --envelope, --gmsh, --ftetwild, --keep-surface, --uniform-size and --mesher-timeout apply to surface assets (.obj, .stl, .ply, .glb, .gltf), not to the volume mesh {}",
            path.display()
        );
    }
    let mesh = asset.volume_selection().read(path)?;
    Ok(Loaded {
        mesh,
        seconds: t.elapsed().as_secs_f64(),
        asset_key: None,
    })
}

/// [`load_mesh`] with a progress stage for reading a volume mesh (meshing a surface asset
/// reports its own).
///
/// # Errors
/// As [`load_mesh`].
pub fn load_mesh_with_progress(
    path: &std::path::Path,
    asset: &AssetOptions,
) -> anyhow::Result<Loaded> {
    if is_surface_asset(path) {
        return load_mesh(path, asset);
    }
    let mut progress = Progress::new("bake");
    progress.update(BakeStage::Read);
    let result = load_mesh(path, asset);
    progress.finish();
    result
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

/// The asset options a bake meshes with: a transfer table needs 4-node tetrahedra, so without
/// `--order` a surface asset is meshed at order 1 when `table` (with a note on stderr).
pub fn asset_for(asset: &AssetOptions, table: bool, mesh: &std::path::Path) -> AssetOptions {
    if table && asset.order.is_none() && is_surface_asset(mesh) {
        eprintln!(
            "note: meshing {} at --order 1: the peak-transfer table (--transfer-h) needs 4-node tetrahedra",
            mesh.display()
        );
        return AssetOptions {
            order: Some(1),
            ..asset.clone()
        };
    }
    asset.clone()
}

impl BakeOptions {
    /// The modes the eigensolver will be asked for, for the size estimate: the count (20
    /// for a frequency request) plus six rigid-body modes.
    pub fn modes_for_estimate(&self) -> usize {
        self.modes.unwrap_or(20) + 6
    }
}

/// What a bake does before the factorization, once the mesh is in memory: the size estimate
/// against the budget (a refusal unless `--force`), and warnings about an implausible size
/// (unless `surface`: meshing already said it) or mass, naming the likely unit mistake.
/// `params`: what the bake makes (a transfer table's mode set is in the estimate; the table
/// itself is checked once its modes are known).
///
/// # Errors
/// The estimate over the budget.
pub fn before_factorization(
    file: &str,
    mesh: &modal_bake::mesh::TetMesh,
    options: &BakeOptions,
    params: &BakeParams,
    budget: &super::budget::BudgetOptions,
    units: super::mesh::Units,
    surface: bool,
) -> anyhow::Result<()> {
    budget.check_mesh(file, mesh, params)?;
    let extent = mesh.extent();
    let material = options.model.material();
    let mass = material.density * mesh.volume();
    if !surface {
        super::mesh::warn_extent(file, extent, units, &format!(" and weighs {mass:.4e} kg"));
    }
    let small = extent < bake::PLAUSIBLE_EXTENT_M[0];
    let warnings = bake::plausibility_warnings(small.then_some(extent), mass, &material, None);
    for w in warnings {
        eprintln!("warning: {file}: {w}");
    }
    Ok(())
}

/// Records in `base`'s free-form `meta.bake_params` where its material came from
/// (`material_choice`), what each fixed-node selector fixed (`fixed_by`), which part of the
/// input file `input` the base is and in which unit it was read ([`selection_record`]) and,
/// for a surface asset, the meshing options it was meshed with ([`meshing_record`]; `asset`
/// resolved by [`asset_for`]); none enters `params_hash` (the geometry hash covers the
/// selected mesh, in metres).
pub fn annotate(
    base: &mut ModesFile,
    options: &BakeOptions,
    asset: &AssetOptions,
    input: &std::path::Path,
    report: &BakeReport,
) {
    if let Some(obj) = base.meta.bake_params.as_object_mut() {
        obj.insert(
            "material_choice".into(),
            options.model.material_choice().to_json(),
        );
        obj.insert("fixed_by".into(), serde_json::json!(report.fixed_by));
        obj.insert("selection".into(), selection_record(asset).into());
        if is_surface_asset(input) {
            obj.insert("meshing".into(), meshing_record(asset).into());
        }
    }
}

/// Whether the base at `out` of the surface asset `path` is up to date without meshing the
/// asset again: its recorded [`AssetKey`] matches the asset now (its bytes, this build, the
/// meshers' versions), its recorded selection and meshing options are `asset`'s, and it is up
/// to date for `params` ([`bake::same_mesh_base_status`]). `false` means "mesh and compare"
/// (so a stale base's detail always comes from the real comparison), never "stale".
///
/// # Errors
/// Invalid parameters (as the full check).
pub fn unchanged_asset_up_to_date(
    path: &std::path::Path,
    asset: &AssetOptions,
    params: &BakeParams,
    out: &std::path::Path,
) -> anyhow::Result<bool> {
    if !is_surface_asset(path) {
        return Ok(false);
    }
    let Ok(base) = ModesFile::read(out) else {
        return Ok(false);
    };
    let record = &base.meta.bake_params;
    let Some(key) = record
        .get("asset_key")
        .and_then(|k| serde_json::from_value::<AssetKey>(k.clone()).ok())
    else {
        return Ok(false);
    };
    let same_options = record.get("selection").and_then(|v| v.as_object())
        == Some(&selection_record(asset))
        && record.get("meshing").and_then(|v| v.as_object()) == Some(&meshing_record(asset));
    let Ok(mesh_params) = asset.params() else {
        return Ok(false);
    };
    if !same_options || !key.matches_now(path, &mesh_params) {
        return Ok(false);
    }
    let file = path.display().to_string();
    Ok(bake::same_mesh_base_status(&file, params, &base)? == BaseStatus::UpToDate)
}

/// Records `provenance` in `base`'s `meta.bake_params` (`mesh_choice`, `asset_key`).
pub fn record_provenance(base: &mut ModesFile, provenance: Provenance) {
    if let Some(obj) = base.meta.bake_params.as_object_mut() {
        if let Some(choice) = provenance.mesh_choice {
            obj.insert("mesh_choice".into(), choice);
        }
        if let Some(key) = provenance.asset_key {
            obj.insert(
                "asset_key".into(),
                serde_json::to_value(key).expect("a key serialises"),
            );
        }
    }
}

/// The record `meta.bake_params.meshing` of the options a surface asset was meshed with:
/// `mesher` (`auto`, `gmsh`, `ftetwild`: the choice asked for), `size` (m; null: the
/// default), `order`, `envelope` (m; null: the default), `keep_surface`, `uniform_size`,
/// `thickness_sizing`.
pub fn meshing_record(asset: &AssetOptions) -> serde_json::Map<String, serde_json::Value> {
    let v = serde_json::json!({
        "mesher": asset.mesher.name(),
        "size": asset.size,
        "order": asset.order(),
        "envelope": asset.envelope,
        "keep_surface": asset.keep_surface,
        "uniform_size": asset.uniform_size,
        "thickness_sizing": !asset.no_thickness_sizing,
    });
    match v {
        serde_json::Value::Object(m) => m,
        _ => unreachable!("a JSON object literal"),
    }
}

/// The record `meta.bake_params.selection` of how the input was read: `object`, `piece` and
/// `straighten` when given, and always `units` (`m`, `cm`, `mm`, `in`).
pub fn selection_record(asset: &AssetOptions) -> serde_json::Map<String, serde_json::Value> {
    let mut selection = serde_json::Map::new();
    if let Some(o) = &asset.object {
        selection.insert("object".into(), o.clone().into());
    }
    if let Some(n) = asset.piece {
        selection.insert("piece".into(), n.into());
    }
    if asset.straighten {
        selection.insert("straighten".into(), true.into());
    }
    selection.insert("units".into(), asset.units.name().into());
    selection
}

/// When `base` was read from its file with another selection or unit than `asset` gives (its
/// recorded [`selection_record`]), the sentence that says so; `None` when they agree. A base
/// without the record (baked by an older tool) is compared on `object`, `piece` and
/// `straighten` only.
pub fn selection_mismatch(base: &ModesFile, asset: &AssetOptions) -> Option<String> {
    let mut recorded = base
        .meta
        .bake_params
        .get("selection")
        .and_then(|v| v.as_object())
        .cloned()
        .unwrap_or_default();
    let mut asked = selection_record(asset);
    if !recorded.contains_key("units") {
        asked.remove("units");
    }
    if recorded == asked {
        return None;
    }
    let show = |s: &mut serde_json::Map<String, serde_json::Value>| {
        let options = options_line(selection_pairs(s));
        let unit = if s.contains_key("units") {
            ""
        } else {
            " (unit not recorded)"
        };
        if options.is_empty() {
            format!("the whole file in metres{unit}")
        } else {
            format!("`{options}`{unit}")
        }
    };
    Some(format!(
        "the base was read from its file as {}, this as {}: give the bake's --object, --piece, --straighten and --units",
        show(&mut recorded),
        show(&mut asked)
    ))
}

/// When `base` was meshed from its surface asset with other meshing options than `asset`
/// (resolved by [`asset_for`]) gives (its recorded [`meshing_record`]), the sentence that says
/// so; `None` when they agree or the base records none.
pub fn meshing_mismatch(base: &ModesFile, asset: &AssetOptions) -> Option<String> {
    let recorded = base.meta.bake_params.get("meshing")?.as_object()?.clone();
    let asked = meshing_record(asset);
    if recorded == asked {
        return None;
    }
    let chosen = base
        .meta
        .bake_params
        .get("mesh_choice")
        .and_then(|c| c.get("target_error_pct"))
        .and_then(serde_json::Value::as_f64)
        .map(|p| format!(" (the --size `bake --target-error {p}` chose)"))
        .unwrap_or_default();
    Some(format!(
        "the base's asset was meshed with `{}`{chosen}, this with `{}`: give the bake's meshing options",
        options_line(meshing_pairs(&recorded)),
        options_line(meshing_pairs(&asked))
    ))
}

/// A stale status's one-line detail; when the geometry differs, led by how the base at `out`
/// was read or meshed differently from what `asset` asks ([`selection_mismatch`],
/// [`meshing_mismatch`]).
pub fn stale_detail(
    status: &BaseStatus,
    out: &std::path::Path,
    asset: &AssetOptions,
) -> Option<String> {
    let detail = status.detail()?.to_string();
    match status {
        BaseStatus::GeometryChanged(_) => {
            let base = ModesFile::read(out).ok();
            let mut parts: Vec<String> = base
                .iter()
                .flat_map(|b| [selection_mismatch(b, asset), meshing_mismatch(b, asset)])
                .flatten()
                .collect();
            parts.push(detail);
            Some(parts.join("; "))
        }
        _ => Some(detail),
    }
}

/// The checks every `bake` runs first (output path, option ranges, budget, the default
/// material's warning); returns the meshing options for the input.
///
/// # Errors
/// An output that must not be written, an option out of range, a malformed budget.
pub fn check_args(args: &BakeArgs) -> anyhow::Result<AssetOptions> {
    super::check_output(&args.out, "-o", &[&args.mesh])?;
    args.options.model.check_ranges()?;
    args.budget.budget()?;
    if let Some(w) = args.options.model.default_material_warning() {
        eprintln!("warning: {w}");
    }
    Ok(asset_for(
        &args.asset,
        args.transfer.transfer_h.is_some(),
        &args.mesh,
    ))
}

/// `bake` without `--target-error` (after [`check_args`]): reads or meshes the input, bakes
/// it and writes the base.
pub fn run(args: &BakeArgs, asset: &AssetOptions) -> anyhow::Result<()> {
    let params = BakeParams {
        transfer: args.transfer.params(),
        ..args.options.params()
    };
    if is_surface_asset(&args.mesh) {
        args.budget.check_surface(
            &args.mesh,
            asset,
            args.options.modes_for_estimate(),
            args.table_modes(),
        )?;
    }
    let loaded = load_mesh_with_progress(&args.mesh, asset)?;
    let provenance = Provenance {
        mesh_choice: None,
        asset_key: loaded.asset_key,
    };
    bake_loaded(
        args,
        asset,
        provenance,
        &params,
        loaded.mesh,
        loaded.seconds,
    )
}

/// What a base records of how its mesh was made, beside the options ([`annotate`]).
#[derive(Default)]
pub struct Provenance {
    /// `meta.bake_params.mesh_choice`: a mesh `--target-error` chose.
    pub mesh_choice: Option<serde_json::Value>,
    /// `meta.bake_params.asset_key`: what the mesh of a surface asset depends on.
    pub asset_key: Option<AssetKey>,
}

/// Bakes the mesh `--target-error` chose for a surface asset, meshed with `chosen` (the
/// chosen `--size`), as `bake` would.
///
/// # Errors
/// As `bake`.
pub fn bake_chosen_mesh(
    args: &BakeArgs,
    chosen: &AssetOptions,
    choice: serde_json::Value,
    mesh: modal_bake::mesh::TetMesh,
) -> anyhow::Result<()> {
    let params = BakeParams {
        transfer: args.transfer.params(),
        ..args.options.params()
    };
    let provenance = Provenance {
        mesh_choice: Some(choice),
        asset_key: None,
    };
    bake_loaded(args, chosen, provenance, &params, mesh, 0.0)
}

/// The checks before the factorization, the bake of a mesh in memory (read in `read_s`
/// seconds, with `asset`: the options it was read or meshed with, resolved by [`asset_for`]),
/// the record of the material, selectors and input (and the mesh's [`Provenance`]) and the
/// atomic write of `args.out`; `on_stage` sees each stage. Shared by `bake` and `batch`.
///
/// # Errors
/// The estimate over the budget, or a failed bake or write (nothing is written).
pub fn bake_and_write(
    args: &BakeArgs,
    asset: &AssetOptions,
    provenance: Provenance,
    params: &BakeParams,
    mesh: modal_bake::mesh::TetMesh,
    read_s: f64,
    on_stage: &mut dyn FnMut(BakeStage),
) -> anyhow::Result<BakeReport> {
    let surface = is_surface_asset(&args.mesh);
    let file = args.mesh.display().to_string();
    before_factorization(
        &file,
        &mesh,
        &args.options,
        params,
        &args.budget,
        args.asset.units,
        surface,
    )?;
    let mut params = params.clone();
    if let Some(t) = &mut params.transfer {
        t.budget = args.budget.table_budget()?;
    }
    bake::bake_mesh(mesh, &params, &file, &mut |s| on_stage(s))
        .map_err(|e| args.budget.explain_table_refusal(e))
        .and_then(|(mut base, mut report)| {
            report.read_s = read_s;
            report.material_name = args.options.model.material_choice().describe();
            annotate(&mut base, &args.options, asset, &args.mesh, &report);
            record_provenance(&mut base, provenance);
            on_stage(BakeStage::Write);
            let t = std::time::Instant::now();
            super::create_parent(&args.out)?;
            base.write_atomic(&args.out)?;
            report.write_s = t.elapsed().as_secs_f64();
            Ok(report)
        })
        .with_context(|| format!("baking {} failed; nothing was written", args.mesh.display()))
}

/// The bake of a mesh in memory (read in `read_s` seconds): the checks before the
/// factorization, the bake, the record of the material and selectors, the atomic write and
/// the report.
fn bake_loaded(
    args: &BakeArgs,
    asset: &AssetOptions,
    provenance: Provenance,
    params: &BakeParams,
    mesh: modal_bake::mesh::TetMesh,
    read_s: f64,
) -> anyhow::Result<()> {
    let file = args.mesh.display().to_string();
    let mut progress = Progress::new("bake");
    let report = bake_and_write(args, asset, provenance, params, mesh, read_s, &mut |s| {
        progress.update(s);
    });
    progress.finish();
    let report = report?;
    if let Some(w) = bake::plausibility_warnings(
        None,
        f64::NAN,
        &args.options.model.material(),
        report.frequencies_hz.first().copied(),
    )
    .into_iter()
    .find(|w| w.contains("lowest elastic mode"))
    {
        eprintln!("warning: {file}: {w}");
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
    if let Some(m) = &r.material {
        outln!(
            "  material: {}: E {:.4e} Pa, ν {}, ρ {} kg/m³",
            if r.material_name.is_empty() {
                "given"
            } else {
                r.material_name.as_str()
            },
            m.youngs,
            m.poisson,
            m.density
        );
    }
    outln!(
        "  element order {} ({}-node tetrahedra)",
        r.order,
        if r.order == 2 { 10 } else { 4 }
    );
    for n in &r.notes {
        outln!("  note: {n}");
    }
    if r.reoriented_tets > 0 {
        outln!("  reoriented {} inverted tetrahedra", r.reoriented_tets);
    }
    if r.rigid_modes_excluded > 0 {
        outln!(
            "  fixed: nothing (free-free): {} rigid-body modes detected (|λ| ≤ {:.2e} rad²/s²) and excluded",
            r.rigid_modes_excluded,
            r.rigid_eigenvalues
                .iter()
                .fold(0.0f64, |a, l| a.max(l.abs()))
        );
    } else {
        outln!("  fixed: {} nodes", r.fixed_nodes);
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
