//! `modal-bake mesh`: a surface asset (OBJ, STL, PLY, glTF) to a tetrahedral gmsh mesh.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use modal_bake::mesh::{MeshParams, MeshedAsset, MesherChoice};

pub use modal_bake::mesh::Units;

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

/// The tetrahedral mesher (`--mesher`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MesherArg {
    /// Inspect the surface: gmsh when it bounds one solid as it is, fTetWild otherwise; the
    /// other one when the first fails.
    Auto,
    /// gmsh only (quality remeshing of clean closed surfaces); a defective surface is refused.
    Gmsh,
    /// fTetWild only (any surface: open, self-intersecting, non-manifold, several shells).
    Ftetwild,
}

impl MesherArg {
    /// The option's spelling (`auto`, `gmsh`, `ftetwild`).
    pub fn name(self) -> &'static str {
        match self {
            MesherArg::Auto => "auto",
            MesherArg::Gmsh => "gmsh",
            MesherArg::Ftetwild => "ftetwild",
        }
    }
}

/// Element order of a surface asset's tetrahedra when `--order` is not given: 10-node
/// (order 2), far more accurate per degree of freedom than 4-node tetrahedra in bending.
pub const DEFAULT_ORDER: u8 = 2;

/// How the geometry is read: the unit of its coordinates (any mesh) and how a surface asset is
/// tetrahedralized (shared by `mesh`, `bake` and `check`).
#[derive(Args, Clone, Debug)]
pub struct AssetOptions {
    /// Unit of the mesh's or asset's coordinates; they are scaled into metres when read, so
    /// the base, its geometry hash and every other length option (--size, --fixed-below,
    /// --fixed-box, --transfer-region) are in metres.
    #[arg(long, value_enum, default_value_t = Units::M)]
    pub units: Units,
    /// Surface assets: the tetrahedral mesher. `auto` inspects the surface first (open and
    /// non-manifold edges, non-manifold vertices, self-intersections, shells) and runs gmsh on
    /// a surface that bounds one solid as it is, fTetWild on any other, falling back to the
    /// other when one fails; the report says which ran and why.
    #[arg(long, value_enum, default_value_t = MesherArg::Auto)]
    pub mesher: MesherArg,
    /// Surface assets: target tetrahedron size (m; fTetWild's ideal edge length) [default:
    /// 1/20 of the bounding-box diagonal]. gmsh's remeshing makes elements finer where the
    /// surface curves: at most 2π·R/N for a radius of curvature R, with N = 6 elements per
    /// turn at the default size and N in proportion to 1/size (12 at half of it), so every
    /// element scales with --size.
    #[arg(long, value_name = "M")]
    pub size: Option<f64>,
    /// Surface assets, gmsh remeshing: one size everywhere (no finer elements where the
    /// surface curves, nor around short feature curves of a faceted surface).
    #[arg(long)]
    pub uniform_size: bool,
    /// Surface assets, gmsh remeshing: no thickness-aware sizing. By default the elements in a
    /// wall thinner than half the size are at most twice its thickness (measured by rays cast
    /// along the inward normals; never below size/4), so thin walls are not too stiff.
    #[arg(long)]
    pub no_thickness_sizing: bool,
    /// Surface assets: element order, 1 (4-node tetrahedra) or 2 (10-node, straight-sided;
    /// far more accurate per degree of freedom) [default: 2; 1 with --transfer-h, whose table
    /// needs 4-node tetrahedra].
    #[arg(long, value_name = "1|2", value_parser = clap::value_parser!(u8).range(1..=2))]
    pub order: Option<u8>,
    /// Surface assets, fTetWild: how far (m) the tetrahedral surface may lie from the asset's
    /// triangles [default: 1/1000 of the bounding-box diagonal].
    #[arg(long, value_name = "M")]
    pub envelope: Option<f64>,
    /// Surface assets: the gmsh to run: an executable, or the PyPI package's gmsh.py (or the
    /// folder holding it) [default: `gmsh` on PATH, else python3's gmsh module; the Python is
    /// $MODAL_BAKE_PYTHON when set].
    #[arg(long, value_name = "PATH")]
    pub gmsh: Option<PathBuf>,
    /// Surface assets: a FloatTetwild_bin executable to run for fTetWild [default: python3
    /// (or $MODAL_BAKE_PYTHON) with the PyPI package pytetwild].
    #[arg(long, value_name = "PATH")]
    pub ftetwild: Option<PathBuf>,
    /// Surface assets: gmsh keeps the asset's triangles as the boundary instead of remeshing
    /// the surface at --size (for surfaces gmsh cannot reparametrize).
    #[arg(long)]
    pub keep_surface: bool,
    /// Surface assets: time limit of one mesher run (s); the mesher is stopped past it.
    #[arg(long, value_name = "S", default_value_t = modal_bake::mesh::work::DEFAULT_TIMEOUT_S)]
    pub mesher_timeout: f64,
    /// Mesh (or bake) only this named object of the file: a glTF node (with its children,
    /// where the scene places it) or mesh, an OBJ object or group (`o`/`g`), or, in a gmsh
    /// `.msh` volume mesh, a 3-D physical group (its name, or its number when it has none)
    /// [default: the whole file]. A name the file does not have is refused with the names it
    /// has.
    #[arg(long, value_name = "NAME")]
    pub object: Option<String>,
    /// Volume meshes (.msh, .json): bake only connected piece N (tetrahedra joined through
    /// shared nodes; numbered from 1, largest volume first), after --object [default: the
    /// whole mesh, which must be one piece; a mesh of several is refused with the list of its
    /// pieces: number, tetrahedra, volume and bounding box]. A surface asset's parts are
    /// selected by name with --object.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub piece: Option<u64>,
    /// Volume meshes of order 2 (.msh, .json): move every mid-edge node to its edge's midpoint,
    /// so a curved mesh (gmsh's `-order 2` default, Netgen's second order) bakes as
    /// straight-sided, its boundary faceted at the corner nodes as `modal-bake mesh --order 2`
    /// makes it; the largest move is noted [default: a curved element is refused].
    #[arg(long)]
    pub straighten: bool,
}

