//! Tetrahedralization of any triangle surface — open, self-intersecting, non-manifold,
//! several shells, triangle soup — with fTetWild (Hu et al. 2020, "Fast Tetrahedral Meshing in
//! the Wild"), run as a program: `python3` with the PyPI package `pytetwild` (its compiled
//! fTetWild, called directly), or a `FloatTetwild_bin` executable given explicitly.
//!
//! fTetWild meshes the space around the input, keeps every input triangle within an envelope of
//! half-width ε of the tetrahedral surface, and keeps the tetrahedra whose centroid has a
//! generalized winding number above ½ with respect to the input: a closed surface gives its
//! solid, and an open one the solid its winding number fills (a small gap, like a teapot's lid
//! seam, is closed across; a large opening is cut where the winding number crosses ½). Parameters
//! in SI: the ideal edge length `size` (m, default 1/20 of the bounding-box diagonal, fTetWild's
//! own default) and the envelope `envelope` (m, default 1/1000 of the diagonal, fTetWild's
//! default ε).
//!
//! Determinism: one thread, fixed optimisation settings (80 iterations, stop energy 10), and a
//! fixed sequence for `std::random_device`, from which fTetWild seeds the shuffle of its
//! triangle insertion: the child loads `shim/random_device.c` (compiled by the build script) with
//! `RTLD_GLOBAL` before fTetWild (`LD_PRELOAD` for `FloatTetwild_bin`). Linux only; elsewhere
//! [`FtetwildInfo::reproducible`] is false and two runs may give different meshes.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use super::surface::SurfaceMesh;
use super::work::{python_interpreter, run_child, WorkDir};
use super::{MeshError, TetMesh};

/// How to install fTetWild, for the error when it is not found.
pub const INSTALL_HINT: &str = "install it with `python3 -m pip install pytetwild==0.4.2` (PyPI; the fTetWild library, no PyVista needed) \
     or pass --ftetwild PATH (a FloatTetwild_bin executable)";

/// The fixed-sequence `std::random_device` (empty when it could not be built).
const SHIM: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/random_device_shim.so"));

/// fTetWild parameters (SI).
#[derive(Clone, Debug, PartialEq)]
pub struct FtetwildParams {
    /// Ideal edge length (m); `None`: 1/20 of the surface's bounding-box diagonal.
    pub size: Option<f64>,
    /// Envelope half-width ε (m): how far the tetrahedral surface may be from the input;
    /// `None`: 1/1000 of the bounding-box diagonal.
    pub envelope: Option<f64>,
    /// A `FloatTetwild_bin` executable; `None`: `python3` with `pytetwild`.
    pub program: Option<PathBuf>,
    /// Time limit of the run. Default [`super::work::DEFAULT_TIMEOUT_S`].
    pub timeout: Duration,
}

impl Default for FtetwildParams {
    fn default() -> Self {
        FtetwildParams {
            size: None,
            envelope: None,
            program: None,
            timeout: Duration::from_secs_f64(super::work::DEFAULT_TIMEOUT_S),
        }
    }
}

/// What an fTetWild run reports.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FtetwildInfo {
    /// How fTetWild was run.
    pub program: String,
    /// pytetwild's version (or `FloatTetwild_bin`).
    pub version: String,
    /// Ideal edge length used (m).
    pub size_m: f64,
    /// Envelope half-width used (m).
    pub envelope_m: f64,
    /// Threads (always 1).
    pub threads: u32,
    /// Whether the fixed `std::random_device` was loaded (same input → same mesh).
    pub reproducible: bool,
    /// Wall-clock seconds in fTetWild.
    pub seconds: f64,
}

/// Why fTetWild failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FtetwildError {
    /// Neither pytetwild nor the given executable could be run.
    #[error("fTetWild not found ({detail}); {INSTALL_HINT}")]
    NotFound {
        /// What was tried.
        detail: String,
    },
    /// Invalid parameters.
    #[error("{0}")]
    Params(String),
    /// Writing the input or reading the output failed.
    #[error("fTetWild work files: {0}")]
    Io(String),
    /// The time limit ended the run.
    #[error("fTetWild ({program}) did not finish meshing {file} within {seconds:.0} s and was stopped; raise --mesher-timeout, or give a larger --size")]
    TimedOut {
        /// The surface file.
        file: String,
        /// How fTetWild was run.
        program: String,
        /// The limit (s).
        seconds: f64,
    },
    /// fTetWild ran but produced no mesh.
    #[error("fTetWild ({program}) failed to mesh {file}: {detail}")]
    Failed {
        /// The surface file.
        file: String,
        /// How fTetWild was run.
        program: String,
        /// Its error lines or exit status.
        detail: String,
    },
    /// The result could not be read.
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

const PY: &str = r#"
import ctypes, importlib.machinery, importlib.util, os, sys
shim = sys.argv[1]
if shim:
    ctypes.CDLL(shim, mode=ctypes.RTLD_GLOBAL)
