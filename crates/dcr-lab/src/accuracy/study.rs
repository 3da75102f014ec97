//! One object's study: seeded impact/contact points in its region, the converged full-order
//! truth there, and every method's peaks through the runtime (`DistantResponse`), with their
//! errors, query cost, bake time and base size.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use dcr_runtime::format::ModesFile;
use dcr_runtime::response::{Impact, RestingContact, ServedBy};
use dcr_runtime::{DistantResponse, Method, ModalModel};
use modal_bake::bake::{bake_mesh, BakeError, BakeParams, ModeRequest};
use modal_bake::bake::{mode_set_from_dense, mode_set_lanczos};
use modal_bake::full_order::{
    converged_peaks, ConvergedPeaks, FullOrderSystem, ModalAll, PeakSolver, PeakWindow,
    RefineParams, SystemParams,
};
use modal_bake::mesh::TetMesh;
use modal_bake::target_error::{PairsParams, ReferencePairs};
use modal_bake::transfer::{
    build_transfer_table, select_region, TableOrder, TransferModes, TransferParams,
    AUTO_LANCZOS_MODES, DENSE_MAX_DOFS, UP_MIN_COS,
};

use super::objects::ObjectSpec;
use super::truth_cache::cached_converged_peaks;

/// Rigid-body step of every scene (s).
pub const H: f64 = 0.01;
/// Impulse of every impact (N·s), into the surface.
pub const IMPULSE: f64 = 10.0;
/// Impacts and resting contacts per object (a third at region vertices, a third at triangle
/// centroids, a third at uniformly random points inside triangles).
pub const IMPACTS: usize = 6;
/// See [`IMPACTS`].
pub const CONTACTS: usize = 24;
/// Pairs closer than this (m) are left out: the response there is the impact's own.
pub const MIN_DISTANCE: f64 = 0.1;
/// First step of the truth's refinement (s).
pub const TRUTH_DT0: f64 = 1e-5;
/// Impacts of the busy query (with every sampled resting contact): a table's cost grows with
/// impacts × contacts, a modal base's with impacts + contacts.
pub const MANY_IMPACTS: usize = 4;
/// Modes of the runtime base every table sits in (the paper's count).
pub const BASE_MODES: usize = 20;

/// The report's seeded pairs with `impacts` impacts: [`CONTACTS`] resting contacts, seed 2,
/// [`MIN_DISTANCE`], [`IMPULSE`], window [`H`], the truth refined from [`TRUTH_DT0`] (at most 8
/// halvings, 0.5 %).
pub fn pairs_params(impacts: usize) -> PairsParams {
    PairsParams {
        impacts,
        contacts: CONTACTS,
        seed: 2,
        min_distance: MIN_DISTANCE,
        impulse: IMPULSE,
        h: H,
        dt0: TRUTH_DT0,
        refine: RefineParams {
            max_refinements: 8,
            ..RefineParams::default()
        },
    }
}

/// An object's 20-mode runtime base (the cost reference every table sits in) and its region.
pub struct Base20 {
    /// The bake parameters (material, fixed groups, [`BASE_MODES`] modes).
    pub params: BakeParams,
    /// The base.
    pub base: ModesFile,
    /// Free dofs of the mesh.
    pub free_dofs: usize,
    /// Seconds of the bake.
    pub seconds: f64,
    /// Region vertices (ascending surface-vertex indices) of the object's boxes and up filter.
    pub region: Vec<u32>,
}

/// Bakes `spec`'s 20-mode base from `mesh` and selects its region.
///
/// # Errors
/// The bake's.
pub fn base20(spec: &ObjectSpec, mesh: &TetMesh) -> Result<Base20, BakeError> {
    let params = BakeParams {
        material: spec.material,
        modes: ModeRequest::Count(BASE_MODES),
        fixed: spec.fixed.clone(),
        ..Default::default()
    };
    let t = Instant::now();
    let (base, rep) = bake_mesh(mesh.clone(), &params, &spec.source, &mut |_| {})?;
    let seconds = t.elapsed().as_secs_f64();
    let model = ModalModel::from_base(base.clone())
        .map_err(|e| BakeError::Params(format!("{}: {e}", spec.source)))?;
    let region = select_region(&model, &spec.boxes, spec.up, UP_MIN_COS);
    Ok(Base20 {
        params,
        base,
        free_dofs: rep.free_dofs,
        seconds,
        region,
    })
}

