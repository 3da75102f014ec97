//! `modal-bake export`: a base's mode shapes as VTU (ParaView, meshio), GLB (Blender,
//! three.js) and a PNG contact sheet.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use dcr_runtime::format::ModesFile;
use modal_bake::export::{
    select_modes, write_modes_glb, write_modes_glb_onto, write_modes_onto_gltf, write_modes_png,
    write_modes_vtu, AssetMesh, ModeGltfParams, OntoParams, SheetParams,
};

use super::mesh::Units;

/// Largest mapping distance, as a fraction of the asset's bounding-box diagonal, below which
/// `--onto` does not warn (gmsh's remeshed surface lies within a small fraction of the asset).
const ONTO_WARN_FRACTION: f64 = 0.02;

/// Arguments of `modal-bake export`.
#[derive(clap::Args, Debug, Clone)]
#[command(after_help = "Examples:\n  \
    modal-bake export out/bases/table.modes --vtu table.vtu --gltf table.glb --png table.png\n  \
    modal-bake export table.modes --png sheet.png --modes 8 --columns 4\n  \
    modal-bake export chair.modes --gltf chair_modes.glb --onto chair.obj\n\n\
    VTU: surface triangles, one point-data vector per mode named mode_NN_F.FHz (displacement in m \
    for a unit modal coordinate, object frame); in ParaView use Warp By Vector.\n\
    GLB: one morph target and one animation per mode (a 1 s sine); the scale and each mode's \
    modal coordinate at weight 1 are in the document's extras.dcr.\n\
    PNG: the lowest modes side by side, coloured by displacement magnitude normalised per mode \
    (viridis, legend below), over a grey ghost of the rest shape, each seen side-on to its own \
    motion; the title names the base, its material and mesh.\n\
    GLB with --onto ASSET: the modes as morph targets named \"mode N — F Hz\" on the asset's own \
    vertices (their count and order); each asset vertex takes the mode at its closest point on the \
    base's surface (the largest such distance is printed). An OBJ, STL or PLY asset is written as \
    one new mesh (positions in m). A glTF asset (.glb, .gltf) is kept, with the targets added to \
    the primitives of the scene or --object in each mesh's own frame: its nodes, materials, \
    textures, UVs, skins and animations stay, images beside a .gltf are embedded, and one preview \
    animation per mode follows its own.\n\
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
    /// With --gltf: put the morph targets on this surface asset's own vertices (.obj, .stl,
    /// .ply, .glb, .gltf; the file the base was baked from) instead of the base's surface.
    #[arg(long, value_name = "ASSET", requires = "gltf")]
    pub onto: Option<PathBuf>,
    /// Unit of the --onto asset's coordinates (as given to `mesh`/`bake` --units).
    #[arg(long, value_enum, default_value_t = Units::M, requires = "onto")]
    pub units: Units,
    /// The named object of the --onto asset the base was baked from (as given to
    /// `mesh`/`bake` --object): a glTF node or mesh, an OBJ object or group.
    #[arg(long, value_name = "NAME", requires = "onto")]
    pub object: Option<String>,
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
    let mut plan = dcr_files::OutputPlan::new();
    plan.input("the base", &args.file);
    if let Some(asset) = &args.onto {
        plan.input("--onto", asset);
    }
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
        if let Some(asset_path) = &args.onto {
            let params = OntoParams {
                modes,
                scale: args.scale,
                ..Default::default()
            };
            let to_metres = args.units.to_metres();
            let object = args.object.as_deref();
            let is_gltf = asset_path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"));
            let info = if is_gltf {
                write_modes_onto_gltf(&base, asset_path, to_metres, object, &params, p)
                    .with_context(|| format!("writing {}", p.display()))?
            } else {
                let asset = AssetMesh::read(asset_path, to_metres, object)
                    .with_context(|| format!("reading --onto {}", asset_path.display()))?;
                write_modes_glb_onto(&base, &asset, &params, p).with_context(|| {
                    format!(
                        "writing {} (modes onto {})",
                        p.display(),
                        asset_path.display()
                    )
                })?
            };
            let kept = if is_gltf {
                format!(
                    " ({} primitive{}; the asset's nodes, materials and animations kept)",
                    info.primitives,
                    if info.primitives == 1 { "" } else { "s" }
                )
            } else {
                String::new()
            };
            report(
                p,
                &format!(
                    "GLB, {modes} morph targets on {} vertices of {}{kept}",
                    info.vertices,
                    asset_path.display()
                ),
                t,
            );
            let rel = info.max_distance_m / info.diagonal_m;
            eprintln!(
                "  mapping: largest distance from an asset vertex to the base's surface {:.3e} m ({:.2} % of the {:.4} m diagonal, vertex {})",
                info.max_distance_m,
                100.0 * rel,
                info.diagonal_m,
                info.max_distance_vertex
            );
            if !(rel <= ONTO_WARN_FRACTION) {
                eprintln!(
                    "warning: asset vertices lie up to {:.1} % of the diagonal from the base's surface (more than {:.0} %): check that {} was baked from {} and that --units matches the bake's (a mesher that closed openings of the asset, as fTetWild does, also moves the boundary: compare with the distance `modal-bake mesh` reported)",
                    100.0 * rel,
                    100.0 * ONTO_WARN_FRACTION,
                    args.file.display(),
                    asset_path.display()
                );
            }
        } else {
            let params = ModeGltfParams {
                modes,
                scale: args.scale,
                ..Default::default()
            };
            write_modes_glb(&base, &params, p)
                .with_context(|| format!("writing {}", p.display()))?;
            report(p, &format!("GLB, {modes} morph targets"), t);
        }
    }
    if let Some(p) = &args.png {
        let t = std::time::Instant::now();
        let params = SheetParams {
            modes,
            scale: args.scale,
            columns: args.columns,
            title: args
                .file
                .file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            ..Default::default()
        };
        write_modes_png(&base, &params, p).with_context(|| format!("writing {}", p.display()))?;
        report(p, &format!("PNG, {modes} panels"), t);
    }
    Ok(())
}
