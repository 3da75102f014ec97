//! `modal-bake mesh`: a surface asset (OBJ, STL, PLY) to a tetrahedral gmsh mesh.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use modal_bake::mesh::gmsh::{GmshOutput, GmshParams};
use modal_bake::mesh::surface::SurfaceInfo;

/// Length unit of a mesh's or surface asset's coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Units {
    /// Metres (Blender's default export).
    M,
    /// Centimetres.
    Cm,
    /// Millimetres (most CAD exports).
    Mm,
    /// Inches.
    In,
}

impl Units {
    /// Metres per unit.
    pub fn to_metres(self) -> f64 {
        match self {
            Units::M => 1.0,
            Units::Cm => 0.01,
            Units::Mm => 0.001,
            Units::In => 0.0254,
        }
    }

    /// The coordinate `x` (in this unit) in metres. Centimetres and millimetres divide by 100
    /// and 1000 (one correctly rounded operation, so a coordinate exactly representable in
    /// the unit, such as a whole number of millimetres, gives the same bits as the metre value
    /// written in decimal); inches multiply by 0.0254.
    pub fn to_metres_of(self, x: f64) -> f64 {
        match self {
            Units::M => x,
            Units::Cm => x / 100.0,
            Units::Mm => x / 1000.0,
            Units::In => x * 0.0254,
        }
    }

    /// The option's spelling (`m`, `cm`, `mm`, `in`).
    pub fn name(self) -> &'static str {
        match self {
            Units::M => "m",
            Units::Cm => "cm",
            Units::Mm => "mm",
            Units::In => "in",
        }
    }
}

/// Warns (stderr) when an object `extent_m` across (bounding-box diagonal, m) is outside
/// plausible object sizes (0.01 … 100 m), suggesting the `--units` that would bring it
/// into range; `what` names the file and `extra` adds to the message (e.g. its mass).
pub fn warn_extent(what: &str, extent_m: f64, units: Units, extra: &str) {
    if !(extent_m > 100.0) {
        return;
    }
    let hint = if units != Units::M {
        format!(
            "it was read with --units {}: check the file's real unit",
            units.name()
        )
    } else if extent_m <= 100.0 * 1000.0 {
        format!(
            "if the file is in millimetres, rerun with --units mm ({:.4} m across){}",
            extent_m / 1000.0,
            if extent_m <= 100.0 * 100.0 {
                format!("; in centimetres, --units cm ({:.4} m)", extent_m / 100.0)
            } else {
                String::new()
            }
        )
    } else {
        "even read as millimetres (--units mm) it would be over 100 m: is a node misplaced?"
            .to_string()
    };
    eprintln!(
        "warning: {what} is {extent_m:.4e} m across{extra} (plausible objects: 0.01 … 100 m); coordinates are read in metres unless --units says otherwise: {hint}"
    );
}

/// How the geometry is read: the unit of its coordinates (any mesh) and how a surface asset is
/// tetrahedralized (shared by `mesh`, `bake` and `check`).
#[derive(Args, Clone, Debug)]
pub struct AssetOptions {
    /// Unit of the mesh's or asset's coordinates; they are scaled into metres when read, so
    /// the base, its geometry hash and every other length option (--size, --fixed-below,
    /// --fixed-box, --transfer-region) are in metres.
    #[arg(long, value_enum, default_value_t = Units::M)]
    pub units: Units,
    /// Surface assets: target tetrahedron size (m) [default: 1/20 of the bounding-box
    /// diagonal].
    #[arg(long, value_name = "M")]
    pub size: Option<f64>,
    /// Surface assets: element order, 1 (4-node tetrahedra) or 2 (10-node, straight-sided;
    /// far more accurate per degree of freedom).
    #[arg(long, value_name = "1|2", default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub order: u8,
    /// Surface assets: the gmsh to run: an executable, or the PyPI package's gmsh.py
    /// [default: `gmsh` on PATH, else python3's gmsh module].
    #[arg(long, value_name = "PATH")]
    pub gmsh: Option<PathBuf>,
    /// Surface assets: keep the asset's triangles as the boundary instead of remeshing the
    /// surface at --size (for surfaces gmsh cannot reparametrize).
    #[arg(long)]
    pub keep_surface: bool,
}

