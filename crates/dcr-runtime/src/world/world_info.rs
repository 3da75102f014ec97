//! [`WorldStepInfo`], [`ObjectStepInfo`] and [`EnergyInfo`]: what a world step did.

use crate::response::StepInfo;

/// Counters of the last rigid-body step, all objects: the last [`crate::DcrWorld::step`], or
/// zeros (but `step`) after [`crate::DcrWorld::advance`] — summing them over steps counts each
/// event once. Running totals are in [`ObjectTotals`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WorldStepInfo {
    /// Index of the step (0 for the first call).
    pub step: u64,
    /// Contact reports that involve an elastic object's body.
    pub contacts: u32,
    /// Impacts classified from the contact reports (one per object side).
    pub impacts: u32,
    /// Chained impacts: impulses of the step given to a dynamic elastic object's body.
    pub chained_impacts: u32,
    /// Resting contacts (a dynamic body on an elastic object, impulse > 0).
    pub resting: u32,
    /// Elastic objects whose response ran this step (had impacts, or carry-over filters
    /// still ringing).
    pub queries: u32,
    /// Impulse events issued.
    pub events: u32,
    /// Impulses to a dynamic elastic object that could not chain: the object was processed
    /// earlier in the step (chains only go forward) or the chain was at
    /// [`crate::WorldParams::max_chain_depth`]. The impulse is still issued.
    pub chains_dropped: u32,
    /// Objects whose responses the energy bound scaled down this step.
    pub energy_limited: u32,
    /// Kinetic energy the responses gave the receiving bodies this step (J, all objects).
    pub injected: f64,
    /// Energy the step's impacts dissipated (J, all objects; the estimate of [`EnergyInfo`]).
    pub dissipated: f64,
}

/// The energy account of one elastic object (J). Per step: the last step's values; `total_*`:
/// sums since the object was added.
///
/// `dissipated` is estimated per impact from the post-step data (see [`crate::DcrWorld`],
/// "Energy bound"); `injected` is exact for rigid bodies: Σ over receiving bodies of
/// `P·V + ½ PᵀM⁻¹P` with P the body's summed impulse (linear and angular) from this object
/// and V its velocity before them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyInfo {
    /// Energy the step's engine impacts on this object dissipated (J, ≥ 0).
    pub dissipated: f64,
    /// Kinetic energy chained impulses gave this object's body this step (J, ≥ 0): with
    /// `dissipated`, the budget of the bound.
    pub received: f64,
    /// Kinetic energy the object's responses would have given without the bound (J).
    pub requested: f64,
    /// Kinetic energy the object's responses gave the receiving bodies (J, after scaling).
    pub injected: f64,
    /// The uniform scale the bound applied to the object's impulses (1: not limited).
    pub scale: f64,
    /// Σ `dissipated` since the object was added (J).
    pub total_dissipated: f64,
    /// Σ `received` since the object was added (J).
    pub total_received: f64,
    /// Σ `injected` since the object was added (J).
    pub total_injected: f64,
}

/// What the last rigid-body step did for one elastic object: the last
/// [`crate::DcrWorld::step`], or zeros after [`crate::DcrWorld::advance`] (the energy totals
/// `energy.total_*` are kept). Per-step counters only: summing them over steps counts each
/// impact once. Running totals since the object was added are [`ObjectTotals`]
/// ([`crate::DcrWorld::object_totals`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ObjectStepInfo {
    /// Engine impacts on the object.
    pub impacts: u32,
    /// Chained impacts on the object (impulses from other objects' responses).
    pub chained_impacts: u32,
    /// Resting contacts on the object.
    pub resting: u32,
    /// Impulse events the object's response issued.
    pub events: u32,
    /// Whether the object's response ran this step.
    pub queried: bool,
    /// Wall time of the object's response call this step (ns; 0 when it did not run). For
    /// profiling; the world's results never depend on it.
    pub response_time_ns: u64,
    /// The response's own counters for the step (zeros when it did not run): impacts applied
    /// or below threshold, contacts mapped, served by the transfer table or by its modal
    /// fallback ([`StepInfo::contacts_table_fallback`]).
    pub response: StepInfo,
    /// The energy account.
    pub energy: EnergyInfo,
}

/// Running totals of one elastic object since it was added ([`crate::DcrWorld::object_totals`]),
/// kept apart from the per-step counters of [`ObjectStepInfo`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObjectTotals {
    /// Engine impacts on the object.
    pub impacts: u64,
    /// Chained impacts on the object.
    pub chained_impacts: u64,
    /// Steps on which the object's response ran.
    pub queries: u64,
    /// Impulse events the object's response issued.
    pub events: u64,
    /// Resting contacts the response found farther than its `max_map_distance` from the
    /// surface (zero response): a contact in the wrong frame or far from the base's surface.
    pub contacts_unmapped: u64,
    /// Impacts farther than `max_map_distance` from the surface (ignored).
    pub impacts_unmapped: u64,
    /// Resting contacts a transfer-table response served with the modal method instead
    /// ([`crate::response::StepInfo::contacts_table_fallback`]).
    pub contacts_table_fallback: u64,
    /// Steps the object spent disabled ([`crate::DcrWorld::set_enabled`]).
    pub disabled_steps: u64,
}
