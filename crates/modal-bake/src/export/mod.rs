//! Mode shapes out of a `.modes` base, in the formats artists and viewers open:
//!
//! - [`write_modes_vtu`]: the surface as a VTK XML unstructured grid (`.vtu`, ParaView,
//!   meshio) with one point-data vector array per mode (m, object frame);
//! - [`write_modes_glb`]: the surface as binary glTF 2.0 (`.glb`, Blender, three.js) with one
//!   morph target and one animation per mode;
//! - [`write_modes_glb_onto`]: the same morph targets on the artist's own mesh (its vertex
//!   count and order), each vertex mapped to the closest point of the base's surface;
//! - [`write_modes_onto_gltf`]: the same morph targets added to a glTF asset, which is kept
//!   otherwise (nodes, materials, textures, animations);
//! - [`render_contact_sheet`] / [`write_modes_png`]: a PNG contact sheet of the lowest modes
//!   (displacement magnitude as colour over the rest shape, each mode seen side-on to its
//!   motion, a title and a colour legend; the paper's Fig. 2), rendered on the CPU.
//!
//! [`GltfBuilder`] is the small glTF/GLB assembler both this module and `dcr-scenes` use.
//!
//! A mode shape is a column of the M-orthonormal basis U (m·kg^-½): vertex v moves by
//! `U[v, :, j] · q_j` for a modal coordinate q_j (kg^½·m). Exports show each mode with q_j
//! chosen so that its largest vertex displacement is a stated length (see each writer).
//!
//! Every writer draws the same surface (`ExportSurface`): the base's vertices and outward linear
//! triangles, a second-order base's 6-node triangles each split into four through their
//! mid-edge nodes (which carry their own mode rows).

mod contact_sheet;
mod gltf_builder;
mod mode_gltf;
mod mode_onto;
mod mode_vtu;
mod onto_gltf;
mod raster;

use std::path::{Path, PathBuf};

use dcr_runtime::format::ModesFile;

pub use contact_sheet::{
    render_contact_sheet, write_modes_png, SheetParams, SHEET_LEGEND_H, SHEET_TITLE_H,
};
pub use gltf_builder::{extras_of, GltfBuilder, GLTF_GENERATOR};
pub use mode_gltf::{write_modes_glb, ModeGltfParams};
pub use mode_onto::{
    map_modes_onto, mode_title, write_modes_glb_onto, AssetMesh, OntoInfo, OntoMapping, OntoParams,
};
pub use mode_vtu::write_modes_vtu;
pub use onto_gltf::write_modes_onto_gltf;

/// Largest visual amplitude `scale` of the GLB morph targets and the PNG sheet: the largest
/// displacement as a fraction of the bounding-box diagonal.
pub const MAX_SCALE: f64 = 10.0;

/// What went wrong writing an export.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// Operating-system I/O error on `path`.
    #[error("{path}: {source}")]
    Io {
        /// File concerned.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The encoder refused the content (VTK XML, PNG).
    #[error("{path}: cannot encode: {detail}")]
    Encode {
        /// File concerned.
        path: PathBuf,
        /// What the encoder said.
        detail: String,
    },
    /// Options that cannot be honoured (no modes selected, a mode index out of range, a
    /// non-positive scale...).
    #[error("{0}")]
    Invalid(String),
    /// The writer refused or failed (the message names the path).
    #[error(transparent)]
    Write(dcr_files::WriteError),
}

/// The selected modes' label, e.g. `mode_01_12.3Hz`: 1-based mode number (two digits at
/// least) and frequency (Hz, one decimal; three significant digits below 1 Hz).
///
/// ```
/// assert_eq!(modal_bake::export::mode_label(0, 12.34), "mode_01_12.3Hz");
/// assert_eq!(modal_bake::export::mode_label(11, 0.0432), "mode_12_0.0432Hz");
/// ```
pub fn mode_label(j: usize, hz: f64) -> String {
    if hz >= 1.0 {
        format!("mode_{:02}_{:.1}Hz", j + 1, hz)
    } else {
        format!("mode_{:02}_{}Hz", j + 1, format_sig(hz, 3))
    }
}

fn format_sig(x: f64, digits: i32) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let e = x.abs().log10().floor() as i32;
    let decimals = (digits - 1 - e).max(0) as usize;
    format!("{:.*}", decimals, x)
}

/// The weight of an animated mode at keyframe `i` of `k` per period: sin 2πi/k, the keyframes
/// of one sine period (`i` = 0 and `k` give 0).
///
/// Computed with the `libm` crate's `sin` (the same bits on every platform): a C library's
/// `sin` need not be, and MinGW's, which a Windows build links, differs from glibc's in the
/// last bits near multiples of π (1.22464e-16 against 1.22465e-16 at π), so the glTF exports
/// of the two builds would differ in a few bytes.
pub(crate) fn loop_weight(i: usize, k: usize) -> f32 {
    libm::sin(std::f64::consts::TAU * i as f64 / k as f64) as f32
}

/// The default number of exported modes: every mode of the base up to 20.
pub const DEFAULT_EXPORT_MODES: usize = 20;