impl AssetOptions {
    /// The gmsh parameters.
    pub fn params(&self) -> GmshParams {
        GmshParams {
            size: self.size,
            order: self.order,
            gmsh: self.gmsh.clone(),
            keep_surface: self.keep_surface,
        }
    }

    /// Whether any surface-asset option differs from its default (all but --units apply to
    /// surface assets only).
    pub fn any_set(&self) -> bool {
        self.size.is_some() || self.order != 1 || self.gmsh.is_some() || self.keep_surface
    }
}

/// Arguments of `modal-bake mesh`.
#[derive(Args)]
#[command(
    after_help = "The surface must be closed, manifold and consistently oriented; the \
    error names the first defect with its position (m). gmsh runs on one thread with fixed \
    algorithms and seed, so a given gmsh version always gives the same mesh. Without gmsh: \
    `pip install gmsh` or `apt-get install gmsh`."
)]
pub struct MeshArgs {
    /// Surface asset: .obj, .stl (ASCII or binary) or .ply (ASCII or binary).
    pub asset: PathBuf,
    /// Output tetrahedral mesh (gmsh MSH 4.1 binary; written atomically).
    #[arg(short = 'o', long = "out", value_name = "OUT.msh")]
    pub out: PathBuf,
    /// The asset's unit (--units; the mesh is written in metres) and meshing options.
    #[command(flatten)]
    pub asset_options: AssetOptions,
    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Meshes `asset` with a line on stderr while gmsh runs.
pub fn mesh_asset(
    asset: &Path,
    options: &AssetOptions,
) -> anyhow::Result<(GmshOutput, SurfaceInfo)> {
    eprintln!(
        "meshing {} with gmsh (order {}) ...",
        asset.display(),
        options.order
    );
    let (out, info) =
        modal_bake::mesh::mesh_asset(asset, options.units.to_metres(), &options.params())
            .with_context(|| format!("meshing {} failed; nothing was written", asset.display()))?;
    let [lo, hi] = info.bbox;
    let extent = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    warn_extent(&asset.display().to_string(), extent, options.units, "");
    Ok((out, info))
}

pub fn run(args: &MeshArgs) -> anyhow::Result<()> {
    super::check_output(&args.out, "-o", &[&args.asset])?;
    let (out, surface) = mesh_asset(&args.asset, &args.asset_options)?;
    dcr_runtime::format::write_atomic(&args.out, &out.msh)
        .with_context(|| format!("writing {}", args.out.display()))?;
    let m = &out.mesh;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "asset": args.asset.display().to_string(),
                "out": args.out.display().to_string(),
                "surface": surface,
                "gmsh": out.info,
                "nodes": m.nodes.len(),
                "tets": m.tets.len(),
                "order": if m.is_quadratic() { 2 } else { 1 },
                "dofs": m.dofs(),
            }))?
        );
    } else {
        outln!("wrote {}", args.out.display());
        outln!(
            "  surface: {} vertices, {} triangles, volume {:.6e} m³{}",
            surface.vertices,
            surface.triangles,
            surface.volume_m3,
            if surface.flipped {
                " (triangles faced inward: reversed)"
            } else {
                ""
            }
        );
        outln!(
            "  mesh: {} nodes, {} {}-node tetrahedra ({} dofs), size {:.4e} m",
            m.nodes.len(),
            m.tets.len(),
            if m.is_quadratic() { 10 } else { 4 },
            m.dofs(),
            out.info.size_m
        );
        outln!(
            "  gmsh {} ({}), {:.2} s",
            out.info.version,
            out.info.program,
            out.info.seconds
        );
    }
    Ok(())
}