/// The full-order system parameters of `spec` (its material and fixed groups, the bake's
/// default Rayleigh damping).
pub fn system_params(spec: &ObjectSpec) -> SystemParams {
    SystemParams {
        material: spec.material,
        fixed: spec.fixed.clone(),
        ..Default::default()
    }
}

/// |errors| (%) of the pairs selected by `keep(contact at vertex)`.
pub fn abs_errors(errors: &[(f64, bool)], keep: impl Fn(bool) -> bool) -> Vec<f64> {
    errors
        .iter()
        .filter(|(_, v)| keep(*v))
        .map(|(e, _)| e.abs())
        .collect()
}

/// One method's result on an object.
#[derive(Clone, Debug)]
pub struct MethodRow {
    /// What it is.
    pub label: String,
    /// The default of `modal-bake bake --transfer-h H` (the method the verdict is about).
    pub best: bool,
    /// Signed errors (%) over the pairs, with whether the contact is at a vertex.
    pub errors: Vec<(f64, bool)>,
    /// One query: 1 impact, 8 resting contacts (µs, least of 15 batch means).
    pub query_us: f64,
    /// One busy query: [`MANY_IMPACTS`] impacts, every sampled resting contact (µs, as above).
    pub query_many_us: f64,
    /// Seconds to bake it (20-mode base + mode set + table), NaN when not measured.
    pub bake_s: f64,
    /// Written base size (bytes).
    pub bytes: u64,
}

impl MethodRow {
    /// |errors| of the pairs selected by `keep(contact at vertex)`.
    pub fn abs(&self, keep: impl Fn(bool) -> bool) -> Vec<f64> {
        abs_errors(&self.errors, keep)
    }
}

/// What was done for an object.
#[derive(Clone, Debug)]
pub struct ObjectStudy {
    /// The object.
    pub spec: ObjectSpec,
    /// Volume nodes, tets, free dofs, region vertices.
    pub nodes: usize,
    /// Tetrahedra.
    pub tets: usize,
    /// Free dofs.
    pub dofs: usize,
    /// Region vertices of its tables.
    pub region: usize,
    /// Truth: method and its convergence.
    pub truth_method: String,
    /// The converged truth (peaks per impact, contact; m).
    pub truth: ConvergedPeaks,
    /// Independent check at the step reached: method and largest difference (%).
    pub cross_check: Option<(String, f64)>,
    /// Seconds of the truth (eigensolve or factorizations, and every level; for a cached
    /// truth, the levels' seconds when it was computed).
    pub truth_s: f64,
    /// The truth's levels were read from the cache.
    pub truth_cached: bool,
    /// Impacts and resting contacts sampled.
    pub points: (usize, usize),
    /// Pairs evaluated (distance ≥ [`MIN_DISTANCE`]).
    pub pairs: usize,
    /// Every method, cheapest first.
    pub rows: Vec<MethodRow>,
    /// C of the paper's s = C/r (20-mode amplitude) that best matches the truth (median).
    pub attenuation_c: f64,
    /// Notes (failed bakes and the like).
    pub notes: Vec<String>,
    /// The default table's worst pairs, one Markdown line each.
    pub worst: Vec<String>,
}

/// The lowest `m` modes of `base` (same surface and metadata; no table).
pub fn truncate(base: &ModesFile, m: usize) -> ModesFile {
    let mm = base.num_modes();
    let mut b = base.clone();
    b.modes = base
        .modes
        .chunks_exact(mm)
        .flat_map(|row| row[..m].iter().copied())
        .collect();
    b.eigenvalues.truncate(m);
    b.residuals.truncate(m);
    b.transfer = None;
    b
}

