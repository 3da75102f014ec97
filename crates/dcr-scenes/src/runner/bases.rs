//! Modal bases for a scene's elastic objects: baked on demand into `out/bases/`, rebaked
//! when the mesh or the bake parameters change (content hashes, `modal_bake::bake::is_up_to_date`,
//! which also compares a base's transfer-table parameters).
//!
//! Each object has up to two bases: `NAME.modes` (the modal base every method but the transfer
//! table reads) and `NAME.transfer.modes` (the same modes plus the bake-time peak-transfer
//! table, baked only when a run asks for `transfer`). The two never share a file, so baking a
//! table leaves the modal base and the runs that read it untouched.
//!
//! An on-demand bake is sized first, as `modal-bake bake` sizes it: the mesh's modes and a
//! table's mode set before anything is solved ([`SizeEstimate::of_bake`]), the table itself
//! once its modes are known (`modal_bake::transfer::TablePlan`); over the run's budget
//! ([`RunParams::bake_budget`](super::RunParams::bake_budget)) the bake is refused with the
//! estimate and the scene settings that lower it. Progress goes to stderr.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use modal_bake::bake::{
    format_bytes, format_seconds, BakeParams, BakeStage, Budget, MaterialSi, ModeRequest,
    SizeEstimate,
};
use modal_bake::transfer::{TableOrder, TransferModes, TransferParams};

use crate::scene::{ElasticDesc, TableOrderDesc, TransferDesc};

/// The bake parameters of an elastic object (material, modes, fixed nodes, Rayleigh).
pub fn bake_params(e: &ElasticDesc) -> BakeParams {
    BakeParams {
        material: MaterialSi {
            youngs: e.material.youngs,
            poisson: e.material.poisson,
            density: e.material.density,
        },
        modes: ModeRequest::Count(e.modes),
        fixed: e.fixed.clone(),
        fixed_below: e.fixed_below(),
        fixed_boxes: e.fixed_boxes.clone(),
        rayleigh: e.rayleigh,
        ..BakeParams::default()
    }
}

/// The fixed-node selectors of `e` in words: `groups ["feet"]`, `y ≤ 0.01 m`, `box [..]`,
/// joined by `+`; `nothing (free-free)` when none is given.
fn fixed_summary(e: &ElasticDesc) -> String {
    let mut parts = Vec::new();
    if !e.fixed.is_empty() {
        parts.push(format!("groups {:?}", e.fixed));
    }
    parts.extend(
        e.fixed_below
            .iter()
            .map(|b| format!("{} ≤ {} m", ["x", "y", "z"][b.axis as usize], b.value)),
    );
    parts.extend(e.fixed_boxes.iter().map(|b| format!("box {b:?} m")));
    if parts.is_empty() {
        "nothing (free-free)".into()
    } else {
        parts.join(" + ")
    }
}

/// The transfer-table parameters of elastic object `e` with settings `t`, for a scene stepping
/// `h` (s): the table is baked for that step. The default mode count (`t.modes` unset) is
/// `TransferModes::Auto`: every mode when the mesh has at most `DENSE_MAX_DOFS` free dofs, else
/// `AUTO_LANCZOS_MODES`.
///
/// # Errors
/// `t.h` is set and differs from `h` (relative tolerance 1e-9, the runtime's): a table serves
/// one step only. The message names the object and both steps.
pub fn transfer_params(e: &ElasticDesc, t: &TransferDesc, h: f64) -> Result<TransferParams> {
    if let Some(th) = t.h {
        if !((th - h).abs() <= 1e-9 * h.abs()) {
            bail!(
                "elastic object {}: its transfer table is pinned to h = {th} s but the scene steps \
                 h = {h} s; a table serves one step only (set `transfer.h` to {h} or remove it to \
                 bake the table for the scene's step)",
                e.name
            );
        }
    }
    Ok(TransferParams {
        h,
        modes: match t.modes {
            Some(n) => TransferModes::Count(n),
            None => TransferModes::Auto,
        },
        boxes: t.boxes.clone(),
        up: t.up,
        order: match t.order {
            TableOrderDesc::Auto => TableOrder::Auto,
            TableOrderDesc::Linear => TableOrder::Linear,
            TableOrderDesc::Quadratic => TableOrder::Quadratic,
            TableOrderDesc::Cubic => TableOrder::Cubic,
        },
        ..TransferParams::default()
    })
}

