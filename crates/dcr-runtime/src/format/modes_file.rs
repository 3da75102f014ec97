//! The `.modes` file: the one place that defines how a modal base is stored (read AND write).
//!
//! A `.modes` file is an uncompressed NPZ archive (a zip of `.npy` arrays) that
//! `numpy.load` opens. The schema is documented in `docs/modes-format.md`; bump
//! [`FORMAT_VERSION`] on any incompatible change.
//!
//! | entry | dtype | shape | meaning |
//! |---|---|---|---|
//! | `format_version` | u32 | () | [`FORMAT_VERSION`] |
//! | `eigenvalues` | f64 | (m,) | λ = ω² (rad²/s²), ascending, elastic modes only |
//! | `frequencies_hz` | f64 | (m,) | √λ / 2π (Hz) |
//! | `surface_vertices` | f64 | (ns, 3) | surface vertex positions (m, object frame) |
//! | `surface_triangles` | u32 | (nt, 3) | outward-oriented (counter-clockwise seen from outside) |
//! | `surface_to_volume` | u32 | (ns,) | volume-mesh node index of each surface vertex |
//! | `modes` | f64 or f32 | (ns, 3, m) | surface rows of the M-orthonormal basis U (m·kg^-1/2) |
//! | `material` | f64 | (3,) | Young's modulus E (Pa), Poisson ratio ν, density ρ (kg/m³) |
//! | `rayleigh` | f64 | (2,) | default Rayleigh damping (α0 in 1/s, α1 in s) |
//! | `fixed_nodes` | u32 | (nf,) | volume-mesh nodes fixed at bake time (empty: free-free) |
//! | `residuals` | f64 | (m,) | relative residual ‖Ku − λMu‖/‖Ku‖ of each mode at bake |
//! | `meta` | u8 | (bytes,) | UTF-8 JSON: [`ModesMeta`] |
//!
//! Optional: `surface_order` u32 (ns,), a fill-reducing elimination order of the surface
//! vertices (a permutation of 0..ns) for the heat-geodesic factor, chosen at bake time
//! (`modal_bake::ordering::plan_surface_order`: METIS nested dissection or AMD, whichever fills
//! less); without it the runtime orders with AMD at load.
//!
//! Optional (all or none): the peak-transfer table ([`TransferTable`]): `transfer_vertices`
//! u32 (nr,), `transfer_peaks` f32 (np(np+1)/2,) packed upper triangle over np = nr + ne points
//! (m per N·s),
//! `transfer_h` f64 () (s), `transfer_rayleigh` f64 (2,), `transfer_modes` u32 (),
//! `transfer_samples` u32 (), and optionally `transfer_edges` u32 (ne, 2), `transfer_order`
//! u32 () (1, 2, 3; absent: 2 with edges, else 1) and `transfer_faces` u32 (nf, 3) (order 3).
//! Readers that predate the table ignore these entries.
//!
//! Optional (version ≥ 2, all or none): the mid-edge rows of a second-order (P2) base
//! ([`QuadraticSurface`]): `surface_edges` u32 (ne, 2), `edge_to_volume` u32 (ne,),
//! `edge_modes` f64 or f32 (ne, 3, m). A file carries the lowest version that describes it
//! ([`ModesFile::required_format_version`]): linear bases stay version 1, which every earlier
//! reader opens; second-order bases are version 2, which version-1 readers refuse rather than
//! interpolate them linearly.
//!
//! Files are written (cargo feature `write`, which engines leave off) deterministically (fixed
//! zip timestamps, fixed entry order, stored) and atomically through the tools' one writer
//! (`dcr_files::write_atomic`: a unique temporary beside the destination, then a rename).
//!
//! Reading distrusts every size in the file: only regular files are opened; each entry's
//! declared size is checked against the archive's length, each `.npy` header length against
//! the entry's bytes and each shape against the data present before anything is allocated;
//! the content is then validated ([`ModesFile::validate`], one table of rules per kind of value).

#[cfg(feature = "write")]
use std::io::Cursor;
use std::io::{Read, Seek};
use std::path::{Path, PathBuf};

#[cfg(feature = "write")]
use super::npy::write_entry;
use super::npy::{decode, parse_header_text, NpyElement};
use serde::{Deserialize, Serialize};

use super::quadratic_surface::{QuadraticSurface, QUADRATIC_ENTRIES, QUADRATIC_FORMAT_VERSION};
use super::regular_file::{open_regular_file, OpenError};
use super::transfer_table::{
    TransferTable, TRANSFER_EDGES_ENTRY, TRANSFER_ENTRIES, TRANSFER_FACES_ENTRY,
    TRANSFER_ORDER_ENTRY,
};

/// Newest `.modes` schema version this build reads and writes (it reads every version from 1).
pub const FORMAT_VERSION: u32 = 2;

/// Largest `.npy` entry accepted when reading (bytes); guards against hostile headers.
const MAX_ENTRY_BYTES: u64 = 8 << 30;

/// Largest `meta` JSON accepted (bytes).
const MAX_META_BYTES: u64 = 16 << 20;

/// Storage precision of the mode shapes in the file (memory is always f64).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ModesPrecision {
    /// 8-byte floats (default).
    #[default]
    F64,
    /// 4-byte floats: half the size, ~1e-7 relative rounding of U.
    F32,
}

/// Isotropic linear-elastic material (SI).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MaterialSi {
    /// Young's modulus E (Pa).
    pub youngs: f64,
    /// Poisson ratio ν (dimensionless, −1 < ν < 0.5).
    pub poisson: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
}

/// Free-form bake metadata stored as JSON in the `meta` entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModesMeta {
    /// Schema version (same as the `format_version` entry): 1 to [`FORMAT_VERSION`], at least
    /// [`ModesFile::required_format_version`].
    pub format_version: u32,
    /// Tool that wrote the file, e.g. `modal-bake 0.1.0`.
    pub tool_version: String,
    /// Content hash of the parsed geometry (node positions, tets, fixed set), `sha256:<hex>`.
    pub source_hash: String,
    /// Hash of the bake parameters that influence the result, `sha256:<hex>`.
    pub params_hash: String,
    /// The bake parameters as given (material, modes request, rayleigh, lumped, precision...).
    pub bake_params: serde_json::Value,
    /// Volume-mesh node count.
    pub volume_nodes: usize,
    /// Volume-mesh tetrahedron count.
    pub volume_tets: usize,
    /// Rigid-body modes detected and excluded (6 for free-free objects, 0 when fixed).
    pub rigid_modes_excluded: usize,
    /// Total mass of the object (kg).
    pub mass_kg: f64,
    /// Inverted tetrahedra that were reoriented while baking.
    pub reoriented_tets: usize,
    /// What `modal-bake bake --target-error` chose and its measured error (absent otherwise;
    /// files without it read as `None` and are written byte for byte as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<AccuracyRecord>,
}