/// Bytes of `base` written as a `.modes` file.
fn base_bytes(base: &ModesFile, tag: &str) -> u64 {
    let tmp = std::env::temp_dir().join(format!("dcr_accuracy_{tag}_{}.modes", std::process::id()));
    base.write_atomic(&tmp).expect("write a temporary base");
    let n = std::fs::metadata(&tmp).map(|m| m.len()).unwrap_or(0);
    let _ = std::fs::remove_file(&tmp);
    n
}

/// Least of 15 batch means of 400 warm steps (µs): robust to preemption on shared cores.
fn time_step(dr: &mut DistantResponse, imp: &[Impact], resting: &[RestingContact]) -> f64 {
    let (batches, reps) = (15, 400);
    std::hint::black_box(dr.step(imp, resting));
    1e6 * (0..batches)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..reps {
                std::hint::black_box(dr.step(imp, resting));
            }
            t.elapsed().as_secs_f64() / reps as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// Every runtime row is scored on the same pairs.
struct Bench<'a> {
    pairs: &'a ReferencePairs,
}

impl Bench<'_> {
    /// Runs `base` through the runtime (Method::Transfer: the table where it applies, else
    /// modal), checks who served, scores it.
    fn row(
        &self,
        label: String,
        base: ModesFile,
        served: ServedBy,
        bake_s: f64,
        tag: &str,
    ) -> MethodRow {
        self.row_with(label, base, served, bake_s, tag, Method::Transfer, 1.0)
    }

    /// As [`Bench::row`] with `method`, peaks scaled by `gain`.
    #[allow(clippy::too_many_arguments)]
    fn row_with(
        &self,
        label: String,
        base: ModesFile,
        served: ServedBy,
        bake_s: f64,
        tag: &str,
        method: Method,
        gain: f64,
    ) -> MethodRow {
        let bytes = base_bytes(&base, tag);
        let model = Arc::new(ModalModel::from_base(base).expect("a valid base"));
        let mut dr = self.pairs.response(model, method);
        let (errors, by) = self.pairs.errors(&mut dr, gain);
        assert!(by.iter().all(|b| *b == served), "{label}: served by {by:?}");
        let n = self.pairs.resting.len().min(8);
        let query_us = time_step(&mut dr, &self.pairs.impacts[..1], &self.pairs.resting[..n]);
        let k = self.pairs.impacts.len().min(MANY_IMPACTS);
        let query_many_us = time_step(&mut dr, &self.pairs.impacts[..k], &self.pairs.resting);
        MethodRow {
            label,
            best: false,
            errors,
            query_us,
            query_many_us,
            bake_s,
            bytes,
        }
    }
}

