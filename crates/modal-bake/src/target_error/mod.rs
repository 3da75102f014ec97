//! Choosing the representation by accuracy (`modal-bake bake --target-error PCT`): the
//! cheapest base — runtime modes, with or without a transfer table, its modes and order — whose
//! worst error against the bake's own full-order truth is below the target.
//!
//! The truth is [`crate::full_order`]'s, refined until it converges, at seeded impact/contact
//! pairs of the table's region (vertices and points inside triangles, [`ReferencePairs`]); each
//! candidate is read and stepped through `dcr_runtime::DistantResponse` exactly as an engine
//! does. Candidates, cheapest payload first: the lowest m ∈ {5, 10, 20, 40, 80, 160, 320, 640}
//! modes without a table, as long as their query costs at most twice the paper's 20 modes
//! (cost model: m·S multiply-adds per impact–contact pair, S = h/T samples at the paper's
//! T = π/(2ω_m)); then 20 modes with a table of 160 modes, then of every mode (dense solve) or
//! 640 (Lanczos), each quadratic then cubic (k² lookups per pair, k = 6 or 10 nodes). With a
//! budget ([`TransferParams::budget`]) a table candidate is planned first
//! ([`crate::transfer::TablePlan`]): over the budget, the every-mode candidate becomes the most
//! modes that fit (when more than any table tried before it) and any other is skipped
//! ([`Skipped`]), so a choice never starts a table its bake's budget refuses. The first
//! whose worst |error| over the pairs is at most the target is chosen; if none is, the one with
//! the smallest worst error, marked as not meeting it. The choice and its figures are stored
//! in the base ([`dcr_runtime::format::AccuracyRecord`]); they are deterministic, so the file is
//! too.
//!
//! For a surface asset without a transfer table, [`choose_mesh`] picks the mesh instead:
//! refined until the lowest modes move by less than the target.

mod mesh_choice;
mod reference_pairs;

pub use mesh_choice::{choose_mesh, MeshChoice, MeshStep, MAX_STEPS, REFINE};
pub use reference_pairs::{sample_points, PairsParams, ReferencePairs, SamplePoint, TruthProblem};

use std::sync::Arc;

use dcr_runtime::filter::{samples_per_step, Sampling};
use dcr_runtime::format::{AccuracyRecord, ModesFile};
use dcr_runtime::{Method, ModalModel};

use crate::bake::{
    bake_mesh, mode_set_from_dense, mode_set_lanczos, BakeError, BakeParams, BakeReport, BakeStage,
    ModeRequest,
};
use crate::full_order::{FullOrderSystem, ModalAll, SystemParams};
use crate::mesh::TetMesh;
use crate::transfer::{
    build_transfer_table, select_region, OverBudget, TableOrder, TransferError, TransferModes,
    TransferParams, AUTO_LANCZOS_MODES, DENSE_MAX_DOFS, UP_MIN_COS,
};

/// Modal candidates (modes), cheapest first.
pub const MODAL_CANDIDATES: [usize; 8] = [5, 10, 20, 40, 80, 160, 320, 640];

/// Modes of the runtime base under a table candidate.
pub const TABLE_BASE_MODES: usize = 20;

/// What a candidate is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Representation {
    /// m modal filters, no table.
    Modal(usize),
    /// The 20-mode base with a table of this many modes (`None`: every mode of the set) and
    /// order.
    Table(Option<usize>, u8),
}

/// One candidate's measured accuracy and cost.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// What it is.
    pub representation: Representation,
    /// Median |error| (%).
    pub median_pct: f64,
    /// Worst |error| (%).
    pub worst_pct: f64,
    /// Query cost model (multiply-adds per impact–contact pair).
    pub query_cost: f64,
    /// Payload bytes (mode rows and table entries).
    pub payload_bytes: u64,
    /// Wall time of building its table (s); 0 without one.
    pub build_s: f64,
}