/// The accuracy a base was chosen for (`modal-bake bake --target-error PCT`): its error against
/// the bake's own converged full-order truth at seeded pairs of the region, and its cost. Every
/// figure is deterministic (no timings), so the file stays bit-identical.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AccuracyRecord {
    /// Target: worst |error| allowed over the pairs (%).
    pub target_pct: f64,
    /// Whether the chosen representation meets it (else it is the most accurate tried).
    pub met: bool,
    /// Median |error| over the pairs (%).
    pub median_pct: f64,
    /// Worst |error| over the pairs (%).
    pub worst_pct: f64,
    /// Pairs measured (impact, resting contact; vertices and points inside triangles).
    pub pairs: usize,
    /// Rigid-body step h the peaks are taken over (s).
    pub h: f64,
    /// The truth: `all-modes` (dense sum) or `newmark`.
    pub truth: String,
    /// The truth's step after refinement (s).
    pub truth_dt: f64,
    /// The truth's estimated error (%), see `modal_bake::full_order::converged_peaks`.
    pub truth_error_pct: f64,
    /// Runtime modes kept in the base.
    pub modes: usize,
    /// Modes summed by its transfer table (`None`: no table).
    pub table_modes: Option<usize>,
    /// Interpolation order of its table (`None`: no table).
    pub table_order: Option<u8>,
    /// Query cost model: multiply-adds per (impact, resting contact) pair — m·S for m modal
    /// filters sampled S times per step, (nodes per triangle)² table lookups for a table.
    pub query_cost: f64,
    /// The same for the paper's 20 modes, for comparison.
    pub query_cost_20: f64,
    /// Bytes of the numeric payload (mode rows and table entries; the file adds a few KiB).
    pub payload_bytes: u64,
}

/// A modal base in memory: exactly what a `.modes` file holds.
#[derive(Clone, Debug, PartialEq)]
pub struct ModesFile {
    /// λ_j = ω_j² (rad²/s²), ascending, length m.
    pub eigenvalues: Vec<f64>,
    /// Surface vertex positions (m, object frame), length ns.
    pub surface_vertices: Vec<[f64; 3]>,
    /// Outward-oriented surface triangles, indices into `surface_vertices`.
    pub surface_triangles: Vec<[u32; 3]>,
    /// Volume-mesh node index of each surface vertex, length ns.
    pub surface_to_volume: Vec<u32>,
    /// Surface rows of U, row-major (ns, 3, m): `modes[(v * 3 + axis) * m + j]`
    /// (m·kg^-1/2: a unit modal coordinate displaces vertex v by this much).
    pub modes: Vec<f64>,
    /// Material the base was baked with.
    pub material: MaterialSi,
    /// Default Rayleigh damping (α0 in 1/s, α1 in s): D = α0 M + α1 K.
    pub rayleigh: [f64; 2],
    /// Volume-mesh nodes that were fixed (empty: free-free).
    pub fixed_nodes: Vec<u32>,
    /// Relative residual ‖Ku − λMu‖/‖Ku‖ of each mode at bake time.
    pub residuals: Vec<f64>,
    /// Bake metadata.
    pub meta: ModesMeta,
    /// Storage precision of `modes` in the file.
    pub precision: ModesPrecision,
    /// Optional bake-time peak-transfer table (`None`: the base has none).
    pub transfer: Option<TransferTable>,
    /// Optional fill-reducing elimination order of the surface vertices for the heat-geodesic
    /// factor (`order[k]` = the vertex eliminated k-th; a permutation of 0..ns). `None`: the
    /// runtime computes AMD when it first needs the factor.
    pub surface_order: Option<Vec<u32>>,
    /// Second-order bases: the mid-edge nodes of the 6-node surface triangles and their mode
    /// rows (`None`: a linear base, modes interpolated linearly in each triangle).
    pub quadratic: Option<QuadraticSurface>,
}

