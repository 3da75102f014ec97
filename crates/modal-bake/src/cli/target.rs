//! `modal-bake bake --target-error PCT`: the cheapest base meeting an accuracy target (see
//! [`modal_bake::target_error`]).

use anyhow::Context;
use modal_bake::target_error::{bake_to_target, Candidate, PairsParams, Representation};

use super::bake::{print_report, BakeArgs, Progress};

fn describe(r: Representation) -> String {
    match r {
        Representation::Modal(m) => format!("{m} modes, no table"),
        Representation::Table(Some(n), k) => format!("20 modes + table of {n} modes, order {k}"),
        Representation::Table(None, k) => format!("20 modes + table of every mode, order {k}"),
    }
}

pub fn run(args: &BakeArgs, target: f64) -> anyhow::Result<()> {
    let params = args.options.params();
    let transfer = args
        .transfer
        .params()
        .context("--target-error needs --transfer-h (the scene's step)")?;
    let mut progress = Progress::new();
    let (mesh, _) = super::bake::load_mesh(&args.mesh, &args.asset)?;
    let file = args.mesh.display().to_string();
    let res = bake_to_target(
        mesh,
        &params,
        &transfer,
        target,
        &PairsParams::default(),
        &file,
        &mut |s| progress.update(s),
    );
    progress.bar.finish_and_clear();
    if let Some(plain) = &mut progress.plain {
        plain.end_stage();
    }
    let (base, report, tried) =
        res.with_context(|| format!("baking {} failed; nothing was written", args.mesh.display()))?;
    base.write_atomic(&args.out)
        .with_context(|| format!("writing {} failed", args.out.display()))?;
    let acc = base
        .meta
        .accuracy
        .clone()
        .expect("recorded by bake_to_target");
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "report": report,
                "accuracy": acc,
                "tried": tried.iter().map(|c: &Candidate| serde_json::json!({
                    "representation": describe(c.representation),
                    "median_pct": c.median_pct,
                    "worst_pct": c.worst_pct,
                    "query_cost": c.query_cost,
                    "payload_bytes": c.payload_bytes,
                })).collect::<Vec<_>>(),
            }))?
        );
        return Ok(());
    }
    print_report(&args.out, &report);
    outln!(
        "  target {} %: {} — {} (median {:.2} %, worst {:.2} % over {} pairs vs the {} truth at dt {:.2e} s)",
        acc.target_pct,
        if acc.met { "met" } else { "NOT MET (the most accurate candidate was kept)" },
        tried
            .iter()
            .find(|c| c.worst_pct == acc.worst_pct && c.median_pct == acc.median_pct)
            .map_or_else(String::new, |c| describe(c.representation)),
        acc.median_pct,
        acc.worst_pct,
        acc.pairs,
        acc.truth,
        acc.truth_dt
    );
    outln!(
        "  query cost {:.0} multiply-adds per impact-contact pair ({:.2}× the 20-mode query), payload {:.1} KiB",
        acc.query_cost,
        acc.query_cost / acc.query_cost_20,
        acc.payload_bytes as f64 / 1024.0
    );
    for c in &tried {
        outln!(
            "    tried {:<42} median {:>7.2} %  worst {:>7.2} %  cost {:>9.0}  {:>9.1} KiB",
            describe(c.representation),
            c.median_pct,
            c.worst_pct,
            c.query_cost,
            c.payload_bytes as f64 / 1024.0
        );
    }
    Ok(())
}
