//! [`DcrModel`]: a loaded, validated `.modes` base (immutable, shared between threads).

use std::ffi::{c_char, CStr};
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use dcr_runtime::format::{FormatError, ModesFile};
use dcr_runtime::{LoadError, ModalModel};

use crate::guard::guard;
use crate::ptr::{arg_ref, arg_slice, check_len, read_vec3, write_out};
use crate::status::{DcrStatus, Failure};

/// A baked modal base, loaded and validated (opaque). Immutable: one model may serve any
/// number of responses and worlds on any number of threads at once. Created by
/// `dcr_model_load` or `dcr_model_load_bytes`, released by `dcr_model_free`; the responses and
/// worlds built on it hold their own reference, so it may be freed before them.
#[derive(Debug)]
pub struct DcrModel {
    pub(crate) model: Arc<ModalModel>,
}

/// Sizes and scalars of a model (`dcr_model_info`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrModelInfo {
    /// Number of modes m.
    pub num_modes: usize,
    /// Number of surface vertices.
    pub num_surface_vertices: usize,
    /// Number of surface triangles.
    pub num_surface_triangles: usize,
    /// Volume-mesh nodes fixed at bake time (0: a free-free object).
    pub num_fixed_nodes: usize,
    /// Total mass of the object (kg).
    pub mass_kg: f64,
    /// Lower corner of the surface's axis-aligned bounding box (m, object frame).
    pub bounding_box_min: [f64; 3],
    /// Upper corner of the surface's axis-aligned bounding box (m, object frame).
    pub bounding_box_max: [f64; 3],
    /// Diagonal of that box (m); 5% of it is the default mapping distance.
    pub bounding_box_diagonal_m: f64,
    /// The base's Rayleigh damping: α0 (1/s), α1 (s), with D = α0 M + α1 K.
    pub rayleigh: [f64; 2],
    /// Whether the base carries a bake-time peak-transfer table (`modal-bake bake
    /// --transfer-h`).
    pub has_transfer_table: bool,
    /// The rigid-body step h (s) the transfer table was baked for; 0 without a table.
    pub transfer_table_h: f64,
}

/// A point projected onto a model's surface (`dcr_model_project`), object frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DcrSurfacePoint {
    /// The projected point (m, object frame).
    pub point: [f64; 3],
    /// Outward unit normal there (object frame): area-weighted vertex normals interpolated
    /// with the barycentric weights, normalised.
    pub normal: [f64; 3],
    /// Index of the surface triangle.
    pub triangle: u32,
    /// Barycentric weights of the triangle's three vertices (sum 1, each ≥ 0).
    pub bary: [f64; 3],
    /// Distance from the query point to `point` (m).
    pub distance: f64,
}

fn load_failure(e: LoadError) -> Failure {
    let status = match &e {
        LoadError::Format(FormatError::Io { .. }) => DcrStatus::Io,
        _ => DcrStatus::InvalidBase,
    };
    Failure::new(status, e.to_string())
}

/// A path from a NUL-terminated C string (any bytes on Unix; UTF-8 elsewhere).
fn c_path(path: &CStr) -> Result<PathBuf, Failure> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(PathBuf::from(std::ffi::OsStr::from_bytes(path.to_bytes())))
    }
    #[cfg(not(unix))]
    {
        path.to_str()
            .map(PathBuf::from)
            .map_err(|e| Failure::invalid(format!("`path` is not UTF-8: {e}")))
    }
}

/// Loads and validates a `.modes` file and builds its surface BVH.
///
/// `path`: NUL-terminated file path (bytes on Unix, UTF-8 elsewhere). On success `*out`
/// receives a new model (free it with `dcr_model_free`); on failure `*out` is set to NULL.
///
/// # Errors
/// `DCR_STATUS_IO` when the file cannot be read (the message names it and the OS error);
/// `DCR_STATUS_INVALID_BASE` when it is not a valid base (the message names the file and the
/// entry or value at fault); `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_model_load(path: *const c_char, out: *mut *mut DcrModel) -> DcrStatus {
    guard("dcr_model_load", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, std::ptr::null_mut(), "out")? };
        // SAFETY: non-null is checked by arg_ref; the caller guarantees NUL termination.
        let path = unsafe { CStr::from_ptr(arg_ref(path, "path")?) };
        let path = c_path(path)?;
        let model = ModalModel::load(&path).map_err(load_failure)?;
        let handle = Box::into_raw(Box::new(DcrModel { model }));
        // SAFETY: `out` was checked above.
        unsafe { out.write(handle) };
        Ok(())
    })
}

/// Loads and validates a `.modes` base from `len` bytes in memory (e.g. a game's asset
/// archive); messages name it `<memory>`. The bytes are copied: the caller may free them after
/// the call. On success `*out` receives a new model; on failure `*out` is set to NULL.
///
/// # Errors
/// `DCR_STATUS_INVALID_BASE` when the bytes are not a valid base; `DCR_STATUS_NULL_POINTER`
/// for a NULL `out`, or a NULL `data` with `len` > 0.
///
/// # Safety
/// `data` must point to `len` readable bytes (or be anything when `len` is 0); `out` NULL or
/// valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_model_load_bytes(
    data: *const u8,
    len: usize,
    out: *mut *mut DcrModel,
) -> DcrStatus {
    guard("dcr_model_load_bytes", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, std::ptr::null_mut(), "out")? };
        // SAFETY: caller contract: `len` readable bytes.
        let bytes = unsafe { arg_slice(data, len, "data")? };
        let name = Path::new("<memory>");
        let base = ModesFile::read_from(Cursor::new(bytes), name)
            .map_err(|e| load_failure(LoadError::Format(e)))?;
        let model = Arc::new(ModalModel::from_base(base).map_err(load_failure)?);
        let handle = Box::into_raw(Box::new(DcrModel { model }));
        // SAFETY: `out` was checked above.
        unsafe { out.write(handle) };
        Ok(())
    })
}