/// The full study of one object (see the module docs). `quick`: fewer rows; `newmark_impacts`:
/// impacts for an object whose truth is Newmark (more than [`DENSE_MAX_DOFS`] free dofs; each
/// impact is one more Newmark run at every level of the refinement), [`IMPACTS`] when `None`;
/// `impacts`: this object's impacts, overriding both; `truth_cache`: folder of cached truths
/// ([`super::truth_cache`]), `None` to always compute.
pub fn study_object(
    spec: &ObjectSpec,
    mesh: TetMesh,
    quick: bool,
    newmark_impacts: Option<usize>,
    impacts: Option<usize>,
    truth_cache: Option<&Path>,
) -> ObjectStudy {
    let name = spec.name;
    let file = spec.source.clone();
    let (nodes, tets) = (mesh.nodes.len(), mesh.tets.len());
    let mut notes = Vec::new();
    eprintln!("{name}: 20-mode base…");
    let Base20 {
        params: bp,
        base: base20,
        free_dofs: dofs,
        seconds: base20_s,
        region,
    } = base20(spec, &mesh).expect("20-mode bake");
    // Truth: the dense all-mode sum where it fits, else Newmark; refined until converged.
    eprintln!("{name}: truth ({dofs} free dofs)…");
    let t = Instant::now();
    let sys =
        FullOrderSystem::new(mesh.clone(), &system_params(spec), &file).expect("full-order system");
    let dense = dofs <= DENSE_MAX_DOFS;
    let ma = dense.then(|| ModalAll::new(&sys, DENSE_MAX_DOFS).expect("dense eigensolve"));
    let dense_s = t.elapsed().as_secs_f64();
    let impacts = match (impacts, newmark_impacts) {
        (Some(n), _) => n,
        (None, Some(n)) if !dense => n,
        _ => IMPACTS,
    };
    let pp = pairs_params(impacts);
    let mut last_line = Instant::now();
    let mut cached = false;
    let pairs = ReferencePairs::with_truth(&sys, ma.as_ref(), &base20, &region, &pp, &mut |tp| {
        cached_converged_peaks(
            truth_cache,
            &sys,
            tp,
            &mut |p| {
                if p.done == 0 || last_line.elapsed().as_secs() >= 10 {
                    eprintln!(
                        "{name}: truth level {} (dt {:.2e} s) {}/{}",
                        p.level, p.dt, p.done, p.total
                    );
                    last_line = Instant::now();
                }
            },
            &mut cached,
        )
    })
    .expect("truth");
    // A cached truth reports the seconds its levels took when it was computed.
    let truth_s = if cached {
        dense_s + pairs.truth.history.iter().map(|l| l.seconds).sum::<f64>()
    } else {
        t.elapsed().as_secs_f64()
    };
    let truth_method = if dense {
        "sum over every mode (dense)"
    } else {
        "Newmark (β = ¼, γ = ½)"
    };
    // The independent check of the dense sum: Newmark at the step it reached.
    let cross_check = ma
        .as_ref()
        .map(|_| newmark_cross_check(&sys, &pairs, &pp.refine));
    eprintln!(
        "{name}: truth converged {} at dt {:.2e} s, est. error {:.3} %, {:.0} s",
        pairs.truth.converged,
        pairs.truth.dt,
        100.0 * pairs.truth.estimated_error,
        truth_s
    );
    let bench = Bench { pairs: &pairs };
    // The many-mode set: every dense mode, or a Lanczos bake of 640.
    eprintln!("{name}: mode set…");
    let t = Instant::now();
    let (set, set_label) =
        many_mode_set(ma.as_ref(), &base20, &sys, (&mesh, &bp, &file), &mut notes);
    let set_s = if dense {
        dense_s
    } else {
        t.elapsed().as_secs_f64()
    };
    let nset = set.num_modes();
    let mut out = Vec::new();
    // Modal rows (the runtime's filters over m modes).
    let counts: Vec<usize> = if quick {
        vec![20, 80]
    } else {
        vec![20, 80, 320, 640]
    };
    for m in counts.into_iter().filter(|&m| m <= nset) {
        eprintln!("{name}: modal, {m} modes…");
        let b = if m == BASE_MODES {
            base20.clone()
        } else {
            truncate(&set, m)
        };
        let bake_s = if m == BASE_MODES { base20_s } else { f64::NAN };
        out.push(bench.row(
            format!("modal, {m} modes"),
            b,
            ServedBy::Modal,
            bake_s,
            name,
        ));
    }
    let (att_row, c_fit) = attenuation_row(&bench, &base20, base20_s, name);
    out.push(att_row);
    out.extend(table_rows(
        &bench,
        spec,
        (&set, &set_label),
        (&base20, base20_s + set_s),
        quick,
        &mut notes,
    ));
    let worst = out
        .iter()
        .find(|r| r.best)
        .map(|r| worst_pairs(&pairs, r, 3))
        .unwrap_or_default();
    ObjectStudy {
        spec: spec.clone(),
        worst,
        nodes,
        tets,
        dofs,
        region: region.len(),
        truth_method: truth_method.into(),
        truth: pairs.truth.clone(),
        cross_check,
        truth_s,
        truth_cached: cached,
        points: (pairs.impacts.len(), pairs.resting.len()),
        pairs: pairs.pairs(),
        rows: out,
        attenuation_c: c_fit,
        notes,
    }
}

