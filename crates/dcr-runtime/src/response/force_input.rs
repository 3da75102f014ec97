//! [`ForceInput`]: a force held over the step (e.g. a shaking machine).

/// A force applied at a point, held constant over the step (zero-order hold).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceInput {
    /// Application point (m, object frame); mapped to the surface with the BVH.
    pub point: [f64; 3],
    /// Force (N, object frame) acting on this object.
    pub force: [f64; 3],
}
