//! The bake pipeline: mesh → oriented, validated mesh → K, M → boundary conditions →
//! lowest elastic modes → surface extraction → [`ModesFile`].

use std::path::Path;

pub use dcr_runtime::format::{MaterialSi, ModesFile, ModesPrecision};

use crate::mesh::TetMesh;

/// How many modes to keep.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModeRequest {
    /// The lowest `n` elastic modes.
    Count(usize),
    /// Every elastic mode below this frequency (Hz).
    MaxFreqHz(f64),
}

/// Everything that determines a bake's result (SI units).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BakeParams {
    /// Isotropic material (E in Pa, ν, ρ in kg/m³). Default: the paper's table, 1.1 GPa, 0.3, 770.
    pub material: MaterialSi,
    /// Modes to keep. Default: the lowest 20.
    pub modes: ModeRequest,
    /// Names of physical groups whose nodes are fixed (empty: free-free).
    pub fixed: Vec<String>,
    /// Fix every node at or below a coordinate (`--fixed-below y=0.01`); combined with the
    /// other selectors by union.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_below: Vec<FixedBelow>,
    /// Fix every node inside an axis-aligned box `[x0, y0, z0, x1, y1, z1]` (m, object frame,
    /// bounds included; `--fixed-box`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_boxes: Vec<[f64; 6]>,
    /// Default Rayleigh damping stored in the base (α0 in 1/s, α1 in s). Default (10, 1e-7).
    pub rayleigh: [f64; 2],
    /// Lumped (diagonal) mass instead of consistent mass.
    pub lumped: bool,
    /// Storage precision of the surface mode shapes.
    pub precision: ModesPrecision,
}

/// A half-space selector of fixed nodes: every node whose coordinate `axis` is ≤ `value`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FixedBelow {
    /// The axis: 0 = x, 1 = y, 2 = z (object frame).
    pub axis: usize,
    /// The threshold (m); nodes at or below it are fixed.
    pub value: f64,
}

impl std::fmt::Display for FixedBelow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let axis = ["x", "y", "z"].get(self.axis).copied().unwrap_or("?");
        write!(f, "{axis}={}", self.value)
    }
}

impl Default for BakeParams {
    fn default() -> Self {
        BakeParams {
            material: MaterialSi {
                youngs: 1.1e9,
                poisson: 0.3,
                density: 770.0,
            },
            modes: ModeRequest::Count(20),
            fixed: Vec::new(),
            fixed_below: Vec::new(),
            fixed_boxes: Vec::new(),
            rayleigh: [10.0, 1e-7],
            lumped: false,
            precision: ModesPrecision::F64,
        }
    }
}

use std::time::Instant;

use sha2::{Digest, Sha256};

use crate::eigen::{self, EigenError, EigenParams, EigenProgress};
use crate::fem::{self, Material, MaterialError};
use crate::mesh::{tet_faces, MeshError, DEFAULT_DEGENERATE_REL_TOL, DEFAULT_STRAIGHT_REL_TOL};
use dcr_runtime::format::{FormatError, ModesMeta, QuadraticSurface};

/// Version of what `modal-bake` writes for given inputs, stored in every base
/// (`meta.bake_params.output_version`). Bumped by any change of the tool that changes a base's
/// content for the same mesh and options (assembly, eigensolver, surface extraction, hashing),
/// and only then — not by the crate version — so `check` calls bases of an older output stale
/// and an upgrade that changes nothing keeps them fresh.
pub const OUTPUT_VERSION: u32 = 1;

/// `modal-bake <version>`, stored in every base.
pub const TOOL_VERSION: &str = concat!("modal-bake ", env!("CARGO_PKG_VERSION"));

/// The schema number mixed into [`BakeParams::hash`]; changes only when the meaning of a
/// parameter changes (new parameters at their defaults leave the hash unchanged).
const PARAMS_HASH_VERSION: u32 = 1;

/// A near-zero eigenvalue is a rigid-body mode when |λ| ≤ this × the first elastic λ.
pub const RIGID_REL_TOL: f64 = 1e-6;

/// Largest relative residual ‖Ku − λMu‖/‖Ku‖ accepted for a mode that is written, unless the
/// residual is at its double-precision floor (see `bake_mesh`).
pub const MAX_RESIDUAL: f64 = 1e-8;

/// Why a bake failed. Every variant names what and where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BakeError {
    /// The mesh could not be read or is invalid (file, line or element in the message).
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Material parameters out of range.
    #[error("invalid material: {0}")]
    Material(#[from] MaterialError),
    /// Inconsistent bake parameters.
    #[error("invalid bake parameters: {0}")]
    Params(String),
    /// The mesh has several disconnected pieces.
    #[error(
        "{file}: the mesh has {pieces} disconnected pieces; bake each piece as its own object"
    )]
    Disconnected {
        /// Mesh file.
        file: String,
        /// Number of connected components.
        pieces: usize,
    },
    /// A free-free object did not show exactly six rigid-body modes.
    #[error("{file}: expected 6 rigid-body modes for a free-free object, found {found} eigenvalues with |λ| ≤ {tol:.3e} rad²/s² (a mechanism, or a near-singular mesh)")]
    RigidModes {
        /// Mesh file.
        file: String,
        /// Near-zero eigenvalues found.
        found: usize,
        /// Threshold used (rad²/s²).
        tol: f64,
    },
    /// The eigensolver failed or did not converge; nothing is written.
    #[error("{file}: {error}")]
    Eigen {
        /// Mesh file.
        file: String,
        /// What the solver reported.
        error: EigenError,
    },
    /// Modes whose residual exceeds [`MAX_RESIDUAL`]; nothing is written.
    #[error("{file}: mode {mode} did not converge (relative residual {residual:.3e} > {MAX_RESIDUAL:.0e}); refusing to write the base")]
    NotConverged {
        /// Mesh file.
        file: String,
        /// 0-based elastic mode index.
        mode: usize,
        /// Its relative residual.
        residual: f64,
    },
    /// Writing or reading the `.modes` file failed.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The peak-transfer table could not be built (`--transfer-h`); nothing is written.
    #[error("{file}: {error}")]
    Transfer {
        /// Mesh file.
        file: String,
        /// What failed.
        error: Box<crate::transfer::TransferError>,
    },
}

