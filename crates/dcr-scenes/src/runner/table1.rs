//! `dcr-scenes table1`: every scene on and off, our Table 1 columns beside the paper's.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Result;
use serde_json::{json, Value};

use dcr_rapier::f64::{ApplyMode, StepGate};

use crate::runner::{run_scene, MethodChoice, ModelReport, RunParams, RunReport};
use crate::scene::SceneDesc;

/// One row of the paper's Table 1.
#[derive(Clone, Copy, Debug)]
pub struct PaperRow {
    /// Scene.
    pub scene: &'static str,
    /// Model.
    pub model: &'static str,
    /// Surface vertices.
    pub vertices: usize,
    /// Surface triangles.
    pub triangles: usize,
    /// Modes.
    pub modes: usize,
    /// Rigid step (s).
    pub h: f64,
    /// IIR step (s).
    pub t: f64,
    /// Distant contacts.
    pub contacts: usize,
    /// Compute time per query (ms, i9-9980HK).
    pub ms: f64,
}

/// The paper's Table 1.
pub fn paper_rows() -> Vec<PaperRow> {
    let r = |scene, model, vertices, triangles, t, contacts, ms| PaperRow {
        scene,
        model,
        vertices,
        triangles,
        modes: 20,
        h: 1e-2,
        t,
        contacts,
        ms,
    };
    vec![
        r("dinner", "table", 966, 1928, 4.9e-4, 41, 3.8),
        r("roof", "roof", 1002, 2000, 7.0e-3, 7, 0.8),
        r("scaffold", "scaffold", 5384, 10776, 3.0e-3, 58, 27.5),
        r("lowrider", "ground", 1570, 3136, 3.1e-4, 40, 5.6),
        r("rockfall", "cliff", 7182, 14360, 4.0e-3, 24, 18.1),
        r("washing", "floor", 360, 716, 1.7e-4, 26, 1.1),
        r("washing", "fridge", 250, 496, 8.6e-5, 6, 0.2),
    ]
}

/// Settings of a `table1` run.
#[derive(Clone, Debug)]
pub struct Table1Params {
    /// Scene names, in order.
    pub scenes: Vec<String>,
    /// Override of every scene's run length (s).
    pub seconds: Option<f64>,
    /// Repository root.
    pub root: PathBuf,
    /// Bases directory.
    pub bases_dir: PathBuf,
    /// Also run the scaffold with attenuation at these β.
    pub scaffold_betas: Vec<f64>,
    /// How the "on" runs apply the responses.
    pub apply: ApplyMode,
    /// Energy bound η of the "on" runs (`None`: unbounded).
    pub energy_eta: Option<f64>,
    /// Lateral kick in the "on" runs.
    pub lateral_kick: bool,
    /// Launch rule of the "on" runs (default the paper's, [`dcr_runtime::Launch::PeakOverStep`]).
    pub launch: dcr_runtime::Launch,
    /// rapier's contact recycling on the elastic objects' colliders.
    pub contact_recycling: bool,
    /// On which steps the contacts are read.
    pub gate: StepGate,
    /// Energy-bound sweep: also run every scene unbounded and at each of these η, and report
    /// which outcomes move by more than 5 % from the unbounded run.
    pub eta_sweep: Vec<f64>,
    /// If set, write each scene's on and off runs side by side as `DIR/SCENE.glb`.
    pub gltf_dir: Option<PathBuf>,
    /// The work a missing or stale base may take to bake ([`RunParams::bake_budget`]).
    pub bake_budget: Option<modal_bake::bake::Budget>,
}

/// An outcome "changes" when it moves by more than this fraction of the reference value (or of
/// 1e-3 of the unit, whichever is larger).
const CHANGE_REL: f64 = 0.05;

fn changed(v: f64, reference: f64) -> bool {
    (v - reference).abs() > CHANGE_REL * reference.abs().max(1e-3)
}

fn fmt_opt(x: Option<f64>, scale: f64, prec: usize) -> String {
    x.map_or("-".into(), |v| format!("{:.*}", prec, v * scale))
}