/// What went wrong reading or writing a `.modes` file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FormatError {
    /// Operating-system I/O error.
    #[error("{path}: {source}")]
    Io {
        /// File concerned.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The archive itself is unreadable (not a zip, truncated, corrupt).
    #[error("{path}: not a readable .modes (NPZ) archive: {detail}")]
    Archive {
        /// File concerned.
        path: PathBuf,
        /// What the zip reader said.
        detail: String,
    },
    /// A required entry is missing.
    #[error("{path}: missing entry `{entry}`")]
    Missing {
        /// File concerned.
        path: PathBuf,
        /// Entry name without `.npy`.
        entry: &'static str,
    },
    /// An entry is malformed (bad header, wrong dtype or rank, truncated data).
    #[error("{path}: entry `{entry}`: {detail}")]
    Entry {
        /// File concerned.
        path: PathBuf,
        /// Entry name without `.npy`.
        entry: &'static str,
        /// What is wrong.
        detail: String,
    },
    /// The path names a directory, device, FIFO or socket, not a regular file.
    #[error("{path}: not a regular file ({what})")]
    NotRegular {
        /// Path concerned.
        path: PathBuf,
        /// What it is instead ("a directory", "a FIFO", ...).
        what: &'static str,
    },
    /// A write (cargo feature `write`) would replace something that is not a regular file.
    #[error("{path}: is {what}; refusing to replace it with a file (give the path of a file)")]
    Clobber {
        /// Path concerned.
        path: PathBuf,
        /// What it is ("a directory", "a character device", ...).
        what: &'static str,
    },
    /// The file was written by an incompatible schema version.
    #[error("{path}: format version {found} is not supported (this build reads versions 1 to {FORMAT_VERSION})")]
    Version {
        /// File concerned.
        path: PathBuf,
        /// Version found.
        found: u32,
    },
    /// Shapes or values are inconsistent (mismatched lengths, NaN, out-of-range index...).
    #[error("{path}: invalid content: {detail}")]
    Invalid {
        /// File concerned.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
}

#[cfg(feature = "write")]
impl From<dcr_files::WriteError> for FormatError {
    fn from(e: dcr_files::WriteError) -> FormatError {
        match e {
            dcr_files::WriteError::Clobber { path, what } => FormatError::Clobber { path, what },
            dcr_files::WriteError::Io { path, source } => FormatError::Io { path, source },
            dcr_files::WriteError::InUse { path, source } => FormatError::Io {
                path,
                source: std::io::Error::new(
                    source.kind(),
                    format!("cannot be replaced ({source}): {}", dcr_files::IN_USE_HINT),
                ),
            },
            // `WriteError` is non-exhaustive: a future kind keeps its message.
            other => FormatError::Io {
                path: PathBuf::new(),
                source: std::io::Error::other(other.to_string()),
            },
        }
    }
}

impl ModesFile {
    /// Number of modes m.
    pub fn num_modes(&self) -> usize {
        self.eigenvalues.len()
    }

    /// Number of surface vertices ns.
    pub fn num_surface_vertices(&self) -> usize {
        self.surface_vertices.len()
    }

    /// The lowest format version that can hold this base: [`QUADRATIC_FORMAT_VERSION`] with a
    /// second-order surface, else 1.
    pub fn required_format_version(&self) -> u32 {
        if self.quadratic.is_some() {
            QUADRATIC_FORMAT_VERSION
        } else {
            1
        }
    }

    /// Frequencies f_j = √λ_j / 2π (Hz).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues
            .iter()
            .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect()
    }

    /// Checks version, shapes, value ranges and index ranges; `path` is used in messages.
    ///
    /// Table-driven: every entry's length, its values' range and its indices' bound are rows of
    /// three tables (lengths, `RealRule`s, `IndexRule`s), so a new entry is a row in each.
    /// Messages name the entry, the element (`residuals[3]`, `modes[v][axis][j]`) and the
    /// range that holds.
    ///
    /// # Errors
    /// [`FormatError::Invalid`] or [`FormatError::Version`] naming what is wrong.
    pub fn validate(&self, path: &Path) -> Result<(), FormatError> {
        let inv = |detail: String| FormatError::Invalid {
            path: path.to_path_buf(),
            detail,
        };
        if !(1..=FORMAT_VERSION).contains(&self.meta.format_version) {
            return Err(FormatError::Version {
                path: path.to_path_buf(),
                found: self.meta.format_version,
            });
        }
        if self.meta.format_version < self.required_format_version() {
            return Err(inv(format!(
                "format version {} cannot hold a second-order surface (needs {QUADRATIC_FORMAT_VERSION})",
                self.meta.format_version
            )));
        }
        self.check_lengths().map_err(inv)?;
        self.check_values().map_err(inv)?;
        self.check_material_and_meta().map_err(inv)?;
        self.check_sections().map_err(inv)?;
        Ok(())
    }

    /// Counts and entry lengths against the surface and mode counts (`validate`'s first step).
    fn check_lengths(&self) -> Result<(), String> {
        let m = self.num_modes();
        let ns = self.num_surface_vertices();
        if m == 0 {
            return Err("no modes".into());
        }
        if ns == 0 || self.surface_triangles.is_empty() {
            return Err("empty surface".into());
        }
        // Lengths: (entry, length, expected, expected as a formula).
        let lengths = [
            ("modes", self.modes.len(), ns * 3 * m, "ns×3×m"),
            ("surface_to_volume", self.surface_to_volume.len(), ns, "ns"),
            ("residuals", self.residuals.len(), m, "m"),
        ];
        for (entry, len, expected, formula) in lengths {
            if len != expected {
                return Err(format!(
                    "{entry} holds {len} values, expected {formula} = {expected} (ns = {ns} surface vertices, m = {m} modes)"
                ));
            }
        }
        Ok(())
    }

    /// Every value's range and every index's bound (the rule tables), ascending eigenvalues and
    /// a supported surface extent.
    fn check_values(&self) -> Result<(), String> {
        let m = self.num_modes();
        let ns = self.num_surface_vertices();
        let nv = self.meta.volume_nodes;
        let modes_shape = [3, m];
        let reals = [
            RealRule::new("eigenvalues", &self.eigenvalues, &[], ValueRule::Positive),
            RealRule::new("residuals", &self.residuals, &[], ValueRule::NonNegative),
            RealRule::new("modes", &self.modes, &modes_shape, ValueRule::Finite),
            RealRule::new(
                "surface_vertices",
                self.surface_vertices.as_flattened(),
                &[3],
                ValueRule::Coordinate,
            ),
            RealRule::new("rayleigh", &self.rayleigh, &[], ValueRule::NonNegative),
        ];
        const VOLUME_NODES: &str = "volume nodes (meta.volume_nodes)";
        let indices = [
            IndexRule {
                entry: "surface_triangles",
                values: self.surface_triangles.as_flattened(),
                shape: &[3],
                bound: ns,
                counts: "surface vertices",
            },
            IndexRule {
                entry: "surface_to_volume",
                values: &self.surface_to_volume,
                shape: &[],
                bound: nv,
                counts: VOLUME_NODES,
            },
            IndexRule {
                entry: "fixed_nodes",
                values: &self.fixed_nodes,
                shape: &[],
                bound: nv,
                counts: VOLUME_NODES,
            },
        ];
        for rule in &reals {
            rule.check()?;
        }
        for rule in &indices {
            rule.check()?;
        }
        if let Some(j) = (1..m).find(|&j| self.eigenvalues[j] < self.eigenvalues[j - 1]) {
            return Err(format!("eigenvalues not ascending at mode {j}"));
        }
        let extent = surface_extent(&self.surface_vertices);
        if !(extent >= MIN_EXTENT_M) {
            return Err(format!(
                "surface extent {extent:.2e} m (bounding-box diagonal) is below the supported {MIN_EXTENT_M:e} m"
            ));
        }
        Ok(())
    }

    /// The material (SI) and the metadata's mass, node count and rigid-mode count.
    fn check_material_and_meta(&self) -> Result<(), String> {
        let ns = self.num_surface_vertices();
        let nv = self.meta.volume_nodes;
        let MaterialSi {
            youngs,
            poisson,
            density,
        } = self.material;
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(youngs) && positive(density) && poisson > -1.0 && poisson < 0.5) {
            return Err(format!(
                "material out of range: E={youngs} ν={poisson} ρ={density} (E, ρ finite and > 0, −1 < ν < 0.5)"
            ));
        }
        let meta = &self.meta;
        if !positive(meta.mass_kg) {
            return Err(format!(
                "meta.mass_kg = {} (must be finite and > 0)",
                meta.mass_kg
            ));
        }
        if nv < ns {
            return Err(format!(
                "meta.volume_nodes = {nv} is below the {ns} surface vertices"
            ));
        }
        if !matches!(meta.rigid_modes_excluded, 0 | 6) {
            return Err(format!(
                "meta.rigid_modes_excluded = {} (must be 0, fixed, or 6, free-free)",
                meta.rigid_modes_excluded
            ));
        }
        Ok(())
    }

    /// The optional sections: the transfer table, the second-order surface, the surface order.
    fn check_sections(&self) -> Result<(), String> {
        let m = self.num_modes();
        let ns = self.num_surface_vertices();
        if let Some(t) = &self.transfer {
            t.check(ns)?;
        }
        if let Some(q) = &self.quadratic {
            q.check(ns, m, &self.surface_triangles)?;
            if self.transfer.is_some() {
                return Err(
                    "a peak-transfer table on a second-order base is not supported (the table interpolates P1 midpoint rows)".into(),
                );
            }
        }
        if let Some(order) = &self.surface_order {
            if order.len() != ns {
                return Err(format!(
                    "surface_order has {} entries for {ns} surface vertices",
                    order.len()
                ));
            }
            let mut seen = vec![false; ns];
            for (k, &v) in order.iter().enumerate() {
                if v as usize >= ns || std::mem::replace(&mut seen[v as usize], true) {
                    return Err(format!(
                        "surface_order is not a permutation: entry {k} is {v} (repeated or ≥ {ns})"
                    ));
                }
            }
        }
        Ok(())
    }

    /// Writes the base to `path` atomically and deterministically (same content → same bytes);
    /// cargo feature `write`.
    ///
    /// The data is written to a temporary file beside `path`, synced, then renamed over it
    /// (`dcr_files::AtomicFile`: unique temporary names, stale temporaries of dead writers
    /// removed); on any error the temporary file is removed and `path` is left untouched.
    ///
    /// # Errors
    /// [`FormatError::Invalid`] if the content fails [`ModesFile::validate`];
    /// [`FormatError::Clobber`] if `path` is a directory, device, FIFO or socket; I/O errors.
    #[cfg(feature = "write")]
    pub fn write_atomic(&self, path: &Path) -> Result<(), FormatError> {
        self.validate(path)?;
        let bytes = self.to_bytes().map_err(|detail| FormatError::Archive {
            path: path.to_path_buf(),
            detail,
        })?;
        dcr_files::write_atomic(path, &bytes).map_err(FormatError::from)
    }

    /// Serialises the archive to bytes (deterministic: stored entries, fixed timestamps, the
    /// entries in a fixed order).
    #[cfg(feature = "write")]
    pub(crate) fn to_bytes(&self) -> Result<Vec<u8>, String> {
        let m = self.num_modes();
        let ns = self.num_surface_vertices();
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .last_modified_time(zip::DateTime::default());
        let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
        let z = &mut zip;
        let tri: Vec<u32> = self.surface_triangles.iter().flatten().copied().collect();
        let pos: Vec<f64> = self.surface_vertices.iter().flatten().copied().collect();
        let meta = serde_json::to_vec(&self.meta).map_err(|err| err.to_string())?;
        let f32s = |v: &[f64]| -> Vec<f32> { v.iter().map(|&x| x as f32).collect() };
        write_entry(z, "format_version", opts, &[], &[self.meta.format_version])?;
        write_entry(z, "eigenvalues", opts, &[m], &self.eigenvalues)?;
        write_entry(z, "frequencies_hz", opts, &[m], &self.frequencies_hz())?;
        write_entry(z, "surface_vertices", opts, &[ns, 3], &pos)?;
        let nt = self.surface_triangles.len();
        write_entry(z, "surface_triangles", opts, &[nt, 3], &tri)?;
        let nv = self.surface_to_volume.len();
        write_entry(z, "surface_to_volume", opts, &[nv], &self.surface_to_volume)?;
        match self.precision {
            ModesPrecision::F64 => write_entry(z, "modes", opts, &[ns, 3, m], &self.modes)?,
            ModesPrecision::F32 => write_entry(z, "modes", opts, &[ns, 3, m], &f32s(&self.modes))?,
        }
        let mat = &self.material;
        write_entry(
            z,
            "material",
            opts,
            &[3],
            &[mat.youngs, mat.poisson, mat.density],
        )?;
        write_entry(z, "rayleigh", opts, &[2], &self.rayleigh)?;
        let nf = self.fixed_nodes.len();
        write_entry(z, "fixed_nodes", opts, &[nf], &self.fixed_nodes)?;
        let nr = self.residuals.len();
        write_entry(z, "residuals", opts, &[nr], &self.residuals)?;
        write_entry(z, "meta", opts, &[meta.len()], &meta)?;
        if let Some(order) = &self.surface_order {
            write_entry(z, "surface_order", opts, &[order.len()], order)?;
        }
        if let Some(q) = &self.quadratic {
            let ne = q.edges.len();
            let edges: Vec<u32> = q.edges.iter().flatten().copied().collect();
            write_entry(z, QUADRATIC_ENTRIES[0], opts, &[ne, 2], &edges)?;
            let nev = q.edge_to_volume.len();
            write_entry(z, QUADRATIC_ENTRIES[1], opts, &[nev], &q.edge_to_volume)?;
            match self.precision {
                ModesPrecision::F64 => {
                    write_entry(z, QUADRATIC_ENTRIES[2], opts, &[ne, 3, m], &q.modes)?
                }
                ModesPrecision::F32 => {
                    write_entry(z, QUADRATIC_ENTRIES[2], opts, &[ne, 3, m], &f32s(&q.modes))?
                }
            }
        }
        if let Some(t) = &self.transfer {
            let nv = t.vertices.len();
            write_entry(z, "transfer_vertices", opts, &[nv], &t.vertices)?;
            write_entry(z, "transfer_peaks", opts, &[t.peaks.len()], &t.peaks)?;
            write_entry(z, "transfer_h", opts, &[], &[t.h])?;
            write_entry(z, "transfer_rayleigh", opts, &[2], &t.rayleigh)?;
            write_entry(z, "transfer_modes", opts, &[], &[t.modes])?;
            write_entry(z, "transfer_samples", opts, &[], &[t.samples])?;
            let edges: Vec<u32> = t.edges.iter().flatten().copied().collect();
            write_entry(z, TRANSFER_EDGES_ENTRY, opts, &[t.edges.len(), 2], &edges)?;
            // Only when it differs from what a reader infers (2 with edges, else 1), so that
            // order-1 and order-2 files keep the bytes of readers that predate the entry.
            if t.order != if t.edges.is_empty() { 1 } else { 2 } {
                write_entry(z, TRANSFER_ORDER_ENTRY, opts, &[], &[u32::from(t.order)])?;
                let faces: Vec<u32> = t.faces.iter().flatten().copied().collect();
                write_entry(z, TRANSFER_FACES_ENTRY, opts, &[t.faces.len(), 3], &faces)?;
            }
        }
        Ok(zip.finish().map_err(|e| e.to_string())?.into_inner())
    }

    /// Reads and validates a `.modes` file.
    ///
    /// Never trusts sizes declared in the file: every entry is bounded by its real length.
    ///
    /// # Errors
    /// A [`FormatError`] naming the file and the entry or value at fault.
    pub fn read(path: &Path) -> Result<ModesFile, FormatError> {
        let (file, _) = open_regular_file(path).map_err(|e| match e {
            OpenError::Io(source) => FormatError::Io {
                path: path.to_path_buf(),
                source,
            },
            OpenError::NotRegular(what) => FormatError::NotRegular {
                path: path.to_path_buf(),
                what,
            },
        })?;
        Self::read_from(std::io::BufReader::new(file), path)
    }

    /// Reads and validates a `.modes` archive from any seekable reader; `path` names it in errors.
    ///
    /// # Errors
    /// As [`ModesFile::read`].
    pub fn read_from<R: Read + Seek>(mut reader: R, path: &Path) -> Result<ModesFile, FormatError> {
        let io = |source| FormatError::Io {
            path: path.to_path_buf(),
            source,
        };
        let archive_len = reader.seek(std::io::SeekFrom::End(0)).map_err(io)?;
        let eocd_at = check_zip_directory(&mut reader, archive_len).map_err(|detail| {
            FormatError::Archive {
                path: path.to_path_buf(),
                detail,
            }
        })?;
        reader.seek(std::io::SeekFrom::Start(0)).map_err(io)?;
        let mut zip = zip::ZipArchive::new(reader).map_err(|err| FormatError::Archive {
            path: path.to_path_buf(),
            detail: format!(
                "{err} (the end-of-central-directory signature found at byte {eocd_at} of {archive_len} does not lead to a valid zip directory)"
            ),
        })?;
        let mut rd = EntryReader {
            zip: &mut zip,
            path,
            archive_len,
        };
        let version: u32 = rd.scalar("format_version")?;
        if !(1..=FORMAT_VERSION).contains(&version) {
            return Err(FormatError::Version {
                path: path.to_path_buf(),
                found: version,
            });
        }
        let meta_bytes: Vec<u8> = rd.vector("meta", MAX_META_BYTES)?;
        let meta: ModesMeta =
            serde_json::from_slice(&meta_bytes).map_err(|err| FormatError::Entry {
                path: path.to_path_buf(),
                entry: "meta",
                detail: format!("invalid JSON: {err}"),
            })?;
        let eigenvalues: Vec<f64> = rd.vector("eigenvalues", MAX_ENTRY_BYTES)?;
        let frequencies: Vec<f64> = rd.vector("frequencies_hz", MAX_ENTRY_BYTES)?;
        let (pos, pos_shape) = rd.array::<f64>("surface_vertices", 2)?;
        let (tri, tri_shape) = rd.array::<u32>("surface_triangles", 2)?;
        let surface_to_volume: Vec<u32> = rd.vector("surface_to_volume", MAX_ENTRY_BYTES)?;
        let (modes, modes_shape, precision) = match rd.array::<f64>("modes", 3) {
            Ok((v, s)) => (v, s, ModesPrecision::F64),
            Err(FormatError::Entry { detail, .. }) if detail.contains("dtype") => {
                let (v, s) = rd.array::<f32>("modes", 3)?;
                (
                    v.into_iter().map(f64::from).collect(),
                    s,
                    ModesPrecision::F32,
                )
            }
            Err(err) => return Err(err),
        };
        let material: Vec<f64> = rd.vector("material", 1024)?;
        let rayleigh: Vec<f64> = rd.vector("rayleigh", 1024)?;
        let fixed_nodes: Vec<u32> = rd.vector("fixed_nodes", MAX_ENTRY_BYTES)?;
        let residuals: Vec<f64> = rd.vector("residuals", MAX_ENTRY_BYTES)?;
        let transfer = rd.transfer()?;
        let surface_order = if rd.zip.index_for_name("surface_order.npy").is_some() {
            Some(rd.vector::<u32>("surface_order", MAX_ENTRY_BYTES)?)
        } else {
            None
        };
        let quadratic = rd.quadratic(precision)?;

        let inv = |detail: String| FormatError::Invalid {
            path: path.to_path_buf(),
            detail,
        };
        let m = eigenvalues.len();
        if pos_shape[1] != 3 || tri_shape[1] != 3 {
            return Err(inv(format!(
                "surface_vertices shape {pos_shape:?} / surface_triangles shape {tri_shape:?}: second axis must be 3"
            )));
        }
        let ns = pos_shape[0];
        if modes_shape != [ns, 3, m] {
            return Err(inv(format!(
                "modes shape {modes_shape:?} does not match (ns, 3, m) = ({ns}, 3, {m})"
            )));
        }
        if let Some((q, shape)) = &quadratic {
            let ne = q.edges.len();
            if shape != &[ne, 3, m] {
                return Err(inv(format!(
                    "edge_modes shape {shape:?} does not match (ne, 3, m) = ({ne}, 3, {m})"
                )));
            }
        }
        let quadratic = quadratic.map(|(q, _)| q);
        if frequencies.len() != m {
            return Err(inv(format!(
                "frequencies_hz has {} entries for {m} eigenvalues",
                frequencies.len()
            )));
        }
        if material.len() != 3 || rayleigh.len() != 2 {
            return Err(inv("material must hold 3 values and rayleigh 2".into()));
        }
        let out = ModesFile {
            eigenvalues,
            surface_vertices: pos.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            surface_triangles: tri.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            surface_to_volume,
            modes,
            material: MaterialSi {
                youngs: material[0],
                poisson: material[1],
                density: material[2],
            },
            rayleigh: [rayleigh[0], rayleigh[1]],
            fixed_nodes,
            residuals,
            meta,
            precision,
            transfer,
            surface_order,
            quadratic,
        };
        if out.meta.format_version != version {
            return Err(inv(format!(
                "the format_version entry ({version}) and meta.format_version ({}) disagree",
                out.meta.format_version
            )));
        }
        out.validate(path)?;
        for (j, (&f, g)) in frequencies.iter().zip(out.frequencies_hz()).enumerate() {
            if !((f - g).abs() <= 1e-9 * g.abs()) {
                return Err(inv(format!(
                    "frequencies_hz[{j}] = {f} disagrees with its eigenvalue ({g} Hz)"
                )));
            }
        }
        Ok(out)
    }
}

