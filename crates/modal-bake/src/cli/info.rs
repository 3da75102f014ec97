//! `modal-bake info`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use dcr_runtime::format::ModesFile;

#[derive(Args)]
pub struct InfoArgs {
    /// A .modes base, or a volume mesh (.msh, .json): its size, extent, connected pieces
    /// (--piece), node groups (--fixed, --object) and whether its elements are straight.
    pub file: PathBuf,
    /// One JSON object on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
}

/// Where the base's material came from, from `meta.bake_params.material_choice` (`steel`,
/// `steel with --youngs`, `given`, `default (no --material given)`, or `not recorded` for a
/// base baked before it was stored).
fn material_name(base: &ModesFile) -> String {
    let Some(c) = base.meta.bake_params.get("material_choice") else {
        return "not recorded".into();
    };
    let list = |k: &str| -> Vec<String> {
        c.get(k)
            .and_then(|v| v.as_array())
            .map(|a| {
                a.iter()
                    .filter_map(|s| s.as_str().map(|s| format!("--{s}")))
                    .collect()
            })
            .unwrap_or_default()
    };
    let (explicit, defaulted) = (list("explicit"), list("defaulted"));
    match c.get("preset").and_then(|p| p.as_str()) {
        Some(p) if explicit.is_empty() => p.to_string(),
        Some(p) => format!("{p} with {}", explicit.join(", ")),
        None if defaulted.is_empty() => format!("given ({})", explicit.join(", ")),
        None if explicit.is_empty() => "default (no --material given)".into(),
        None => format!(
            "given ({}), default {}",
            explicit.join(", "),
            defaulted.join(", ")
        ),
    }
}

/// The fixed-node selectors of the base (`below y=0.005: 120 nodes`, `group feet`, ...), from
/// `meta.bake_params`; empty for a free-free base.
fn selectors(base: &ModesFile) -> Vec<String> {
    let p = &base.meta.bake_params;
    if let Some(by) = p.get("fixed_by").and_then(|v| v.as_array()) {
        return by
            .iter()
            .filter_map(|e| {
                let what = e.get(0)?.as_str()?;
                let n = e.get(1)?.as_u64()?;
                Some(format!("{what} ({n} nodes)"))
            })
            .collect();
    }
    let mut out = Vec::new();
    for g in p
        .get("fixed")
        .and_then(|v| v.as_array())
        .into_iter()
        .flatten()
    {
        if let Some(g) = g.as_str() {
            out.push(format!("group {g}"));
        }
    }
    for b in p
        .get("fixed_below")
        .and_then(|v| v.as_array())
        .into_iter()
        .flatten()
    {
        if let Ok(b) = serde_json::from_value::<modal_bake::bake::FixedBelow>(b.clone()) {
            out.push(format!("below {b}"));
        }
    }
    for b in p
        .get("fixed_boxes")
        .and_then(|v| v.as_array())
        .into_iter()
        .flatten()
    {
        out.push(format!("box {b}"));
    }
    out
}

/// Warnings about an implausible size, mass or lowest frequency of the base (a unit mistake).
fn warnings(base: &ModesFile) -> Vec<String> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &base.surface_vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    modal_bake::bake::plausibility_warnings(
        Some(extent),
        base.meta.mass_kg,
        &base.material,
        base.frequencies_hz().first().copied(),
    )
}

pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    if super::info_mesh::is_volume_mesh(&args.file) {
        return super::info_mesh::run(&args.file, args.json);
    }
    if modal_bake::mesh::surface::is_surface_asset(&args.file) {
        anyhow::bail!(
            "{} is a surface asset: `modal-bake mesh {} --dry-run` inspects it (its objects, the mesher, the size estimate)",
            args.file.display(),
            args.file.display()
        );
    }
    // FormatError messages name the file and the entry at fault.
    let base = ModesFile::read(&args.file)?;
    let warnings = warnings(&base);
    let text = if args.json {
        let v = info_json(&args.file, &base, &warnings);
        format!("{}\n", serde_json::to_string_pretty(&v)?)
    } else {
        info_text(&args.file, &base, &warnings)?
    };
    super::emit(&text);
    Ok(())
}