/// A table candidate not built: its [`crate::transfer::TablePlan`] is over the bake's budget
/// ([`TransferParams::budget`]) and no smaller table of its order has more modes than the
/// tables tried before it.
#[derive(Clone, Debug)]
pub struct Skipped {
    /// What it would have been.
    pub representation: Representation,
    /// Its plan, the budget and what would fit.
    pub over_budget: Box<OverBudget>,
}

/// What [`bake_to_target`] made.
#[derive(Clone, Debug)]
pub struct TargetBake {
    /// The chosen base (its `meta.accuracy` records the choice).
    pub base: ModesFile,
    /// The bake's report (the chosen base's modes and table).
    pub report: BakeReport,
    /// Every candidate scored, in the order tried.
    pub tried: Vec<Candidate>,
    /// Table candidates over the budget, not built.
    pub skipped: Vec<Skipped>,
}

/// The candidates scored so far, and the most accurate one's base (kept, so a choice that
/// meets no target writes it without building it again).
#[derive(Default)]
struct Tried {
    all: Vec<Candidate>,
    best: Option<(ModesFile, Candidate)>,
}

impl Tried {
    /// Records `c`, scored on base `b`.
    fn push(&mut self, b: &ModesFile, c: &Candidate) {
        let better = self
            .best
            .as_ref()
            .is_none_or(|(_, x)| c.worst_pct.total_cmp(&x.worst_pct).is_lt());
        if better {
            self.best = Some((b.clone(), c.clone()));
        }
        self.all.push(c.clone());
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// m·S: the modal query's multiply-adds per pair for the lowest `m` modes of `base` at step h.
fn modal_cost(base: &ModesFile, m: usize, h: f64) -> f64 {
    let w = base.eigenvalues[m - 1].max(0.0).sqrt();
    (m * samples_per_step(h, Sampling::PaperT.period(w))) as f64
}

/// Mode rows payload of `m` modes (bytes).
fn modal_bytes(base: &ModesFile, m: usize) -> u64 {
    let per = match base.precision {
        dcr_runtime::format::ModesPrecision::F32 => 4,
        dcr_runtime::format::ModesPrecision::F64 => 8,
    };
    (base.num_surface_vertices() * 3 * m * per) as u64
}

fn score(pairs: &ReferencePairs, base: ModesFile) -> (f64, f64) {
    let model = Arc::new(ModalModel::from_base(base).expect("a base built here is valid"));
    let mut dr = pairs.response(model, Method::Transfer);
    let (errors, _) = pairs.errors(&mut dr, 1.0);
    let mut abs: Vec<f64> = errors.iter().map(|(e, _)| e.abs()).collect();
    let worst = abs.iter().fold(0.0f64, |a, b| a.max(*b));
    (median(&mut abs), worst)
}

/// Bakes `mesh` into the cheapest representation whose worst error at the seeded pairs of the
/// table region (`transfer`: h, boxes, up direction; its modes and order are chosen here) is at
/// most `target_pct` (see the module docs). `pairs`: sampling and truth settings (its h is
/// taken from `transfer`). With `transfer.budget` set, a table candidate whose plan is over it
/// is not built: the every-mode candidate becomes the most modes that fit (when more than any
/// table tried before it), any other is [`Skipped`].
///
/// # Errors
/// [`BakeError`] from the bakes; [`BakeError::Transfer`] for a bad target or region, a truth or
/// table that cannot be computed.
pub fn bake_to_target(
    mesh: TetMesh,
    params: &BakeParams,
    transfer: &TransferParams,
    target_pct: f64,
    pairs_params: &PairsParams,
    file: &str,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<TargetBake, BakeError> {
    let terr = |error| BakeError::Transfer {
        file: file.to_string(),
        error: Box::new(error),
    };
    if !(target_pct.is_finite() && target_pct > 0.0) {
        return Err(terr(TransferError::Params(format!(
            "the target error must be a percentage > 0, got {target_pct}"
        ))));
    }
    transfer.check().map_err(terr)?;
    let base_params = BakeParams {
        modes: ModeRequest::Count(TABLE_BASE_MODES),
        transfer: None,
        ..params.clone()
    };
    let (base20, report20) = bake_mesh(mesh.clone(), &base_params, file, progress)?;
    let dofs = report20.free_dofs;
    let model20 = ModalModel::from_base(base20.clone()).expect("a baked base is valid");
    let region = select_region(&model20, &transfer.boxes, transfer.up, transfer.up_min_cos);
    if region.is_empty() {
        return Err(terr(TransferError::Params(
            "the region (boxes / up direction) selects no surface vertex".into(),
        )));
    }
    // The many-mode set: every mode (dense) or 640 (Lanczos); modal candidates truncate it.
    progress(BakeStage::TransferModes);
    let set_start = std::time::Instant::now();
    let sp = SystemParams::of_bake(params);
    let sys = FullOrderSystem::new(mesh.clone(), &sp, file).map_err(|e| terr(e.into()))?;
    let dense = dofs <= DENSE_MAX_DOFS;
    let ma = if dense {
        Some(ModalAll::new(&sys, DENSE_MAX_DOFS).map_err(|e| terr(e.into()))?)
    } else {
        None
    };
    let set = match &ma {
        Some(m) => mode_set_from_dense(&base20, &sys, m, m.eigenvalues.len()),
        None => mode_set_lanczos(&mesh, &base_params, AUTO_LANCZOS_MODES, file)?,
    };
    let modes_s = set_start.elapsed().as_secs_f64();
    let pp = PairsParams {
        h: transfer.h,
        ..pairs_params.clone()
    };
    let pairs = ReferencePairs::new(&sys, ma.as_ref(), &base20, &region, &pp, &mut |p| {
        progress(BakeStage::Truth(p))
    })
    .map_err(|e| terr(e.into()))?;
    drop(ma);
    let h = transfer.h;
    let cost20 = modal_cost(&set, TABLE_BASE_MODES.min(set.num_modes()), h);
    let mut tried = Tried::default();
    let mut skipped: Vec<Skipped> = Vec::new();
    let mut chosen = try_modal(&set, &base20, &pairs, h, cost20, target_pct, &mut tried);
    if chosen.is_none() {
        chosen = try_tables(
            &set,
            &base20,
            &pairs,
            transfer,
            params.rayleigh,
            target_pct,
            &mut tried,
            &mut skipped,
            progress,
        )
        .map_err(terr)?;
    }
    let met = chosen.is_some();
    let (mut base, c) = match chosen {
        Some(x) => x,
        // The most accurate tried.
        None => tried.best.take().expect("a candidate at least"),
    };
    record_accuracy(
        &mut base, &c, met, &pairs, params, transfer, target_pct, cost20,
    );
    let mut report = report20;
    report.modes = base.num_modes();
    report.frequencies_hz = base.frequencies_hz();
    report.residuals = base.residuals.clone();
    report.transfer = base.transfer.as_ref().map(|t| {
        let source = if dense { "dense" } else { "lanczos" };
        crate::bake::TransferReport::of(t, source, modes_s, c.build_s)
    });
    Ok(TargetBake {
        base,
        report,
        tried: tried.all,
        skipped,
    })
}

/// The first modal candidate (the lowest m of [`MODAL_CANDIDATES`] costing at most twice the
/// 20-mode query) whose worst error is within `target_pct`; every one scored is pushed to
/// `tried`.
fn try_modal(
    set: &ModesFile,
    base20: &ModesFile,
    pairs: &ReferencePairs,
    h: f64,
    cost20: f64,
    target_pct: f64,
    tried: &mut Tried,
) -> Option<(ModesFile, Candidate)> {
    for &m in MODAL_CANDIDATES.iter().filter(|&&m| m <= set.num_modes()) {
        let cost = modal_cost(set, m, h);
        if cost > 2.0 * cost20 {
            break;
        }
        let b = crate::target_error::truncate(set, base20, m);
        let (median_pct, worst_pct) = score(pairs, b.clone());
        let c = Candidate {
            representation: Representation::Modal(m),
            median_pct,
            worst_pct,
            query_cost: cost,
            build_s: 0.0,
            payload_bytes: modal_bytes(set, m),
        };
        tried.push(&b, &c);
        if worst_pct <= target_pct {
            return Some((b, c));
        }
    }
    None
}

/// The first table candidate (160 modes or every mode, quadratic then cubic, over the 20-mode
/// base) whose worst error is within `target_pct`; every one scored is pushed to `tried`, every
/// one over `transfer.budget` to `skipped` (the every-mode one first tries the most modes that
/// fit, when more than any table tried before it).
///
/// # Errors
/// A table that cannot be built (a cubic table too large for the format is skipped).
#[allow(clippy::too_many_arguments)]
fn try_tables(
    set: &ModesFile,
    base20: &ModesFile,
    pairs: &ReferencePairs,
    transfer: &TransferParams,
    rayleigh: [f64; 2],
    target_pct: f64,
    tried: &mut Tried,
    skipped: &mut Vec<Skipped>,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<Option<(ModesFile, Candidate)>, TransferError> {
    let mut variants: Vec<(TransferModes, TableOrder)> = Vec::new();
    for modes in [TransferModes::Count(160), TransferModes::All] {
        for order in [TableOrder::Quadratic, TableOrder::Cubic] {
            variants.push((modes, order));
        }
    }
    // The most modes of a table tried so far: a table cut to fit the budget is only tried with
    // more (fewer modes lose more than a higher order gains: on the npm bunny at h = 10 ms, a
    // cubic table of 265 modes is 51 % worst where a quadratic one of 1,053 is 15 %).
    let mut most_tried = 0;
    for (modes, order) in variants {
        if matches!(modes, TransferModes::Count(n) if n >= set.num_modes()) {
            continue;
        }
        let mut tp = TransferParams {
            modes,
            order,
            ..transfer.clone()
        };
        let mut build = |tp: &TransferParams| {
            build_transfer_table(set, tp, rayleigh, &mut |p| progress(BakeStage::Transfer(p)))
        };
        let start = std::time::Instant::now();
        let table = match build(&tp) {
            Ok(t) => t,
            // A cubic table too large for the format: the quadratic one stands.
            Err(TransferError::Params(_)) if order == TableOrder::Cubic => continue,
            Err(TransferError::OverBudget(over)) => {
                let most = match modes {
                    TransferModes::All => {
                        over.most_modes.map(|p| p.modes).filter(|&m| m > most_tried)
                    }
                    _ => None,
                };
                let Some(m) = most else {
                    skipped.push(Skipped {
                        representation: Representation::Table(
                            matches!(modes, TransferModes::Count(_)).then_some(over.plan.modes),
                            over.plan.order,
                        ),
                        over_budget: over,
                    });
                    continue;
                };
                tp.modes = TransferModes::Count(m);
                build(&tp)?
            }
            Err(e) => return Err(e),
        };
        let k = match table.order {
            1 => 3.0,
            2 => 6.0,
            _ => 10.0,
        };
        let payload = modal_bytes(base20, TABLE_BASE_MODES) + 4 * table.peaks.len() as u64;
        let representation = Representation::Table(
            matches!(tp.modes, TransferModes::Count(_)).then_some(table.modes as usize),
            table.order,
        );
        let build_s = start.elapsed().as_secs_f64();
        most_tried = most_tried.max(table.modes as usize);
        let mut b = base20.clone();
        b.transfer = Some(table);
        let (median_pct, worst_pct) = score(pairs, b.clone());
        let c = Candidate {
            representation,
            median_pct,
            worst_pct,
            query_cost: k * k,
            build_s,
            payload_bytes: payload,
        };
        tried.push(&b, &c);
        if worst_pct <= target_pct {
            return Ok(Some((b, c)));
        }
    }
    Ok(None)
}

/// Records the chosen candidate `c` in `base`: `meta.accuracy`, and in `meta.bake_params` the
/// target and the parameters of what was chosen as `bake` records them — the mode count, and
/// the table's full record (`transfer` with the chosen modes and order) — with `params_hash`
/// of those parameters, so that `check` with [`check_options`] finds the base up to date.
#[allow(clippy::too_many_arguments)]
fn record_accuracy(
    base: &mut ModesFile,
    c: &Candidate,
    met: bool,
    pairs: &ReferencePairs,
    params: &BakeParams,
    transfer: &TransferParams,
    target_pct: f64,
    cost20: f64,
) {
    let table_modes = base.transfer.as_ref().map(|t| t.modes as usize);
    let table_order = base.transfer.as_ref().map(|t| t.order);
    base.meta.accuracy = Some(AccuracyRecord {
        target_pct,
        met,
        median_pct: c.median_pct,
        worst_pct: c.worst_pct,
        pairs: pairs.pairs(),
        h: transfer.h,
        truth: pairs.truth_method.into(),
        truth_dt: pairs.truth.dt,
        truth_error_pct: 100.0 * pairs.truth.estimated_error,
        modes: base.num_modes(),
        table_modes,
        table_order,
        query_cost: c.query_cost,
        query_cost_20: cost20,
        payload_bytes: c.payload_bytes,
    });
    let recorded = BakeParams {
        modes: ModeRequest::Count(base.num_modes()),
        transfer: None,
        ..params.clone()
    };
    base.meta.params_hash = recorded.hash();
    let table = base.transfer.as_ref().map(|t| {
        let chosen = TransferParams {
            modes: TransferModes::Count(t.modes as usize),
            order: match t.order {
                1 => TableOrder::Linear,
                2 => TableOrder::Quadratic,
                _ => TableOrder::Cubic,
            },
            ..transfer.clone()
        };
        crate::bake::transfer_meta(&chosen, params)
    });
    if let Some(obj) = base.meta.bake_params.as_object_mut() {
        obj.insert(
            "modes".into(),
            serde_json::to_value(recorded.modes).expect("a mode request serialises"),
        );
        if let Some(table) = table {
            obj.insert("transfer".into(), table);
        }
        obj.insert("target_error_pct".into(), serde_json::json!(target_pct));
    }
}

/// For a base `bake --target-error` chose (it records `target_error_pct`), how `modal-bake
/// check` is given the choice with the bake's other options: `--modes M`, and for a table
/// `--transfer-modes N --transfer-order O`, in place of `--target-error` — a modal choice
/// without `--transfer-h` and the other `--transfer-*` options (it has no table); `None` for
/// any other base.
pub fn check_options(base: &ModesFile) -> Option<String> {
    base.meta.bake_params.get("target_error_pct")?;
    let modes = base.num_modes();
    Some(match &base.transfer {
        Some(t) => format!(
            "`--modes {modes} --transfer-modes {} --transfer-order {}` in place of --target-error",
            t.modes, t.order
        ),
        None => format!(
            "`--modes {modes}` in place of --target-error, without --transfer-h and the other --transfer-* options"
        ),
    })
}

/// The lowest `m` modes of the mode set `set` in the layout and metadata of `base20` (same
/// surface), with `m` as the recorded mode request.
pub fn truncate(set: &ModesFile, base20: &ModesFile, m: usize) -> ModesFile {
    let mm = set.num_modes();
    let mut b = base20.clone();
    b.modes = set
        .modes
        .chunks_exact(mm)
        .flat_map(|row| row[..m].iter().copied())
        .collect();
    b.eigenvalues = set.eigenvalues[..m].to_vec();
    b.residuals = set.residuals[..m].to_vec();
    b.transfer = None;
    if let Some(obj) = b.meta.bake_params.as_object_mut() {
        obj.insert("modes".into(), serde_json::json!({ "count": m }));
    }
    b
}

/// The region helper shared with the lab: `select_region` with the default cosine.
pub fn region_of(model: &ModalModel, boxes: &[[f64; 6]], up: Option<[f64; 3]>) -> Vec<u32> {
    select_region(model, boxes, up, UP_MIN_COS)
}