/// Largest |coordinate| (m) of a surface vertex (and, in `modal-bake`, of a mesh node). A
/// base describes one object of a rigid-body scene; a coordinate beyond 1000 km is a unit or
/// export error, and far beyond it squared lengths and areas (heat method, BVH) overflow.
pub const MAX_COORDINATE_M: f64 = 1e6;

/// Smallest bounding-box diagonal (m) of a surface (and of a mesh in `modal-bake`): below a
/// micrometre, squared lengths and areas approach the floating-point underflow the heat
/// method and the stiffness assembly cannot work in, and no rigid-body object is that small.
pub const MIN_EXTENT_M: f64 = 1e-6;

/// The range the values of one entry must lie in (a row of [`ModesFile::validate`]'s table).
#[derive(Clone, Copy, Debug)]
enum ValueRule {
    /// Finite.
    Finite,
    /// Finite and > 0.
    Positive,
    /// Finite and ≥ 0.
    NonNegative,
    /// Finite and within ±[`MAX_COORDINATE_M`] (m).
    Coordinate,
}

impl ValueRule {
    fn holds(self, x: f64) -> bool {
        match self {
            ValueRule::Finite => x.is_finite(),
            ValueRule::Positive => x.is_finite() && x > 0.0,
            ValueRule::NonNegative => x.is_finite() && x >= 0.0,
            ValueRule::Coordinate => x.abs() <= MAX_COORDINATE_M,
        }
    }