/// `info --json`: every field of the base's summary, the mode table and the warnings.
fn info_json(file: &Path, base: &ModesFile, warnings: &[String]) -> serde_json::Value {
    let freqs = base.frequencies_hz();
    let order = if base.quadratic.is_some() { 2 } else { 1 };
    serde_json::json!({
        "file": file.display().to_string(),
        "format_version": base.meta.format_version,
        "tool_version": base.meta.tool_version,
        "source_hash": base.meta.source_hash,
        "params_hash": base.meta.params_hash,
        "modes": base.num_modes(),
        "eigenvalues": base.eigenvalues,
        "frequencies_hz": freqs,
        "residuals": base.residuals,
        "surface_vertices": base.num_surface_vertices(),
        "surface_triangles": base.surface_triangles.len(),
        "order": order,
        "surface_mid_edge_nodes": base.quadratic.as_ref().map_or(0, |q| q.edges.len()),
        "volume_nodes": base.meta.volume_nodes,
        "volume_tets": base.meta.volume_tets,
        "fixed_nodes": base.fixed_nodes.len(),
        "rigid_modes_excluded": base.meta.rigid_modes_excluded,
        "mass_kg": base.meta.mass_kg,
        "material": {"name": material_name(base), "youngs_pa": base.material.youngs, "poisson": base.material.poisson, "density_kg_m3": base.material.density},
        "fixed_by": selectors(base),
        "warnings": warnings,
        "rayleigh": base.rayleigh,
        "precision": base.precision,
        "bake_params": base.meta.bake_params,
        "surface_order": base.surface_order.is_some(),
        "transfer": base.transfer.as_ref().map(|t| serde_json::json!({
            "h_s": t.h,
            "rayleigh": t.rayleigh,
            "modes": t.modes,
            "samples": t.samples,
            "region_vertices": t.len(),
            "edge_midpoints": t.edges.len(),
            "order": t.order,
            "edges": t.edges.len(),
            "faces": t.faces.len(),
            "points": t.num_points(),
            "packed_values": t.peaks.len(),
            "max_peak_m_per_ns": t.peaks.iter().fold(0.0f32, |a, &b| a.max(b)),
        })),
        "accuracy": base.meta.accuracy,
        // The options `check MESH BASE …` finds it up to date with (null: not a bake's
        // record), and what the base does not record.
        "check_args": super::bake_options::bake_options_of(base).ok().map(|o| serde_json::json!({
            "args": o.args,
            "missing": o.missing,
        })),
    })
}

/// The `check` command that finds the base up to date, rebuilt from its record
/// ([`bake_options_of`](super::bake_options::bake_options_of)); `MESH` stands for the file it
/// was baked from, which a base does not record.
fn write_bake_options(out: &mut String, file: &Path, base: &ModesFile) -> std::fmt::Result {
    match super::bake_options::bake_options_of(base) {
        Ok(o) => {
            writeln!(
                out,
                "  check it with: modal-bake check MESH {} {}",
                file.display(),
                o.args.join(" ")
            )?;
            writeln!(
                out,
                "    (MESH: the file it was baked from; `bake MESH -o OUT` with the same options bakes it again)"
            )?;
            for m in o.missing {
                writeln!(out, "    add by hand: {m}")?;
            }
        }
        Err(e) => writeln!(out, "  check options: not known ({e})")?,
    }
    Ok(())
}

/// `info`: the base's summary as text, then the warnings and the mode table.
fn info_text(
    file: &Path,
    base: &ModesFile,
    warnings: &[String],
) -> Result<String, std::fmt::Error> {
    let mut out = String::new();
    write_model(&mut out, file, base)?;
    write_surface(&mut out, base)?;
    write_tables(&mut out, base)?;
    write_bake_options(&mut out, file, base)?;
    for w in warnings {
        writeln!(out, "  warning: {w}")?;
    }
    write_modes(&mut out, base)?;
    Ok(out)
}

/// The file, format, material, volume mesh and fixed nodes.
fn write_model(out: &mut String, file: &Path, base: &ModesFile) -> std::fmt::Result {
    let order = if base.quadratic.is_some() { 2 } else { 1 };
    writeln!(
        out,
        "{}  (format v{}, {})",
        file.display(),
        base.meta.format_version,
        base.meta.tool_version
    )?;
    writeln!(
        out,
        "  material: {}: E {:.4e} Pa, ν {}, ρ {} kg/m³; mass {:.6} kg",
        material_name(base),
        base.material.youngs,
        base.material.poisson,
        base.material.density,
        base.meta.mass_kg
    )?;
    writeln!(
        out,
        "  volume mesh: {} nodes, {} tets, element order {order} ({}-node tetrahedra)",
        base.meta.volume_nodes,
        base.meta.volume_tets,
        if order == 2 { 10 } else { 4 }
    )?;
    if let Some(sel) = base
        .meta
        .bake_params
        .get("selection")
        .and_then(|v| v.as_object())
    {
        let options = super::bake_options::options_line(super::bake_options::selection_pairs(sel));
        if !options.is_empty() {
            writeln!(out, "  input: its file with {options}")?;
        }
    }
    if let Some(m) = base
        .meta
        .bake_params
        .get("meshing")
        .and_then(|v| v.as_object())
    {
        writeln!(
            out,
            "  meshed from its surface asset with {}",
            super::bake_options::options_line(super::bake_options::meshing_pairs(m))
        )?;
    }
    if let Some(c) = base.meta.bake_params.get("mesh_choice") {
        let num = |k: &str| c.get(k).and_then(serde_json::Value::as_f64);
        writeln!(
            out,
            "  mesh chosen by --target-error {} %: {} — --size {:.4e} m (mesh {} of the refinement); the lowest {} modes moved ≤ {} in the last refinement, estimated error {}",
            num("target_error_pct").unwrap_or(f64::NAN),
            if c.get("met") == Some(&serde_json::Value::Bool(true)) {
                "met"
            } else {
                "NOT met (the finest mesh within the budget)"
            },
            num("size").unwrap_or(f64::NAN),
            c.get("meshes").and_then(serde_json::Value::as_u64).unwrap_or(0),
            c.get("modes_compared").and_then(serde_json::Value::as_u64).unwrap_or(0),
            num("last_change_pct").map_or("(one mesh only)".into(), |x| format!("{x:.2} %")),
            num("estimated_error_pct").map_or("unknown".into(), |x| format!("≈ {x:.2} %")),
        )?;
    }
    if base.fixed_nodes.is_empty() {
        writeln!(
            out,
            "  fixed: nothing (free-free, {} rigid modes excluded)",
            base.meta.rigid_modes_excluded
        )?;
    } else {
        let sel = selectors(base);
        writeln!(
            out,
            "  fixed: {} nodes{}{}",
            base.fixed_nodes.len(),
            if sel.is_empty() { "" } else { " by " },
            sel.join("; ")
        )?;
    }
    Ok(())
}