/// The independent check of the dense all-mode truth: Newmark (no refinement) at the step the
/// truth reached, for the same impacts and resting contacts. Returns the solver's name and the
/// worst relative difference of the peaks (%).
fn newmark_cross_check(
    sys: &FullOrderSystem,
    pairs: &ReferencePairs,
    refine: &RefineParams,
) -> (String, f64) {
    let loads: Vec<Vec<f64>> = pairs
        .impacts
        .iter()
        .map(|i| {
            let s = sys.surface.project(i.point).expect("on the surface");
            sys.load_vector(&s, i.direction, i.impulse)
        })
        .collect();
    let rows: Vec<Vec<f64>> = pairs
        .resting
        .iter()
        .map(|c| sys.contact_row(&sys.surface.project(c.point).expect("on the surface")))
        .collect();
    let single = RefineParams {
        max_refinements: 0,
        ..*refine
    };
    let w = PeakWindow {
        h: H,
        dt: pairs.truth.dt,
    };
    let c = converged_peaks(
        sys,
        PeakSolver::Newmark,
        &loads,
        &rows,
        w,
        &single,
        &mut |_| {},
    )
    .expect("Newmark check");
    let d = pairs
        .truth
        .peaks
        .iter()
        .flatten()
        .zip(c.peaks.iter().flatten())
        .fold(0.0f64, |m, (a, b)| m.max(((b - a) / a).abs()));
    ("Newmark".to_string(), 100.0 * d)
}

/// The many-mode set the tables are built from and its label: every dense mode (`ma`), or a
/// Lanczos bake of [`AUTO_LANCZOS_MODES`] of `mesh` with `bp` (`file`: its name in errors);
/// if that fails, the 20-mode base, with a note.
fn many_mode_set(
    ma: Option<&ModalAll>,
    base20: &ModesFile,
    sys: &FullOrderSystem,
    (mesh, bp, file): (&TetMesh, &BakeParams, &str),
    notes: &mut Vec<String>,
) -> (ModesFile, String) {
    match ma {
        Some(m) => (
            mode_set_from_dense(base20, sys, m, m.eigenvalues.len()),
            format!("all {}", m.eigenvalues.len()),
        ),
        None => match mode_set_lanczos(mesh, bp, AUTO_LANCZOS_MODES, file) {
            Ok(b) => (b, AUTO_LANCZOS_MODES.to_string()),
            Err(e) => {
                notes.push(format!(
                    "the {AUTO_LANCZOS_MODES}-mode Lanczos bake failed: {e}"
                ));
                (base20.clone(), BASE_MODES.to_string())
            }
        },
    }
}

/// The paper's spatial attenuation row (Eq. 16, s = C r⁻¹, heat distances, the 20-mode local
/// amplitude) with C fitted to the truth (median ratio over the pairs), and the fitted C.
fn attenuation_row(
    bench: &Bench,
    base20: &ModesFile,
    base20_s: f64,
    name: &str,
) -> (MethodRow, f64) {
    let att = |c: f64| {
        Method::Attenuation(dcr_runtime::response::AttenuationParams {
            law: dcr_runtime::response::AttenuationLaw::Simplified { c, beta: 1.0 },
            ..Default::default()
        })
    };
    let probe = bench.row_with(
        "attenuation".into(),
        base20.clone(),
        ServedBy::Attenuation,
        f64::NAN,
        name,
        att(1.0),
        1.0,
    );
    let ratios: Vec<f64> = probe
        .errors
        .iter()
        .map(|(e, _)| 1.0 / (1.0 + e / 100.0))
        .collect();
    let c_fit = median(&ratios);
    let mut att_row = bench.row_with(
        format!("attenuation s = C/r, 20-mode amplitude, C = {c_fit:.3e} fitted"),
        base20.clone(),
        ServedBy::Attenuation,
        base20_s,
        name,
        att(1.0),
        c_fit,
    );
    att_row.query_us = probe.query_us;
    att_row.query_many_us = probe.query_many_us;
    (att_row, c_fit)
}