    /// The range in words, for messages.
    fn range(self) -> String {
        match self {
            ValueRule::Finite => "must be finite".into(),
            ValueRule::Positive => "must be finite and > 0".into(),
            ValueRule::NonNegative => "must be finite and ≥ 0".into(),
            ValueRule::Coordinate => format!("must be within ±{MAX_COORDINATE_M:e} m"),
        }
    }
}

/// A row of [`ModesFile::validate`]'s table of real values: every value of `entry` obeys `rule`.
struct RealRule<'a> {
    entry: &'static str,
    values: &'a [f64],
    /// Trailing dimensions of the entry (for element indices in messages).
    shape: &'a [usize],
    rule: ValueRule,
}

impl<'a> RealRule<'a> {
    fn new(entry: &'static str, values: &'a [f64], shape: &'a [usize], rule: ValueRule) -> Self {
        RealRule {
            entry,
            values,
            shape,
            rule,
        }
    }

    fn check(&self) -> Result<(), String> {
        match self.values.iter().position(|&x| !self.rule.holds(x)) {
            None => Ok(()),
            Some(i) => Err(format!(
                "{}{} = {} ({})",
                self.entry,
                element_index(i, self.shape),
                show(self.values[i]),
                self.rule.range()
            )),
        }
    }
}

/// A row of [`ModesFile::validate`]'s table of indices: every value of `entry` is < `bound`.
struct IndexRule<'a> {
    entry: &'static str,
    values: &'a [u32],
    /// Trailing dimensions of the entry (for element indices in messages).
    shape: &'a [usize],
    bound: usize,
    /// What `bound` counts, for messages.
    counts: &'static str,
}

