//! The world's part of the lateral kick (paper §5.4): the tangential velocity change a response
//! asks for at a resting contact, issued after the normal part by the same Gauss–Seidel rule.
//! See [`DcrWorld`](super::DcrWorld)'s documentation, "Lateral kick".

use crate::math::{add, cross, dot, mat_vec, norm, scale};
use crate::response::effective_mass;
use crate::world::BodyState;

/// `j` plus the tangential impulse `m_eff,t (g |Δv_t| − a_t) t̂` (N·s, world) for the lateral
/// velocity change `lateral` (m/s, world, non-zero) at arm `r` (m, from body `b`'s centre of
/// mass): `a_t` is what the impulses already issued to `b` this step (its velocity changes
/// `dlin`, m/s, and `dang`, rad/s) and the normal part `j` produce along
/// `t̂ = lateral / |lateral|`, `m_eff,t` Eq. 17's effective mass along `t̂`.
/// Returns `j` unchanged when that is already reached or the body is immovable.
#[inline]
pub(super) fn add_lateral_impulse(
    j: [f64; 3],
    lateral: [f64; 3],
    gain: f64,
    b: &BodyState,
    r: [f64; 3],
    dlin: [f64; 3],
    dang: [f64; 3],
) -> [f64; 3] {
    let mag = norm(lateral);
    let dir = scale(lateral, 1.0 / mag);
    let jv = scale(j, b.inv_mass);
    let jw = mat_vec(&b.inv_inertia, cross(r, j));
    let achieved = dot(add(add(dlin, jv), cross(add(dang, jw), r)), dir);
    let want = gain * mag - achieved;
    let m_eff = effective_mass(b.inv_mass, b.inv_inertia, r, dir);
    if want > 0.0 && m_eff > 0.0 {
        add(j, scale(dir, m_eff * want))
    } else {
        j
    }
}
