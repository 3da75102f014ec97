//! Tetrahedralization of a checked surface ([`crate::mesh::surface`]) with the real gmsh.
//!
//! gmsh is run as a program: the `gmsh` binary (Debian package `gmsh`, or the launcher the PyPI
//! `gmsh` package installs) or the PyPI package's Python module (`python3` importing `gmsh`),
//! found on `PATH` or given explicitly. The surface is handed over as an MSH 2.2 file of
//! triangles (exact decimal coordinates) with a `.geo` script that, by default, classifies it
//! into patches (feature angle 40°), rebuilds a geometry and remeshes it at the requested size
//! (gmsh tutorial t13) — uniformly, or finer where the surface curves
//! ([`GmshParams::curvature_elements`], gmsh's `Mesh.MeshSizeFromCurvature`), and no larger
//! than a thickness-aware size field in thin walls ([`GmshParams::size_grid`], gmsh's
//! `Structured` background field read from `sizes.dat`) — or keeps the
//! asset's triangles as the boundary (`keep_surface`), then fills the volume (Frontal-Delaunay 2D, Delaunay 3D). Second order uses straight-sided
//! elements (`Mesh.SecondOrderLinear = 1`), which the P2 assembly requires.
//!
//! Determinism: one thread (`General.NumThreads = 1`), fixed algorithms and `Mesh.RandomSeed`;
//! the same surface, size, order and gmsh version give the same mesh.
//!
//! gmsh runs in a private work folder under `$TMPDIR` (prefix `modal-bake-gmsh`), removed on
//! every exit path, signals included, and for at most [`GmshParams::timeout`]
//! ([`super::work`]).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use super::surface::SurfaceMesh;
use super::work::{python_interpreter, run_child, run_child_watched, WorkDir, DEFAULT_TIMEOUT_S};
use super::{MeshError, TetMesh};

/// How to install gmsh, for the error when none is found.
pub const INSTALL_HINT: &str = "install it with `pip install gmsh` (PyPI, ships the gmsh library and a `gmsh` launcher) \
     or `apt-get install gmsh` (Debian), or pass --gmsh PATH (a gmsh executable, or the PyPI package's gmsh.py)";

/// Meshing parameters (SI).
#[derive(Clone, Debug, PartialEq)]
pub struct GmshParams {
    /// Target element size (m); `None`: [`default_size`] of the surface's bounding box.
    pub size: Option<f64>,
    /// Element order: 1 (4-node tetrahedra) or 2 (10-node, straight-sided). Default 1.
    pub order: u8,
    /// The gmsh to run: an executable, or a `gmsh.py` (or the folder holding it) run with
    /// `python3`; `None`: `gmsh` on `PATH`, else `python3 -c "import gmsh"`.
    pub gmsh: Option<PathBuf>,
    /// Keep the asset's triangles as the boundary mesh instead of remeshing it at `size`
    /// (for surfaces gmsh cannot reparametrize; the tetrahedra then follow the asset's
    /// triangle sizes near the surface). Default false.
    pub keep_surface: bool,
    /// Time limit of the gmsh run; gmsh is stopped and an error returned past it. Default
    /// [`DEFAULT_TIMEOUT_S`].
    pub timeout: Duration,
    /// Curvature-driven sizes when remeshing: at most 2π/`curvature_elements` times the local
    /// radius of curvature (gmsh's `Mesh.MeshSizeFromCurvature`, elements per full turn),
    /// never above `size`; 0 (the default here) for a uniform `size`: then gmsh's extension
    /// of boundary sizes into the surfaces and the volume is off too
    /// (`Mesh.MeshSizeExtendFromBoundary = 0`), so short feature curves of a faceted asset
    /// do not set finer sizes around them. Ignored with `keep_surface`.
    pub curvature_elements: u32,
    /// Thickness-aware sizes when remeshing ([`super::sizing::thickness_grid`]): gmsh's
    /// `Structured` background field, combined with the size and the curvature sizes by
    /// taking the smallest. `None` (the default here): none. Ignored with `keep_surface`.
    pub size_grid: Option<super::sizing::SizeGrid>,
    /// Stop gmsh once its surface mesh is known to have more triangles than this, before the
    /// volume is filled ([`GmshError::SurfaceOverLimit`]): a guard against a sizing that went
    /// far finer than asked. gmsh's run is unchanged (the same mesh when under the limit);
    /// its log is watched for the node count it starts the volume from (`Tetrahedrizing N
    /// nodes`, 2N − 4 triangles on a closed surface). `None` (the default): no limit.
    pub max_surface_triangles: Option<u64>,
}