impl AssetOptions {
    /// How a volume mesh is read: `--object`, `--units`, `--piece`, `--straighten`.
    pub fn volume_selection(&self) -> modal_bake::mesh::VolumeSelection {
        modal_bake::mesh::VolumeSelection {
            object: self.object.clone(),
            units: self.units,
            piece: self.piece,
            straighten: self.straighten,
        }
    }

    /// The element order: `--order`, else [`DEFAULT_ORDER`].
    pub fn order(&self) -> u8 {
        self.order.unwrap_or(DEFAULT_ORDER)
    }

    /// The meshing parameters.
    ///
    /// # Errors
    /// An invalid `--mesher-timeout`; `--piece` or `--straighten`, which apply to volume
    /// meshes only.
    pub fn params(&self) -> anyhow::Result<MeshParams> {
        if let Some(n) = self.piece {
            anyhow::bail!(
                "--piece {n} selects a connected piece of a volume mesh (.msh, .json); a surface asset's parts are selected by name: --object NAME (`modal-bake mesh ASSET --dry-run` lists them)"
            );
        }
        if self.straighten {
            anyhow::bail!(
                "--straighten applies to second-order volume meshes (.msh, .json); a surface asset is meshed straight-sided already"
            );
        }
        Ok(MeshParams {
            mesher: match self.mesher {
                MesherArg::Auto => MesherChoice::Auto,
                MesherArg::Gmsh => MesherChoice::Gmsh,
                MesherArg::Ftetwild => MesherChoice::Ftetwild,
            },
            size: self.size,
            order: self.order(),
            envelope: self.envelope,
            gmsh: self.gmsh.clone(),
            ftetwild: self.ftetwild.clone(),
            keep_surface: self.keep_surface,
            timeout: modal_bake::mesh::work::timeout_of(self.mesher_timeout)
                .map_err(anyhow::Error::msg)?,
            curvature: !self.uniform_size,
            thickness: !self.no_thickness_sizing,
            object: self.object.clone(),
        })
    }

