//! A rapier body's state as the world API's [`BodyState`].

use dcr_runtime::BodyState;

use super::rapier::prelude::RigidBody;
use super::{arr, to_f64};

/// `body`'s state after the step (world frame): inverse mass (1/kg, rapier's effective inverse
/// mass, i.e. with locked translations zeroed — the x axis is taken), world inverse inertia
/// (1/(kg·m²), locked rotations zeroed), centre of mass (m), linear (m/s) and angular (rad/s)
/// velocity.
pub(super) fn body_state(id: u64, body: &RigidBody) -> BodyState {
    let mp = body.mass_properties();
    let ii = mp.effective_world_inv_inertia;
    let (m11, m12, m13) = (to_f64(ii.m11), to_f64(ii.m12), to_f64(ii.m13));
    let (m22, m23, m33) = (to_f64(ii.m22), to_f64(ii.m23), to_f64(ii.m33));
    BodyState {
        id,
        inv_mass: to_f64(mp.effective_inv_mass.x),
        inv_inertia: [[m11, m12, m13], [m12, m22, m23], [m13, m23, m33]],
        center_of_mass: arr(body.center_of_mass()),
        linvel: arr(body.linvel()),
        angvel: arr(body.angvel()),
    }
}