/// The transfer-table rows: the default (auto modes, auto order, marked best) and cheaper or
/// lower-order variants, built from the many-mode `set` (labelled `set_label`) on `base20`;
/// `base_s`: seconds to bake the 20-mode base and the set. A failed build adds a note.
fn table_rows(
    bench: &Bench,
    spec: &ObjectSpec,
    (set, set_label): (&ModesFile, &str),
    (base20, base_s): (&ModesFile, f64),
    quick: bool,
    notes: &mut Vec<String>,
) -> Vec<MethodRow> {
    let name = spec.name;
    let mut out = Vec::new();
    // Tables: the default (auto modes, auto order) and cheaper or lower-order variants.
    let mut variants: Vec<(TransferModes, TableOrder, bool)> = vec![
        (TransferModes::All, TableOrder::Auto, true),
        (TransferModes::All, TableOrder::Quadratic, false),
    ];
    if !quick {
        variants.push((TransferModes::Count(160), TableOrder::Auto, false));
    }
    let mut best_order = 0u8;
    for (modes, order, best) in variants {
        if order == TableOrder::Quadratic && best_order == 2 {
            continue;
        }
        let tp = TransferParams {
            h: H,
            modes,
            boxes: spec.boxes.clone(),
            up: spec.up,
            order,
            ..Default::default()
        };
        let t = Instant::now();
        let table = match build_transfer_table(set, &tp, base20.rayleigh, &mut |_| {}) {
            Ok(t) => t,
            Err(e) => {
                notes.push(format!("table ({modes:?}, {order:?}) failed: {e}"));
                continue;
            }
        };
        let build_s = t.elapsed().as_secs_f64();
        if best {
            best_order = table.order;
        }
        let used = if matches!(modes, TransferModes::Count(_)) {
            table.modes.to_string()
        } else {
            set_label.to_string()
        };
        eprintln!(
            "{name}: table, {used} modes, order {}, {} points, built in {build_s:.1} s…",
            table.order,
            table.num_points()
        );
        let label = format!(
            "table, {used} modes, order {} ({} points, S = {})",
            table.order,
            table.num_points(),
            table.samples
        );
        let mut b = base20.clone();
        b.transfer = Some(table);
        let bake_s = base_s + build_s;
        let mut row = bench.row(label, b, ServedBy::TransferTable, bake_s, name);
        row.best = best;
        out.push(row);
    }
    out
}

/// The `n` pairs of `row` with the largest |error|, one line each: where the impact and the
/// contact are (m, object frame; at a vertex or inside a triangle), their distance (m), the truth
/// and the method's peak (m). `row.errors` lists the counted pairs impact by impact, contact by
/// contact, as [`ReferencePairs::errors`] does.
fn worst_pairs(pairs: &ReferencePairs, row: &MethodRow, n: usize) -> Vec<String> {
    let ids: Vec<(usize, usize)> = (0..pairs.impacts.len())
        .flat_map(|i| (0..pairs.resting.len()).map(move |c| (i, c)))
        .filter(|&(i, c)| pairs.pair_ok[i][c])
        .collect();
    let mut order: Vec<usize> = (0..row.errors.len().min(ids.len())).collect();
    order.sort_by(|&a, &b| row.errors[b].0.abs().total_cmp(&row.errors[a].0.abs()));
    let fmt = |p: [f64; 3]| format!("({:.3}, {:.3}, {:.3})", p[0], p[1], p[2]);
    order
        .into_iter()
        .take(n)
        .map(|k| {
            let (i, c) = ids[k];
            let (a, b) = (pairs.impacts[i].point, pairs.resting[c].point);
            let d = (0..3).map(|j| (a[j] - b[j]).powi(2)).sum::<f64>().sqrt();
            let t = pairs.truth.peaks[i][c];
            let e = row.errors[k].0;
            format!(
                "{e:+.1} %: impact {} → contact {} ({}), {d:.3} m apart; truth {t:.3e} m, table {:.3e} m",
                fmt(a),
                fmt(b),
                if pairs.contact_at_vertex[c] { "at a vertex" } else { "inside a triangle" },
                t * (1.0 + e / 100.0)
            )
        })
        .collect()
}

/// Median of `v` (NaN when empty).
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    if s.is_empty() {
        return f64::NAN;
    }
    s[s.len() / 2]
}

/// Largest of `v` (0 when empty).
pub fn maxv(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, b| a.max(*b))
}