/// Where an elastic object's modal base lives (`NAME.modes`).
pub fn base_path(bases_dir: &Path, e: &ElasticDesc) -> PathBuf {
    bases_dir.join(format!("{}.modes", e.name))
}

/// Where an elastic object's base with a transfer table lives (`NAME.transfer.modes`), beside
/// and distinct from its modal base.
///
/// ```
/// use std::path::Path;
/// use dcr_scenes::runner::{base_path, transfer_base_path};
/// use dcr_scenes::scene::ElasticDesc;
/// let e: ElasticDesc = serde_json::from_str(
///     r#"{"name": "floor", "mesh": "data/scenes/floor.msh",
///         "material": {"youngs": 1e10, "poisson": 0.3, "density": 540},
///         "body": "static", "method": {"transfer": {"up": [0, 1, 0]}}}"#,
/// )
/// .unwrap();
/// let dir = Path::new("out/bases");
/// assert_eq!(base_path(dir, &e), dir.join("floor.modes"));
/// assert_eq!(transfer_base_path(dir, &e), dir.join("floor.transfer.modes"));
/// ```
pub fn transfer_base_path(bases_dir: &Path, e: &ElasticDesc) -> PathBuf {
    bases_dir.join(format!("{}.transfer.modes", e.name))
}

/// A base whose surface shows object `e` (the modal base, or the transfer base when only that
/// one was baked: both hold the same surface).
pub fn surface_base_path(bases_dir: &Path, e: &ElasticDesc) -> PathBuf {
    let modal = base_path(bases_dir, e);
    let transfer = transfer_base_path(bases_dir, e);
    if !modal.exists() && transfer.exists() {
        transfer
    } else {
        modal
    }
}

/// Bakes `e`'s modal base into `bases_dir` unless an up-to-date one is there, refusing a bake
/// whose estimate is over `budget` (`None`: no limit). Returns the path and whether it baked.
/// Progress on stderr.
///
/// # Errors
/// Mesh or bake failures, with the mesh path; a bake over the budget.
pub fn ensure_base(
    root: &Path,
    bases_dir: &Path,
    e: &ElasticDesc,
    budget: Option<Budget>,
) -> Result<(PathBuf, bool)> {
    ensure(root, &base_path(bases_dir, e), e, &bake_params(e), budget)
}

/// Bakes `e`'s base with the peak-transfer table `t` for step `h` (s) into `bases_dir`
/// (`NAME.transfer.modes`) unless an up-to-date one is there (same mesh, bake and table
/// parameters), refusing a bake or a table whose estimate is over `budget` (`None`: no limit).
/// Returns the path and whether it baked. Progress on stderr.
///
/// # Errors
/// As [`transfer_params`]; mesh, bake or table failures (an empty region among them), with the
/// object and the mesh path; a bake or a table over the budget.
pub fn ensure_transfer_base(
    root: &Path,
    bases_dir: &Path,
    e: &ElasticDesc,
    t: &TransferDesc,
    h: f64,
    budget: Option<Budget>,
) -> Result<(PathBuf, bool)> {
    let params = BakeParams {
        transfer: Some(TransferParams {
            budget,
            ..transfer_params(e, t, h)?
        }),
        ..bake_params(e)
    };
    ensure(root, &transfer_base_path(bases_dir, e), e, &params, budget)
}

/// How to run a refused bake anyway (the `dcr-scenes` options).
const BUDGET_HINT: &str = "or raise --max-bake-memory / --max-bake-time, or pass --force-bake";