impl IndexRule<'_> {
    fn check(&self) -> Result<(), String> {
        match self.values.iter().position(|&v| v as usize >= self.bound) {
            None => Ok(()),
            Some(i) => Err(format!(
                "{}{} = {} (must be < {} {})",
                self.entry,
                element_index(i, self.shape),
                self.values[i],
                self.bound,
                self.counts
            )),
        }
    }
}

/// `x` for a message: plain between 1e-3 and 1e6, else in exponent form (`1e150`, not 151
/// digits).
fn show(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-3..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `[i0][i1]…` of flat index `flat` in an array whose trailing dimensions are `shape`.
fn element_index(flat: usize, shape: &[usize]) -> String {
    let mut idx = vec![0; shape.len() + 1];
    let mut rest = flat;
    for (k, &d) in shape.iter().enumerate().rev() {
        idx[k + 1] = rest % d.max(1);
        rest /= d.max(1);
    }
    idx[0] = rest;
    idx.iter().map(|i| format!("[{i}]")).collect()
}

/// Bounding-box diagonal (m) of `points`; NaN when empty or not finite.
fn surface_extent(points: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let d: f64 = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    if d.is_finite() {
        d
    } else {
        f64::NAN
    }
}

/// Bounded reads of single `.npy` entries from the archive.
struct EntryReader<'a, R: Read + Seek> {
    zip: &'a mut zip::ZipArchive<R>,
    path: &'a Path,
    /// Bytes in the whole archive: no entry holds more.
    archive_len: u64,
}

/// Most entries a `.modes` archive may declare (it has about 20): the zip reader reserves
/// memory per declared entry, ~200 bytes each, before reading any.
const MAX_ARCHIVE_ENTRIES: u64 = 256;