impl Default for GmshParams {
    fn default() -> Self {
        GmshParams {
            size: None,
            order: 1,
            gmsh: None,
            keep_surface: false,
            timeout: Duration::from_secs_f64(DEFAULT_TIMEOUT_S),
            curvature_elements: 0,
            size_grid: None,
            max_surface_triangles: None,
        }
    }
}

/// What a gmsh run reports.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct GmshInfo {
    /// How gmsh was run (`gmsh` path, or `python3 + gmsh module`).
    pub program: String,
    /// gmsh's version string.
    pub version: String,
    /// Element size used (m).
    pub size_m: f64,
    /// Element order.
    pub order: u8,
    /// Wall-clock seconds in gmsh.
    pub seconds: f64,
}

/// A gmsh result: the mesh, gmsh's MSH 4.1 binary file as written, and the run's facts.
#[derive(Clone, Debug)]
pub struct GmshOutput {
    /// The tetrahedral mesh read back (m).
    pub mesh: TetMesh,
    /// The `.msh` bytes gmsh wrote (what `modal-bake mesh` saves).
    pub msh: Vec<u8>,
    /// Version, size, time.
    pub info: GmshInfo,
}

/// Why meshing failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GmshError {
    /// No gmsh could be found or started.
    #[error("gmsh not found ({detail}); {INSTALL_HINT}")]
    NotFound {
        /// What was tried.
        detail: String,
    },
    /// Invalid parameters.
    #[error("{0}")]
    Params(String),
    /// Writing the input or reading the output failed.
    #[error("gmsh work files: {0}")]
    Io(String),
    /// The time limit ended the run.
    #[error("gmsh {version} did not finish meshing {file} within {seconds:.0} s and was stopped; raise --mesher-timeout, give a larger --size, or try --mesher ftetwild")]
    TimedOut {
        /// The surface file.
        file: String,
        /// gmsh's version.
        version: String,
        /// The limit (s).
        seconds: f64,
    },
    /// gmsh ran but produced no mesh.
    #[error("gmsh {version} failed to mesh {file}: {detail}")]
    Failed {
        /// The surface file.
        file: String,
        /// gmsh's version.
        version: String,
        /// gmsh's error lines (or exit status).
        detail: String,
    },
    /// The surface mesh went over [`GmshParams::max_surface_triangles`]; gmsh was stopped
    /// before filling the volume.
    #[error("gmsh {version}'s surface mesh of {file} has {triangles} triangles, over the limit of {limit}; gmsh was stopped before filling the volume")]
    SurfaceOverLimit {
        /// The surface file.
        file: String,
        /// gmsh's version.
        version: String,
        /// Triangles of gmsh's surface mesh (2N − 4 for its N nodes).
        triangles: u64,
        /// The limit.
        limit: u64,
    },
    /// gmsh's output could not be read.
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// The triangles of the closed surface mesh gmsh starts a Delaunay volume from, read from its
/// log line `Info    : Tetrahedrizing N nodes...` (2N − 4 by Euler's formula).
fn surface_triangles_of(line: &str) -> Option<u64> {
    let rest = line.split("Tetrahedrizing ").nth(1)?;
    let n: u64 = rest.split(' ').next()?.parse().ok()?;
    rest[rest.find(' ')?..]
        .starts_with(" nodes")
        .then(|| (2 * n).saturating_sub(4))
}

/// Default element size (m): 1/20 of the bounding-box diagonal
/// ([`super::sizing::default_size`]).
pub fn default_size(bbox: [[f64; 3]; 2]) -> f64 {
    super::sizing::default_size(bbox)
}