spec = importlib.util.find_spec("pytetwild")
if spec is None:
    sys.stderr.write("%s has no module pytetwild\n" % sys.executable)
    sys.exit(3)
from importlib.metadata import version
if sys.argv[2] == "--version":
    print(version("pytetwild"))
    sys.exit(0)
import numpy as np
d = spec.submodule_search_locations[0]
lib = sorted(f for f in os.listdir(d) if f.startswith("PyfTetWildWrapper.") and f.endswith((".so", ".pyd")))
if not lib:
    sys.stderr.write("pytetwild in %s has no PyfTetWildWrapper library\n" % d)
    sys.exit(3)
loader = importlib.machinery.ExtensionFileLoader("PyfTetWildWrapper", os.path.join(d, lib[0]))
w = importlib.util.module_from_spec(importlib.util.spec_from_loader("PyfTetWildWrapper", loader))
loader.exec_module(w)
size, eps_rel = float(sys.argv[3]), float(sys.argv[4])
v = np.fromfile("surface_v.bin", dtype="<f8").reshape(-1, 3)
f = np.fromfile("surface_f.bin", dtype="<u4").reshape(-1, 3)
try:
    V, T = w.tetrahedralize_mesh(v, f, True, False, 0.05, size, eps_rel, 10.0, False, 1, 80, 6, True,
        False, False, np.empty((0, 3)), np.empty((0, 4), dtype=np.int32), np.empty(0))
except TypeError as e:
    sys.stderr.write("pytetwild %s has an unsupported interface (tested: 0.4.2): %s\n" % (version("pytetwild"), e))
    sys.exit(4)
np.ascontiguousarray(V, dtype="<f8").tofile("tets_v.bin")
np.ascontiguousarray(T, dtype="<i4").tofile("tets_t.bin")
"#;