/// Checks the entry counts a zip archive declares (end-of-central-directory record, and its
/// zip64 form if present) against [`MAX_ARCHIVE_ENTRIES`] and the archive's length before the
/// zip reader trusts them. An archive without the record is refused here, with the byte range
/// searched (a truncated file, typically). Returns the record's byte offset.
fn check_zip_directory<R: Read + Seek>(reader: &mut R, len: u64) -> Result<u64, String> {
    let io = |e: std::io::Error| format!("unreadable: {e}");
    let tail_len = len.min(22 + 65_535 + 20 + 56);
    reader
        .seek(std::io::SeekFrom::Start(len - tail_len))
        .map_err(io)?;
    let mut tail = vec![0u8; tail_len as usize];
    reader.read_exact(&mut tail).map_err(io)?;
    let Some(eocd) = (0..tail.len().saturating_sub(21))
        .rev()
        .find(|&i| &tail[i..i + 4] == b"PK\x05\x06")
    else {
        return Err(format!(
            "no zip end-of-central-directory record (PK\\x05\\x06) between byte {} and the file's end at byte {len}: truncated, or not a .modes file",
            len - tail_len
        ));
    };
    let eocd_at = len - tail_len + eocd as u64;
    let u16_at = |i: usize| u64::from(u16::from_le_bytes([tail[i], tail[i + 1]]));
    let mut counts = vec![u16_at(eocd + 8), u16_at(eocd + 10)];
    // zip64: the locator just before the record points at the zip64 record with u64 counts.
    if counts.contains(&0xFFFF) && eocd >= 20 && &tail[eocd - 20..eocd - 16] == b"PK\x06\x07" {
        let at = u64::from_le_bytes(tail[eocd - 12..eocd - 4].try_into().unwrap_or([0; 8]));
        let mut rec = [0u8; 56];
        if at.checked_add(56).is_some_and(|end| end <= len) {
            reader.seek(std::io::SeekFrom::Start(at)).map_err(io)?;
            reader.read_exact(&mut rec).map_err(io)?;
            if &rec[..4] == b"PK\x06\x06" {
                counts = vec![
                    u64::from_le_bytes(rec[24..32].try_into().unwrap_or([0; 8])),
                    u64::from_le_bytes(rec[32..40].try_into().unwrap_or([0; 8])),
                ];
            }
        }
    }
    match counts.iter().max() {
        Some(&n) if n > MAX_ARCHIVE_ENTRIES || n.saturating_mul(46) > len => Err(format!(
            "the zip directory (end-of-central-directory record at byte {eocd_at}) declares {n} entries (a .modes archive has about 20; at most {MAX_ARCHIVE_ENTRIES}, 46 bytes each, are accepted)"
        )),
        _ => Ok(eocd_at),
    }
}

/// Largest `.npy` header accepted (bytes): numpy's own default (`max_header_size`).
const MAX_NPY_HEADER: usize = 10_000;

/// Deepest bracket nesting accepted in a `.npy` header (a dict holding a shape tuple is 2).
const MAX_NPY_NESTING: usize = 8;

