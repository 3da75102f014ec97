//! `modal-bake info`.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;
use dcr_runtime::format::ModesFile;

#[derive(Args)]
pub struct InfoArgs {
    /// A .modes base.
    pub file: PathBuf,
    /// One JSON object on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    // FormatError messages name the file and the entry at fault.
    let base = ModesFile::read(&args.file)?;
    let freqs = base.frequencies_hz();
    if args.json {
        let v = serde_json::json!({
            "file": args.file.display().to_string(),
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
            "order": if base.quadratic.is_some() { 2 } else { 1 },
            "surface_mid_edge_nodes": base.quadratic.as_ref().map_or(0, |q| q.edges.len()),
            "volume_nodes": base.meta.volume_nodes,
            "volume_tets": base.meta.volume_tets,
            "fixed_nodes": base.fixed_nodes.len(),
            "rigid_modes_excluded": base.meta.rigid_modes_excluded,
            "mass_kg": base.meta.mass_kg,
            "material": {"youngs_pa": base.material.youngs, "poisson": base.material.poisson, "density_kg_m3": base.material.density},
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
        });
        super::emit(&format!("{}\n", serde_json::to_string_pretty(&v)?));
        return Ok(());
    }
    let mut out = String::new();
    writeln!(
        out,
        "{}  (format v{}, {})",
        args.file.display(),
        base.meta.format_version,
        base.meta.tool_version
    )?;
    writeln!(
        out,
        "  material: E {:.4e} Pa, ν {}, ρ {} kg/m³; mass {:.6} kg",
        base.material.youngs, base.material.poisson, base.material.density, base.meta.mass_kg
    )?;
    writeln!(
        out,
        "  volume mesh: {} nodes, {} tets; {}",
        base.meta.volume_nodes,
        base.meta.volume_tets,
        if base.fixed_nodes.is_empty() {
            format!(
                "free-free ({} rigid modes excluded)",
                base.meta.rigid_modes_excluded
            )
        } else {
            format!("{} fixed nodes", base.fixed_nodes.len())
        }
    )?;
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
    writeln!(out, "  {} modes:", base.num_modes())?;
    writeln!(out, "     #   freq (Hz)      λ (rad²/s²)    residual")?;
    for (j, (&l, f)) in base.eigenvalues.iter().zip(&freqs).enumerate() {
        writeln!(
            out,
            "  {j:4}  {f:12.4}  {l:14.6e}  {:9.1e}",
            base.residuals[j]
        )?;
    }
    super::emit(&out);
    Ok(())
}