/// Runs every scene on and off and returns (text table, JSON object).
///
/// # Errors
/// Any run's failure.
pub fn table1(p: &Table1Params) -> Result<(String, Value)> {
    let paper = paper_rows();
    let mut entries = Vec::new();
    let mut text = table_header();
    let mut outcome_lines = String::new();
    for name in &p.scenes {
        let desc = SceneDesc::read(&p.root.join("scenes").join(format!("{name}.json")))?;
        let run =
            |dcr: bool, method: MethodChoice| run_one(p, (name, &desc), dcr, method, p.energy_eta);
        let on = run(true, MethodChoice::Scene)?;
        let off = run(false, MethodChoice::Scene)?;
        if let Some(dir) = &p.gltf_dir {
            write_on_off_glb(p, (name, &desc), dir, &on, &off)?;
        }
        let sweep = energy_sweep(p, (name, &desc), &on, &mut outcome_lines)?;
        let outcomes = on_off_outcomes(name, &on, &off, &mut outcome_lines);
        let extra = if name == "scaffold" {
            attenuation_runs(p, (name, &desc), &mut outcome_lines)?
        } else {
            Vec::new()
        };
        for m in &on.models {
            let pr = paper
                .iter()
                .find(|r| r.scene == name.as_str() && r.model == m.model);
            text.push_str(&model_row(name, m, pr, &on));
            let mut entry = json!({
                "name": name,
                "model": m.model,
                "surface_vertices": m.surface_vertices,
                "surface_triangles": m.surface_triangles,
                "modes": m.modes,
                "method": m.method,
                "h": on.h,
                "iir_T": m.iir_t,
                "samples_per_step": m.samples_per_step,
                "distant_contacts": m.distant_contacts,
                "queries": m.queries,
                "impacts": m.stats.impacts,
                "query_us_median": m.query_us_median,
                "query_us_p99": m.query_us_p99,
                "dcr_share_of_step": on.dcr_share_of_step,
                "rapier_ms": on.rapier_ms,
                "adapter_ms": on.adapter_ms,
                "seconds": on.seconds,
                "outcomes": outcomes,
                "energy": {"injected_ke_j": m.stats.injected_ke, "dissipated_j": m.stats.dissipated, "received_j": m.stats.received, "energy_limited_steps": m.stats.energy_limited_steps},
                "energy_eta": on.energy_eta,
                "apply": on.apply,
                "lateral_kick": on.lateral_kick,
                "contact_recycling": on.contact_recycling,
                "gate": on.gate,
                "world_steps": on.world_steps,
                "replay_missed": on.replay_missed,
                "steps": on.steps,
                "energy_sweep": sweep,
                "attenuation_runs": extra,
                "trajectory_hash_on": on.trajectory_hash,
                "trajectory_hash_off": off.trajectory_hash,
                "paper": pr.map(|r| json!({"vertices": r.vertices, "triangles": r.triangles, "modes": r.modes, "h": r.h, "iir_T": r.t, "distant_contacts": r.contacts, "compute_ms": r.ms})),
            });
            // Set apart: one more key in the literal above exceeds `json!`'s recursion limit.
            entry["launch"] = json!(on.launch);
            entries.push(entry);
        }
    }
    text.push_str("\noutcomes (response on vs off):\n");
    text.push_str(&outcome_lines);
    Ok((text, json!({"scenes": entries})))
}

/// The table's two header lines (column names; which columns hold ours/paper).
fn table_header() -> String {
    let mut text = String::new();
    text.push_str(&format!(
        "{:9} {:8} {:>12} {:>13} {:>9} {:>6} {:>15} {:>10} {:>22} {:>8}\n",
        "scene",
        "model",
        "vertices",
        "triangles",
        "modes",
        "h",
        "T (s)",
        "contacts",
        "query ms med/p99",
        "share"
    ));
    text.push_str(&format!(
        "{:9} {:8} {:>12} {:>13} {:>9} {:>6} {:>15} {:>10} {:>22} {:>8}\n",
        "",
        "",
        "ours/paper",
        "ours/paper",
        "",
        "",
        "ours/paper",
        "ours/paper",
        "ours (paper mean)",
        "of step"
    ));
    text
}