/// Checks a `.npy` entry's preamble (magic, version, header length) against the entry's real
/// size before its header is parsed: the header length field is distrusted (a version-2 length
/// of 4 GiB would otherwise be allocated), and so is the header's bracket nesting (the header
/// parser recurses).
fn check_npy_preamble(buf: &[u8]) -> Result<std::ops::Range<usize>, String> {
    if buf.len() < 10 || &buf[..6] != b"\x93NUMPY" {
        return Err("not a .npy entry (no \\x93NUMPY magic)".into());
    }
    let (len, start) = match buf[6] {
        1 => (u16::from_le_bytes([buf[8], buf[9]]) as usize, 10),
        2 | 3 if buf.len() >= 12 => (
            u32::from_le_bytes([buf[8], buf[9], buf[10], buf[11]]) as usize,
            12,
        ),
        2 | 3 => return Err("truncated .npy preamble".into()),
        v => return Err(format!("unsupported .npy version {v}.{}", buf[7])),
    };
    let present = buf.len() - start;
    if len > present || len > MAX_NPY_HEADER {
        return Err(format!(
            ".npy header of {len} bytes declared, but the entry holds {present} bytes after its preamble (and at most {MAX_NPY_HEADER} are accepted)"
        ));
    }
    let mut depth = 0usize;
    for &b in &buf[start..start + len] {
        match b {
            b'(' | b'[' | b'{' => {
                depth += 1;
                if depth > MAX_NPY_NESTING {
                    return Err(format!(
                        ".npy header nests brackets deeper than {MAX_NPY_NESTING} levels"
                    ));
                }
            }
            b')' | b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    Ok(start..start + len)
}

impl<R: Read + Seek> EntryReader<'_, R> {
    fn err(&self, entry: &'static str, detail: impl Into<String>) -> FormatError {
        FormatError::Entry {
            path: self.path.to_path_buf(),
            entry,
            detail: detail.into(),
        }
    }

    /// Raw bytes of `entry.npy`, at most `cap` bytes of payload.
    fn bytes(&mut self, entry: &'static str, cap: u64) -> Result<Vec<u8>, FormatError> {
        let name = format!("{entry}.npy");
        let path = self.path.to_path_buf();
        let mut f = match self.zip.by_name(&name) {
            Ok(f) => f,
            Err(zip::result::ZipError::FileNotFound) => {
                return Err(FormatError::Missing { path, entry })
            }
            Err(err) => {
                return Err(FormatError::Entry {
                    path,
                    entry,
                    detail: err.to_string(),
                })
            }
        };
        let declared = f.size().max(f.compressed_size());
        if declared > self.archive_len {
            return Err(FormatError::Entry {
                path,
                entry,
                detail: format!(
                    "declares {declared} bytes, but the whole archive holds {}",
                    self.archive_len
                ),
            });
        }
        let mut buf = Vec::new();
        // Never trust the declared size: read at most cap + header bytes.
        (&mut f)
            .take(cap + 4096)
            .read_to_end(&mut buf)
            .map_err(|err| FormatError::Entry {
                path: path.clone(),
                entry,
                detail: format!("unreadable: {err}"),
            })?;
        if buf.len() as u64 > cap + 4096 - 1 {
            return Err(FormatError::Entry {
                path,
                entry,
                detail: format!("larger than the {cap}-byte limit"),
            });
        }
        Ok(buf)
    }

    /// Parses an n-d array of element type `A`, checking the header's declared length against the
    /// bytes present before anything is allocated for it.
    fn parse<A: NpyElement>(
        &mut self,
        entry: &'static str,
        cap: u64,
    ) -> Result<(Vec<A>, Vec<usize>), FormatError> {
        let buf = self.bytes(entry, cap)?;
        let text = check_npy_preamble(&buf).map_err(|detail| self.err(entry, detail))?;
        let header_end = text.end;
        let header = parse_header_text(&buf[text]).map_err(|detail| self.err(entry, detail))?;
        let elem = A::SIZE;
        let descr = format!("'{}'", header.descr);
        let descr_size = header
            .descr
            .trim_start_matches(|c: char| !c.is_ascii_digit())
            .parse::<usize>()
            .ok()
            .or((header.descr == "B").then_some(1));
        if descr_size != Some(elem) {
            return Err(self.err(entry, format!("unexpected dtype {descr}")));
        }
        let declared = header
            .shape
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .and_then(|n| n.checked_mul(elem));
        let remaining = buf.len() - header_end;
        match declared {
            Some(bytes) if bytes == remaining => {}
            Some(bytes) => {
                return Err(self.err(
                    entry,
                    format!(
                        "shape {:?} needs {bytes} bytes of data but {remaining} are present",
                        header.shape
                    ),
                ))
            }
            None => return Err(self.err(entry, format!("shape {:?} overflows", header.shape))),
        }
        if header.fortran_order && header.shape.len() > 1 {
            return Err(self.err(entry, "Fortran-ordered arrays are not supported"));
        }
        let values = decode::<A>(&header.descr, &buf[header_end..])
            .map_err(|detail| self.err(entry, detail))?;
        Ok((values, header.shape))
    }

    fn array<A: NpyElement>(
        &mut self,
        entry: &'static str,
        ndim: usize,
    ) -> Result<(Vec<A>, Vec<usize>), FormatError> {
        let (v, shape) = self.parse::<A>(entry, MAX_ENTRY_BYTES)?;
        if shape.len() != ndim {
            return Err(self.err(
                entry,
                format!("expected {ndim} dimensions, found shape {shape:?}"),
            ));
        }
        Ok((v, shape))
    }

    fn vector<A: NpyElement>(
        &mut self,
        entry: &'static str,
        cap: u64,
    ) -> Result<Vec<A>, FormatError> {
        let (v, shape) = self.parse::<A>(entry, cap)?;
        if shape.len() != 1 {
            return Err(self.err(
                entry,
                format!("expected 1 dimension, found shape {shape:?}"),
            ));
        }
        Ok(v)
    }

    /// The optional transfer table: `None` when none of its entries is present, an error
    /// naming the missing one when only some are.
    fn transfer(&mut self) -> Result<Option<TransferTable>, FormatError> {
        let present: Vec<&'static str> = TRANSFER_ENTRIES
            .iter()
            .copied()
            .filter(|e| self.zip.index_for_name(&format!("{e}.npy")).is_some())
            .collect();
        if present.is_empty() {
            return Ok(None);
        }
        if let Some(missing) = TRANSFER_ENTRIES.iter().find(|e| !present.contains(e)) {
            return Err(FormatError::Missing {
                path: self.path.to_path_buf(),
                entry: missing,
            });
        }
        let vertices: Vec<u32> = self.vector("transfer_vertices", MAX_ENTRY_BYTES)?;
        let peaks: Vec<f32> = self.vector("transfer_peaks", MAX_ENTRY_BYTES)?;
        let h: f64 = self.scalar("transfer_h")?;
        let rayleigh: Vec<f64> = self.vector("transfer_rayleigh", 1024)?;
        let modes: u32 = self.scalar("transfer_modes")?;
        let samples: u32 = self.scalar("transfer_samples")?;
        let edges = if self
            .zip
            .index_for_name(&format!("{TRANSFER_EDGES_ENTRY}.npy"))
            .is_some()
        {
            let (flat, shape) = self.array::<u32>(TRANSFER_EDGES_ENTRY, 2)?;
            if shape[1] != 2 {
                return Err(self.err(
                    TRANSFER_EDGES_ENTRY,
                    format!("expected shape (ne, 2), found {shape:?}"),
                ));
            }
            flat.chunks_exact(2).map(|c| [c[0], c[1]]).collect()
        } else {
            Vec::new()
        };
        let has = |rd: &Self, e: &str| rd.zip.index_for_name(&format!("{e}.npy")).is_some();
        let order = if has(self, TRANSFER_ORDER_ENTRY) {
            let o: u32 = self.scalar(TRANSFER_ORDER_ENTRY)?;
            u8::try_from(o).unwrap_or(u8::MAX)
        } else if edges.is_empty() {
            1
        } else {
            2
        };
        let faces = if has(self, TRANSFER_FACES_ENTRY) {
            let (flat, shape) = self.array::<u32>(TRANSFER_FACES_ENTRY, 2)?;
            if shape[1] != 3 {
                return Err(self.err(
                    TRANSFER_FACES_ENTRY,
                    format!("expected shape (nf, 3), found {shape:?}"),
                ));
            }
            flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
        } else {
            Vec::new()
        };
        if rayleigh.len() != 2 {
            return Err(self.err(
                "transfer_rayleigh",
                format!("expected 2 values, found {}", rayleigh.len()),
            ));
        }
        Ok(Some(TransferTable {
            h,
            rayleigh: [rayleigh[0], rayleigh[1]],
            modes,
            samples,
            vertices,
            order,
            edges,
            faces,
            peaks,
        }))
    }

    /// The optional second-order surface with the shape of its `edge_modes`: `None` when none
    /// of its entries is present, an error naming the missing one when only some are.
    #[allow(clippy::type_complexity)]
    fn quadratic(
        &mut self,
        precision: ModesPrecision,
    ) -> Result<Option<(QuadraticSurface, Vec<usize>)>, FormatError> {
        let present = QUADRATIC_ENTRIES
            .iter()
            .filter(|e| self.zip.index_for_name(&format!("{e}.npy")).is_some())
            .count();
        if present == 0 {
            return Ok(None);
        }
        if let Some(missing) = QUADRATIC_ENTRIES
            .iter()
            .find(|e| self.zip.index_for_name(&format!("{e}.npy")).is_none())
        {
            return Err(FormatError::Missing {
                path: self.path.to_path_buf(),
                entry: missing,
            });
        }
        let (flat, shape) = self.array::<u32>(QUADRATIC_ENTRIES[0], 2)?;
        if shape[1] != 2 {
            return Err(self.err(
                QUADRATIC_ENTRIES[0],
                format!("expected shape (ne, 2), found {shape:?}"),
            ));
        }
        let edges = flat.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        let edge_to_volume: Vec<u32> = self.vector(QUADRATIC_ENTRIES[1], MAX_ENTRY_BYTES)?;
        let (modes, shape) = match precision {
            ModesPrecision::F64 => self.array::<f64>(QUADRATIC_ENTRIES[2], 3)?,
            ModesPrecision::F32 => {
                let (v, s) = self.array::<f32>(QUADRATIC_ENTRIES[2], 3)?;
                (v.into_iter().map(f64::from).collect(), s)
            }
        };
        Ok(Some((
            QuadraticSurface {
                edges,
                edge_to_volume,
                modes,
            },
            shape,
        )))
    }

    fn scalar<A: NpyElement + Copy>(&mut self, entry: &'static str) -> Result<A, FormatError> {
        let (v, shape) = self.parse::<A>(entry, 1024)?;
        match (shape.len(), v.first()) {
            (0, Some(&x)) => Ok(x),
            _ => Err(self.err(entry, format!("expected a scalar, found shape {shape:?}"))),
        }
    }
}
