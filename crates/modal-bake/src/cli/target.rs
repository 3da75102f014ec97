//! `modal-bake bake --target-error PCT`: the cheapest base meeting an accuracy target (see
//! [`modal_bake::target_error`]).

use anyhow::Context;
use modal_bake::target_error::{
    bake_to_target, Candidate, PairsParams, Representation, Skipped, TargetBake,
};
use modal_bake::transfer::{TransferModes, TransferParams};

use super::bake::{annotate, before_factorization, print_report, BakeArgs, Progress};
use super::mesh::AssetOptions;
use modal_bake::mesh::surface::is_surface_asset;

fn describe(r: Representation) -> String {
    match r {
        Representation::Modal(m) => format!("{m} modes, no table"),
        Representation::Table(Some(n), k) => format!("20 modes + table of {n} modes, order {k}"),
        Representation::Table(None, k) => format!("20 modes + table of every mode, order {k}"),
    }
}

pub fn run(args: &BakeArgs, asset: &AssetOptions, target: f64) -> anyhow::Result<()> {
    let params = args.options.params();
    let surface = is_surface_asset(&args.mesh);
    let Some(mut transfer) = args.transfer.params() else {
        if !surface {
            anyhow::bail!(
                "--target-error without --transfer-h chooses the mesh of a surface asset (.obj, .stl, .ply, .glb, .gltf); {} is a volume mesh: give --transfer-h (the scene's step) to choose its representation",
                args.mesh.display()
            );
        }
        return choose_mesh_and_bake(args, asset, target);
    };
    if surface {
        args.budget
            .check_surface(&args.mesh, asset, args.options.modes_for_estimate(), None)?;
    }
    let loaded = super::bake::load_mesh_with_progress(&args.mesh, asset)?;
    let mesh = loaded.mesh;
    let file = args.mesh.display().to_string();
    // The choice solves for the table's every-mode set (dense where it fits, else Lanczos) and
    // holds each candidate table to the budget.
    let estimated = modal_bake::bake::BakeParams {
        transfer: Some(TransferParams {
            modes: TransferModes::All,
            ..transfer.clone()
        }),
        ..params.clone()
    };
    before_factorization(
        &file,
        &mesh,
        &args.options,
        &estimated,
        &args.budget,
        asset.units,
        surface,
    )?;
    transfer.budget = args.budget.table_budget()?;
    let mut progress = Progress::new("bake");
    let res = bake_to_target(
        mesh,
        &params,
        &transfer,
        target,
        &PairsParams::default(),
        &file,
        &mut |s| progress.update(s),
    );
    progress.finish();
    let TargetBake {
        mut base,
        mut report,
        tried,
        skipped,
    } =
        res.with_context(|| format!("baking {} failed; nothing was written", args.mesh.display()))?;
    report.material_name = args.options.model.material_choice().describe();
    annotate(&mut base, &args.options, asset, &args.mesh, &report);
    super::bake::record_provenance(
        &mut base,
        super::bake::Provenance {
            mesh_choice: None,
            asset_key: loaded.asset_key,
        },
    );
    base.write_atomic(&args.out)
        .with_context(|| format!("writing {} failed", args.out.display()))?;
    let acc = base
        .meta
        .accuracy
        .clone()
        .expect("recorded by bake_to_target");
    let check = modal_bake::target_error::check_options(&base).expect("a target-error base");
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "report": report,
                "accuracy": acc,
                // The options `check` takes in place of --target-error (null: leave out).
                "check_options": {
                    "modes": base.num_modes(),
                    "transfer_modes": base.transfer.as_ref().map(|t| t.modes),
                    "transfer_order": base.transfer.as_ref().map(|t| t.order),
                },
                "tried": tried.iter().map(|c: &Candidate| serde_json::json!({
                    "representation": describe(c.representation),
                    "median_pct": c.median_pct,
                    "worst_pct": c.worst_pct,
                    "query_cost": c.query_cost,
                    "payload_bytes": c.payload_bytes,
                    "build_s": c.build_s,
                })).collect::<Vec<_>>(),
                "skipped": skipped.iter().map(|k: &Skipped| serde_json::json!({
                    "representation": describe(k.representation),
                    "estimated_s": k.over_budget.plan.seconds(),
                    "estimated_bytes": k.over_budget.plan.bytes(),
                    "reason": k.over_budget.to_string(),
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
    outln!("  check it with the bake's options, {check}");
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
    for k in &skipped {
        outln!(
            "    skipped {:<40} {} (over the budget: --max-memory, --max-time; --force builds it)",
            describe(k.representation),
            k.over_budget.plan.describe()
        );
    }
    Ok(())
}

/// Lowest modes compared between successive meshes of the refinement.
const MESH_CHOICE_MODES: usize = 5;

/// `--target-error` without a transfer table on a surface asset: refine the mesh until the
/// lowest modes converge to the target ([`modal_bake::target_error::choose_mesh`]), then bake
/// the chosen mesh as `bake` would.
fn choose_mesh_and_bake(args: &BakeArgs, asset: &AssetOptions, target: f64) -> anyhow::Result<()> {
    use modal_bake::bake::{BakeError, SizeEstimate, SurfaceMeasures};
    use modal_bake::target_error::choose_mesh;
    let budget = args.budget.budget()?;
    // The reader's errors name the file.
    let mut s =
        modal_bake::mesh::surface::read_surface_object(&args.mesh, asset.object.as_deref())?;
    if asset.units.to_metres() != 1.0 {
        s.scale(asset.units.to_metres());
    }
    let measures = SurfaceMeasures::of(&s.vertices, &s.triangles);
    let start = asset
        .size
        .unwrap_or_else(|| modal_bake::mesh::gmsh::default_size(s.bounding_box()));
    let order = asset.order();
    let modes = args.options.modes_for_estimate();
    let force = args.budget.force;
    let file = args.mesh.display().to_string();
    let estimate =
        |h: f64| SizeEstimate::of_surface(&measures, h, asset.keep_surface, order, modes);
    let mut fits = |h: f64| force || estimate(h).fits(&budget);
    let mut mesh_at = |h: f64| {
        eprintln!(
            "target error: meshing at --size {h:.4e} m ({})",
            estimate(h).describe()
        );
        let opts = AssetOptions {
            size: Some(h),
            ..asset.clone()
        };
        super::mesh::mesh_asset(&args.mesh, &opts)
            .map(|out| out.mesh)
            .map_err(|e| BakeError::Params(super::one_line(&e)))
    };
    let mut progress = Progress::new("bake");
    let choice = choose_mesh(
        &mut mesh_at,
        &mut fits,
        start,
        order,
        &args.options.params(),
        target,
        MESH_CHOICE_MODES,
        &file,
        &mut |s| progress.update(s),
    );
    progress.finish();
    let choice = choice
        .with_context(|| format!("choosing a mesh for {file} failed; nothing was written"))?;
    for st in &choice.steps {
        eprintln!(
            "  size {:.4e} m: {} tets, {} dofs, lowest {} Hz{}",
            st.size_m,
            st.tets,
            st.dofs,
            st.frequencies_hz
                .iter()
                .map(|f| format!("{f:.2}"))
                .collect::<Vec<_>>()
                .join(", "),
            match (st.change_pct, st.size_m < start) {
                (Some(c), _) => format!("; moved ≤ {c:.2} %"),
                (None, true) =>
                    "; the same mesh as the previous size (gmsh kept a finer size of its own)"
                        .into(),
                (None, false) => String::new(),
            }
        );
    }
    let last = choice.steps.last().expect("one step at least");
    match (choice.converged, choice.error_pct()) {
        (true, Some(e)) => eprintln!(
            "target error {target} %: met at --size {:.4e} m (order {order}); the lowest {MESH_CHOICE_MODES} modes moved ≤ {:.2} % in the last refinement, estimated error ≈ {e:.2} % (Richardson)",
            last.size_m,
            last.change_pct.unwrap_or(0.0)
        ),
        (_, e) => eprintln!(
            "warning: target error {target} % NOT met: the finest mesh within the budget (--size {:.4e} m) still moved {} (estimated error {}); raise --max-memory / --max-time, or --force",
            last.size_m,
            last.change_pct.map_or("(one mesh only)".into(), |c| format!("{c:.2} %")),
            e.map_or("unknown".into(), |e| format!("≈ {e:.2} %"))
        ),
    }
    let chosen = AssetOptions {
        size: Some(last.size_m),
        ..asset.clone()
    };
    let record = serde_json::json!({
        "target_error_pct": target,
        "met": choice.converged,
        "size": last.size_m,
        "meshes": choice.steps.len(),
        "last_change_pct": last.change_pct,
        "estimated_error_pct": choice.error_pct(),
        "modes_compared": MESH_CHOICE_MODES,
    });
    super::bake::bake_chosen_mesh(args, &chosen, record, choice.mesh)
}