    /// Whether any surface-asset option differs from its default (all but --units apply to
    /// surface assets only).
    pub fn any_set(&self) -> bool {
        self.size.is_some()
            || self.order.is_some()
            || self.gmsh.is_some()
            || self.keep_surface
            || self.uniform_size
            || self.no_thickness_sizing
            || self.mesher != MesherArg::Auto
            || self.envelope.is_some()
            || self.ftetwild.is_some()
            || self.mesher_timeout != modal_bake::mesh::work::DEFAULT_TIMEOUT_S
            || self.object.is_some()
            || self.piece.is_some()
            || self.straighten
    }

    /// Whether an option other than `--object`, `--piece`, `--straighten` and `--units` is
    /// set: those apply to surface assets only (`--object` also selects a physical volume of a
    /// `.msh`; `--piece` and `--straighten` apply to volume meshes only).
    pub fn any_meshing_set(&self) -> bool {
        AssetOptions {
            object: None,
            piece: None,
            straighten: false,
            ..self.clone()
        }
        .any_set()
    }
}

/// Arguments of `modal-bake mesh`.
#[derive(Args)]
#[command(
    after_help = "The surface is inspected first (open and non-manifold edges, non-manifold \
    vertices, self-intersections, shells; each with its position in m). With --mesher auto \
    (the default) a surface that bounds one solid goes to gmsh, any other to fTetWild, and \
    the other backend runs when the first fails. The report names the backend and why, \
    the solid that was filled, and the Hausdorff distance between the asset and the mesh \
    boundary. Both backends run on one thread with fixed seeds: the same inputs and versions \
    give the same bytes. Install: `pip install gmsh` (or `apt-get install gmsh`) and \
    `pip install pytetwild==0.4.2`.\n\n\
    Examples:\n  \
    modal-bake mesh scene.glb --dry-run            (its objects, the mesher, the estimate)\n  \
    modal-bake mesh scene.glb --object Chair -o chair.msh\n  \
    modal-bake mesh lowpoly.obj -o lowpoly.msh --uniform-size"
)]
pub struct MeshArgs {
    /// Surface asset: .obj, .stl (ASCII or binary), .ply (ASCII or binary), or glTF 2.0 (.glb,
    /// or .gltf with its buffers embedded or beside it): every triangle mesh its scene places,
    /// in the scene's frame (glTF's metres, +Y up).
    pub asset: PathBuf,
    /// Output tetrahedral mesh (gmsh MSH 4.1 binary; written atomically).
    #[arg(
        short = 'o',
        long = "out",
        value_name = "OUT.msh",
        required_unless_present = "dry_run"
    )]
    pub out: Option<PathBuf>,
    /// Read and inspect the asset, list its objects, choose the mesher and estimate the work
    /// against the budget, print them and stop: nothing is meshed or written (-o not needed).
    /// Exits 1 when the estimate is over the budget, as the real run would refuse it.
    #[arg(long)]
    pub dry_run: bool,
    /// The asset's unit (--units; the mesh is written in metres) and meshing options.
    #[command(flatten)]
    pub asset_options: AssetOptions,
    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub budget: super::budget::BudgetOptions,
}