/// Releases a model handle (NULL is a no-op). Responses and worlds built on it keep their own
/// reference and stay valid.
///
/// # Safety
/// `model` must be NULL or a handle from `dcr_model_load*` not freed before.
#[no_mangle]
pub unsafe extern "C" fn dcr_model_free(model: *mut DcrModel) {
    if model.is_null() {
        return;
    }
    let _ = std::panic::catch_unwind(|| {
        // SAFETY: a live handle from Box::into_raw (caller contract), freed once.
        drop(unsafe { Box::from_raw(model) });
    });
}

/// Fills `out` with the model's sizes, mass, bounding-box diagonal, damping and table data.
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` for a NULL argument.
///
/// # Safety
/// `model` must be NULL or a live handle; `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_model_info(
    model: *const DcrModel,
    out: *mut DcrModelInfo,
) -> DcrStatus {
    guard("dcr_model_info", || {
        // SAFETY: caller contract (NULL is checked).
        let m = unsafe { &arg_ref(model, "model")?.model };
        let b = m.base();
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &b.surface_vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let info = DcrModelInfo {
            num_modes: m.num_modes(),
            num_surface_vertices: m.num_vertices(),
            num_surface_triangles: b.surface_triangles.len(),
            num_fixed_nodes: b.fixed_nodes.len(),
            mass_kg: b.meta.mass_kg,
            bounding_box_min: lo,
            bounding_box_max: hi,
            bounding_box_diagonal_m: m.bounding_box_diagonal(),
            rayleigh: b.rayleigh,
            has_transfer_table: b.transfer.is_some(),
            transfer_table_h: b.transfer.as_ref().map_or(0.0, |t| t.h),
        };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, info, "out") }
    })
}

/// Copies the model's undamped natural frequencies f_j = ω_j / 2π (Hz, ascending) into
/// `out_hz`, which holds `capacity` doubles. `*count` receives the number of modes m whatever
/// the outcome.
///
/// # Errors
/// `DCR_STATUS_BUFFER_TOO_SMALL` when `capacity` < m (nothing is written; call again with
/// `*count` doubles); `DCR_STATUS_NULL_POINTER` for a NULL `model` or `count`, or a NULL
/// `out_hz` with `capacity` ≥ m > 0.
///
/// # Safety
/// `model` must be NULL or a live handle; `out_hz` must point to `capacity` writable doubles
/// (or be NULL); `count` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_model_frequencies(
    model: *const DcrModel,
    out_hz: *mut f64,
    capacity: usize,
    count: *mut usize,
) -> DcrStatus {
    guard("dcr_model_frequencies", || {
        // SAFETY: caller contract (NULL is checked).
        let m = unsafe { &arg_ref(model, "model")?.model };
        let omega = m.omega();
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(count, omega.len(), "count")? };
        if capacity < omega.len() {
            return Err(Failure::new(
                DcrStatus::BufferTooSmall,
                format!(
                    "`capacity` is {capacity} but the model has {} modes",
                    omega.len()
                ),
            ));
        }
        if omega.is_empty() {
            return Ok(());
        }
        crate::ptr::check_ptr(out_hz, "out_hz")?;
        check_len::<f64>(omega.len(), "out_hz")?;
        for (j, w) in omega.iter().enumerate() {
            // SAFETY: out_hz is non-null, aligned and holds capacity ≥ m doubles.
            unsafe { out_hz.add(j).write(w / (2.0 * std::f64::consts::PI)) };
        }
        Ok(())
    })
}

/// Projects `point` (3 doubles, m, object frame) onto the model's surface: the nearest surface
/// point, its outward normal, triangle and barycentric weights, written to `out`.
///
/// `max_distance` (m): farthest the point may be from the surface; NaN selects the default
/// mapping distance of a response, 5% of the bounding-box diagonal; +∞ accepts any point.
///
/// # Errors
/// `DCR_STATUS_NOT_FOUND` when the point is farther than `max_distance` (or not finite);
/// `DCR_STATUS_INVALID_ARGUMENT` for a negative `max_distance`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `model` must be NULL or a live handle; `point` NULL or 3 readable doubles; `out` NULL or
/// valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_model_project(
    model: *const DcrModel,
    point: *const f64,
    max_distance: f64,
    out: *mut DcrSurfacePoint,
) -> DcrStatus {
    guard("dcr_model_project", || {
        // SAFETY: caller contract (NULL is checked).
        let m = unsafe { &arg_ref(model, "model")?.model };
        // SAFETY: caller contract (3 readable doubles; NULL is checked).
        let p = unsafe { read_vec3(point, "point")? };
        crate::ptr::check_ptr(out, "out")?;
        let max = if max_distance.is_nan() {
            0.05 * m.bounding_box_diagonal()
        } else {
            max_distance
        };
        if !(max >= 0.0) {
            return Err(Failure::invalid(format!(
                "`max_distance` is {max_distance} m (must be ≥ 0, or NaN for the default)"
            )));
        }
        let sp = m.project(p, max).ok_or_else(|| {
            Failure::new(
                DcrStatus::NotFound,
                format!("point {p:?} is farther than {max} m from the surface"),
            )
        })?;
        let v = DcrSurfacePoint {
            point: sp.point,
            normal: sp.normal,
            triangle: sp.triangle,
            bary: sp.bary,
            distance: sp.distance,
        };
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, v, "out") }
    })
}
