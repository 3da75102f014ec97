//! [`ContactResponse`]: what one resting contact receives this step.

/// The distant response at one resting contact for the step. `#[repr(C)]` (plain data for a C
/// boundary).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ContactResponse {
    /// The resting contact's id.
    pub id: u64,
    /// Mapped surface point (m, object frame); the query point when not mapped.
    pub point: [f64; 3],
    /// Outward surface normal (object frame): the resting body is pushed along +normal.
    /// `[0, 0, 0]` when not mapped.
    pub normal: [f64; 3],
    /// Peak normal displacement over the step (m, Eq. 11 / 13; Eq. 15 × s for attenuation).
    pub peak_displacement: f64,
    /// Velocity change along +normal (m/s, Eq. 12 / 13 / 16): `peak_displacement / h` (under
    /// [`crate::Launch::SustainedPeak`] a target for the body's normal velocity, not an
    /// increment).
    pub delta_v: f64,
    /// Tangential velocity change (m/s, object frame, ⟂ `normal`): the peak tangential
    /// displacement over the step / h, along its direction at the peak (the lateral kick,
    /// paper §5.4). `[0, 0, 0]` unless [`crate::ResponseParams::lateral_kick`].
    pub lateral_delta_v: [f64; 3],
    /// Which method produced `peak_displacement` (the modal method also serves the contacts a
    /// [`crate::Method::Transfer`] table cannot: outside its region, forces, h mismatch).
    pub served_by: ServedBy,
    /// `false`: the contact is farther than `max_map_distance` from the surface: zero response.
    pub mapped: bool,
}

/// The method that served one contact's response this step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum ServedBy {
    /// The truncated modal base (Eq. 9–13).
    #[default]
    Modal,
    /// Spatial attenuation (Eq. 14–16).
    Attenuation,
    /// The base's bake-time peak-transfer table ([`crate::format::TransferTable`]).
    TransferTable,
    /// Not mapped to the surface: zero response.
    Unmapped,
}

impl ServedBy {
    /// The method's name in reports: `modal`, `attenuation`, `transfer_table`, `unmapped`.
    pub fn name(self) -> &'static str {
        match self {
            ServedBy::Modal => "modal",
            ServedBy::Attenuation => "attenuation",
            ServedBy::TransferTable => "transfer_table",
            ServedBy::Unmapped => "unmapped",
        }
    }
}