/// One run of scene `desc` (named `name` in the table) with the table's settings: response on or off, `method`, energy
/// bound `eta` (`None`: unbounded).
fn run_one(
    p: &Table1Params,
    (name, desc): (&str, &SceneDesc),
    dcr: bool,
    method: MethodChoice,
    eta: Option<f64>,
) -> Result<RunReport> {
    eprintln!(
        "[dcr-scenes] table1: {name} dcr {}{}",
        if dcr { "on" } else { "off" },
        match (dcr, eta) {
            (false, _) => String::new(),
            (true, None) => " (no energy bound)".into(),
            (true, Some(e)) => format!(" (eta {e})"),
        }
    );
    run_scene(
        desc,
        &RunParams {
            seconds: p.seconds,
            method,
            out_dir: None,
            progress: true,
            bases_dir: p.bases_dir.clone(),
            apply: p.apply,
            energy_eta: eta,
            lateral_kick: p.lateral_kick,
            launch: p.launch,
            contact_recycling: p.contact_recycling,
            gate: p.gate,
            bake_budget: p.bake_budget,
            ..RunParams::new(p.root.clone(), dcr)
        },
    )
}

/// Writes the on and off runs of scene `desc` side by side as `dir/NAME.glb`.
fn write_on_off_glb(
    p: &Table1Params,
    (name, desc): (&str, &SceneDesc),
    dir: &Path,
    on: &RunReport,
    off: &RunReport,
) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    let path = dir.join(format!("{name}.glb"));
    let sides = [on, off].map(|r| crate::export::Side {
        label: crate::export::side_label(r),
        report: r,
    });
    crate::export::write_scene_glb(desc, &p.root, &p.bases_dir, &sides, &path)?;
    eprintln!(
        "[dcr-scenes] table1: {name} on/off glTF: {}",
        path.display()
    );
    Ok(())
}

/// Energy-bound sweep (empty without `p.eta_sweep`): the unbounded run, then each η, every
/// outcome flagged where it moves by more than [`CHANGE_REL`] from the unbounded run. Reuses
/// `on` where its bound matches; appends one line per run to `outcome_lines`.
fn energy_sweep(
    p: &Table1Params,
    (name, desc): (&str, &SceneDesc),
    on: &RunReport,
    outcome_lines: &mut String,
) -> Result<Vec<Value>> {
    let mut sweep = Vec::new();
    if p.eta_sweep.is_empty() {
        return Ok(sweep);
    }
    let free = if p.energy_eta.is_none() {
        on.clone()
    } else {
        run_one(p, (name, desc), true, MethodChoice::Scene, None)?
    };
    let mut rows = vec![(None, free)];
    for &eta in &p.eta_sweep {
        let r = if p.energy_eta == Some(eta) {
            on.clone()
        } else {
            run_one(p, (name, desc), true, MethodChoice::Scene, Some(eta))?
        };
        rows.push((Some(eta), r));
    }
    let reference = rows[0].1.outcomes.clone();
    for (eta, r) in &rows {
        let label = eta.map_or("none".to_string(), |e| e.to_string());
        let mut outs = serde_json::Map::new();
        let mut moved = Vec::new();
        for (k, (v, unit)) in &r.outcomes {
            let base = reference.get(k).map_or(*v, |x| x.0);
            let ch = changed(*v, base);
            if ch {
                moved.push(k.clone());
            }
            outs.insert(k.clone(), json!({"value": v, "unit": unit, "changed": ch}));
        }
        outcome_lines.push_str(&format!(
            "  {:9} {:28} eta {:>5}: injected {:.4e} J, dissipated {:.4e} J, limited steps {}; changed: {}\n",
            name,
            "energy bound",
            label,
            r.injected_ke,
            r.dissipated,
            r.models.iter().map(|m| m.stats.energy_limited_steps).sum::<usize>(),
            if moved.is_empty() { "none".to_string() } else { moved.join(", ") }
        ));
        sweep.push(json!({
            "energy_eta": eta,
            "outcomes": outs,
            "injected_ke_j": r.injected_ke,
            "dissipated_j": r.dissipated,
            "energy_limited_steps": r.models.iter().map(|m| m.stats.energy_limited_steps).sum::<usize>(),
        }));
    }
    Ok(sweep)
}

