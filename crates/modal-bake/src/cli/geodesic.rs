//! `modal-bake geodesic`: heat-method geodesic distances (Crane et al. 2013) on the surface of a
//! `.modes` base from one surface vertex to every surface vertex (m, base order).

use std::path::PathBuf;

use anyhow::{bail, Context};
use dcr_runtime::ModalModel;
use ndarray_npy::WriteNpyExt;

/// Arguments of `modal-bake geodesic`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    after_help = "Heat-method geodesic distances (m) from one surface vertex to every surface vertex, \
        in the base's surface-vertex order (Crane, Weischedel & Wardetzky 2013: t = mean edge \
        length², cotan Laplacian, lumped mass, no boundary averaging). Without --npy or --json the \
        distances are printed one per line."
)]
pub struct GeodesicArgs {
    /// The `.modes` file.
    pub file: PathBuf,
    /// Source surface vertex index (0-based, base order).
    #[arg(long)]
    pub from_vertex: usize,
    /// Write the distances as a float64 `.npy` vector here.
    #[arg(long)]
    pub npy: Option<PathBuf>,
    /// Print JSON: {"from_vertex": V, "distances_m": [...]}.
    #[arg(long)]
    pub json: bool,
}

/// Runs `modal-bake geodesic`.
///
/// # Errors
/// Unreadable or invalid file, vertex out of range, a surface the heat method cannot factor, or
/// an unwritable output (one-line messages).
pub fn run(args: &GeodesicArgs) -> anyhow::Result<()> {
    if let Some(path) = &args.npy {
        super::check_output(path, "--npy", &[&args.file])?;
    }
    // LoadError messages already name the file and the cause: one line, no repeated chain.
    let model = ModalModel::load(&args.file).map_err(|e| anyhow::anyhow!("{e}"))?;
    let ns = model.num_vertices();
    if args.from_vertex >= ns {
        bail!(
            "{}: --from-vertex {} is out of range (the surface has {ns} vertices)",
            args.file.display(),
            args.from_vertex
        );
    }
    let heat = model
        .heat_geodesic()
        .map_err(|e| anyhow::anyhow!("{}: heat geodesics: {e}", args.file.display()))?;
    let mut d = vec![0.0; ns];
    heat.distances_from_vertex(args.from_vertex, &mut d);
    if let Some(path) = &args.npy {
        let mut bytes = Vec::new();
        ndarray::Array1::from(d.clone())
            .write_npy(&mut bytes)
            .context("encoding the distances as .npy")?;
        super::create_parent(path)?;
        dcr_files::write_atomic(path, &bytes)?;
    }
    if args.json {
        outln!(
            "{}",
            serde_json::json!({ "from_vertex": args.from_vertex, "distances_m": d })
        );
    } else if args.npy.is_none() {
        for x in &d {
            outln!("{x}");
        }
    }
    Ok(())
}