/// The stored surface, damping, geometry hash and heat-geodesic order.
fn write_surface(out: &mut String, base: &ModesFile) -> std::fmt::Result {
    match &base.quadratic {
        Some(q) => writeln!(
            out,
            "  surface: {} vertices + {} mid-edge nodes, {} 6-node triangles (second order: quadratic interpolation); mode shapes stored as {:?}",
            base.num_surface_vertices(),
            q.edges.len(),
            base.surface_triangles.len(),
            base.precision
        )?,
        None => writeln!(
            out,
            "  surface: {} vertices, {} triangles; mode shapes stored as {:?}",
            base.num_surface_vertices(),
            base.surface_triangles.len(),
            base.precision
        )?,
    }
    writeln!(
        out,
        "  Rayleigh damping: α0 {} 1/s, α1 {} s",
        base.rayleigh[0], base.rayleigh[1]
    )?;
    writeln!(out, "  geometry hash: {}", base.meta.source_hash)?;
    writeln!(
        out,
        "  heat-geodesic elimination order: {}",
        if base.surface_order.is_some() {
            "stored"
        } else {
            "none (AMD at load)"
        }
    )?;
    Ok(())
}

/// The transfer table and the accuracy record, if stored.
fn write_tables(out: &mut String, base: &ModesFile) -> std::fmt::Result {
    match &base.transfer {
        Some(t) => writeln!(
            out,
            "  transfer table: {} region vertices, {} edges, {} faces, order {} ({} points; {} f32 values, {:.1} KiB), h {} s, {} modes, {} samples per step, Rayleigh α0 {} α1 {}, largest peak {:.4e} m per N·s",
            t.len(),
            t.edges.len(),
            t.faces.len(),
            t.order,
            t.num_points(),
            t.peaks.len(),
            t.peaks.len() as f64 * 4.0 / 1024.0,
            t.h,
            t.modes,
            t.samples,
            t.rayleigh[0],
            t.rayleigh[1],
            t.peaks.iter().fold(0.0f32, |a, &b| a.max(b))
        )?,
        None => writeln!(out, "  transfer table: none")?,
    }
    if let Some(a) = &base.meta.accuracy {
        writeln!(
            out,
            "  accuracy target {} %: {} — median {:.2} %, worst {:.2} % over {} pairs at h {} s vs the {} truth (dt {:.2e} s, est. error {:.2} %); query cost {:.0} multiply-adds per pair ({:.2}× 20 modes), payload {:.1} KiB",
            a.target_pct,
            if a.met { "met" } else { "not met" },
            a.median_pct,
            a.worst_pct,
            a.pairs,
            a.h,
            a.truth,
            a.truth_dt,
            a.truth_error_pct,
            a.query_cost,
            a.query_cost / a.query_cost_20,
            a.payload_bytes as f64 / 1024.0
        )?;
    }
    Ok(())
}

/// The mode table: frequency, eigenvalue and residual of each mode.
fn write_modes(out: &mut String, base: &ModesFile) -> std::fmt::Result {
    let freqs = base.frequencies_hz();
    writeln!(out, "  {} modes:", base.num_modes())?;
    writeln!(out, "     #   freq (Hz)      λ (rad²/s²)    residual")?;
    for (j, (&l, f)) in base.eigenvalues.iter().zip(&freqs).enumerate() {
        writeln!(
            out,
            "  {j:4}  {f:12.4}  {l:14.6e}  {:9.1e}",
            base.residuals[j]
        )?;
    }
    Ok(())
}