/// Meshes `asset`, with progress lines on stderr (which backend runs and why).
pub fn mesh_asset(asset: &Path, options: &AssetOptions) -> anyhow::Result<MeshedAsset> {
    let params = options.params()?;
    eprintln!(
        "meshing {} (order {}, --mesher {}) ...",
        asset.display(),
        options.order(),
        match options.mesher {
            MesherArg::Auto => "auto",
            MesherArg::Gmsh => "gmsh",
            MesherArg::Ftetwild => "ftetwild",
        }
    );
    let mut heartbeat = super::progress::Progress::new("mesh");
    heartbeat.stage("mesh", &format!("meshing {}", asset.display()));
    let progress = |line: &str| eprintln!("  {line}");
    let result = modal_bake::mesh::mesh_asset(asset, options.units.to_metres(), &params, &progress);
    heartbeat.finish();
    let out = result
        .with_context(|| format!("meshing {} failed; nothing was written", asset.display()))?;
    let r = &out.report;
    eprintln!("  backend: {} — {}", r.backend.name(), r.reason);
    if let Some(f) = &r.fallback_from {
        eprintln!("  fallback: {f}");
    }
    eprintln!("  sizing: {}", r.sizing);
    if let Some(e) = &r.excess {
        eprintln!("note: {}: {e}", asset.display());
    }
    let finest = r.wall_size_m.unwrap_or(r.size_m);
    if let Some(t) = r.thin_parts_m.filter(|t| finest > 2.0 * t) {
        eprintln!(
            "warning: {}: the thinnest parts (5 % of the surface) are {t:.3e} m thick and the elements there are up to {:.3e} m: walls thinner than half an element are too stiff in bending, so the lowest frequencies may come out high; check with --target-error PCT, or give --size {:.3e} (twice their thickness) if the budget allows",
            asset.display(),
            finest,
            2.0 * t
        );
    }
    let [lo, hi] = r.inspection.bbox;
    let extent = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    warn_extent(&asset.display().to_string(), extent, options.units, "");
    Ok(out)
}

pub fn run(args: &MeshArgs) -> anyhow::Result<()> {
    let out_path = match (&args.out, args.dry_run) {
        (Some(p), false) => p,
        _ => return dry_run(args),
    };
    super::check_output(out_path, "-o", &[&args.asset])?;
    args.budget
        .check_surface(&args.asset, &args.asset_options, 26, None)?;
    let out = mesh_asset(&args.asset, &args.asset_options)?;
    dcr_files::write_atomic(out_path, &out.msh)
        .with_context(|| format!("writing {}", out_path.display()))?;
    args.budget
        .warn_bake(&out_path.display().to_string(), &out.mesh)?;
    let m = &out.mesh;
    let r = &out.report;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "asset": args.asset.display().to_string(),
                "out": out_path.display().to_string(),
                "report": r,
                "backend": r.backend,
                "reason": r.reason,
                "distance": r.distance,
                "nodes": m.nodes.len(),
                "tets": m.tets.len(),
                "order": if m.is_quadratic() { 2 } else { 1 },
                "dofs": m.dofs(),
            }))?
        );
    } else {
        let i = &r.inspection;
        outln!("wrote {}", out_path.display());
        outln!(
            "  surface: {} vertices, {} triangles: {}{}",
            i.vertices,
            i.triangles,
            i.summary(),
            match i.first_defect() {
                Some(d) => format!(" (first: {d})"),
                None => String::new(),
            }
        );
        outln!(
            "  backend: {} {} ({}), {:.2} s — {}",
            r.backend.name(),
            r.version,
            r.program,
            r.seconds,
            r.reason
        );
        if let Some(f) = &r.fallback_from {
            outln!("  fallback: {f}");
        }
        outln!("  solid: {}", r.solid);
        outln!(
            "  mesh: {} nodes, {} {}-node tetrahedra ({} dofs), size {:.4e} m{}{}{}",
            m.nodes.len(),
            m.tets.len(),
            if m.is_quadratic() { 10 } else { 4 },
            m.dofs(),
            r.size_m,
            r.curvature_elements
                .map(|n| format!(
                    " (finer where the surface curves: {n} elements per turn, at most {:.3}·R at a radius of curvature R)",
                    std::f64::consts::TAU / f64::from(n)
                ))
                .unwrap_or_default(),
            r.envelope_m
                .map(|e| format!(", envelope {e:.4e} m"))
                .unwrap_or_default(),
            if r.reproducible {
                ""
            } else {
                " (not reproducible on this platform: fTetWild's random seed could not be fixed)"
            }
        );
        let d = &r.distance;
        outln!(
            "  distance asset ↔ mesh boundary: Hausdorff {:.4e} m ({:.3} % of the {:.4e} m diagonal); asset→mesh {:.4e} m at ({:.4}, {:.4}, {:.4}), mesh→asset {:.4e} m at ({:.4}, {:.4}, {:.4}); sampled every {:.2e} m",
            d.hausdorff_m,
            100.0 * d.relative,
            if d.relative > 0.0 { d.hausdorff_m / d.relative } else { 0.0 },
            d.asset_to_mesh_m,
            d.asset_to_mesh_at[0],
            d.asset_to_mesh_at[1],
            d.asset_to_mesh_at[2],
            d.mesh_to_asset_m,
            d.mesh_to_asset_at[0],
            d.mesh_to_asset_at[1],
            d.mesh_to_asset_at[2],
            d.spacing_m
        );
    }
    Ok(())
}