/// What a bake reports besides the base: timings (s) and facts about the mesh and the modes.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct BakeReport {
    /// Seconds spent reading the mesh.
    pub read_s: f64,
    /// Seconds assembling K and M.
    pub assemble_s: f64,
    /// Seconds in the numeric (and symbolic) factorization of K − σM.
    pub factor_s: f64,
    /// Seconds in the eigensolver after factorization.
    pub eigensolve_s: f64,
    /// Seconds writing the file.
    pub write_s: f64,
    /// Volume nodes and tetrahedra.
    pub nodes: usize,
    /// Tetrahedra.
    pub tets: usize,
    /// Free degrees of freedom solved for.
    pub free_dofs: usize,
    /// Inverted tetrahedra reoriented.
    pub reoriented_tets: usize,
    /// Fixed nodes (the union of every selector's).
    pub fixed_nodes: usize,
    /// What each fixed-node selector picked: (`group NAME` / `below y=0.01` / `box ...`,
    /// nodes), in the order groups, half-spaces, boxes; selectors may overlap.
    pub fixed_by: Vec<(String, usize)>,
    /// Element order: 1 (4-node tetrahedra) or 2 (10-node).
    pub order: u8,
    /// Second-order bases: surface mid-edge nodes whose mode rows are stored (0 for P1).
    pub surface_edge_nodes: usize,
    /// Rigid-body modes detected and excluded (6 when free-free).
    pub rigid_modes_excluded: usize,
    /// Their eigenvalues (rad²/s²), as computed (≈ 0).
    pub rigid_eigenvalues: Vec<f64>,
    /// Elastic modes written.
    pub modes: usize,
    /// Their frequencies (Hz).
    pub frequencies_hz: Vec<f64>,
    /// Their relative residuals.
    pub residuals: Vec<f64>,
    /// Their double-precision residual floors (see [`MAX_RESIDUAL`]).
    pub residual_floors: Vec<f64>,
    /// Surface vertices and triangles.
    pub surface_vertices: usize,
    /// Surface triangles.
    pub surface_triangles: usize,
    /// Object mass (kg).
    pub mass_kg: f64,
    /// Notes from reading (skipped element types, ...).
    pub notes: Vec<String>,
    /// Geometry hash stored in the base.
    pub source_hash: String,
    /// Seconds computing the transfer table's modes (0 without a table or when the base's own
    /// modes sufficed).
    pub transfer_modes_s: f64,
    /// Seconds building the transfer table (0 without one).
    pub transfer_s: f64,
    /// Transfer table: region vertices (0: no table).
    pub transfer_vertices: usize,
    /// Transfer table: region edges whose points are tabulated.
    pub transfer_edges: usize,
    /// Transfer table: interpolation order (1, 2, 3; 0 without a table).
    pub transfer_order: u8,
    /// Transfer table: points (vertices, edge and face points).
    pub transfer_points: usize,
    /// Transfer table: modes summed.
    pub transfer_modes: usize,
    /// Transfer table: samples per step.
    pub transfer_samples: usize,
    /// Transfer table: where its modes came from (`base`, `dense`, `lanczos`).
    pub transfer_mode_source: String,
    /// Bounding-box diagonal of the mesh (m).
    pub extent_m: f64,
    /// The output's folder, when the bake had to create it ([`bake_file`]).
    pub created_folder: Option<String>,
}

/// Progress of a bake, for a CLI bar.
#[derive(Clone, Copy, Debug)]
pub enum BakeStage {
    /// Reading the mesh.
    Read,
    /// Assembling K and M.
    Assemble,
    /// Factoring K − σM (before the first Lanczos step).
    Factor,
    /// Iterating; carries the eigensolver's progress.
    Eigensolve(EigenProgress),
    /// Solving for the transfer table's modes (dense or Lanczos).
    TransferModes,
    /// Building the transfer table; carries rows done / total.
    Transfer(crate::transfer::TransferProgress),
    /// Writing the file.
    Write,
}

impl BakeParams {
    /// The number of elastic modes requested as a minimum count (1 for a frequency request).
    fn min_modes(&self) -> usize {
        match self.modes {
            ModeRequest::Count(n) => n,
            ModeRequest::MaxFreqHz(_) => 1,
        }
    }

    fn check(&self) -> Result<Material, BakeError> {
        let mat = Material::new(
            self.material.youngs,
            self.material.poisson,
            self.material.density,
        )?;
        match self.modes {
            ModeRequest::Count(0) => {
                return Err(BakeError::Params("--modes must be at least 1".into()))
            }
            ModeRequest::Count(n) if n > 5000 => {
                return Err(BakeError::Params(format!(
                    "--modes {n} is more than the supported 5000"
                )))
            }
            ModeRequest::MaxFreqHz(f) if !(f.is_finite() && f > 0.0) => {
                return Err(BakeError::Params(format!(
                    "--max-freq must be a positive frequency in Hz, got {f}"
                )))
            }
            _ => {}
        }
        if !self.rayleigh.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(BakeError::Params(format!(
                "--rayleigh coefficients must be finite and ≥ 0, got {:?}",
                self.rayleigh
            )));
        }
        for b in &self.fixed_below {
            if b.axis > 2 || !b.value.is_finite() {
                return Err(BakeError::Params(format!(
                    "--fixed-below needs an axis x, y or z and a finite value in m, got axis {} value {}",
                    b.axis, b.value
                )));
            }
        }
        for b in &self.fixed_boxes {
            if !b.iter().all(|x| x.is_finite()) || (0..3).any(|k| b[k] > b[k + 3]) {
                return Err(BakeError::Params(format!(
                    "--fixed-box {b:?}: expected finite X0,Y0,Z0,X1,Y1,Z1 (m) with each minimum ≤ its maximum"
                )));
            }
        }
        Ok(mat)
    }

    /// `sha256:<hex>` of everything in these parameters that changes the result, plus a
    /// schema number.
    pub fn hash(&self) -> String {
        let json = serde_json::to_vec(&(PARAMS_HASH_VERSION, self)).expect("params serialise");
        format!("sha256:{:x}", Sha256::digest(&json))
    }
}

