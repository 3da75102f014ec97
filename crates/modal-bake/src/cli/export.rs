//! `modal-bake export`: a base's mode shapes as VTU (ParaView, meshio), GLB (Blender,
//! three.js) and a PNG contact sheet.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use dcr_runtime::format::ModesFile;
use modal_bake::export::{
    select_modes, write_modes_glb, write_modes_png, write_modes_vtu, ModeGltfParams, SheetParams,
};

/// Arguments of `modal-bake export`.
#[derive(clap::Args, Debug, Clone)]
#[command(after_help = "Examples:\n  \
    modal-bake export out/bases/table.modes --vtu table.vtu --gltf table.glb --png table.png\n  \
    modal-bake export table.modes --png sheet.png --modes 8 --columns 4\n\n\
    VTU: surface triangles, one point-data vector per mode named mode_NN_F.FHz (displacement in m \
    for a unit modal coordinate, object frame); in ParaView use Warp By Vector.\n\
    GLB: one morph target and one animation per mode (a 1 s sine); the scale and each mode's \
    modal coordinate at weight 1 are in the document's extras.dcr.\n\
    PNG: the lowest modes side by side, coloured by displacement magnitude (viridis).\n\
    Second-order bases: each 6-node surface triangle is written as four linear ones through \
    its mid-edge nodes, which follow the corner vertices with their own mode rows.")]
pub struct ExportArgs {
    /// The `.modes` base.
    pub file: PathBuf,
    /// Write the surface and mode shapes as VTK XML unstructured grid here (.vtu).
    #[arg(long, value_name = "OUT.vtu")]
    pub vtu: Option<PathBuf>,
    /// Write the surface with one morph target and one animation per mode here (.glb).
    #[arg(long, value_name = "OUT.glb")]
    pub gltf: Option<PathBuf>,
    /// Write a contact sheet of the modes here (.png).
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    /// How many of the lowest modes (default: every mode up to 20).
    #[arg(long)]
    pub modes: Option<usize>,
    /// Visual amplitude of the GLB morph targets and the PNG: largest displacement as a
    /// fraction of the bounding-box diagonal.
    #[arg(long, default_value_t = 0.05)]
    pub scale: f64,
    /// Contact-sheet panels per row.
    #[arg(long, default_value_t = 4)]
    pub columns: usize,
}

fn report(path: &Path, what: &str, t: std::time::Instant) {
    let size = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    eprintln!(
        "wrote {} ({what}, {:.1} KiB, {:.2} s)",
        path.display(),
        size as f64 / 1024.0,
        t.elapsed().as_secs_f64()
    );
}

/// Runs `modal-bake export`.
///
/// # Errors
/// An unreadable base, no output given, options out of range, or an unwritable output.
pub fn run(args: &ExportArgs) -> anyhow::Result<()> {
    if args.vtu.is_none() && args.gltf.is_none() && args.png.is_none() {
        bail!(
            "nothing to write: give at least one of --vtu OUT.vtu, --gltf OUT.glb, --png OUT.png"
        );
    }
    let mut plan = dcr_runtime::format::OutputPlan::new();
    plan.input("the base", &args.file);
    for (option, path) in [
        ("--vtu", &args.vtu),
        ("--gltf", &args.gltf),
        ("--png", &args.png),
    ] {
        if let Some(p) = path {
            plan.output(option, p)?;
        }
    }
    let base = ModesFile::read(&args.file).map_err(|e| anyhow::anyhow!("{e}"))?;
    let modes = select_modes(&base, args.modes)?;
    if let Some(p) = &args.vtu {
        let t = std::time::Instant::now();
        write_modes_vtu(&base, modes, p).with_context(|| format!("writing {}", p.display()))?;
        report(p, &format!("VTU, {modes} modes"), t);
    }
    if let Some(p) = &args.gltf {
        let t = std::time::Instant::now();
        let params = ModeGltfParams {
            modes,
            scale: args.scale,
            ..Default::default()
        };
        write_modes_glb(&base, &params, p).with_context(|| format!("writing {}", p.display()))?;
        report(p, &format!("GLB, {modes} morph targets"), t);
    }
    if let Some(p) = &args.png {
        let t = std::time::Instant::now();
        let params = SheetParams {
            modes,
            scale: args.scale,
            columns: args.columns,
            ..Default::default()
        };
        write_modes_png(&base, &params, p).with_context(|| format!("writing {}", p.display()))?;
        report(p, &format!("PNG, {modes} panels"), t);
    }
    Ok(())
}