/// A way to run gmsh.
#[derive(Clone, Debug)]
enum Launcher {
    /// A gmsh executable taking gmsh's command line.
    Binary(PathBuf),
    /// `python3` importing the `gmsh` module (from `dir` when given).
    Python(Option<PathBuf>),
}

const PY_RUN: &str = "import sys\nif sys.argv[1]: sys.path.insert(0, sys.argv[1])\nimport gmsh\n\
     gmsh.initialize(['gmsh'] + sys.argv[2:], readConfigFiles=False, run=True)\ngmsh.finalize()\n";
const PY_VERSION: &str =
    "import sys\nif sys.argv[1]: sys.path.insert(0, sys.argv[1])\nimport gmsh\nprint(gmsh.__version__)\n";

impl Launcher {
    fn command(&self, script: &str) -> Command {
        match self {
            Launcher::Binary(p) => Command::new(p),
            Launcher::Python(dir) => {
                let mut c = Command::new(python_interpreter());
                c.arg("-c").arg(script).arg(
                    dir.as_ref()
                        .map(|d| d.display().to_string())
                        .unwrap_or_default(),
                );
                c
            }
        }
    }

    fn describe(&self) -> String {
        match self {
            Launcher::Binary(p) => p.display().to_string(),
            Launcher::Python(Some(d)) => format!(
                "{} + gmsh module in {}",
                python_interpreter().display(),
                d.display()
            ),
            Launcher::Python(None) => format!("{} + gmsh module", python_interpreter().display()),
        }
    }

    /// gmsh's version, or `None` when it does not run (or does not answer within a minute).
    fn version(&self) -> Option<String> {
        let cmd = match self {
            Launcher::Binary(_) => {
                let mut c = self.command("");
                c.arg("--version");
                c
            }
            Launcher::Python(_) => self.command(PY_VERSION),
        };
        let out = run_child(cmd, Duration::from_secs(60), &|_| {}).ok()?;
        if !out.status?.success() {
            return None;
        }
        let v = out.text.split_whitespace().next()?.to_string();
        v.chars().next()?.is_ascii_digit().then_some(v)
    }
}

fn on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

/// Finds gmsh: `explicit` (an executable, a `gmsh.py`, or a folder holding `gmsh.py`), else
/// `gmsh` on `PATH`, else the `gmsh` Python module. Returns how to run it and its version.
fn find_gmsh(explicit: Option<&Path>) -> Result<(Launcher, String), GmshError> {
    let mut tried = Vec::new();
    let candidates: Vec<Launcher> = match explicit {
        Some(p) if p.is_dir() => vec![Launcher::Python(Some(p.to_path_buf()))],
        Some(p) if p.extension().is_some_and(|e| e == "py") => {
            vec![Launcher::Python(p.parent().map(Path::to_path_buf))]
        }
        Some(p) => vec![Launcher::Binary(p.to_path_buf())],
        None => {
            let mut c = Vec::new();
            if let Some(p) = on_path("gmsh") {
                c.push(Launcher::Binary(p));
            }
            c.push(Launcher::Python(None));
            c
        }
    };
    for l in candidates {
        match l.version() {
            Some(v) => return Ok((l, v)),
            None => tried.push(l.describe()),
        }
    }
    Err(GmshError::NotFound {
        detail: if tried.is_empty() {
            "nothing to try".into()
        } else {
            format!("tried {}", tried.join(", "))
        },
    })
}

/// The version of the gmsh [`tetrahedralize`] would run.
///
/// # Errors
/// [`GmshError::NotFound`] with installation instructions.
pub fn gmsh_version(explicit: Option<&Path>) -> Result<String, GmshError> {
    find_gmsh(explicit).map(|(_, v)| v)
}

