//! [`BodyState`]: what the world needs to know about a body that may receive a response.

/// A dynamic (or kinematic) body of the engine after the step, world frame.
///
/// Give one per body that touches an elastic object: the bodies resting on elastic objects
/// receive the responses (their mass properties turn Δv into impulses, Eq. 17–18), and the
/// velocities of both bodies of an impact give the energy it dissipated (the energy bound).
/// A body id absent from the list is immovable and at rest (static ground, walls); a body with
/// zero inverse mass and inertia (kinematic) never receives a response.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct BodyState {
    /// Engine id of the body (as in [`crate::ContactReport::body1`]).
    pub id: u64,
    /// Inverse mass (1/kg); 0 for a kinematic or static body.
    pub inv_mass: f64,
    /// Inverse inertia tensor in the world frame (1/(kg·m²)), symmetric, row-major.
    pub inv_inertia: [[f64; 3]; 3],
    /// Centre of mass (m, world frame).
    pub center_of_mass: [f64; 3],
    /// Linear velocity of the centre of mass after the step (m/s, world frame).
    pub linvel: [f64; 3],
    /// Angular velocity after the step (rad/s, world frame).
    pub angvel: [f64; 3],
}

impl BodyState {
    /// An immovable body at rest (zero inverse mass and inertia) with id `id`.
    pub fn fixed(id: u64) -> BodyState {
        BodyState {
            id,
            inv_mass: 0.0,
            inv_inertia: [[0.0; 3]; 3],
            center_of_mass: [0.0; 3],
            linvel: [0.0; 3],
            angvel: [0.0; 3],
        }
    }

    /// Whether the body can be pushed (non-zero inverse mass or inertia).
    pub fn is_dynamic(&self) -> bool {
        self.inv_mass > 0.0 || self.inv_inertia.iter().flatten().any(|&x| x != 0.0)
    }
}
