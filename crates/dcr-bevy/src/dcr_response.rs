//! [`DcrResponse`]: one response impulse, as a Bevy message.

use bevy::prelude::{Entity, Message, Vec3};

/// One distant-response impulse the plugin applied in the last physics step (a Bevy
/// [`Message`]: read it with `MessageReader<DcrResponse>`).
///
/// Written in the fixed-timestep schedule right after bevy_rapier's step, in the order the
/// world issued them; the impulse is already in the body's velocity (and in its `Velocity`
/// component after bevy_rapier's writeback). A body the response lifts off (Δv ≥ g·h along
/// the normal) also receives its *support*: an impulse `m |g| h` along the normal at its centre
/// of mass, with `delta_v` 0, which gravity takes back over the next step, so the body ends
/// that step with the response's Δv (`dcr_rapier::WorldParams::gravity`, bevy_rapier's gravity
/// through the plugin). Under [`dcr_rapier::f32::ApplyMode::MeasureOnly`]
/// the messages report what would have been applied.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct DcrResponse {
    /// The rigid-body entity receiving the impulse (a body resting on the elastic object).
    pub body: Entity,
    /// The elastic entity ([`crate::DcrElastic`]) whose response this is.
    pub object: Entity,
    /// Application point (m, world frame): the resting contact on `body` (the body's centre of
    /// mass for a support impulse).
    pub point: Vec3,
    /// Impulse (N·s, world frame): along `normal`, plus a tangential part when the object's
    /// lateral kick is on.
    pub impulse: Vec3,
    /// Unit outward normal of the elastic object at the contact (world frame): the direction
    /// the body is pushed.
    pub normal: Vec3,
    /// Velocity change this impulse gives `body` at `point` along `normal` (m/s); 0 for a
    /// support impulse.
    pub delta_v: f32,
    /// Whether the object's response was driven (in part) by chained impacts (another elastic
    /// object's response pushing this object's body).
    pub chained: bool,
}
