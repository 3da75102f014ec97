//! The meshing chain for a surface asset: check the range, inspect, choose a backend, run it,
//! fall back, measure the result.
//!
//! 1. Every vertex within ±[`dcr_runtime::format::MAX_COORDINATE_M`] and the surface at least
//!    [`dcr_runtime::format::MIN_EXTENT_M`] across (the volume reader's bounds), and the element
//!    count implied by the size below [`MAX_TETS_FROM_SIZE`] — before any child process runs.
//! 2. [`inspect_surface`]: open, non-manifold, inconsistently oriented, self-intersecting, shells.
//! 3. [`MesherChoice::Auto`]: a surface that bounds one solid as it is goes to gmsh (quality
//!    remeshing); any other to fTetWild (made for surfaces from the wild) — decided up front,
//!    so a defect visible in the inspection never costs a gmsh run. A forced gmsh on a defective
//!    surface is refused with the defect, its position and the fix.
//! 4. Auto only: when the chosen backend fails, the other runs (gmsh only for a surface that
//!    bounds a solid), and the report says why.
//! 5. Second order from either backend by straight-sided mid-edge nodes (gmsh's own, or
//!    [`TetMesh::to_quadratic`] for fTetWild's linear tetrahedra).
//! 6. [`surface_distance`]: the Hausdorff distance between the asset and the mesh boundary,
//!    and the thickness of the asset's thinnest parts ([`super::sizing::thin_parts`]).
//!
//! The size is `--size`, or 1/20 of the bounding-box diagonal; gmsh's remeshing makes elements
//! finer where the surface curves ([`super::sizing`]), in proportion to the size.

use std::path::PathBuf;
use std::time::Duration;

use super::distance::{surface_distance, SurfaceDistance};
use super::ftetwild::{self, FtetwildError, FtetwildParams};
use super::gmsh::{self, GmshError, GmshParams};
use super::sizing::diagonal;
use super::surface::{inspect_surface, SurfaceError, SurfaceInspection, SurfaceMesh};
use super::work::DEFAULT_TIMEOUT_S;
use super::{msh41_bytes, read_msh_bytes, MeshError, TetMesh};

/// Most tetrahedra a `size` may imply (volume over a regular tetrahedron of edge `size`) before
/// meshing: beyond it no bake on one machine would finish, and gmsh or fTetWild would run for
/// hours.
pub const MAX_TETS_FROM_SIZE: f64 = 2.0e7;

/// Which tetrahedral mesher to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MesherChoice {
    /// gmsh for a surface that bounds one solid as it is, fTetWild otherwise (default).
    #[default]
    Auto,
    /// gmsh only (a defective surface is refused).
    Gmsh,
    /// fTetWild only.
    Ftetwild,
}

/// The backend that made a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// gmsh.
    Gmsh,
    /// fTetWild.
    Ftetwild,
}

impl Backend {
    /// `gmsh` or `fTetWild`.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Gmsh => "gmsh",
            Backend::Ftetwild => "fTetWild",
        }
    }
}

/// Meshing parameters (SI).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshParams {
    /// Backend choice. Default [`MesherChoice::Auto`].
    pub mesher: MesherChoice,
    /// Target element size (m; fTetWild's ideal edge length); `None`: 1/20 of the bounding-box
    /// diagonal.
    pub size: Option<f64>,
    /// Element order, 1 or 2 (straight-sided 10-node tetrahedra). Default 1.
    pub order: u8,
    /// fTetWild's envelope (m); `None`: 1/1000 of the bounding-box diagonal.
    pub envelope: Option<f64>,
    /// The gmsh to run ([`GmshParams::gmsh`]).
    pub gmsh: Option<PathBuf>,
    /// A `FloatTetwild_bin` to run instead of pytetwild.
    pub ftetwild: Option<PathBuf>,
    /// gmsh: keep the asset's triangles as the boundary ([`GmshParams::keep_surface`]).
    pub keep_surface: bool,
    /// Time limit of each mesher run. Default [`DEFAULT_TIMEOUT_S`].
    pub timeout: Duration,
    /// gmsh remeshing: finer elements where the surface curves, N =
    /// [`super::sizing::curvature_elements`] per full turn (6 at the default size, in
    /// proportion to 1/size). Default true.
    pub curvature: bool,
    /// gmsh remeshing: elements no larger than [`super::sizing::WALL_SIZE_FACTOR`] times the
    /// local wall thickness where the asset is thin ([`super::sizing::thickness_grid`]).
    /// Default true.
    pub thickness: bool,
    /// The named object of the asset to mesh ([`super::surface::read_surface_object`]: a glTF
    /// node or mesh, an OBJ object or group); `None` (the default): the whole asset. Read by
    /// [`super::mesh_asset`].
    pub object: Option<String>,
}