/// `sha256:<hex>` of the canonical geometry: node positions rounded to 16 significant
/// digits, tetrahedra (after orientation) and the sorted fixed-node set. Independent of the
/// file's format and bytes.
///
/// Why 16 digits: gmsh prints ASCII MSH coordinates with `%.16g`, which does not round-trip
/// every `f64`, so its ASCII and binary files of one mesh can differ by an ulp per coordinate.
/// Rounding is idempotent on what gmsh prints (x and the double nearest its 16-digit decimal
/// round alike), so every form gmsh writes of one mesh — MSH 2.2 or 4.1, ASCII or binary —
/// and a meshio JSON of it hash alike. Two meshes whose coordinates differ only beyond the
/// 16th significant digit (relative change below ~5e-16) share a hash; their bases differ by
/// rounding only.
pub fn geometry_hash(mesh: &TetMesh, fixed: &[usize]) -> String {
    let mut h = Sha256::new();
    h.update(b"dcr-geometry-v2");
    h.update((mesh.nodes.len() as u64).to_le_bytes());
    for p in &mesh.nodes {
        for &x in p {
            h.update(round_16_digits(x).to_bits().to_le_bytes());
        }
    }
    h.update((mesh.tets.len() as u64).to_le_bytes());
    for t in &mesh.tets {
        for &v in t {
            h.update((v as u64).to_le_bytes());
        }
    }
    h.update((fixed.len() as u64).to_le_bytes());
    for &v in fixed {
        h.update((v as u64).to_le_bytes());
    }
    // Second-order meshes only, so linear meshes keep their hash.
    if mesh.is_quadratic() {
        h.update(b"tet10");
        for e in &mesh.mid_edges {
            for &v in e {
                h.update((v as u64).to_le_bytes());
            }
        }
    }
    format!("sha256:{:x}", h.finalize())
}

/// `x` rounded to 16 significant decimal digits (the double nearest `%.16g` of `x`); non-finite
/// values unchanged.
pub fn round_16_digits(x: f64) -> f64 {
    use std::io::Write;
    if !x.is_finite() {
        return x;
    }
    // "-d.ddddddddddddddde-308" is 23 bytes.
    let mut buf = [0u8; 32];
    let mut w = &mut buf[..];
    let _ = write!(w, "{x:.15e}");
    let n = 32 - w.len();
    std::str::from_utf8(&buf[..n])
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(x)
}

/// A mesh prepared for baking: oriented, checked, with its fixed-node set and hash.
struct Prepared {
    mesh: TetMesh,
    fixed: Vec<usize>,
    /// What each selector fixed: (description, nodes), in the order groups, below, boxes.
    fixed_by: Vec<(String, usize)>,
    /// Second-order meshes: each edge (sorted corner pair) with its mid-edge node, sorted.
    mid_table: Vec<([usize; 2], usize)>,
    reoriented: usize,
    hash: String,
}

/// The nodes (sorted) each fixed-node selector of `params` picks, with a description per
/// selector (`group bottom`, `below y=0.01`, `box [..]`).
///
/// # Errors
/// An unknown group, or a selector that picks no node (it names the mesh's extent).
fn select_fixed(
    mesh: &TetMesh,
    params: &BakeParams,
    file: &str,
) -> Result<Vec<(String, Vec<usize>)>, BakeError> {
    let name_file = |mut e: MeshError| {
        if e.file.is_empty() {
            e.file = file.to_string();
        }
        e
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &mesh.nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = || {
        format!(
            "the mesh spans x {:.6}…{:.6}, y {:.6}…{:.6}, z {:.6}…{:.6} m",
            lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
        )
    };
    let mut out = Vec::new();
    for name in &params.fixed {
        let nodes = mesh.group_nodes(name).map_err(name_file)?.to_vec();
        if nodes.is_empty() {
            return Err(BakeError::Params(format!(
                "{file}: --fixed {name} fixes no node (the group has no node on the tetrahedra)"
            )));
        }
        out.push((format!("group {name}"), nodes));
    }
    for b in &params.fixed_below {
        let nodes: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&v| mesh.nodes[v][b.axis] <= b.value)
            .collect();
        if nodes.is_empty() {
            return Err(BakeError::Params(format!(
                "{file}: --fixed-below {b} fixes no node ({})",
                extent()
            )));
        }
        out.push((format!("below {b}"), nodes));
    }
    for bx in &params.fixed_boxes {
        let nodes: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&v| (0..3).all(|k| (bx[k]..=bx[k + 3]).contains(&mesh.nodes[v][k])))
            .collect();
        if nodes.is_empty() {
            return Err(BakeError::Params(format!(
                "{file}: --fixed-box {} fixes no node ({})",
                bx.map(|x| x.to_string()).join(","),
                extent()
            )));
        }
        out.push((
            format!("box {}", bx.map(|x| x.to_string()).join(",")),
            nodes,
        ));
    }
    Ok(out)
}

fn prepare(mut mesh: TetMesh, params: &BakeParams, file: &str) -> Result<Prepared, BakeError> {
    let name_file = |mut e: MeshError| {
        if e.file.is_empty() {
            e.file = file.to_string();
        }
        e
    };
    if mesh.tets.is_empty() {
        return Err(BakeError::Params(format!(
            "{file}: the mesh has no tetrahedra"
        )));
    }
    mesh.check_extent().map_err(name_file)?;
    let reoriented = mesh
        .orient_tets(DEFAULT_DEGENERATE_REL_TOL)
        .map_err(name_file)?;
    mesh.check_straight(DEFAULT_STRAIGHT_REL_TOL)
        .map_err(name_file)?;
    let mid_table = mesh.edge_mid_nodes().map_err(name_file)?;
    mesh.check_overlaps().map_err(name_file)?;
    let pieces = mesh.connected_components();
    if pieces != 1 {
        return Err(BakeError::Disconnected {
            file: file.to_string(),
            pieces,
        });
    }
    let selected = select_fixed(&mesh, params, file)?;
    let fixed_by: Vec<(String, usize)> = selected
        .iter()
        .map(|(what, nodes)| (what.clone(), nodes.len()))
        .collect();
    let mut fixed: Vec<usize> = selected.into_iter().flat_map(|(_, n)| n).collect();
    fixed.sort_unstable();
    fixed.dedup();
    if !fixed.is_empty() && !spans_a_plane(&mesh, &fixed) {
        return Err(BakeError::Params(format!(
            "{file}: the fixed nodes ({} of them: {}) are collinear, so rotations about their line stay free \
             (a mechanism, K is singular); fix a patch of at least three non-collinear nodes",
            fixed.len(),
            fixed_by.iter().map(|(w, _)| w.as_str()).collect::<Vec<_>>().join(", ")
        )));
    }
    if !fixed.is_empty() && fixed.len() == mesh.nodes.len() {
        return Err(BakeError::Params(format!(
            "{file}: --fixed fixes every node; nothing can vibrate"
        )));
    }
    let hash = geometry_hash(&mesh, &fixed);
    Ok(Prepared {
        mesh,
        fixed,
        fixed_by,
        mid_table,
        reoriented,
        hash,
    })
}

