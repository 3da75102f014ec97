//! [`Impact`]: a new collision this step.

/// A new collision on this object during the step (paper §4.2: "new contacts").
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Impact {
    /// Contact point (m, object frame); mapped to the surface with the BVH.
    pub point: [f64; 3],
    /// Unit direction in which the impulse acts ON THIS OBJECT (object frame); usually −normal.
    pub direction: [f64; 3],
    /// Impulse magnitude λ (N·s, ≥ 0); below `ResponseParams::impact_threshold` it is ignored.
    pub impulse: f64,
}
