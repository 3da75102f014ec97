//! The report's energy-bound section: every scene of Table 1 run unbounded and with the
//! world's energy bound at η = 1, 0.5 and 0.1 (`dcr_scenes::runner::table1` with an η sweep,
//! as `dcr-scenes table1 --energy-sweep 1,0.5,0.1`): per scene the kinetic energy the distant
//! responses injected, the energy the impacts dissipated (J), the object-steps the bound
//! scaled, and which outcomes moved by more than 5 % from the unbounded run.

use std::fmt::Write as _;
use std::path::Path;

use dcr_scenes::runner::{table1, Table1Params};
use serde_json::Value;

/// The η values of the sweep.
pub const ETAS: [f64; 3] = [1.0, 0.5, 0.1];

/// Runs the sweep (bases baked into `ROOT/out/bases` when missing) and returns its Markdown
/// section.
///
/// # Errors
/// A scene fails to load, bake or run.
pub fn energy_section(root: &Path) -> anyhow::Result<String> {
    let scenes: Vec<String> = dcr_scenes::SCENES.iter().map(|s| s.to_string()).collect();
    eprintln!("energy bound: table1 with η sweep {ETAS:?}…");
    let (_, value) = table1(&Table1Params {
        scenes,
        seconds: None,
        root: root.to_path_buf(),
        bases_dir: root.join("out").join("bases"),
        scaffold_betas: Vec::new(),
        apply: Default::default(),
        energy_eta: Some(1.0),
        lateral_kick: false,
        launch: Default::default(),
        contact_recycling: true,
        gate: Default::default(),
        eta_sweep: ETAS.to_vec(),
        gltf_dir: None,
        bake_budget: Some(modal_bake::bake::Budget::default()),
    })?;
    Ok(render(&value))
}

/// The section from `table1`'s JSON (`{"scenes": [{"name", "energy_sweep": [...]}, ...]}`, one
/// entry per elastic object, the sweep repeated on each of a scene's objects).
fn render(value: &Value) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "\n## Energy bound (η)\n");
    let _ = writeln!(md, "The world (`DcrWorld`, `WorldParams::energy_eta`, `dcr-scenes … --energy-eta`) bounds, per elastic object and step, the kinetic energy its distant responses inject by η × (the energy that step's impacts on it dissipated + what chained impulses gave its body), scaling the object's impulses uniformly when over; default η = 1 (passive: a response never gives more than its impacts lost). The property is proven by `crates/dcr-runtime/tests/energy_bound.rs` (seeded random worlds, gains up to 100, the injected energy measured independently from the bodies' kinetic energies; the bound holds to rounding at η = 1, 0.5 and 0.1 and is active in some steps).\n");
    let _ = writeln!(md, "Every scene of Table 1 as committed (its methods and gains), unbounded and at each η (`dcr-scenes table1 --energy-sweep 1,0.5,0.1`); energies summed over the run (J); `bounded` = object-steps the bound scaled; `changed` = outcomes that moved by more than 5 % from the unbounded run.\n");
    let _ = write!(
        md,
        "| scene | dissipated J | injected J, unbounded (÷ dissipated) |"
    );
    for e in ETAS {
        let _ = write!(md, " η = {e}: injected J, bounded, changed |");
    }
    let _ = writeln!(md);
    let _ = writeln!(md, "|---|---|---|{}", "---|".repeat(ETAS.len()));
    let scenes = value
        .get("scenes")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut done: Vec<&str> = Vec::new();
    for s in &scenes {
        let name = s.get("name").and_then(Value::as_str).unwrap_or("?");
        if done.contains(&name) {
            continue;
        }
        done.push(name);
        let sweep = s
            .get("energy_sweep")
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default();
        let num = |r: &Value, k: &str| r.get(k).and_then(Value::as_f64).unwrap_or(f64::NAN);
        let at = |eta: Option<f64>| {
            sweep
                .iter()
                .find(|r| r.get("energy_eta").and_then(Value::as_f64) == eta)
        };
        let Some(free) = at(None) else { continue };
        let d = num(free, "dissipated_j");
        let inj = num(free, "injected_ke_j");
        let _ = write!(
            md,
            "| {name} | {d:.3e} | {inj:.3e} ({:.2} %) |",
            100.0 * inj / d
        );
        for e in ETAS {
            match at(Some(e)) {
                Some(r) => {
                    let changed: Vec<&str> = r
                        .get("outcomes")
                        .and_then(Value::as_object)
                        .map(|o| {
                            o.iter()
                                .filter(|(_, v)| {
                                    v.get("changed").and_then(Value::as_bool) == Some(true)
                                })
                                .map(|(k, _)| k.as_str())
                                .collect()
                        })
                        .unwrap_or_default();
                    let _ = write!(
                        md,
                        " {:.3e}, {}, {} |",
                        num(r, "injected_ke_j"),
                        r.get("energy_limited_steps")
                            .and_then(Value::as_u64)
                            .unwrap_or(0),
                        if changed.is_empty() {
                            "none".to_string()
                        } else {
                            changed.join(", ")
                        }
                    );
                }
                None => {
                    let _ = write!(md, " – |");
                }
            }
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "\nThe bound at smaller η and the first outcome each scene loses are in `docs/benchmarks.md` (\"Energy bound sweep\").\n");
    md
}

#[cfg(test)]
mod tests {
    use super::render;
    use serde_json::json;

    /// One row per scene (a scene's objects repeat its sweep), the ratio injected/dissipated,
    /// and the changed outcomes per η.
    #[test]
    fn renders_one_row_per_scene_with_changes() {
        let sweep = json!([
            {"energy_eta": null, "injected_ke_j": 0.02, "dissipated_j": 1.0, "energy_limited_steps": 0,
             "outcomes": {"plates": {"value": 7.0, "changed": false}}},
            {"energy_eta": 1.0, "injected_ke_j": 0.02, "dissipated_j": 1.0, "energy_limited_steps": 0,
             "outcomes": {"plates": {"value": 7.0, "changed": false}}},
            {"energy_eta": 0.5, "injected_ke_j": 0.02, "dissipated_j": 1.0, "energy_limited_steps": 1,
             "outcomes": {"plates": {"value": 7.0, "changed": false}}},
            {"energy_eta": 0.1, "injected_ke_j": 0.01, "dissipated_j": 1.0, "energy_limited_steps": 4,
             "outcomes": {"plates": {"value": 5.0, "changed": true}}}
        ]);
        let v = json!({"scenes": [
            {"name": "washing", "model": "floor", "energy_sweep": sweep},
            {"name": "washing", "model": "fridge", "energy_sweep": sweep}
        ]});
        let md = render(&v);
        let rows: Vec<&str> = md.lines().filter(|l| l.starts_with("| washing")).collect();
        assert_eq!(rows.len(), 1, "{md}");
        assert!(rows[0].contains("(2.00 %)"), "{}", rows[0]);
        assert!(rows[0].ends_with("1.000e-2, 4, plates |"), "{}", rows[0]);
        assert!(rows[0].contains("2.000e-2, 1, none"), "{}", rows[0]);
    }
}
