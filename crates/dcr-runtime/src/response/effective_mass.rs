//! Eq. 17–19: turning a desired normal velocity change into an impulse on the resting body.

use crate::math::cross;

/// Effective mass (kg) of a body at a contact along unit normal `n` (Eq. 17):
/// `1 / (m⁻¹ + (r × n)ᵀ I⁻¹ (r × n))`.
///
/// `inv_mass` in 1/kg, `inv_inertia_world` the world-frame inverse inertia tensor (1/(kg·m²)),
/// `r` = contact point − centre of mass (m, world), `n` unit (world). Returns 0 for an
/// immovable body (zero inverse mass and inertia): there is nothing to push.
pub fn effective_mass(
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
    let denom = inv_mass + quad;
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