/// Whether the nodes `set` contain three non-collinear points (relative tolerance 1e-9 of the
/// set's extent): only then do they suppress every rigid-body motion.
fn spans_a_plane(mesh: &TetMesh, set: &[usize]) -> bool {
    let p0 = mesh.nodes[set[0]];
    let dist2 = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>();
    let Some(&far) = set
        .iter()
        .max_by(|&&a, &&b| dist2(p0, mesh.nodes[a]).total_cmp(&dist2(p0, mesh.nodes[b])))
    else {
        return false;
    };
    let p1 = mesh.nodes[far];
    let l2 = dist2(p0, p1);
    if !(l2 > 0.0) {
        return false;
    }
    // Area of (p0, p1, p) relative to |p0 p1|²: twice the triangle area = |(p1−p0)×(p−p0)|.
    let e = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
    set.iter().any(|&v| {
        let p = mesh.nodes[v];
        let d = [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]];
        let c = [
            e[1] * d[2] - e[2] * d[1],
            e[2] * d[0] - e[0] * d[2],
            e[0] * d[1] - e[1] * d[0],
        ];
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() > 1e-9 * l2
    })
}

/// The boundary surface of a mesh as the bake stores it.
struct Surface {
    /// Sorted volume-node indices of the surface vertices.
    nodes: Vec<usize>,
    /// Their positions (m).
    positions: Vec<[f64; 3]>,
    /// Outward triangles in surface-vertex indices.
    triangles: Vec<[u32; 3]>,
    /// The heat geodesic's elimination order, so loading skips AMD and factors less fill.
    /// A surface the heat method cannot factor (degenerate triangles) simply stores none; the
    /// runtime reports the problem if the heat method is used.
    order: Option<Vec<u32>>,
    /// Second-order meshes: the surface edges (surface-vertex pairs, sorted) and the volume
    /// node of each one's mid-edge node. Empty for a linear mesh.
    edges: Vec<[u32; 2]>,
    edge_nodes: Vec<usize>,
}

impl Surface {
    /// `mid_table`: [`TetMesh::edge_mid_nodes`] (empty for a linear mesh).
    fn of(mesh: &TetMesh, mid_table: &[([usize; 2], usize)]) -> Surface {
        let (nodes, tris) = extract_surface(mesh);
        let mut local = vec![u32::MAX; mesh.nodes.len()];
        for (i, &v) in nodes.iter().enumerate() {
            local[v] = i as u32;
        }
        let triangles: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|v| local[v])).collect();
        let positions: Vec<[f64; 3]> = nodes.iter().map(|&v| mesh.nodes[v]).collect();
        let order = crate::ordering::plan_surface_order(&positions, &triangles).ok();
        let (mut edges, mut edge_nodes) = (Vec::new(), Vec::new());
        if mesh.is_quadratic() {
            edges = QuadraticSurface::edges_of(&triangles);
            // Every surface edge is a tet edge, so the look-up succeeds on a mesh that passed
            // `edge_mid_nodes`; `usize::MAX` would fail the base's validation, not panic.
            edge_nodes = edges
                .iter()
                .map(|&[a, b]| {
                    let key = [nodes[a as usize], nodes[b as usize]];
                    mid_table
                        .binary_search_by(|x| x.0.cmp(&key))
                        .map_or(usize::MAX, |i| mid_table[i].1)
                })
                .collect();
        }
        Surface {
            nodes,
            positions,
            triangles,
            order,
            edges,
            edge_nodes,
        }
    }
}

/// Bits per node index in the packed face keys of [`extract_surface`] (3 × 21 ≤ 64).
const PACK_BITS: u32 = 21;

/// Boundary faces of a tetrahedral mesh, oriented outward, as (sorted surface-vertex list of
/// volume nodes, triangles in volume-node indices). Deterministic: faces are sorted.
pub fn extract_surface(mesh: &TetMesh) -> (Vec<usize>, Vec<[usize; 3]>) {
    let packable = mesh.nodes.len() <= 1 << PACK_BITS && mesh.tets.len() < 1 << 30;
    let tris = if packable {
        boundary_faces_packed(&mesh.tets)
    } else {
        boundary_faces(&mesh.tets)
    };
    let mut verts: Vec<usize> = tris.iter().flatten().copied().collect();
    verts.sort_unstable();
    verts.dedup();
    (verts, tris)
}

/// A face rotated so its smallest index comes first (canonical, orientation kept).
fn canonical_face(f: [usize; 3]) -> [usize; 3] {
    let r = (0..3).min_by_key(|&k| f[k]).unwrap_or(0);
    [f[r], f[(r + 1) % 3], f[(r + 2) % 3]]
}

/// The faces that belong to exactly one tet, canonical, in the order of their sorted node
/// triples.
fn boundary_faces(tets: &[[usize; 4]]) -> Vec<[usize; 3]> {
    let mut faces: Vec<([usize; 3], [usize; 3])> = Vec::with_capacity(tets.len() * 4);
    for &tet in tets {
        for f in tet_faces(tet) {
            let mut key = f;
            key.sort_unstable();
            faces.push((key, f));
        }
    }
    faces.sort_unstable_by_key(|x| x.0);
    let mut tris = Vec::new();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        if j - i == 1 {
            tris.push(canonical_face(faces[i].1));
        }
        i = j;
    }
    tris
}