/// Bounding-box diagonal (m).
fn diagonal(bbox: [[f64; 3]; 2]) -> f64 {
    (0..3)
        .map(|k| (bbox[1][k] - bbox[0][k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn python(shim: &Path) -> Command {
    let mut c = Command::new(python_interpreter());
    c.arg("-c").arg(PY).arg(shim);
    c
}

/// pytetwild's version, or why it cannot run.
///
/// # Errors
/// [`FtetwildError::NotFound`] with installation instructions.
pub fn ftetwild_version(program: Option<&Path>) -> Result<String, FtetwildError> {
    if let Some(p) = program {
        return if p.is_file() {
            Ok("FloatTetwild_bin".into())
        } else {
            Err(FtetwildError::NotFound {
                detail: format!("{} is not a file", p.display()),
            })
        };
    }
    let out = python(Path::new(""))
        .arg("--version")
        .output()
        .map_err(|e| FtetwildError::NotFound {
            detail: format!("{}: {e}", python_interpreter().display()),
        })?;
    let text = String::from_utf8_lossy(&out.stdout).trim().to_string();
    if out.status.success() && !text.is_empty() {
        Ok(text)
    } else {
        Err(FtetwildError::NotFound {
            detail: String::from_utf8_lossy(&out.stderr).trim().to_string(),
        })
    }
}

/// Fills the solid `surface` (m; any triangle surface) describes with linear tetrahedra using
/// fTetWild, in a temporary folder removed afterwards; `file` names the asset in messages and
/// `progress` is called about every 15 s with the seconds elapsed.
///
/// # Errors
/// [`FtetwildError`]: fTetWild missing (with how to install it), invalid size or envelope, a
/// failure or the time limit, or an unreadable result.
pub fn tetrahedralize(
    surface: &SurfaceMesh,
    params: &FtetwildParams,
    file: &str,
    progress: &dyn Fn(f64),
) -> Result<(TetMesh, FtetwildInfo), FtetwildError> {
    let diag = diagonal(surface.bounding_box());
    let positive = |v: Option<f64>, name: &str, default: f64| match v {
        Some(s) if !(s.is_finite() && s > 0.0) => Err(FtetwildError::Params(format!(
            "{name} must be a positive length in metres, got {s}"
        ))),
        Some(s) => Ok(s),
        None => Ok(default),
    };
    let size = positive(params.size, "--size", diag / 20.0)?;
    let envelope = positive(params.envelope, "--envelope", diag / 1000.0)?;
    if !(diag > 0.0) {
        return Err(FtetwildError::Params(format!(
            "{file}: the surface has no extent"
        )));
    }
    let version = ftetwild_version(params.program.as_deref())?;
    let io = |e: std::io::Error| FtetwildError::Io(e.to_string());
    let dir = WorkDir::new("modal-bake-ftetwild").map_err(io)?;
    let reproducible = !SHIM.is_empty();
    let shim = dir.path().join("random_device_shim.so");
    if reproducible {
        std::fs::write(&shim, SHIM).map_err(io)?;
    }
    let shim_arg = if reproducible {
        shim.clone()
    } else {
        PathBuf::new()
    };
    let (mut cmd, program) = match &params.program {
        None => {
            let mut v = Vec::with_capacity(24 * surface.vertices.len());
            for p in &surface.vertices {
                for x in p {
                    v.extend_from_slice(&x.to_le_bytes());
                }
            }
            let mut f = Vec::with_capacity(12 * surface.triangles.len());
            for t in &surface.triangles {
                for &i in t {
                    let i = u32::try_from(i)
                        .map_err(|_| FtetwildError::Params(format!("{file}: too many vertices")))?;
                    f.extend_from_slice(&i.to_le_bytes());
                }
            }
            std::fs::write(dir.path().join("surface_v.bin"), v).map_err(io)?;
            std::fs::write(dir.path().join("surface_f.bin"), f).map_err(io)?;
            let mut c = python(&shim_arg);
            c.arg("run")
                .arg(format!("{size:?}"))
                .arg(format!("{:?}", envelope / diag));
            (
                c,
                format!("{} + pytetwild {version}", python_interpreter().display()),
            )
        }
        Some(bin) => {
            use std::fmt::Write;
            let mut s = String::new();
            for p in &surface.vertices {
                let _ = writeln!(s, "v {:?} {:?} {:?}", p[0], p[1], p[2]);
            }
            for t in &surface.triangles {
                let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
            }
            std::fs::write(dir.path().join("surface.obj"), s).map_err(io)?;
            let mut c = Command::new(bin);
            c.args([
                "-i",
                "surface.obj",
                "-o",
                "volume.msh",
                "--max-threads",
                "1",
            ])
            .args(["--level", "6", "--no-color", "-a"])
            .arg(format!("{size:?}"))
            .arg("-e")
            .arg(format!("{:?}", envelope / diag));
            if reproducible {
                c.env("LD_PRELOAD", &shim);
            }
            (c, bin.display().to_string())
        }
    };
    cmd.current_dir(dir.path());
    let out = run_child(cmd, params.timeout, progress).map_err(|e| FtetwildError::NotFound {
        detail: format!("{program}: {e}"),
    })?;
    let Some(status) = out.status else {
        return Err(FtetwildError::TimedOut {
            file: file.into(),
            program,
            seconds: params.timeout.as_secs_f64(),
        });
    };
    let failed = |detail: String| FtetwildError::Failed {
        file: file.into(),
        program: program.clone(),
        detail,
    };
    if !status.success() {
        let lines: Vec<&str> = out.text.lines().rev().take(4).collect();
        let lines: Vec<&str> = lines.into_iter().rev().collect();
        return Err(failed(format!(
            "exit status {status}: {}",
            lines.join(" | ")
        )));
    }
    let mesh = if params.program.is_some() {
        let msh = std::fs::read(dir.path().join("volume.msh")).map_err(io)?;
        super::read_msh_bytes(&msh, &format!("{file} (meshed by fTetWild)"))?
    } else {
        let v = std::fs::read(dir.path().join("tets_v.bin")).map_err(io)?;
        let t = std::fs::read(dir.path().join("tets_t.bin")).map_err(io)?;
        from_arrays(&v, &t).map_err(failed)?
    };
    if mesh.tets.is_empty() {
        return Err(failed("no tetrahedra: the surface encloses no volume fTetWild could find (a flat or line-like asset?)".into()));
    }
    Ok((
        mesh,
        FtetwildInfo {
            program,
            version,
            size_m: size,
            envelope_m: envelope,
            threads: 1,
            reproducible,
            seconds: out.seconds,
        },
    ))
}

/// A linear mesh from pytetwild's arrays (little-endian f64 positions, i32 tetrahedra),
/// every tetrahedron positively oriented.
fn from_arrays(v: &[u8], t: &[u8]) -> Result<TetMesh, String> {
    if !v.len().is_multiple_of(24) || !t.len().is_multiple_of(16) {
        return Err("truncated output arrays".into());
    }
    let nodes: Vec<[f64; 3]> = v
        .chunks_exact(24)
        .map(|c| {
            let x = |k: usize| {
                f64::from_le_bytes(c[8 * k..8 * k + 8].try_into().expect("8-byte chunk"))
            };
            [x(0), x(1), x(2)]
        })
        .collect();
    let mut tets = Vec::with_capacity(t.len() / 16);
    for c in t.chunks_exact(16) {
        let mut tet = [0usize; 4];
        for (k, slot) in tet.iter_mut().enumerate() {
            let i = i32::from_le_bytes(c[4 * k..4 * k + 4].try_into().expect("4-byte chunk"));
            *slot = usize::try_from(i)
                .ok()
                .filter(|&i| i < nodes.len())
                .ok_or_else(|| format!("tetrahedron names node {i} of {}", nodes.len()))?;
        }
        let [a, b, c, d] = tet.map(|i| nodes[i]);
        if super::signed_volume(a, b, c, d) < 0.0 {
            tet.swap(2, 3);
        }
        tets.push(tet);
    }
    Ok(TetMesh {
        tet_ids: (1..=tets.len() as u64).collect(),
        nodes,
        tets,
        ..Default::default()
    })
}
