//! Mapping engine contacts onto the model surface (paper §4.2): a per-object cache of resting
//! contacts keyed by the caller's stable id, holding the BVH mapping and the contact's modal
//! row `w_c = nᵀ Σ_i b_i U_i`, so a resting contact costs one hash lookup per step.

mod contact_cache;
mod id_hasher;

pub use contact_cache::{CachedContact, ContactCache};
pub(crate) use id_hasher::BuildIdHasher;
