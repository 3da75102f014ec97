//! [`RestingContact`]: an existing contact that may receive a distant response.

/// An existing (resting) contact of another body on this object.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct RestingContact {
    /// The caller's stable contact id (mapping and rows are cached under it).
    pub id: u64,
    /// Contact point (m, object frame).
    pub point: [f64; 3],
}
