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
//! ([`crate::HeatGeodesic::plan_ordering`]); without it the runtime orders with AMD at load.
//!
//! Optional (all or none): the peak-transfer table ([`TransferTable`]): `transfer_vertices`
//! u32 (nr,), `transfer_peaks` f32 (np(np+1)/2,) packed upper triangle over np = nr + ne points
//! (m per N·s),
//! `transfer_h` f64 () (s), `transfer_rayleigh` f64 (2,), `transfer_modes` u32 (),
//! `transfer_samples` u32 (), and optionally `transfer_edges` u32 (ne, 2), `transfer_order`
//! u32 () (1, 2, 3; absent: 2 with edges, else 1) and `transfer_faces` u32 (nf, 3) (order 3).
//! Readers that predate the table ignore these entries.
//!
//! Files are written deterministically (fixed zip timestamps, fixed entry order, stored) and
//! atomically (temporary file in the target directory, then rename).

use std::fs::File;
use std::io::{Cursor, Read, Seek, Write};
use std::path::{Path, PathBuf};

use ndarray::{Array0, Array1, Array2, Array3, ArrayD};
use ndarray_npy::npy::header::Header;
use ndarray_npy::{NpzWriter, ReadNpyExt, ReadableElement};
use serde::{Deserialize, Serialize};

use super::transfer_table::{
    TransferTable, TRANSFER_EDGES_ENTRY, TRANSFER_ENTRIES, TRANSFER_FACES_ENTRY,
    TRANSFER_ORDER_ENTRY,
};

/// Current `.modes` schema version.
pub const FORMAT_VERSION: u32 = 1;

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
    /// Schema version (same as the `format_version` entry).
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
    /// The file was written by an incompatible schema version.
    #[error("{path}: format version {found} is not supported (this build reads version {FORMAT_VERSION})")]
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

impl ModesFile {
    /// Number of modes m.
    pub fn num_modes(&self) -> usize {
        self.eigenvalues.len()
    }

    /// Number of surface vertices ns.
    pub fn num_surface_vertices(&self) -> usize {
        self.surface_vertices.len()
    }

