//! Eq. 17–19: a body's effective mass at a contact, and the impulse that gives it a velocity
//! change. The one definition the world, the engine adapters and the tools use.

use crate::math::cross;

/// Inverse effective mass (1/kg) of a body at a contact along unit direction `n` (Eq. 17):
/// `m⁻¹ + (r × n)ᵀ I⁻¹ (r × n)`, summed term by term in row-major order.
///
/// `inv_mass` in 1/kg, `inv_inertia_world` the world-frame inverse inertia tensor
/// (1/(kg·m²), row-major), `r` = contact point − centre of mass (m), `n` unit; `r`, `n` and the
/// tensor in one frame (the world's for the world API). Zero for an immovable body.
///
/// ```
/// use dcr_runtime::response::{effective_mass, inverse_effective_mass};
/// // A 2 kg body with inverse inertia 3 /(kg·m²) hit 0.1 m off its centre, sideways.
/// let i = [[3.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 3.0]];
/// let k = inverse_effective_mass(0.5, i, [0.1, 0.0, 0.0], [0.0, 1.0, 0.0]);
/// assert!((k - (0.5 + 0.1 * 0.1 * 3.0)).abs() < 1e-15);
/// assert_eq!(effective_mass(0.5, i, [0.1, 0.0, 0.0], [0.0, 1.0, 0.0]), 1.0 / k);
/// ```
pub fn inverse_effective_mass(
    inv_mass: f64,
    inv_inertia_world: [[f64; 3]; 3],
    r: [f64; 3],
    n: [f64; 3],
) -> f64 {
    let rn = cross(r, n);
    let mut quad = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            quad += rn[i] * inv_inertia_world[i][j] * rn[j];
        }
    }
    inv_mass + quad
}

/// Effective mass (kg) of a body at a contact along unit normal `n` (Eq. 17):
/// `1 / (m⁻¹ + (r × n)ᵀ I⁻¹ (r × n))`, the inverse of [`inverse_effective_mass`] (same
/// arguments and units). Returns 0 for an immovable body (zero inverse mass and inertia): there
/// is nothing to push.
pub fn effective_mass(
    inv_mass: f64,
    inv_inertia_world: [[f64; 3]; 3],
    r: [f64; 3],
    n: [f64; 3],
) -> f64 {
    let denom = inverse_effective_mass(inv_mass, inv_inertia_world, r, n);
    if denom > 0.0 && denom.is_finite() {
        1.0 / denom
    } else {
        0.0
    }
}

/// Impulse (N·s, same frame as `n`) giving a body of effective mass `m_eff` (kg) the velocity
/// change `delta_v` (m/s) along unit `n` (Eq. 18; Eq. 19 when `delta_v = s Δx_c / h`).
pub fn response_impulse(m_eff: f64, delta_v: f64, n: [f64; 3]) -> [f64; 3] {
    let s = m_eff * delta_v;
    [s * n[0], s * n[1], s * n[2]]
}