/// `mesh --dry-run`: what `mesh` would do with the asset, without meshing or writing.
fn dry_run(args: &MeshArgs) -> anyhow::Result<()> {
    use modal_bake::mesh::surface::{inspect_surface, object_names};
    let asset = &args.asset;
    let file = asset.display().to_string();
    let options = &args.asset_options;
    let params = options.params()?;
    let s = super::budget::read_in_metres(asset, options)?;
    let inspection = inspect_surface(&s);
    let names = object_names(asset)?;
    let backend = modal_bake::mesh::choose_backend(&s, &inspection, params.mesher, &file);
    let size = options
        .size
        .unwrap_or_else(|| modal_bake::mesh::gmsh::default_size(s.bounding_box()));
    if args.json {
        let estimate = args.budget.check_read_surface(asset, &s, options, 26, None);
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "asset": file,
                "dry_run": true,
                "inspection": inspection,
                "objects": names,
                "backend": backend.as_ref().ok().map(|b| b.0),
                "reason": match &backend {
                    Ok(b) => b.1.clone(),
                    Err(e) => e.to_string(),
                },
                "size_m": size,
                "estimate": estimate.as_ref().ok(),
                "refused": estimate.as_ref().err().map(|e| e.to_string()),
            }))?
        );
        // As the real run: refused over the budget, or with gmsh forced on a non-solid.
        estimate.map_err(|e| anyhow::anyhow!("{e}"))?;
        return backend.map(|_| ()).map_err(anyhow::Error::new);
    }
    outln!("dry run: {file} is not meshed and nothing is written");
    outln!(
        "  surface: {} vertices, {} triangles: {}{}",
        inspection.vertices,
        inspection.triangles,
        inspection.summary(),
        match inspection.first_defect() {
            Some(d) => format!(" (first: {d})"),
            None => String::new(),
        }
    );
    if !names.is_empty() {
        let shown: Vec<String> = names.iter().take(20).map(|n| format!("`{n}`")).collect();
        outln!(
            "  objects (--object NAME meshes one; this run: {}): {}{}",
            match &options.object {
                Some(o) => format!("`{o}`"),
                None => "the whole file".into(),
            },
            shown.join(", "),
            if names.len() > 20 {
                format!(", … ({} in all)", names.len())
            } else {
                String::new()
            }
        );
    }
    match &backend {
        Ok((b, why)) => outln!("  backend: {} — {why}", b.name()),
        Err(e) => outln!("  backend: none — {e}"),
    }
    outln!(
        "  size: {size:.4e} m{}",
        if options.size.is_none() {
            " (the default: 1/20 of the bounding-box diagonal)"
        } else {
            ""
        }
    );
    // The estimate (stderr) and the budget's verdict, as the real run prints them.
    args.budget
        .check_read_surface(asset, &s, options, 26, None)?;
    backend.map_err(anyhow::Error::new)?;
    outln!("  `mesh` would run (the estimate and the budget: above, on stderr)");
    Ok(())
}
