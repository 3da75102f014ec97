//! [`StepInfo`]: counters of the last step (diagnostics).

/// What the last `step` did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepInfo {
    /// Impacts applied (impulse ≥ threshold and mapped).
    pub impacts_applied: u32,
    /// Impacts ignored because their impulse was below the threshold (or not finite).
    pub impacts_below_threshold: u32,
    /// Impacts ignored because they were farther than `max_map_distance` from the surface.
    pub impacts_unmapped: u32,
    /// Forces applied (mapped, non-zero; modal method only).
    pub forces_applied: u32,
    /// Forces ignored (unmapped, or the attenuation method, which has no force input).
    pub forces_ignored: u32,
    /// Resting contacts mapped (or re-mapped) this step (cache misses).
    pub contacts_mapped_now: u32,
    /// Resting contacts beyond `max_map_distance` (zero response).
    pub contacts_unmapped: u32,
    /// Heat-method distance fields computed this step (attenuation cache misses).
    pub distance_fields_computed: u32,
    /// The filter bank was asleep (carry-over mode): no work, zero output.
    pub asleep: bool,
    /// Resting contacts whose response came from the transfer table ([`crate::Method::Transfer`]).
    pub contacts_by_table: u32,
    /// Resting contacts a [`crate::Method::Transfer`] response served with the modal method
    /// instead of its table this step (why: `table_fallback`).
    pub contacts_table_fallback: u32,
    /// Why the table did not serve (some of) this step's contacts; `None` when it served all
    /// of them or was not requested.
    pub table_fallback: Option<TableFallback>,
}

/// Why a [`crate::Method::Transfer`] response fell back to the modal method in a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableFallback {
    /// The table does not apply to this response at all (see
    /// [`crate::DistantResponse::table_status`]); every contact is modal.
    Unavailable,
    /// The step has a force input (the table holds impulse responses only); every contact is
    /// modal.
    Forces,
    /// An applied impact lies outside the table's region; every contact is modal.
    ImpactOutsideRegion,
    /// Some resting contacts lie outside the table's region; those are modal.
    ContactsOutsideRegion,
}