/// Every outcome of the `on` run beside the `off` run's (`{on, off, unit}` by name), with one
/// line each and the energy balance of the `on` run appended to `outcome_lines`.
fn on_off_outcomes(
    name: &str,
    on: &RunReport,
    off: &RunReport,
    outcome_lines: &mut String,
) -> serde_json::Map<String, Value> {
    let mut outcomes = serde_json::Map::new();
    for (k, (v, unit)) in &on.outcomes {
        let off_v = off.outcomes.get(k).map(|x| x.0);
        outcomes.insert(k.clone(), json!({"on": v, "off": off_v, "unit": unit}));
        outcome_lines.push_str(&format!(
            "  {:9} {:28} on {:>10.3}  off {:>10.3} {}\n",
            name,
            k,
            v,
            off_v.unwrap_or(f64::NAN),
            unit
        ));
    }
    outcome_lines.push_str(&format!(
        "  {:9} {:28} injected {:.4e} J <= dissipated {:.4e} J: {}\n",
        name,
        "energy (on)",
        on.injected_ke,
        on.dissipated,
        on.injected_ke <= on.dissipated
    ));
    outcomes
}

/// Runs with the attenuation method at each of `p.scaffold_betas` (response on): their
/// outcomes and first model's query times, one line per outcome appended to `outcome_lines`.
fn attenuation_runs(
    p: &Table1Params,
    (name, desc): (&str, &SceneDesc),
    outcome_lines: &mut String,
) -> Result<Vec<Value>> {
    let mut extra = Vec::new();
    for &beta in &p.scaffold_betas {
        let r = run_one(
            p,
            (name, desc),
            true,
            MethodChoice::AttenuationBeta(beta),
            p.energy_eta,
        )?;
        let outs: BTreeMap<_, _> = r
            .outcomes
            .iter()
            .map(|(k, (v, u))| (k.clone(), json!({"value": v, "unit": u})))
            .collect();
        for (k, (v, u)) in &r.outcomes {
            outcome_lines.push_str(&format!(
                "  {:9} {:28} attenuation beta {beta}: {v:.3} {u}\n",
                name, k
            ));
        }
        let m = &r.models[0];
        extra.push(json!({"beta": beta, "outcomes": outs, "query_us_median": m.query_us_median, "query_us_p99": m.query_us_p99}));
    }
    Ok(extra)
}

/// The table line of model `m` of the `on` run of scene `name`: ours beside the paper's row
/// `pr` (zeros without one).
fn model_row(name: &str, m: &ModelReport, pr: Option<&PaperRow>, on: &RunReport) -> String {
    format!(
        "{:9} {:8} {:>12} {:>13} {:>9} {:>6} {:>15} {:>10} {:>22} {:>7.1}%\n",
        name,
        m.model,
        format!("{}/{}", m.surface_vertices, pr.map_or(0, |r| r.vertices)),
        format!("{}/{}", m.surface_triangles, pr.map_or(0, |r| r.triangles)),
        format!("{}/{}", m.modes, pr.map_or(0, |r| r.modes)),
        on.h,
        format!(
            "{}/{:.1e}",
            fmt_opt(m.iir_t, 1.0, 6),
            pr.map_or(0.0, |r| r.t)
        ),
        format!("{}/{}", m.distant_contacts, pr.map_or(0, |r| r.contacts)),
        format!(
            "{}/{} ({})",
            fmt_opt(m.query_us_median, 1e-3, 3),
            fmt_opt(m.query_us_p99, 1e-3, 3),
            pr.map_or(0.0, |r| r.ms)
        ),
        100.0 * on.dcr_share_of_step
    )
}