    /// Frequencies f_j = √λ_j / 2π (Hz).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues
            .iter()
            .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect()
    }

    /// Checks shapes, index ranges, finiteness and version; `path` is used in messages.
    ///
    /// # Errors
    /// [`FormatError::Invalid`] or [`FormatError::Version`] naming what is wrong.
    pub fn validate(&self, path: &Path) -> Result<(), FormatError> {
        let inv = |detail: String| FormatError::Invalid {
            path: path.to_path_buf(),
            detail,
        };
        if self.meta.format_version != FORMAT_VERSION {
            return Err(FormatError::Version {
                path: path.to_path_buf(),
                found: self.meta.format_version,
            });
        }
        let m = self.num_modes();
        let ns = self.num_surface_vertices();
        if m == 0 {
            return Err(inv("no modes".into()));
        }
        if ns == 0 || self.surface_triangles.is_empty() {
            return Err(inv("empty surface".into()));
        }
        if self.modes.len() != ns * 3 * m {
            return Err(inv(format!(
                "modes hold {} values, expected ns×3×m = {ns}×3×{m}",
                self.modes.len()
            )));
        }
        if self.surface_to_volume.len() != ns {
            return Err(inv(format!(
                "surface_to_volume has {} entries for {ns} surface vertices",
                self.surface_to_volume.len()
            )));
        }
        if self.residuals.len() != m {
            return Err(inv(format!(
                "residuals has {} entries for {m} modes",
                self.residuals.len()
            )));
        }
        for (j, &l) in self.eigenvalues.iter().enumerate() {
            if !(l.is_finite() && l > 0.0) {
                return Err(inv(format!(
                    "eigenvalue {j} is {l} (must be finite and > 0)"
                )));
            }
            if j > 0 && l < self.eigenvalues[j - 1] {
                return Err(inv(format!("eigenvalues not ascending at mode {j}")));
            }
        }
        if let Some(i) = self.modes.iter().position(|x| !x.is_finite()) {
            return Err(inv(format!(
                "non-finite mode value at vertex {}, axis {}, mode {}",
                i / (3 * m),
                (i / m) % 3,
                i % m
            )));
        }
        if let Some(v) = self
            .surface_vertices
            .iter()
            .position(|p| p.iter().any(|x| !x.is_finite()))
        {
            return Err(inv(format!("non-finite position of surface vertex {v}")));
        }
        if let Some((t, _)) = self
            .surface_triangles
            .iter()
            .enumerate()
            .find(|(_, tri)| tri.iter().any(|&i| i as usize >= ns))
        {
            return Err(inv(format!("surface triangle {t} names a vertex ≥ {ns}")));
        }
        let MaterialSi {
            youngs,
            poisson,
            density,
        } = self.material;
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(youngs) && positive(density) && poisson > -1.0 && poisson < 0.5) {
            return Err(inv(format!(
                "material out of range: E={youngs} ν={poisson} ρ={density}"
            )));
        }
        if !self.rayleigh.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(inv(format!(
                "rayleigh coefficients {:?} must be finite and ≥ 0",
                self.rayleigh
            )));
        }
        if let Some(t) = &self.transfer {
            t.check(ns).map_err(inv)?;
        }
        if let Some(order) = &self.surface_order {
            if order.len() != ns {
                return Err(inv(format!(
                    "surface_order has {} entries for {ns} surface vertices",
                    order.len()
                )));
            }
            let mut seen = vec![false; ns];
            for (k, &v) in order.iter().enumerate() {
                if v as usize >= ns || std::mem::replace(&mut seen[v as usize], true) {
                    return Err(inv(format!(
                        "surface_order is not a permutation: entry {k} is {v} (repeated or ≥ {ns})"
                    )));
                }
            }
        }
        Ok(())
    }

    /// Writes the base to `path` atomically and deterministically (same content → same bytes).
    ///
    /// The data is written to a temporary file beside `path`, synced, then renamed over it; on
    /// any error the temporary file is removed and `path` is left untouched.
    ///
    /// # Errors
    /// [`FormatError::Invalid`] if the content fails [`ModesFile::validate`]; I/O errors.
    pub fn write_atomic(&self, path: &Path) -> Result<(), FormatError> {
        self.validate(path)?;
        let io = |source| FormatError::Io {
            path: path.to_path_buf(),
            source,
        };
        let bytes = self.to_bytes().map_err(|detail| FormatError::Archive {
            path: path.to_path_buf(),
            detail,
        })?;
        let dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
        let result = (|| {
            let mut f = File::create(&tmp)?;
            f.write_all(&bytes)?;
            f.sync_all()?;
            std::fs::rename(&tmp, path)
        })();
        if let Err(e) = result {
            let _ = std::fs::remove_file(&tmp);
            return Err(io(e));
        }
        Ok(())
    }

    /// Serialises the archive to bytes (deterministic).
    pub(crate) fn to_bytes(&self) -> Result<Vec<u8>, String> {
        let m = self.num_modes();
        let ns = self.num_surface_vertices();
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .last_modified_time(zip::DateTime::default());
        let mut npz = NpzWriter::new_with_options(Cursor::new(Vec::new()), opts);
        let e = |err: ndarray_npy::WriteNpzError| err.to_string();
        let tri: Vec<u32> = self.surface_triangles.iter().flatten().copied().collect();
        let pos: Vec<f64> = self.surface_vertices.iter().flatten().copied().collect();
        let meta = serde_json::to_vec(&self.meta).map_err(|err| err.to_string())?;
        npz.add_array("format_version", &Array0::from_elem((), FORMAT_VERSION))
            .map_err(e)?;
        npz.add_array("eigenvalues", &Array1::from(self.eigenvalues.clone()))
            .map_err(e)?;
        npz.add_array("frequencies_hz", &Array1::from(self.frequencies_hz()))
            .map_err(e)?;
        npz.add_array(
            "surface_vertices",
            &Array2::from_shape_vec((ns, 3), pos).map_err(|x| x.to_string())?,
        )
        .map_err(e)?;
        npz.add_array(
            "surface_triangles",
            &Array2::from_shape_vec((self.surface_triangles.len(), 3), tri)
                .map_err(|x| x.to_string())?,
        )
        .map_err(e)?;
        npz.add_array(
            "surface_to_volume",
            &Array1::from(self.surface_to_volume.clone()),
        )
        .map_err(e)?;
        match self.precision {
            ModesPrecision::F64 => npz.add_array(
                "modes",
                &Array3::from_shape_vec((ns, 3, m), self.modes.clone())
                    .map_err(|x| x.to_string())?,
            ),
            ModesPrecision::F32 => npz.add_array(
                "modes",
                &Array3::from_shape_vec((ns, 3, m), self.modes.iter().map(|&x| x as f32).collect())
                    .map_err(|x| x.to_string())?,
            ),
        }
        .map_err(e)?;
        let mat = &self.material;
        npz.add_array(
            "material",
            &Array1::from(vec![mat.youngs, mat.poisson, mat.density]),
        )
        .map_err(e)?;
        npz.add_array("rayleigh", &Array1::from(self.rayleigh.to_vec()))
            .map_err(e)?;
        npz.add_array("fixed_nodes", &Array1::from(self.fixed_nodes.clone()))
            .map_err(e)?;
        npz.add_array("residuals", &Array1::from(self.residuals.clone()))
            .map_err(e)?;
        npz.add_array("meta", &Array1::from(meta)).map_err(e)?;
        if let Some(order) = &self.surface_order {
            npz.add_array("surface_order", &Array1::from(order.clone()))
                .map_err(e)?;
        }
        if let Some(t) = &self.transfer {
            npz.add_array("transfer_vertices", &Array1::from(t.vertices.clone()))
                .map_err(e)?;
            npz.add_array("transfer_peaks", &Array1::from(t.peaks.clone()))
                .map_err(e)?;
            npz.add_array("transfer_h", &Array0::from_elem((), t.h))
                .map_err(e)?;
            npz.add_array("transfer_rayleigh", &Array1::from(t.rayleigh.to_vec()))
                .map_err(e)?;
            npz.add_array("transfer_modes", &Array0::from_elem((), t.modes))
                .map_err(e)?;
            npz.add_array("transfer_samples", &Array0::from_elem((), t.samples))
                .map_err(e)?;
            let edges: Vec<u32> = t.edges.iter().flatten().copied().collect();
            npz.add_array(
                TRANSFER_EDGES_ENTRY,
                &Array2::from_shape_vec((t.edges.len(), 2), edges).map_err(|x| x.to_string())?,
            )
            .map_err(e)?;
            // Only when it differs from what a reader infers (2 with edges, else 1), so that
            // order-1 and order-2 files keep the bytes of readers that predate the entry.
            if t.order != if t.edges.is_empty() { 1 } else { 2 } {
                npz.add_array(
                    TRANSFER_ORDER_ENTRY,
                    &Array0::from_elem((), u32::from(t.order)),
                )
                .map_err(e)?;
                let faces: Vec<u32> = t.faces.iter().flatten().copied().collect();
                npz.add_array(
                    TRANSFER_FACES_ENTRY,
                    &Array2::from_shape_vec((t.faces.len(), 3), faces)
                        .map_err(|x| x.to_string())?,
                )
                .map_err(e)?;
            }
        }
        Ok(npz.finish().map_err(e)?.into_inner())
    }

    /// Reads and validates a `.modes` file.
    ///
    /// Never trusts sizes declared in the file: every entry is bounded by its real length.
    ///
    /// # Errors
    /// A [`FormatError`] naming the file and the entry or value at fault.
    pub fn read(path: &Path) -> Result<ModesFile, FormatError> {
        let file = File::open(path).map_err(|source| FormatError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::read_from(std::io::BufReader::new(file), path)
    }

    /// Reads and validates a `.modes` archive from any seekable reader; `path` names it in errors.
    ///
    /// # Errors
    /// As [`ModesFile::read`].
    pub fn read_from<R: Read + Seek>(reader: R, path: &Path) -> Result<ModesFile, FormatError> {
        let mut zip = zip::ZipArchive::new(reader).map_err(|err| FormatError::Archive {
            path: path.to_path_buf(),
            detail: err.to_string(),
        })?;
        let mut rd = EntryReader {
            zip: &mut zip,
            path,
        };
        let version: u32 = rd.scalar("format_version")?;
        if version != FORMAT_VERSION {
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
        };
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

/// Bounded reads of single `.npy` entries from the archive.
struct EntryReader<'a, R: Read + Seek> {
    zip: &'a mut zip::ZipArchive<R>,
    path: &'a Path,
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
    fn parse<A: ReadableElement>(
        &mut self,
        entry: &'static str,
        cap: u64,
    ) -> Result<(Vec<A>, Vec<usize>), FormatError> {
        let buf = self.bytes(entry, cap)?;
        let mut cur = Cursor::new(&buf[..]);
        let header = Header::from_reader(&mut cur)
            .map_err(|err| self.err(entry, format!("bad .npy header: {err}")))?;
        let elem = std::mem::size_of::<A>();
        let descr = header.type_descriptor.to_string();
        let descr_size = descr
            .trim_matches(|c| c == '\'' || c == '"')
            .trim_start_matches(|c: char| !c.is_ascii_digit())
            .parse::<usize>()
            .ok();
        if descr_size != Some(elem) {
            return Err(self.err(entry, format!("unexpected dtype {descr}")));
        }
        let declared = header
            .shape
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .and_then(|n| n.checked_mul(elem));
        let remaining = buf.len() - cur.position() as usize;
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
        if header.layout.is_fortran() && header.shape.len() > 1 {
            return Err(self.err(entry, "Fortran-ordered arrays are not supported"));
        }
        let arr = ArrayD::<A>::read_npy(&buf[..]).map_err(|err| match err {
            ndarray_npy::ReadNpyError::WrongDescriptor(d) => {
                self.err(entry, format!("unexpected dtype {d}"))
            }
            other => self.err(entry, other.to_string()),
        })?;
        let shape = arr.shape().to_vec();
        Ok((arr.into_raw_vec_and_offset().0, shape))
    }

    fn array<A: ReadableElement>(
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

    fn vector<A: ReadableElement>(
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

    fn scalar<A: ReadableElement + Copy>(&mut self, entry: &'static str) -> Result<A, FormatError> {
        let (v, shape) = self.parse::<A>(entry, 1024)?;
        match (shape.len(), v.first()) {
            (0, Some(&x)) => Ok(x),
            _ => Err(self.err(entry, format!("expected a scalar, found shape {shape:?}"))),
        }
    }
}
