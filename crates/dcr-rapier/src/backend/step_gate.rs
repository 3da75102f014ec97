//! [`StepGate`]: on which steps the contacts are read in full and the world stepped.

/// When [`super::DcrRapier::after_step`] reads the contacts in full and steps the world.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StepGate {
    /// Every step: every contact of the elastic objects is read and the world stepped, which
    /// classifies with its own rules (contact ages, [`dcr_runtime::world::ClassifyParams`]). The
    /// simplest contract; its cost grows with the resting contacts on every step.
    EveryStep,
    /// Only on the steps where a contact is an impact (plus the world's settle window and the
    /// steps on which a response still rings); the others only count
    /// ([`dcr_runtime::DcrWorld::advance`]). Every step a light pass reads each solver
    /// contact's normal impulse and records which points carry one; a point is *new* when it
    /// carried none at the previous step, and a new point at or above its object's impact
    /// threshold makes the step an impact step. The world then classifies with this engine
    /// newness ([`dcr_runtime::world::ClassifyParams::engine_newness`]), so it needs no history of its
    /// own. Same impacts as the world's age rules wherever a contact's first loaded step is
    /// within their fresh window. The default.
    #[default]
    ImpactSteps,
}
