//! `dcr-scenes bench-stress`: the adapter's per-step cost against the number of resting
//! contacts, on `scenes/stress.json` cut to its first N boxes.
//!
//! For each N the scene runs with the response on (default application and step gate) and
//! the bench reports medians per step: rapier's step, the adapter on quiet steps (the light
//! pass over the contacts' impulses) and on world steps (full read, classification, queries,
//! impulses), the resting contacts at the queries, and the share of the whole run (adapter over
//! rapier, `dcr_share_of_step`). Wall-clock figures: quote them with the machine's load.

use std::path::PathBuf;

use anyhow::{bail, Result};
use serde_json::{json, Value};

use crate::runner::{run_scene, RunParams, StepTime};
use crate::scene::SceneDesc;

/// Settings of [`stress_bench`].
#[derive(Clone, Debug)]
pub struct StressBenchParams {
    /// Numbers of boxes (each ≤ the scene's).
    pub props: Vec<usize>,
    /// Simulated seconds per run (None: the scene's).
    pub seconds: Option<f64>,
    /// Repository root.
    pub root: PathBuf,
    /// Bases directory.
    pub bases_dir: PathBuf,
    /// Progress on stderr.
    pub progress: bool,
    /// The work a missing or stale base may take to bake ([`RunParams::bake_budget`]).
    pub bake_budget: Option<modal_bake::bake::Budget>,
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    Some(v[v.len() / 2])
}

/// Runs the stress bench; returns one JSON object (`runs`: one entry per N).
///
/// # Errors
/// An N above the scene's box count, or any run's failure.
pub fn stress_bench(p: &StressBenchParams) -> Result<Value> {
    let full = SceneDesc::read(&p.root.join("scenes").join("stress.json"))?;
    let boxes = full
        .props
        .iter()
        .position(|q| q.name == "box")
        .ok_or_else(|| anyhow::anyhow!("scenes/stress.json has no `box` prop"))?;
    let available = full.props[boxes].copies.len();
    let mut runs = Vec::new();
    for &n in &p.props {
        if n == 0 || n > available {
            bail!("--props {n}: the stress scene has 1 to {available} boxes");
        }
        let mut desc = full.clone();
        desc.props[boxes].copies.truncate(n);
        if p.progress {
            eprintln!("[dcr-scenes] bench-stress: {n} boxes");
        }
        let r = run_scene(
            &desc,
            &RunParams {
                seconds: p.seconds,
                bases_dir: p.bases_dir.clone(),
                progress: p.progress,
                bake_budget: p.bake_budget,
                ..RunParams::new(p.root.clone(), true)
            },
        )?;
        let pick = |f: &dyn Fn(&StepTime) -> bool, g: &dyn Fn(&StepTime) -> f64| {
            median(r.step_times.iter().filter(|t| f(t)).map(g).collect())
        };
        let m = &r.models[0];
        runs.push(json!({
            "boxes": n,
            "steps": r.steps,
            "world_steps": r.world_steps,
            "rapier_us_median": pick(&|_| true, &|t| t.rapier_us),
            "adapter_us_median_quiet": pick(&|t| !t.world_stepped, &|t| t.adapter_us),
            "adapter_us_median_world": pick(&|t| t.world_stepped, &|t| t.adapter_us),
            "reports_median_world": pick(&|t| t.world_stepped, &|t| f64::from(t.reports)),
            "resting_contacts_max": m.distant_contacts,
            "query_us_median": m.query_us_median,
            "impacts": m.stats.impacts,
            "rapier_ms": r.rapier_ms,
            "adapter_ms": r.adapter_ms,
            "dcr_share_of_step": r.dcr_share_of_step,
            "outcomes": r.outcomes.iter().map(|(k, (v, u))| (k.clone(), json!({"value": v, "unit": u}))).collect::<serde_json::Map<_, _>>(),
        }));
    }
    Ok(json!({"scene": "stress", "runs": runs}))
}