impl Default for MeshParams {
    fn default() -> Self {
        MeshParams {
            mesher: MesherChoice::Auto,
            size: None,
            order: 1,
            envelope: None,
            gmsh: None,
            ftetwild: None,
            keep_surface: false,
            timeout: Duration::from_secs_f64(DEFAULT_TIMEOUT_S),
            curvature: true,
            thickness: true,
            object: None,
        }
    }
}

/// What the chain did, for the command's report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MeshReport {
    /// The inspection of the asset (m).
    pub inspection: SurfaceInspection,
    /// The backend whose mesh this is.
    pub backend: Backend,
    /// Why that backend ran.
    pub reason: String,
    /// When the first backend failed: its error (the report's backend ran instead).
    pub fallback_from: Option<String>,
    /// What solid the mesh fills.
    pub solid: String,
    /// How the backend was run and its version.
    pub program: String,
    /// The backend's version.
    pub version: String,
    /// Element size (m; fTetWild: the ideal edge length).
    pub size_m: f64,
    /// Thickness of the asset's thinnest parts (m; [`super::sizing::thin_parts`]); `None`
    /// when no inward ray hits the surface again.
    pub thin_parts_m: Option<f64>,
    /// gmsh remeshing: elements per full turn of curvature (finer elements where the surface
    /// curves); `None` for a uniform size, `keep_surface` and fTetWild.
    pub curvature_elements: Option<u32>,
    /// Whether the curvature sizes came from the asset's triangles as the size estimate
    /// measures them ([`super::sizing::local_sizes`], a `Structured` field), not from gmsh's
    /// own curvature sizing: the mesh made again after gmsh's was over [`GMSH_EXCESS`] times
    /// the estimate ([`MeshReport::excess`] says so).
    pub curvature_from_surface: bool,
    /// Which sizing ran and why, in words: uniform, curvature, thickness-aware (with the
    /// share of the surface it refined and the smallest wall size), or why not.
    pub sizing: String,
    /// Thickness-aware sizing: the smallest element size it asked for (m); `None` when it
    /// did not run or refined nothing.
    pub wall_size_m: Option<f64>,
    /// fTetWild's envelope (m); `None` for gmsh.
    pub envelope_m: Option<f64>,
    /// Whether the backend's output is reproducible (same input → same bytes).
    pub reproducible: bool,
    /// Seconds in the backend that made the mesh.
    pub seconds: f64,
    /// Element order.
    pub order: u8,
    /// Volume of the tetrahedral mesh (m³).
    pub volume_m3: f64,
    /// Whether the asset's triangles faced inward (gmsh input reversed).
    pub flipped: bool,
    /// Asset ↔ mesh-boundary distances (m).
    pub distance: SurfaceDistance,
    /// Set when gmsh's curvature sizing made more than [`GMSH_EXCESS`] times the tetrahedra the
    /// size estimate expected: the counts, the likely cause (a faceted surface), and what was
    /// done — the asset meshed again with the curvature sizes the estimate assumes
    /// ([`MeshReport::curvature_from_surface`]), or why that failed.
    pub excess: Option<String>,
}

