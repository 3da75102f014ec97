//! [`ApplyMode`]: how the world's impulse events reach rapier's bodies.

/// How [`super::DcrRapier`] applies the distant responses (paper §3 and §4.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ApplyMode {
    /// Right after the step that saw the impact: each event's impulse (Eq. 17–18, the effective
    /// mass of the receiving body at the contact × Δv, one Gauss–Seidel pass per body inside the
    /// world) is applied with `RigidBody::apply_impulse_at_point`. The bodies leave the contact
    /// during the next step with the requested separation velocity. The default: the response
    /// is in the velocities at once, for any rapier configuration, with no hook and no effect
    /// on contact recycling.
    #[default]
    AfterStep,
    /// Inside the next step's solver (the paper's "add Δv to b" of Eq. 2): rapier's contact
    /// solver has no unbiased separation-velocity input except its restitution pass, so the
    /// events of step N are replayed in step N+1 as a bounce: before the step each receiving
    /// body gets the reverse of its normal impulse (its contact points approach the surface at
    /// the requested Δv), and [`super::DcrSolverHooks`] sets restitution 1 on those contact
    /// manifolds, so the solver's end-of-step restitution pass sends them off at Δv with the
    /// solver's own effective masses. The lateral kick goes through the manifold's
    /// `tangent_velocity` (a friction-limited velocity target). The support of a lifted body
    /// ([`super::DcrRapier::set_gravity`]) is replayed with its response. Needs the hooks
    /// passed to `step` and [`super::DcrRapier::before_step`]; see docs/engine-integration.md
    /// for the source references and the one-step lag.
    InSolver,
    /// Classify, query and account, but apply nothing (an "off" run that still measures the
    /// impacts and what the responses would have been).
    MeasureOnly,
}
