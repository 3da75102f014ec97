//! [`ContactReport`]: one contact point of the rigid-body step, as the engine reports it.

/// One contact point between two engine bodies after a rigid-body step, world frame.
///
/// Report every contact point of the step that involves an elastic object's body (others are
/// ignored cheaply), including points whose impulse is zero (engines such as rapier create
/// contacts predictively, before they carry an impulse; the classification needs to see them).
///
/// Sign convention: `normal` is the unit normal of `body1`'s surface at the contact, pointing
/// from `body1` toward `body2` (rapier's manifold normal, Box2D's `b2Manifold::normal`). The
/// step's contact impulse acts on `body2` as `+impulse · normal` and on `body1` as
/// `−impulse · normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ContactReport {
    /// Stable id of this contact point, the same while the engine tracks it from step to step
    /// (e.g. a hash of the collider pair, the sub-shapes and the manifold point index). An id
    /// that disappears from the reports and comes back later is a new contact
    /// ([`crate::world::ClassifyParams::new_after_missing_steps`]).
    pub id: u64,
    /// Engine id of the first body.
    pub body1: u64,
    /// Engine id of the second body.
    pub body2: u64,
    /// The contact point on `body1`'s surface (m, world frame, after the step).
    pub point1: [f64; 3],
    /// The contact point on `body2`'s surface (m, world frame, after the step). Engines that
    /// report one point per contact pass it in both fields.
    pub point2: [f64; 3],
    /// Unit contact normal (world frame), from `body1` toward `body2`.
    pub normal: [f64; 3],
    /// The normal impulse the solver applied at this point during the step (N·s, ≥ 0); 0 for
    /// a predictive (speculative) contact that did not touch.
    pub impulse: f64,
    /// The engine's own newness: `true` when this point carried no impulse at the engine's
    /// previous step (it did not exist, or only predictively). Rapier: the solver contact's
    /// warm-start impulse is 0; Box2D: a begin-touch event. Read only under
    /// [`crate::world::ClassifyParams::engine_newness`]; pass `false` otherwise.
    pub is_new: bool,
}
