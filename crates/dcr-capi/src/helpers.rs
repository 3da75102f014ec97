//! Eq. 17–18 helpers for callers of the per-object query: effective mass and response impulse.

use dcr_runtime::response::{effective_mass, response_impulse};

use crate::guard::guard;
use crate::ptr::{arg_slice, read_vec3, write_out};
use crate::status::{DcrStatus, Failure};

/// Effective mass (kg) of a body at a contact along unit normal `n` (Eq. 17):
/// `1 / (m⁻¹ + (r × n)ᵀ I⁻¹ (r × n))`, written to `*out`.
///
/// `inv_mass` (1/kg, ≥ 0); `inv_inertia` 9 doubles, the world-frame inverse inertia tensor
/// (1/(kg·m²)) row-major; `r` 3 doubles, contact point − centre of mass (m, world frame); `n`
/// 3 doubles, unit normal (world frame). 0 for an immovable body (zero inverse mass and
/// inertia). Rotate an object-frame `DcrContactResponse.normal` to the world frame first.
///
/// # Errors
/// `DCR_STATUS_INVALID_ARGUMENT` for a negative or non-finite `inv_mass`, or a non-finite
/// element of `inv_inertia`, `r` or `n`; `DCR_STATUS_NULL_POINTER`.
///
/// # Safety
/// `inv_inertia` must be NULL or 9 readable doubles; `r`, `n` NULL or 3 readable doubles;
/// `out` NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dcr_effective_mass(
    inv_mass: f64,
    inv_inertia: *const f64,
    r: *const f64,
    n: *const f64,
    out: *mut f64,
) -> DcrStatus {
    guard("dcr_effective_mass", || {
        if !(inv_mass >= 0.0 && inv_mass.is_finite()) {
            return Err(Failure::invalid(format!(
                "`inv_mass` is {inv_mass} 1/kg (must be finite and ≥ 0)"
            )));
        }
        // SAFETY: caller contract (9 readable doubles; NULL is checked).
        let i = unsafe { arg_slice(inv_inertia, 9, "inv_inertia")? };
        check_finite(i, "inv_inertia", "1/(kg·m²)")?;
        let inv_inertia = [[i[0], i[1], i[2]], [i[3], i[4], i[5]], [i[6], i[7], i[8]]];
        // SAFETY: caller contract (3 readable doubles each; NULL is checked).
        let (r, n) = unsafe { (read_vec3(r, "r")?, read_vec3(n, "n")?) };
        check_finite(&r, "r", "m")?;
        check_finite(&n, "n", "")?;
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, effective_mass(inv_mass, inv_inertia, r, n), "out") }
    })
}

/// Impulse (N·s, 3 doubles written to `out`, the frame of `n`) giving a body of effective mass
/// `m_eff` (kg) the velocity change `delta_v` (m/s) along unit `n` (Eq. 18): `m_eff · delta_v ·
/// n`. Apply it at the contact point with the engine's apply-impulse-at-point.
///
/// # Errors
/// `DCR_STATUS_INVALID_ARGUMENT` for a negative or non-finite `m_eff`, a non-finite `delta_v`
/// or a non-finite element of `n`; `DCR_STATUS_NULL_POINTER` for a NULL `n` or `out`.
///
/// # Safety
/// `n` must be NULL or 3 readable doubles; `out` NULL or 3 writable doubles.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_impulse(
    m_eff: f64,
    delta_v: f64,
    n: *const f64,
    out: *mut f64,
) -> DcrStatus {
    guard("dcr_response_impulse", || {
        if !(m_eff >= 0.0 && m_eff.is_finite()) {
            return Err(Failure::invalid(format!(
                "`m_eff` is {m_eff} kg (must be finite and ≥ 0)"
            )));
        }
        if !delta_v.is_finite() {
            return Err(Failure::invalid(format!(
                "`delta_v` is {delta_v} m/s (must be finite)"
            )));
        }
        // SAFETY: caller contract (3 readable doubles; NULL is checked).
        let n = unsafe { read_vec3(n, "n")? };
        check_finite(&n, "n", "")?;
        let j = response_impulse(m_eff, delta_v, n);
        crate::ptr::check_ptr(out, "out")?;
        // SAFETY: `out` is non-null and aligned (checked), 3 writable doubles per contract.
        unsafe { write_out(out.cast::<[f64; 3]>(), j, "out") }
    })
}

/// `DCR_STATUS_INVALID_ARGUMENT` unless every element of `v` is finite.
fn check_finite(v: &[f64], name: &str, unit: &str) -> Result<(), Failure> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(k) => Err(Failure::invalid(format!(
            "`{name}[{k}]` is {} {unit} (must be finite)",
            v[k]
        ))),
    }
}