/// Checks a mode count against the base: `Some(n)` must be in 1..=m; `None` gives
/// min(m, [`DEFAULT_EXPORT_MODES`]). Returns the count (the lowest n modes are exported).
///
/// # Errors
/// [`ExportError::Invalid`] when the base has no modes or `n` is 0 or above m.
pub fn select_modes(base: &ModesFile, n: Option<usize>) -> Result<usize, ExportError> {
    let m = base.num_modes();
    if m == 0 {
        return Err(ExportError::Invalid("the base has no modes".into()));
    }
    match n {
        None => Ok(m.min(DEFAULT_EXPORT_MODES)),
        Some(0) => Err(ExportError::Invalid(
            "parameter `modes`: the mode count must be at least 1".into(),
        )),
        Some(n) if n > m => Err(ExportError::Invalid(format!(
            "parameter `modes` = {n}: the base has only {m} modes"
        ))),
        Some(n) => Ok(n),
    }
}

/// The surface an export shows: vertices, linear triangles and per-vertex mode rows.
///
/// Built once per export by [`ExportSurface::of`]: for a first-order base, its vertices and
/// triangles; for a second-order base, its corner vertices followed by one vertex per mid-edge
/// node, each 6-node triangle split into four linear ones through its mid-edge nodes.
pub(crate) struct ExportSurface {
    /// Vertex positions (m, object frame).
    pub positions: Vec<[f64; 3]>,
    /// Outward triangles (indices into `positions`).
    pub triangles: Vec<[u32; 3]>,
    /// Volume-mesh node of each vertex.
    pub volume_node: Vec<u32>,
    /// Mode rows (v, 3, m) row-major, m·kg^-½.
    modes: Vec<f64>,
    m: usize,
}

impl ExportSurface {
    /// The export surface of `base`. A second-order base's mid-edge node of edge (a, b) is
    /// placed at the midpoint of a and b (the bake accepts straight-sided elements only) with
    /// its stored mode row and volume node, and triangle (v₀, v₁, v₂) with mid-edge nodes
    /// e₀₁, e₁₂, e₂₀ becomes (v₀, e₀₁, e₂₀), (e₀₁, v₁, e₁₂), (e₂₀, e₁₂, v₂), (e₀₁, e₁₂, e₂₀),
    /// all with the parent's orientation. Mid-edge vertex e is vertex `corners + e`.
    pub fn of(base: &ModesFile) -> ExportSurface {
        let corners = ExportSurface {
            positions: base.surface_vertices.clone(),
            triangles: base.surface_triangles.clone(),
            volume_node: base.surface_to_volume.clone(),
            modes: base.modes.clone(),
            m: base.num_modes(),
        };
        let Some(q) = &base.quadratic else {
            return corners;
        };
        // A base that reads has exactly its triangles' edges (checked by the reader).
        let Ok(tri_edges) = q.triangle_edges(&base.surface_triangles) else {
            return corners;
        };
        let mut out = corners;
        let nv = out.positions.len() as u32;
        let p = &base.surface_vertices;
        out.positions.extend(q.edges.iter().map(|&[a, b]| {
            let (a, b) = (p[a as usize], p[b as usize]);
            [
                0.5 * (a[0] + b[0]),
                0.5 * (a[1] + b[1]),
                0.5 * (a[2] + b[2]),
            ]
        }));
        out.volume_node.extend_from_slice(&q.edge_to_volume);
        out.modes.extend_from_slice(&q.modes);
        out.triangles = base
            .surface_triangles
            .iter()
            .zip(&tri_edges)
            .flat_map(|(&[v0, v1, v2], &[e01, e12, e20])| {
                let (e01, e12, e20) = (nv + e01, nv + e12, nv + e20);
                [
                    [v0, e01, e20],
                    [e01, v1, e12],
                    [e20, e12, v2],
                    [e01, e12, e20],
                ]
            })
            .collect();
        out
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Mode j's displacement of vertex v (m per unit modal coordinate, object frame).
    pub fn mode_vec(&self, v: usize, j: usize) -> [f64; 3] {
        let (m, r) = (self.m, v * 3 * self.m);
        [
            self.modes[r + j],
            self.modes[r + m + j],
            self.modes[r + 2 * m + j],
        ]
    }

    /// Largest vertex displacement norm of mode j (m per unit modal coordinate).
    pub fn mode_max_norm(&self, j: usize) -> f64 {
        (0..self.len())
            .map(|v| {
                let u = self.mode_vec(v, j);
                (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()
            })
            .fold(0.0, f64::max)
    }
}

/// Axis-aligned bounding box (min, max) of the surface (m, object frame).
pub(crate) fn bounding_box(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

/// Length of the bounding-box diagonal (m).
pub(crate) fn diagonal(points: &[[f64; 3]]) -> f64 {
    let (lo, hi) = bounding_box(points);
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

/// Writes `bytes` to `path` through the project's one writer
/// ([`dcr_files::write_atomic`]): a unique temporary beside it, renamed over it when
/// complete; a device, FIFO, socket or folder at `path` is refused, and on failure (or
/// SIGINT/SIGTERM in a tool that installed [`crate::signals::remove_temporaries_on_signals`])
/// nothing is left behind and an existing `path` is untouched. Check the command's outputs
/// against its inputs first ([`dcr_files::OutputPlan`]).
///
/// # Errors
/// [`ExportError::Write`], naming `path`.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    dcr_files::write_atomic(path, bytes).map_err(ExportError::Write)
}
