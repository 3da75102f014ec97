//! [`WorldError`]: set-up errors of a [`crate::DcrWorld`] (never per step).

use crate::response::ParamsError;

/// Invalid world parameters, elastic-object definitions or handles, reported by
/// [`crate::DcrWorld::new`], [`crate::DcrWorld::add_object`], [`crate::DcrWorld::set_h`] and the
/// run-time setters ([`crate::DcrWorld::remove_object`], [`crate::DcrWorld::set_enabled`], …).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WorldError {
    /// A world parameter is out of range.
    #[error("invalid world parameter {field}: {detail}")]
    Params {
        /// Parameter name.
        field: &'static str,
        /// What is wrong, with the value.
        detail: String,
    },
    /// An elastic-object field other than its response parameters is out of range.
    #[error("elastic object on body {body}: invalid {field}: {detail}")]
    Object {
        /// Engine body id of the object.
        body: u64,
        /// Field name.
        field: &'static str,
        /// What is wrong, with the value.
        detail: String,
    },
    /// The object's response could not be set up (parameters, transfer-table policy, heat
    /// geodesics).
    #[error("elastic object on body {body}: {source}")]
    Response {
        /// Engine body id of the object.
        body: u64,
        /// Why.
        source: ParamsError,
    },
    /// Another elastic object already uses this engine body.
    #[error("body {body} already carries elastic object {existing}")]
    DuplicateBody {
        /// Engine body id.
        body: u64,
        /// Index of the object already on it.
        existing: u32,
    },
    /// The handle is not an object of this world: removed (stale: its slot's generation moved
    /// on) or never issued.
    #[error("elastic object {handle} does not exist: {why}")]
    StaleHandle {
        /// The handle given.
        handle: super::ElasticHandle,
        /// Why (removed, or the slot index is past the world's slots).
        why: &'static str,
    },
}