/// [`boundary_faces`] for node indices below 2^[`PACK_BITS`] and fewer than 2^30 tets: the
/// sorted node triple packed into one u64 (same order as the triples) beside the face's
/// number: 16-byte elements sort about twice as fast as the 48-byte (triple, face)
/// pairs (docs/benchmarks.md, "Design measurements"). Same result.
fn boundary_faces_packed(tets: &[[usize; 4]]) -> Vec<[usize; 3]> {
    let mut faces: Vec<(u64, u32)> = Vec::with_capacity(tets.len() * 4);
    for (t, &tet) in tets.iter().enumerate() {
        for (k, mut key) in tet_faces(tet).into_iter().enumerate() {
            key.sort_unstable();
            let packed = ((key[0] as u64) << (2 * PACK_BITS))
                | ((key[1] as u64) << PACK_BITS)
                | key[2] as u64;
            faces.push((packed, (4 * t + k) as u32));
        }
    }
    faces.sort_unstable();
    let same = |j: usize, key: u64| faces.get(j).is_some_and(|&(other, _)| other == key);
    let mut tris = Vec::new();
    for (i, &(key, id)) in faces.iter().enumerate() {
        if !same(i + 1, key) && (i == 0 || !same(i - 1, key)) {
            let id = id as usize;
            tris.push(canonical_face(tet_faces(tets[id / 4])[id % 4]));
        }
    }
    tris
}