/// Bakes `e`'s mesh with `params` to `out` unless `out` is up to date.
fn ensure(
    root: &Path,
    out: &Path,
    e: &ElasticDesc,
    params: &BakeParams,
    budget: Option<Budget>,
) -> Result<(PathBuf, bool)> {
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mesh = root.join(&e.mesh);
    let fresh = modal_bake::bake::is_up_to_date(&mesh, params, out).with_context(|| {
        format!(
            "elastic object {}: checking base of {}",
            e.name,
            mesh.display()
        )
    })?;
    if fresh {
        return Ok((out.to_path_buf(), false));
    }
    let table = match &params.transfer {
        None => String::new(),
        Some(t) => format!(
            " with a transfer table (h {} s, {}, {} region boxes)",
            t.h,
            t.up.map_or("every direction".into(), |u| format!(
                "faces within {:.0}° of ({}, {}, {})",
                t.up_min_cos.acos().to_degrees(),
                u[0],
                u[1],
                u[2]
            )),
            t.boxes.len()
        ),
    };
    let tet_mesh = modal_bake::mesh::read_mesh(&mesh)
        .with_context(|| format!("elastic object {}: reading {}", e.name, mesh.display()))?;
    let estimate = SizeEstimate::of_bake(&tet_mesh, params);
    drop(tet_mesh);
    eprintln!(
        "[dcr-scenes] baking {} ({} modes, fixed {}){table} -> {}: {}",
        e.name,
        e.modes,
        fixed_summary(e),
        out.display(),
        estimate.describe()
    );
    if let Some(b) = budget.filter(|b| !estimate.fits(b)) {
        let mut how = vec![
            "a coarser mesh".to_string(),
            format!("fewer `modes` (now {})", e.modes),
        ];
        if estimate.table_modes_s > 0.0 {
            how.push("a `transfer.modes` count of at most `modes` (no second solve)".into());
        }
        bail!(
            "elastic object {}: refused before baking {}: estimated {} is over the budget of {} and {}; to lower it: {}; {BUDGET_HINT}",
            e.name,
            mesh.display(),
            estimate.describe(),
            format_seconds(b.max_seconds),
            format_bytes(b.max_bytes),
            how.join(", or ")
        );
    }
    let t = std::time::Instant::now();
    let mut reporter = StageReporter::new(&e.name);
    let report = match modal_bake::bake::bake_file(&mesh, params, out, &mut |s| reporter.update(s))
    {
        Ok(r) => r,
        Err(err) if err.is_table_over_budget() => {
            bail!("elastic object {}: {err}; {BUDGET_HINT}", e.name)
        }
        Err(err) => {
            return Err(anyhow::Error::new(err).context(format!(
                "elastic object {}: baking {}",
                e.name,
                mesh.display()
            )))
        }
    };
    let table = match &report.transfer {
        None => String::new(),
        Some(r) => format!(
            "; table: order {}, {} points ({} region vertices), {} modes ({}), {} samples per step, modes {:.1} s + table {:.1} s",
            r.order, r.points, r.vertices, r.modes, r.mode_source, r.samples, r.modes_s, r.build_s
        ),
    };
    eprintln!(
        "[dcr-scenes] baked {} in {:.1} s ({} nodes, {} tets){table}",
        e.name,
        t.elapsed().as_secs_f64(),
        report.nodes,
        report.tets
    );
    Ok((out.to_path_buf(), true))
}

/// Progress lines of an on-demand bake on stderr: each stage once, the table's plan when its
/// build starts and its rows at most every 5 s.
struct StageReporter<'a> {
    name: &'a str,
    stage: &'static str,
    last_rows: Option<std::time::Instant>,
}

impl<'a> StageReporter<'a> {
    fn new(name: &'a str) -> Self {
        StageReporter {
            name,
            stage: "",
            last_rows: None,
        }
    }

    fn update(&mut self, s: BakeStage) {
        let (stage, what) = match s {
            BakeStage::Read | BakeStage::Write | BakeStage::Truth(_) => return,
            BakeStage::Assemble => ("assemble", s.label()),
            BakeStage::Factor => ("factor", s.label()),
            BakeStage::Eigensolve(_) => ("eigensolve", s.label()),
            BakeStage::TransferModes => ("transfer modes", s.label()),
            BakeStage::Transfer(p) => {
                let now = std::time::Instant::now();
                let first = self.stage != "transfer";
                if first {
                    eprintln!(
                        "[dcr-scenes] {}: building the transfer table: {}",
                        self.name,
                        p.plan.describe()
                    );
                } else if p.done < p.total
                    && self
                        .last_rows
                        .is_some_and(|t| now.duration_since(t).as_secs_f64() < 5.0)
                {
                    return;
                }
                self.stage = "transfer";
                self.last_rows = Some(now);
                if !first {
                    eprintln!(
                        "[dcr-scenes] {}: transfer table {}/{} rows",
                        self.name, p.done, p.total
                    );
                }
                return;
            }
        };
        if stage != self.stage {
            self.stage = stage;
            eprintln!("[dcr-scenes] {}: {what}", self.name);
        }
    }
}