/// The surface as an MSH 2.2 ASCII file of 3-node triangles (shortest round-trip decimals:
/// gmsh reads back the exact doubles).
fn surface_msh(surface: &SurfaceMesh) -> String {
    use std::fmt::Write;
    let mut s = String::with_capacity(64 * (surface.vertices.len() + surface.triangles.len()));
    s.push_str("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    let _ = writeln!(s, "{}", surface.vertices.len());
    for (i, p) in surface.vertices.iter().enumerate() {
        let _ = writeln!(s, "{} {:?} {:?} {:?}", i + 1, p[0], p[1], p[2]);
    }
    s.push_str("$EndNodes\n$Elements\n");
    let _ = writeln!(s, "{}", surface.triangles.len());
    for (i, t) in surface.triangles.iter().enumerate() {
        let _ = writeln!(
            s,
            "{} 2 2 1 1 {} {} {}",
            i + 1,
            t[0] + 1,
            t[1] + 1,
            t[2] + 1
        );
    }
    s.push_str("$EndElements\n");
    s
}

/// The `.geo` script meshing `surface.msh` into `volume.msh`.
fn geo_script(
    size: f64,
    order: u8,
    keep_surface: bool,
    curvature_elements: u32,
    size_grid: bool,
) -> String {
    let remesh = if keep_surface {
        ""
    } else {
        "ClassifySurfaces{40 * Pi / 180, 1, 1, Pi};\nCreateGeometry;\n"
    };
    let field = if size_grid && !keep_surface {
        format!(
            "Field[1] = Structured;\n\
             Field[1].FileName = \"sizes.dat\";\n\
             Field[1].TextFormat = 1;\n\
             Field[1].SetOutsideValue = 1;\n\
             Field[1].OutsideValue = {size:?};\n\
             Background Field = 1;\n"
        )
    } else {
        String::new()
    };
    let curvature = if keep_surface { 0 } else { curvature_elements };
    // A uniform remesh is one size everywhere: without this, gmsh carries the sizes of short
    // feature curves (at least 3 nodes each) into the surfaces and the volume, and a faceted
    // asset comes out tens of times finer than `size` (docs/benchmarks.md).
    let extend = if keep_surface || curvature > 0 { 1 } else { 0 };
    format!(
        "General.NumThreads = 1;\n\
         General.Terminal = 1;\n\
         Mesh.RandomSeed = 1;\n\
         Mesh.Algorithm = 6;\n\
         Mesh.Algorithm3D = 1;\n\
         Mesh.MeshSizeMax = {size:?};\n\
         Mesh.MeshSizeFromCurvature = {curvature};\n\
         Mesh.MeshSizeExtendFromBoundary = {extend};\n\
         Mesh.ElementOrder = {order};\n\
         Mesh.SecondOrderLinear = 1;\n\
         Mesh.MshFileVersion = 4.1;\n\
         Mesh.Binary = 1;\n\
         Mesh.SaveAll = 0;\n\
         Merge \"surface.msh\";\n\
         {remesh}\
         {field}\
         Surface Loop(1) = Surface{{:}};\n\
         Volume(1) = {{1}};\n\
         Physical Volume(\"volume\") = {{1}};\n"
    )
}

/// Fills a checked, outward-oriented closed surface (m) with tetrahedra using gmsh, in a
/// temporary folder that is removed afterwards. `file` names the asset in messages.
///
/// # Errors
/// [`GmshError`]: gmsh missing (with how to install it), invalid size or order, gmsh failing
/// (its error lines), or an unreadable result.
pub fn tetrahedralize(
    surface: &SurfaceMesh,
    params: &GmshParams,
    file: &str,
) -> Result<GmshOutput, GmshError> {
    tetrahedralize_with_progress(surface, params, file, &|_| {})
}

/// [`tetrahedralize`], calling `progress` about every 15 s with the seconds gmsh has run.
///
/// # Errors
/// As [`tetrahedralize`], and [`GmshError::TimedOut`] past [`GmshParams::timeout`].
pub fn tetrahedralize_with_progress(
    surface: &SurfaceMesh,
    params: &GmshParams,
    file: &str,
    progress: &dyn Fn(f64),
) -> Result<GmshOutput, GmshError> {
    if !matches!(params.order, 1 | 2) {
        return Err(GmshError::Params(format!(
            "parameter `order` must be 1 or 2, got {}",
            params.order
        )));
    }
    let size = match params.size {
        Some(s) if !(s.is_finite() && s > 0.0) => {
            return Err(GmshError::Params(format!(
                "parameter `size` must be a positive length in metres, got {s}"
            )))
        }
        Some(s) => s,
        None => default_size(surface.bounding_box()),
    };
    let (launcher, version) = find_gmsh(params.gmsh.as_deref())?;
    let io = |e: std::io::Error| GmshError::Io(e.to_string());
    let dir = WorkDir::new("modal-bake-gmsh").map_err(io)?;
    std::fs::write(dir.path().join("surface.msh"), surface_msh(surface)).map_err(io)?;
    let grid = params.size_grid.as_ref().filter(|_| !params.keep_surface);
    if let Some(g) = grid {
        std::fs::write(dir.path().join("sizes.dat"), g.to_gmsh_text()).map_err(io)?;
    }
    std::fs::write(
        dir.path().join("volume.geo"),
        geo_script(
            size,
            params.order,
            params.keep_surface,
            params.curvature_elements,
            grid.is_some(),
        ),
    )
    .map_err(io)?;
    let args = [
        "volume.geo",
        "-3",
        "-nt",
        "1",
        "-o",
        "volume.msh",
        "-v",
        "4",
    ];
    let mut cmd = launcher.command(PY_RUN);
    cmd.args(args).current_dir(dir.path());
    let over = std::cell::Cell::new(None);
    let watch = |line: &str| match (params.max_surface_triangles, surface_triangles_of(line)) {
        (Some(limit), Some(t)) if t > limit => {
            over.set(Some(t));
            true
        }
        _ => false,
    };
    let out = run_child_watched(cmd, params.timeout, progress, &watch).map_err(|e| {
        GmshError::NotFound {
            detail: format!("{}: {e}", launcher.describe()),
        }
    })?;
    if let (Some(triangles), Some(limit)) = (over.get(), params.max_surface_triangles) {
        return Err(GmshError::SurfaceOverLimit {
            file: file.to_string(),
            version,
            triangles,
            limit,
        });
    }
    let seconds = out.seconds;
    let Some(status) = out.status else {
        return Err(GmshError::TimedOut {
            file: file.to_string(),
            version,
            seconds: params.timeout.as_secs_f64(),
        });
    };
    let text = out.text;
    let errors: Vec<&str> = text
        .lines()
        .filter(|l| l.trim_start().starts_with("Error"))
        .collect();
    let result = dir.path().join("volume.msh");
    if !status.success() || !errors.is_empty() || !result.is_file() {
        let detail = if errors.is_empty() {
            format!("exit status {status}, no mesh written")
        } else {
            errors.join("; ")
        };
        let hint = if params.keep_surface {
            ""
        } else {
            " (if the surface cannot be reparametrized, keep the input surface: parameter `keep_surface`)"
        };
        return Err(GmshError::Failed {
            file: file.to_string(),
            version,
            detail: format!("{detail}{hint}"),
        });
    }
    let msh = std::fs::read(&result).map_err(io)?;
    let mesh = super::read_msh_bytes(&msh, &format!("{file} (meshed by gmsh)"))?;
    Ok(GmshOutput {
        mesh,
        msh,
        info: GmshInfo {
            program: launcher.describe(),
            version,
            size_m: size,
            order: params.order,
            seconds,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::surface_triangles_of;

    // Expectation: gmsh 4.15's log line before a Delaunay volume gives 2N − 4 triangles for
    // its N surface nodes; other lines (its "Done tetrahedrizing" count includes the nodes it
    // inserted) give nothing.
    #[test]
    fn the_surface_triangles_come_from_the_tetrahedrizing_line() {
        assert_eq!(
            surface_triangles_of("Info    : Tetrahedrizing 12932 nodes..."),
            Some(25_860)
        );
        assert_eq!(
            surface_triangles_of("Info    : Done tetrahedrizing 12940 nodes (Wall 0.1s, CPU 0.1s)"),
            None
        );
        assert_eq!(
            surface_triangles_of("Info    : Tetrahedrizing x nodes..."),
            None
        );
        assert_eq!(surface_triangles_of("Info    : 2352 nodes"), None);
    }
}