/// Bakes the modal base of an in-memory mesh. `file` names the source in messages.
///
/// Steps: orient tetrahedra (inverted ones are flipped and counted, degenerate ones are an
/// error), refuse disconnected meshes, fix the named groups, assemble K and M, solve
/// K u = λ M u for the lowest modes by shift-invert block Lanczos, exclude the six rigid-body
/// modes of a free-free object, check every residual ≤ [`MAX_RESIDUAL`], keep the surface rows.
///
/// # Errors
/// A [`BakeError`] naming the file and what failed.
pub fn bake_mesh(
    mesh: TetMesh,
    params: &BakeParams,
    file: &str,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<(ModesFile, BakeReport), BakeError> {
    let mat = params.check()?;
    let mut report = BakeReport {
        notes: mesh.notes.clone(),
        ..Default::default()
    };
    let Prepared {
        mesh,
        fixed,
        fixed_by,
        mid_table,
        reoriented,
        hash,
    } = prepare(mesh, params, file)?;
    report.order = if mesh.is_quadratic() { 2 } else { 1 };
    report.fixed_by = fixed_by;
    report.nodes = mesh.nodes.len();
    report.tets = mesh.tets.len();
    report.extent_m = mesh.extent();
    report.reoriented_tets = reoriented;
    report.fixed_nodes = fixed.len();
    report.source_hash = hash.clone();

    progress(BakeStage::Assemble);
    let t = Instant::now();
    let (map, kf, mf) = fem::assemble_clamped(&mesh, &mat, params.lumped, &fixed)
        .map_err(|e| BakeError::Params(format!("{file}: {e}")))?;
    report.assemble_s = t.elapsed().as_secs_f64();
    report.free_dofs = map.n_free();
    report.mass_kg = mat.density * mesh.volume();

    let free_free = fixed.is_empty();
    let rigid = if free_free { 6 } else { 0 };
    let wanted = params.min_modes() + rigid;
    if wanted > map.n_free() {
        return Err(BakeError::Params(format!(
            "{file}: --modes {}: at most {} modes for this mesh (3 × {} nodes − {} fixed dofs{} = {})",
            params.min_modes(),
            map.n_free().saturating_sub(rigid),
            mesh.nodes.len(),
            3 * mesh.nodes.len() - map.n_free(),
            if rigid > 0 { " − 6 rigid" } else { "" },
            map.n_free().saturating_sub(rigid)
        )));
    }
    let eparams = EigenParams {
        nev: wanted,
        max_freq_hz: match params.modes {
            ModeRequest::MaxFreqHz(f) => Some(f),
            ModeRequest::Count(_) => None,
        },
        shift: if free_free {
            eigen::default_shift(&mesh, &mat)
        } else {
            0.0
        },
        // Ten times stricter than the MAX_RESIDUAL a written mode must meet; 1e-10 is below
        // the rounding floor of the higher modes of fine meshes (measured: table, 80 modes,
        // worst 7.4e-10).
        // The MAX_RESIDUAL a written mode must meet: the solver confirms every pair on the
        // same explicit residual, so a stricter tolerance only buys iterations (1e-10 is below
        // the rounding floor of the higher modes of fine meshes).
        tol: MAX_RESIDUAL,
        ..Default::default()
    };
    // The surface and its heat-geodesic ordering depend on the mesh only: they are computed
    // on a second thread during the factorization and eigensolve (the bake bench's 3k / 15k
    // beams: ≈ 5 / 17 ms, otherwise after it).
    progress(BakeStage::Factor);
    let (res, surface) = std::thread::scope(|scope| {
        let surface = scope.spawn(|| Surface::of(&mesh, &mid_table));
        let res = eigen::solve_lowest(&kf, &mf, &eparams, &mut |p| {
            progress(BakeStage::Eigensolve(p))
        });
        (
            res,
            surface.join().expect("the surface thread does not panic"),
        )
    });
    let res = res.map_err(|error| BakeError::Eigen {
        file: file.to_string(),
        error,
    })?;
    report.factor_s = res.info.factor_seconds;
    report.eigensolve_s = res.info.solve_seconds;

    // Rigid-body modes: exactly six near-zero eigenvalues for a free-free object.
    let mut first = 0;
    if free_free {
        let lam7 = res
            .eigenvalues
            .get(rigid)
            .copied()
            .unwrap_or(f64::INFINITY)
            .abs();
        let tol = RIGID_REL_TOL * lam7;
        let near_zero = res.eigenvalues.iter().filter(|l| l.abs() <= tol).count();
        if near_zero != rigid {
            return Err(BakeError::RigidModes {
                file: file.to_string(),
                found: near_zero,
                tol,
            });
        }
        report.rigid_eigenvalues = res.eigenvalues[..rigid].to_vec();
        first = rigid;
    }
    report.rigid_modes_excluded = first;
    let elastic: Vec<usize> = (first..res.eigenvalues.len())
        .filter(|&j| match params.modes {
            ModeRequest::Count(n) => j < first + n,
            ModeRequest::MaxFreqHz(f) => {
                res.eigenvalues[j].max(0.0).sqrt() / (2.0 * std::f64::consts::PI) < f
            }
        })
        .collect();
    if elastic.is_empty() {
        return Err(BakeError::Params(format!(
            "{file}: no elastic mode below the requested frequency (lowest is {:.4} Hz)",
            res.eigenvalues
                .get(first)
                .map_or(0.0, |l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        )));
    }
    for (i, &j) in elastic.iter().enumerate() {
        // A mode passes at MAX_RESIDUAL, or within the eigensolver's factor of its double-
        // precision floor ε(‖|K||u|‖ + λ‖|M||u|‖)/‖Ku‖ ≈ ε·λ_max/λ, which exceeds 1e-8 for the
        // low modes of slender, finely meshed objects (measured: 1.5e-7 on a 300×10×10 beam):
        // no double-precision vector can do better there.
        let floor_ok = res.residuals[j] <= eigen::FLOOR_FACTOR * res.residual_floors[j];
        if !(res.residuals[j] <= MAX_RESIDUAL || floor_ok) || !(res.eigenvalues[j] > 0.0) {
            return Err(BakeError::NotConverged {
                file: file.to_string(),
                mode: i,
                residual: res.residuals[j],
            });
        }
    }

    // Surface rows of U.
    let full = map.expand(res.vectors.as_ref());
    let Surface {
        nodes: surf,
        positions,
        triangles,
        order,
        edges,
        edge_nodes,
    } = surface;
    let nm = elastic.len();
    let rows_of = |nodes: &[usize]| {
        let mut modes = Vec::with_capacity(nodes.len() * 3 * nm);
        for &v in nodes {
            for axis in 0..3 {
                for &j in &elastic {
                    modes.push(if v < mesh.nodes.len() {
                        full[(3 * v + axis, j)]
                    } else {
                        f64::NAN // refused by the base's validation
                    });
                }
            }
        }
        modes
    };
    let modes = rows_of(&surf);
    let quadratic = mesh.is_quadratic().then(|| QuadraticSurface {
        edge_to_volume: edge_nodes.iter().map(|&v| v as u32).collect(),
        modes: rows_of(&edge_nodes),
        edges,
    });
    let eigenvalues: Vec<f64> = elastic.iter().map(|&j| res.eigenvalues[j]).collect();
    let residuals: Vec<f64> = elastic.iter().map(|&j| res.residuals[j]).collect();
    let base = ModesFile {
        eigenvalues,
        surface_vertices: positions,
        surface_triangles: triangles,
        surface_to_volume: surf.iter().map(|&v| v as u32).collect(),
        modes,
        material: params.material,
        rayleigh: params.rayleigh,
        fixed_nodes: fixed.iter().map(|&v| v as u32).collect(),
        residuals,
        meta: ModesMeta {
            format_version: 1,
            tool_version: TOOL_VERSION.to_string(),
            source_hash: hash,
            params_hash: params.hash(),
            bake_params: {
                let mut v = serde_json::to_value(params).expect("params serialise");
                if let Some(obj) = v.as_object_mut() {
                    obj.insert("output_version".into(), OUTPUT_VERSION.into());
                }
                v
            },
            volume_nodes: mesh.nodes.len(),
            volume_tets: mesh.tets.len(),
            rigid_modes_excluded: first,
            mass_kg: report.mass_kg,
            reoriented_tets: reoriented,
            accuracy: None,
        },
        precision: params.precision,
        transfer: None,
        surface_order: order,
        quadratic,
    };
    let mut base = base;
    base.meta.format_version = base.required_format_version();
    report.surface_edge_nodes = base.quadratic.as_ref().map_or(0, |q| q.edges.len());
    report.modes = nm;
    report.frequencies_hz = base.frequencies_hz();
    report.residuals = base.residuals.clone();
    report.residual_floors = elastic.iter().map(|&j| res.residual_floors[j]).collect();
    report.surface_vertices = base.surface_vertices.len();
    report.surface_triangles = base.surface_triangles.len();
    Ok((base, report))
}

/// As [`bake_mesh`], plus (with `transfer`) the bake-time peak-transfer table
/// ([`crate::transfer`]) over the selected region, built from the base's own modes when it
/// keeps enough, else from the dense all-mode eigensolve (≤ [`crate::transfer::DENSE_MAX_DOFS`]
/// free dofs) or a Lanczos bake with that many modes. The table's parameters are recorded in
/// `meta.bake_params.transfer`; `params_hash` stays that of `params` (the table is checked by
/// its own entries: h, Rayleigh, modes).
///
/// # Errors
/// As [`bake_mesh`]; [`BakeError::Transfer`] when the table cannot be built.
pub fn bake_mesh_with_transfer(
    mesh: TetMesh,
    params: &BakeParams,
    transfer: Option<&crate::transfer::TransferParams>,
    file: &str,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<(ModesFile, BakeReport), BakeError> {
    use crate::transfer::{self as tr, TransferModes};
    let Some(tp) = transfer else {
        return bake_mesh(mesh, params, file, progress);
    };
    let terr = |error| BakeError::Transfer {
        file: file.to_string(),
        error: Box::new(error),
    };
    tp.check().map_err(terr)?;
    if mesh.is_quadratic() {
        return Err(terr(tr::TransferError::Params(
            "--transfer-h is not supported for second-order (10-node) meshes: the table interpolates P1 midpoint rows; bake the linear mesh for a table".into(),
        )));
    }
    let (mut base, mut report) = bake_mesh(mesh.clone(), params, file, progress)?;
    let t = Instant::now();
    let tp = &tr::TransferParams {
        modes: tp.modes.resolve(report.free_dofs),
        ..tp.clone()
    };
    let enough = matches!(tp.modes, TransferModes::Count(n) if n <= base.num_modes());
    let set = if enough {
        report.transfer_mode_source = "base".into();
        None
    } else if report.free_dofs <= tr::DENSE_MAX_DOFS {
        progress(BakeStage::TransferModes);
        report.transfer_mode_source = "dense".into();
        Some(tr::mode_set_dense(&base, &mesh, params, tp.modes, file).map_err(terr)?)
    } else {
        let TransferModes::Count(n) = tp.modes else {
            return Err(terr(tr::TransferError::Params(format!(
                "--transfer-modes all needs the dense eigensolve, but the mesh has {} free dofs (limit {}); give a count",
                report.free_dofs,
                tr::DENSE_MAX_DOFS
            ))));
        };
        progress(BakeStage::TransferModes);
        report.transfer_mode_source = "lanczos".into();
        Some(tr::mode_set_lanczos(&mesh, params, n, file).map_err(terr)?)
    };
    report.transfer_modes_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let table = tr::build_transfer_table(
        set.as_ref().unwrap_or(&base),
        tp,
        params.rayleigh,
        &mut |p| progress(BakeStage::Transfer(p)),
    )
    .map_err(terr)?;
    report.transfer_s = t.elapsed().as_secs_f64();
    report.transfer_vertices = table.len();
    report.transfer_edges = table.edges.len();
    report.transfer_order = table.order;
    report.transfer_points = table.num_points();
    report.transfer_modes = table.modes as usize;
    report.transfer_samples = table.samples as usize;
    if let Some(obj) = base.meta.bake_params.as_object_mut() {
        obj.insert("transfer".into(), transfer_meta(tp));
    }
    base.transfer = Some(table);
    Ok((base, report))
}

/// The record of a transfer table's parameters in `meta.bake_params.transfer` (what
/// [`is_up_to_date_with_transfer`] compares).
fn transfer_meta(tp: &crate::transfer::TransferParams) -> serde_json::Value {
    use crate::transfer::TransferModes;
    serde_json::json!({
        "h": tp.h,
        "modes": match tp.modes {
            TransferModes::All => serde_json::json!("all"),
            TransferModes::Auto => serde_json::json!("auto"),
            TransferModes::Count(n) => serde_json::json!(n),
        },
        "regions": tp.boxes,
        "up": tp.up,
        "up_min_cos": tp.up_min_cos,
        "oversample": tp.oversample,
        "order": match tp.order {
            crate::transfer::TableOrder::Auto => serde_json::json!("auto"),
            crate::transfer::TableOrder::Linear => serde_json::json!(1),
            crate::transfer::TableOrder::Quadratic => serde_json::json!(2),
            crate::transfer::TableOrder::Cubic => serde_json::json!(3),
        },
    })
}

/// Reads `mesh_path`, bakes it and writes `out` atomically (nothing is left on failure),
/// creating `out`'s folder if it is missing ([`BakeReport::created_folder`]).
///
/// # Errors
/// A [`BakeError`] naming the file and what failed.
pub fn bake_file(
    mesh_path: &Path,
    params: &BakeParams,
    out: &Path,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<BakeReport, BakeError> {
    bake_file_with_transfer(mesh_path, params, None, out, progress)
}

/// As [`bake_file`], with an optional peak-transfer table ([`bake_mesh_with_transfer`]).
///
/// # Errors
/// A [`BakeError`] naming the file and what failed.
pub fn bake_file_with_transfer(
    mesh_path: &Path,
    params: &BakeParams,
    transfer: Option<&crate::transfer::TransferParams>,
    out: &Path,
    progress: &mut dyn FnMut(BakeStage),
) -> Result<BakeReport, BakeError> {
    progress(BakeStage::Read);
    let t = Instant::now();
    let mesh = crate::mesh::read_mesh(mesh_path)?;
    let read_s = t.elapsed().as_secs_f64();
    let (base, mut report) = bake_mesh_with_transfer(
        mesh,
        params,
        transfer,
        &mesh_path.display().to_string(),
        progress,
    )?;
    report.read_s = read_s;
    progress(BakeStage::Write);
    let t = Instant::now();
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.exists() {
            std::fs::create_dir_all(dir).map_err(|source| FormatError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
            report.created_folder = Some(dir.display().to_string());
        }
    }
    base.write_atomic(out)?;
    report.write_s = t.elapsed().as_secs_f64();
    Ok(report)
}

/// Whether `modes` is an up-to-date base of `mesh_path` baked with `params`: it exists, reads,
/// its stored geometry and parameter hashes equal those of this mesh and these parameters, and
/// it holds the heat-geodesic `surface_order` a bake would store.
///
/// `Ok(false)` when the base is missing, unreadable or stale.
///
/// # Errors
/// A [`BakeError`] when the mesh itself cannot be read or prepared (what `check` exits 2 on).
pub fn is_up_to_date(
    mesh_path: &Path,
    params: &BakeParams,
    modes: &Path,
) -> Result<bool, BakeError> {
    is_up_to_date_with_transfer(mesh_path, params, None, modes)
}

/// As [`is_up_to_date`], also for the peak-transfer table: `transfer` as passed to
/// [`bake_file_with_transfer`]. A base is stale when it has a table and none is asked for, has
/// none and one is asked for, or its table was built with other parameters (step h, modes,
/// region, up direction, oversampling).
///
/// # Errors
/// As [`is_up_to_date`]; invalid transfer parameters.
pub fn is_up_to_date_with_transfer(
    mesh_path: &Path,
    params: &BakeParams,
    transfer: Option<&crate::transfer::TransferParams>,
    modes: &Path,
) -> Result<bool, BakeError> {
    Ok(base_status(mesh_path, params, transfer, modes)? == BaseStatus::UpToDate)
}

/// Whether a base is up to date, and if not why (what `modal-bake check --json` reports).
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum BaseStatus {
    /// The base holds what a bake of this mesh with these options would write.
    UpToDate,
    /// No file at the base's path.
    Missing,
    /// The file does not read as a valid base (the reader's message).
    Unreadable(String),
    /// Written by a `modal-bake` whose output differs ([`OUTPUT_VERSION`]), or without what
    /// this one stores (the heat-geodesic order).
    ToolChanged,
    /// The mesh's geometry or fixed set differs ([`geometry_hash`]).
    GeometryChanged,
    /// The bake parameters differ ([`BakeParams::hash`]).
    ParametersChanged,
    /// The peak-transfer table is missing, unwanted or built with other parameters.
    TransferTableChanged,
}

impl BaseStatus {
    /// The reason as one word (`up_to_date`, `missing`, `unreadable`, `tool_changed`,
    /// `geometry_changed`, `parameters_changed`, `transfer_table_changed`).
    pub fn reason(&self) -> &'static str {
        match self {
            BaseStatus::UpToDate => "up_to_date",
            BaseStatus::Missing => "missing",
            BaseStatus::Unreadable(_) => "unreadable",
            BaseStatus::ToolChanged => "tool_changed",
            BaseStatus::GeometryChanged => "geometry_changed",
            BaseStatus::ParametersChanged => "parameters_changed",
            BaseStatus::TransferTableChanged => "transfer_table_changed",
        }
    }
}

/// Compares the base at `modes` with what a bake of `mesh_path` with `params` (and `transfer`)
/// would write: by content hashes of the parsed geometry and of the parameters, and the
/// [`OUTPUT_VERSION`] of the tool that wrote it — never by file times.
///
/// # Errors
/// A [`BakeError`] when the mesh itself cannot be read or prepared, or the parameters are
/// invalid (what `check` exits 2 on).
pub fn base_status(
    mesh_path: &Path,
    params: &BakeParams,
    transfer: Option<&crate::transfer::TransferParams>,
    modes: &Path,
) -> Result<BaseStatus, BakeError> {
    let file = mesh_path.display().to_string();
    check_options(params, transfer, &file)?;
    let mesh = crate::mesh::read_mesh(mesh_path)?;
    mesh_base_status(mesh, &file, params, transfer, modes)
}

/// Checks the bake and transfer-table parameters (what `check` exits 2 on before any mesh work).
fn check_options(
    params: &BakeParams,
    transfer: Option<&crate::transfer::TransferParams>,
    file: &str,
) -> Result<(), BakeError> {
    params.check()?;
    if let Some(tp) = transfer {
        tp.check().map_err(|error| BakeError::Transfer {
            file: file.to_string(),
            error: Box::new(error),
        })?;
    }
    Ok(())
}

/// As [`is_up_to_date_with_transfer`] for a mesh already in memory (e.g. one gmsh made from a
/// surface asset); `file` names it in messages.
///
/// # Errors
/// As [`is_up_to_date`].
pub fn is_mesh_up_to_date(
    mesh: TetMesh,
    file: &str,
    params: &BakeParams,
    transfer: Option<&crate::transfer::TransferParams>,
    modes: &Path,
) -> Result<bool, BakeError> {
    Ok(mesh_base_status(mesh, file, params, transfer, modes)? == BaseStatus::UpToDate)
}

/// As [`base_status`] for a mesh already in memory; `file` names it in messages.
///
/// # Errors
/// As [`base_status`].
pub fn mesh_base_status(
    mesh: TetMesh,
    file: &str,
    params: &BakeParams,
    transfer: Option<&crate::transfer::TransferParams>,
    modes: &Path,
) -> Result<BaseStatus, BakeError> {
    check_options(params, transfer, file)?;
    let prepared = prepare(mesh, params, file)?;
    if std::fs::symlink_metadata(modes).is_err() {
        return Ok(BaseStatus::Missing);
    }
    let base = match ModesFile::read(modes) {
        Ok(base) => base,
        Err(e) => return Ok(BaseStatus::Unreadable(e.to_string())),
    };
    let output_version = base.meta.bake_params.get("output_version");
    // A base without the stored heat-geodesic order (baked before it existed, or written
    // elsewhere) is stale when this tool would store one.
    let order_matches = base.surface_order.is_some()
        || crate::ordering::plan_surface_order(&base.surface_vertices, &base.surface_triangles)
            .is_err();
    if output_version != Some(&serde_json::json!(OUTPUT_VERSION)) || !order_matches {
        return Ok(BaseStatus::ToolChanged);
    }
    if base.meta.source_hash != prepared.hash {
        return Ok(BaseStatus::GeometryChanged);
    }
    if base.meta.params_hash != params.hash() {
        return Ok(BaseStatus::ParametersChanged);
    }
    let table_matches = match transfer {
        None => base.transfer.is_none(),
        Some(tp) => {
            base.transfer.is_some()
                && base.meta.bake_params.get("transfer") == Some(&transfer_meta(tp))
        }
    };
    if !table_matches {
        return Ok(BaseStatus::TransferTableChanged);
    }
    Ok(BaseStatus::UpToDate)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rounding to 16 digits is idempotent (the geometry hash relies on it: a coordinate and
    /// its `%.16g` print round alike), exact where 16 digits suffice, and moves a value by at
    /// most half a unit of its 16th digit (plus the parse's half ulp). Random bit patterns over
    /// the whole finite range.
    #[test]
    fn rounding_to_16_digits_is_idempotent() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut checked = 0;
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = f64::from_bits(state);
            if !x.is_finite() {
                continue;
            }
            let r = round_16_digits(x);
            let printed: f64 = format!("{x:.15e}").parse().unwrap();
            assert_eq!(r.to_bits(), printed.to_bits(), "{x:e}");
            assert_eq!(round_16_digits(r).to_bits(), r.to_bits(), "{x:e}");
            assert!((r - x).abs() <= 6.2e-16 * x.abs(), "{x:e} → {r:e}");
            checked += 1;
        }
        assert!(checked > 190_000);
        for x in [0.0, -0.0, 1.0, 0.1, 0.3, -2.5e-7, 1e300, 5e-324] {
            assert_eq!(round_16_digits(x).to_bits(), x.to_bits(), "{x:e}");
        }
    }

    /// The packed-key boundary faces equal the general ones (same faces, same order), on a
    /// structured box and on the same box with its tets listed in reverse.
    #[test]
    fn packed_boundary_faces_equal_the_general_ones() {
        let mesh = TetMesh::structured_box([7, 3, 4], [1.0, 0.5, 0.5]);
        let mut tets = mesh.tets.clone();
        let general = boundary_faces(&tets);
        assert_eq!(general.len(), 2 * 2 * (7 * 3 + 7 * 4 + 3 * 4));
        assert_eq!(boundary_faces_packed(&tets), general);
        tets.reverse();
        assert_eq!(boundary_faces_packed(&tets), boundary_faces(&tets));
        assert_eq!(boundary_faces(&tets), general);
    }
}
