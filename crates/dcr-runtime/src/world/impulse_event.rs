//! [`ImpulseEvent`]: one impulse the engine must apply after the step.

use super::ElasticHandle;
use crate::response::ServedBy;

/// An impulse the engine applies to a body at a world point, produced by an elastic object's
/// distant response (paper §4.5, Eq. 17–18). Apply it with the engine's
/// `apply_impulse_at_point` (rapier: `RigidBody::apply_impulse_at_point(impulse, point, true)`).
///
/// Events of one step are in a buffer returned by [`crate::DcrWorld::step`], valid until the
/// next step; they are ordered by elastic object (processing order, see [`crate::DcrWorld`]),
/// then by the order of the contact reports.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ImpulseEvent {
    /// Engine id of the body receiving the impulse.
    pub body: u64,
    /// Application point (m, world frame): the contact point on the receiving body.
    pub point: [f64; 3],
    /// Impulse (N·s, world frame): along `normal`, plus a tangential part when the object's
    /// lateral kick is on.
    pub impulse: [f64; 3],
    /// Unit outward normal of the elastic object at the contact (world frame): the direction
    /// the body is pushed.
    pub normal: [f64; 3],
    /// Velocity change the response asks of this impulse at `point` along `normal` (m/s): the
    /// response's Δv × the object's gain, less what earlier impulses of the step already gave
    /// the body there (one Gauss–Seidel pass), × the energy-bound scale. The impulse also
    /// carries the support compensation of [`crate::WorldParams::gravity`] when it is set, which
    /// this figure leaves out.
    pub delta_v: f64,
    /// The resting contact's id ([`crate::ContactReport::id`]).
    pub contact: u64,
    /// The elastic object whose response this is.
    pub object: ElasticHandle,
    /// Which method computed the response at this contact.
    pub served_by: ServedBy,
    /// Whether the object's response this step was driven (in part) by chained impacts:
    /// impulses this step gave the object's own body through another object's response.
    pub chained: bool,
}