/// The factor over the size estimate's tetrahedra past which a gmsh mesh with curvature
/// sizing is set aside and the asset meshed again with the curvature sizes the estimate
/// measures on its triangles ([`MeshReport::excess`], [`MeshReport::curvature_from_surface`]):
/// the estimate's documented spread where curvature sizing sets the elements is about 2.5
/// (docs/artist-guide.md § 7).
pub const GMSH_EXCESS: f64 = 3.0;

/// A meshed asset: the mesh (m), the `.msh` bytes to save, and the report.
#[derive(Clone, Debug)]
pub struct MeshedAsset {
    /// The tetrahedral mesh as [`super::read_msh_bytes`] reads `msh`.
    pub mesh: TetMesh,
    /// gmsh MSH 4.1 binary.
    pub msh: Vec<u8>,
    /// What was done.
    pub report: MeshReport,
}

/// Why an asset could not be meshed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AssetError {
    /// The surface is unreadable, or (gmsh forced) does not bound a solid.
    #[error(transparent)]
    Surface(#[from] SurfaceError),
    /// gmsh was forced on a surface that does not bound a solid.
    #[error("{file}: --mesher gmsh needs a closed, manifold, consistently oriented surface without self-intersections; this one has {summary}; the first: {first}. Fix: use --mesher ftetwild or --mesher auto (the default), or repair the surface")]
    NotASolid {
        /// The asset.
        file: String,
        /// The defect counts.
        summary: String,
        /// The first defect with its position (m).
        first: String,
    },
    /// A vertex outside the supported range.
    #[error("{file}: vertex {vertex} (1-based, after merging coincident vertices) at ({:e}, {:e}, {:e}) m is outside ±{max:e} m; check --units and the asset's placement (move it near the origin)", at[0], at[1], at[2])]
    OutOfRange {
        /// The asset.
        file: String,
        /// 1-based vertex number.
        vertex: usize,
        /// Its position (m).
        at: [f64; 3],
        /// The bound (m).
        max: f64,
    },
    /// The asset is too small.
    #[error(
        "{file}: the surface is {extent:e} m across, below the supported {min:e} m; check --units"
    )]
    TooSmall {
        /// The asset.
        file: String,
        /// Bounding-box diagonal (m).
        extent: f64,
        /// The bound (m).
        min: f64,
    },
    /// The size implies too many elements.
    #[error("{file}: --size {size:e} m would make about {estimate:.2e} tetrahedra in its {volume:.3e} m³ (limit {MAX_TETS_FROM_SIZE:.0e}); use --size {smallest:.3e} or larger")]
    TooFine {
        /// The asset.
        file: String,
        /// The size (m).
        size: f64,
        /// The estimated tetrahedron count.
        estimate: f64,
        /// The volume used for the estimate (m³).
        volume: f64,
        /// The smallest size within the limit (m).
        smallest: f64,
    },
    /// Invalid options.
    #[error("{0}")]
    Params(String),
    /// gmsh is missing or failed.
    #[error(transparent)]
    Gmsh(#[from] GmshError),
    /// fTetWild is missing or failed.
    #[error(transparent)]
    Ftetwild(#[from] FtetwildError),
    /// Both backends failed (auto).
    #[error("{first}; then {second}")]
    BothFailed {
        /// The first backend's error.
        first: String,
        /// The fallback's error.
        second: String,
    },
    /// A mesh could not be read back.
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// Refuses vertices outside the supported range and sizes implying too many elements.
fn check_ranges(
    surface: &SurfaceMesh,
    inspection: &SurfaceInspection,
    params: &MeshParams,
    file: &str,
) -> Result<f64, AssetError> {
    use dcr_runtime::format::{MAX_COORDINATE_M, MIN_EXTENT_M};
    if let Some(i) = surface
        .vertices
        .iter()
        .position(|p| !p.iter().all(|x| x.abs() <= MAX_COORDINATE_M))
    {
        return Err(AssetError::OutOfRange {
            file: file.into(),
            vertex: i + 1,
            at: surface.vertices[i],
            max: MAX_COORDINATE_M,
        });
    }
    let diag = diagonal(inspection.bbox);
    if !(diag >= MIN_EXTENT_M) {
        return Err(AssetError::TooSmall {
            file: file.into(),
            extent: diag,
            min: MIN_EXTENT_M,
        });
    }
    let size = match params.size {
        Some(s) if !(s.is_finite() && s > 0.0) => {
            return Err(AssetError::Params(format!(
                "--size must be a positive length in metres, got {s}"
            )))
        }
        Some(s) => s,
        None => super::sizing::default_size(inspection.bbox),
    };
    if let Some(e) = params.envelope {
        if !(e.is_finite() && e > 0.0 && e < diag) {
            return Err(AssetError::Params(format!(
                "--envelope must be a positive length in metres below the asset's extent ({diag:.4e} m), got {e}"
            )));
        }
    }
    let b = inspection.bbox;
    let box_volume: f64 = (0..3).map(|k| b[1][k] - b[0][k]).product();
    let closed = surface.signed_volume().abs();
    let volume = if inspection.is_solid() && closed > 0.0 {
        closed
    } else {
        box_volume.max(closed)
    };
    let per_tet = size.powi(3) / (6.0 * std::f64::consts::SQRT_2);
    let estimate = volume / per_tet;
    if estimate > MAX_TETS_FROM_SIZE {
        let smallest = (volume * 6.0 * std::f64::consts::SQRT_2 / MAX_TETS_FROM_SIZE).cbrt();
        return Err(AssetError::TooFine {
            file: file.into(),
            size,
            estimate,
            volume,
            smallest: smallest * 1.001,
        });
    }
    Ok(size)
}

/// The backend `mesher` picks for `surface` (inspected as `inspection`) and why, as
/// [`mesh_surface`] runs it: `Auto` takes gmsh for a surface that bounds one solid as it is
/// (closed, manifold, consistently oriented, no self-intersection, one shell) and fTetWild
/// otherwise, naming the first defect.
///
/// # Errors
/// [`AssetError::NotASolid`] when gmsh is forced on a surface that does not bound a solid
/// (the defect, its position, the fix).
pub fn choose_backend(
    surface: &SurfaceMesh,
    inspection: &SurfaceInspection,
    mesher: MesherChoice,
    file: &str,
) -> Result<(Backend, String), AssetError> {
    let solid = inspection.is_solid();
    let first = inspection
        .first_defect()
        .map_or_else(|| inspection.summary(), |d| d.to_string());
    Ok(match mesher {
        MesherChoice::Auto if solid => (
            Backend::Gmsh,
            "auto: the surface bounds one solid as it is (closed, manifold, consistently oriented, no self-intersection, one shell), so gmsh remeshes it".to_string(),
        ),
        MesherChoice::Auto => {
            // A located defect is named; separate shells are meshed as one object.
            let located = inspection
                .first_defect()
                .map_or_else(String::new, |d| format!(" (first: {d})"));
            let shells = if inspection.shells > 1 {
                "; its shells are meshed together as one object (one named object of a glTF or OBJ: --object NAME)"
            } else {
                ""
            };
            (
                Backend::Ftetwild,
                format!(
                    "auto: the surface has {}{located}; gmsh needs a surface that bounds a solid, fTetWild does not{shells}",
                    inspection.summary()
                ),
            )
        }
        MesherChoice::Gmsh if !solid => {
            // The existing closed-surface check words open edges, orientation and shells with
            // both positions; self-intersections only the inspection sees.
            let mut copy = surface.clone();
            let first = match copy.check_closed(file) {
                Err(e) => e.to_string(),
                Ok(_) => first,
            };
            return Err(AssetError::NotASolid {
                file: file.into(),
                summary: inspection.summary(),
                first,
            });
        }
        MesherChoice::Gmsh => (Backend::Gmsh, "--mesher gmsh".to_string()),
        MesherChoice::Ftetwild => (Backend::Ftetwild, "--mesher ftetwild".to_string()),
    })
}

/// Meshes `surface` (m; as read, not yet checked) following the chain in the module docs.
/// `file` names the asset in messages; `progress` receives a line for each stage and about
/// every 15 s while a backend runs.
///
/// # Errors
/// [`AssetError`]: out of range, too fine, gmsh forced on a defective surface (the defect, its
/// position, the fix), the backends' failures (both, after a fallback), unreadable output.
pub fn mesh_surface(
    surface: &SurfaceMesh,
    params: &MeshParams,
    file: &str,
    progress: &dyn Fn(&str),
) -> Result<MeshedAsset, AssetError> {
    if !matches!(params.order, 1 | 2) {
        return Err(AssetError::Params(format!(
            "--order must be 1 or 2, got {}",
            params.order
        )));
    }
    let inspection = inspect_surface(surface);
    let size = check_ranges(surface, &inspection, params, file)?;
    let solid = inspection.is_solid();
    progress(&format!(
        "inspected {file}: {} vertices, {} triangles: {}",
        inspection.vertices,
        inspection.triangles,
        inspection.summary()
    ));
    let (backend, reason) = choose_backend(surface, &inspection, params.mesher, file)?;
    progress(&format!("meshing with {}: {reason}", backend.name()));
    let curvature = (params.curvature && !params.keep_surface)
        .then(|| super::sizing::curvature_elements(size, diagonal(inspection.bbox)));
    let diameters = super::sizing::shape_diameters(surface);
    let mut grid = (params.thickness && !params.keep_surface)
        .then(|| super::sizing::thickness_grid_from(surface, &diameters, size))
        .flatten();
    let params = &MeshParams {
        size: Some(size),
        ..params.clone()
    };
    let walls = params.thickness.then_some(diameters.as_slice());
    // gmsh's curvature sizing is stopped once its surface mesh is already far finer than the
    // estimate's (the volume would be tens of times over): [`SURFACE_GUARD`].
    let expected_boundary = curvature.map(|_| {
        let h = super::sizing::equivalent_size_with(surface, size, true, walls);
        let measures = crate::bake::SurfaceMeasures::of(&surface.vertices, &surface.triangles);
        crate::bake::SizeEstimate::of_surface(&measures, h, false, 1, 1).boundary
    });
    let surface_limit = expected_boundary.map(|b| (SURFACE_GUARD * b).ceil() as u64);
    let first_try = run_backend(
        backend,
        surface,
        &inspection,
        params,
        (curvature, grid.as_ref(), surface_limit),
        file,
        progress,
    );
    let (mesh, mut report) = match first_try {
        Ok(ok) => ok,
        Err(AssetError::Gmsh(GmshError::SurfaceOverLimit { triangles, .. })) => {
            let note = format!(
                "gmsh's surface mesh had {} triangles, over {SURFACE_GUARD} times the ~{} the size estimate expected, so gmsh was stopped before filling the volume: {OVER_REFINED}",
                crate::bake::group_digits(triangles as usize),
                crate::bake::format_count(expected_boundary.unwrap_or(0.0)),
            );
            let (m, r, own) = mesh_with_own_sizes(
                surface,
                &inspection,
                params,
                (size, walls, curvature),
                (file, &note),
                progress,
            )?;
            grid = own;
            (m, r)
        }
        Err(e) if params.mesher == MesherChoice::Auto => {
            let other = match backend {
                Backend::Gmsh => Backend::Ftetwild,
                Backend::Ftetwild if solid => Backend::Gmsh,
                Backend::Ftetwild => return Err(e),
            };
            progress(&format!(
                "{} failed ({e}); falling back to {}",
                backend.name(),
                other.name()
            ));
            match run_backend(
                other,
                surface,
                &inspection,
                params,
                (curvature, grid.as_ref(), None),
                file,
                progress,
            ) {
                Ok((m, mut r)) => {
                    r.fallback_from = Some(format!("{} failed: {e}", backend.name()));
                    r.reason = format!(
                        "{reason}; {} failed, so {} ran",
                        backend.name(),
                        other.name()
                    );
                    (m, r)
                }
                Err(e2) => {
                    return Err(AssetError::BothFailed {
                        first: e.to_string(),
                        second: e2.to_string(),
                    })
                }
            }
        }
        Err(e) => return Err(e),
    };
    if report.reason.is_empty() {
        report.reason = reason;
    }
    let mut mesh = mesh;
    if report.backend == Backend::Gmsh && curvature.is_some() && !report.curvature_from_surface {
        if let Some(note) = excess(surface, params.order, size, walls, mesh.mesh.tets.len()) {
            // gmsh's curvature sizing followed something other than the surface's curvature
            // (a faceted asset's creases and short feature curves).
            let made = mesh_with_own_sizes(
                surface,
                &inspection,
                params,
                (size, walls, curvature),
                (file, &note),
                progress,
            );
            match made {
                Ok((m, mut r, own)) => {
                    r.reason = std::mem::take(&mut report.reason);
                    r.fallback_from = report.fallback_from.take();
                    r.seconds += report.seconds;
                    report = r;
                    mesh = m;
                    grid = own;
                }
                Err(e) => {
                    report.excess = Some(format!(
                    "{note}; meshing again with {OWN_SIZES} failed ({e}), so this is gmsh's mesh"
                ))
                }
            }
        }
    }
    progress(&format!(
        "measuring the distance between {file} and the mesh boundary"
    ));
    let linear = TetMesh {
        mid_edges: Vec::new(),
        ..mesh.mesh.clone()
    };
    report.distance = surface_distance(surface, &linear);
    report.thin_parts_m = super::sizing::thin_parts_from(surface, &diameters);
    report.sizing = sizing_words(&report, params, grid.as_ref());
    if report.backend == Backend::Gmsh {
        report.wall_size_m = grid.as_ref().map(|g| g.smallest_m);
    }
    Ok(MeshedAsset {
        mesh: mesh.mesh,
        msh: mesh.msh,
        report,
    })
}

/// [`MeshReport::excess`] of a gmsh mesh of `tets` tetrahedra of `order` made with curvature
/// sizing at `size` (m), thickness-aware with the walls' `diameters` when given: `None`
/// within [`GMSH_EXCESS`] times the size estimate's tetrahedra.
fn excess(
    surface: &SurfaceMesh,
    order: u8,
    size: f64,
    diameters: Option<&[Option<f64>]>,
    tets: usize,
) -> Option<String> {
    use crate::bake::{format_count, group_digits, SizeEstimate, SurfaceMeasures};
    let measures = SurfaceMeasures::of(&surface.vertices, &surface.triangles);
    let estimate = |curvature: bool| {
        let h = super::sizing::equivalent_size_with(surface, size, curvature, diameters);
        SizeEstimate::of_surface(&measures, h, false, order, 1).tets
    };
    let expected = estimate(true);
    let ratio = tets as f64 / expected;
    (ratio > GMSH_EXCESS).then(|| {
        format!(
            "gmsh made {ratio:.1} times the tetrahedra the size estimate expected ({} for ~{}): \
             {OVER_REFINED} (--uniform-size: one size everywhere, ~{} tetrahedra at this size; \
             check the accuracy with --target-error PCT)",
            group_digits(tets),
            format_count(expected),
            format_count(estimate(false)),
        )
    })
}

/// The factor over the size estimate's boundary triangles past which gmsh, remeshing with
/// its curvature sizing, is stopped before it fills the volume
/// ([`super::gmsh::GmshParams::max_surface_triangles`]) and the asset meshed with the
/// estimate's curvature sizes at once: its tetrahedra would be far past [`GMSH_EXCESS`] times
/// the estimate (they grow at least as the boundary triangles do). The estimate's own spread
/// on the boundary is within about 2.5 where gmsh's curvature sizing sets it.
pub const SURFACE_GUARD: f64 = 10.0;

/// Why gmsh's curvature sizing went past the estimate, in words (both notes).
const OVER_REFINED: &str = "its curvature sizing refined more than the surface's curvature asks for — on a faceted surface (a low-poly model, as game assets are) it follows the facets' creases and short feature curves";

/// What [`mesh_with_own_sizes`] meshes with, in words.
const OWN_SIZES: &str = "the curvature sizes the size estimate measures on the asset's triangles (a size field; gmsh's own curvature sizing off)";

/// gmsh remeshing `surface` at `size` (m) with the curvature sizes the size estimate assumes
/// ([`super::sizing::local_sizes`]: the asset's own triangles' curvature, with the walls'
/// `diameters` when thickness-aware) as a `Structured` field, gmsh's curvature sizing and its
/// extension of boundary sizes off: the sizing that follows the surface the asset describes,
/// not its facets. `note` says why gmsh's own sizing was set aside. Returns the mesh, its
/// report (`curvature_elements` as asked, `curvature_from_surface` set, `excess` the note
/// with the tetrahedra made instead) and the field.
fn mesh_with_own_sizes(
    surface: &SurfaceMesh,
    inspection: &SurfaceInspection,
    params: &MeshParams,
    (size, walls, curvature): (f64, Option<&[Option<f64>]>, Option<u32>),
    (file, note): (&str, &str),
    progress: &dyn Fn(&str),
) -> Result<(Made, MeshReport, Option<super::sizing::SizeGrid>), AssetError> {
    progress(&format!("{note}: meshing again with {OWN_SIZES}"));
    let sizes = super::sizing::local_sizes(surface, size, true, walls);
    let own = super::sizing::surface_size_grid(surface, &sizes, size);
    let (m, mut r) = run_backend(
        Backend::Gmsh,
        surface,
        inspection,
        params,
        (None, own.as_ref(), None),
        file,
        progress,
    )?;
    r.curvature_elements = curvature;
    r.curvature_from_surface = true;
    r.excess = Some(format!(
        "{note}; meshed again with {OWN_SIZES}: {} tetrahedra",
        crate::bake::group_digits(m.mesh.tets.len())
    ));
    Ok((m, r, own))
}

/// The report's `sizing` line.
fn sizing_words(
    report: &MeshReport,
    params: &MeshParams,
    grid: Option<&super::sizing::SizeGrid>,
) -> String {
    use super::sizing::{MAX_WALL_REFINEMENT, WALL_SIZE_FACTOR};
    let size = report.size_m;
    if report.backend == Backend::Ftetwild {
        return format!(
            "fTetWild: one ideal edge length {size:.4e} m everywhere (fTetWild takes no size field: neither curvature nor thickness sizing applies)"
        );
    }
    if params.keep_surface {
        return "gmsh --keep-surface: the asset's triangles set the sizes near the surface, at most the size inside".into();
    }
    let mut parts = vec![match report.curvature_elements {
        Some(n) if report.curvature_from_surface => {
            let finest = grid.map_or(size, |g| g.smallest_m);
            format!(
                "size {size:.4e} m, finer where the asset's triangles curve ({n} elements per turn, the curvature the size estimate measures, down to {finest:.4e} m with the walls; gmsh's own curvature sizing off)"
            )
        }
        Some(n) => {
            format!("size {size:.4e} m, finer where the surface curves ({n} elements per turn)")
        }
        None => format!("uniform size {size:.4e} m (--uniform-size)"),
    }];
    if report.curvature_from_surface {
        return parts.remove(0);
    }
    parts.push(match (params.thickness, grid) {
        (false, _) => "thickness-aware sizing off".into(),
        (true, None) => format!(
            "thickness-aware sizing: no wall thinner than half the size, nothing refined (elements at most {WALL_SIZE_FACTOR}× the local thickness)"
        ),
        (true, Some(g)) => format!(
            "and thickness-aware: elements at most {WALL_SIZE_FACTOR}× the local wall thickness, never below size/{MAX_WALL_REFINEMENT} — {:.1} % of the surface refined, down to {:.4e} m",
            100.0 * g.refined_area_fraction,
            g.smallest_m
        ),
    });
    parts.join("; ")
}

struct Made {
    mesh: TetMesh,
    msh: Vec<u8>,
}

fn run_backend(
    backend: Backend,
    surface: &SurfaceMesh,
    inspection: &SurfaceInspection,
    params: &MeshParams,
    (curvature, grid, surface_limit): (Option<u32>, Option<&super::sizing::SizeGrid>, Option<u64>),
    file: &str,
    progress: &dyn Fn(&str),
) -> Result<(Made, MeshReport), AssetError> {
    let tick = |s: f64| progress(&format!("  {} running, {s:.0} s", backend.name()));
    match backend {
        Backend::Gmsh => {
            let mut s = surface.clone();
            let info = s.check_closed(file)?;
            let g = GmshParams {
                size: params.size,
                order: params.order,
                gmsh: params.gmsh.clone(),
                keep_surface: params.keep_surface,
                timeout: params.timeout,
                curvature_elements: curvature.unwrap_or(0),
                size_grid: grid.cloned(),
                max_surface_triangles: surface_limit,
            };
            let out = gmsh::tetrahedralize_with_progress(&s, &g, file, &tick)?;
            let volume = out.mesh.volume();
            let report = MeshReport {
                inspection: inspection.clone(),
                backend,
                reason: String::new(),
                fallback_from: None,
                solid: format!(
                    "the closed surface's interior (asset volume {:.6e} m³, mesh {volume:.6e} m³)",
                    info.volume_m3
                ),
                program: out.info.program,
                version: out.info.version,
                size_m: out.info.size_m,
                thin_parts_m: None,
                curvature_elements: curvature,
                curvature_from_surface: false,
                sizing: String::new(),
                wall_size_m: None,
                envelope_m: None,
                reproducible: true,
                seconds: out.info.seconds,
                order: params.order,
                volume_m3: volume,
                flipped: info.flipped,
                distance: SurfaceDistance::default(),
                excess: None,
            };
            Ok((
                Made {
                    mesh: out.mesh,
                    msh: out.msh,
                },
                report,
            ))
        }
        Backend::Ftetwild => {
            let f = FtetwildParams {
                size: params.size,
                envelope: params.envelope,
                program: params.ftetwild.clone(),
                timeout: params.timeout,
            };
            let (linear, info) = ftetwild::tetrahedralize(surface, &f, file, &tick)?;
            let name = format!("{file} (meshed by fTetWild)");
            // Canonical order first (the reader's), then second order on it, so the saved
            // bytes depend only on the mesh.
            let canonical = read_msh_bytes(&msh41_bytes(&linear), &name)?;
            let mesh = if params.order == 2 {
                canonical.to_quadratic()
            } else {
                canonical
            };
            let msh = msh41_bytes(&mesh);
            let mesh = read_msh_bytes(&msh, &name)?;
            let volume = mesh.volume();
            let solid = if inspection.open_edges > 0 {
                format!(
                    "the surface is open ({} open edges): fTetWild kept the tetrahedra its generalized winding number puts inside, closing the openings across; mesh volume {volume:.6e} m³ (see the distance below for how far the closure is from the asset)",
                    inspection.open_edges
                )
            } else if inspection.is_solid() {
                format!("the closed surface's interior (mesh volume {volume:.6e} m³)")
            } else {
                format!(
                    "the region the surface's generalized winding number puts inside (overlaps and touching shells united); mesh volume {volume:.6e} m³"
                )
            };
            let report = MeshReport {
                inspection: inspection.clone(),
                backend,
                reason: String::new(),
                fallback_from: None,
                solid,
                program: info.program,
                version: info.version,
                size_m: info.size_m,
                thin_parts_m: None,
                curvature_elements: None,
                curvature_from_surface: false,
                sizing: String::new(),
                wall_size_m: None,
                envelope_m: Some(info.envelope_m),
                reproducible: info.reproducible,
                seconds: info.seconds,
                order: params.order,
                volume_m3: volume,
                flipped: false,
                distance: SurfaceDistance::default(),
                excess: None,
            };
            Ok((Made { mesh, msh }, report))
        }
    }
}
