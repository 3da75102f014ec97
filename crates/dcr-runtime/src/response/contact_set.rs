//! [`ContactSet`]: the mapping step every method shares — the step's resting contacts looked
//! up in (or added to) the per-object contact cache, evicted when unseen.

use super::{prepared_vec, RestingContact, StepInfo, PREPARED_CONTACTS};
use crate::mapping::{CachedContact, ContactCache};
use crate::model::ModalModel;

/// The resting-contact cache of one response and the slots of the current step's contacts.
#[derive(Debug)]
pub(crate) struct ContactSet {
    cache: ContactCache,
    /// Cache slot of each resting contact of the step, in call order.
    slots: Vec<u32>,
    /// Mapping distance (m).
    max_map: f64,
    /// Contacts unseen for more than this many steps are evicted.
    evict_after: u32,
}

impl ContactSet {
    /// An empty set for an m-mode model, its storage sized for [`PREPARED_CONTACTS`] contacts;
    /// contacts farther than `max_map` (m) from the surface are not mapped, contacts moved
    /// farther than `remap_tolerance` (m) are mapped again, and contacts unseen for more than
    /// `evict_after` steps are evicted.
    pub fn new(m: usize, remap_tolerance: f64, max_map: f64, evict_after: u32) -> ContactSet {
        ContactSet {
            cache: ContactCache::new(m, remap_tolerance, PREPARED_CONTACTS),
            slots: prepared_vec(PREPARED_CONTACTS, 0),
            max_map,
            evict_after,
        }
    }

    /// Evicts contacts unseen for more than `evict_after` steps, then maps the step's `resting`
    /// contacts (cached ones are looked up, new or moved ones mapped); `changed(slot)` is called
    /// for every evicted or (re)mapped slot. Counts `contacts_mapped_now` and
    /// `contacts_unmapped`.
    pub fn map(
        &mut self,
        model: &ModalModel,
        resting: &[RestingContact],
        step: u64,
        info: &mut StepInfo,
        mut changed: impl FnMut(u32),
    ) {
        let max_map = self.max_map;
        self.cache
            .evict_unseen(step, self.evict_after, &mut changed);
        // Last step's slot at the same list position is tried first (contact lists repeat).
        self.slots.resize(resting.len(), u32::MAX);
        for (i, rc) in resting.iter().enumerate() {
            let (s, mapped_now) =
                self.cache
                    .lookup_with_hint(model, rc.id, rc.point, step, max_map, self.slots[i]);
            if mapped_now {
                info.contacts_mapped_now += 1;
                changed(s);
            }
            if self.cache.slot(s).surface.is_none() {
                info.contacts_unmapped += 1;
            }
            self.slots[i] = s;
        }
    }

    /// The step's slots, one per resting contact in call order.
    pub fn slots(&self) -> &[u32] {
        &self.slots
    }

    /// The cached contact in `slot`.
    pub fn slot(&self, slot: u32) -> &CachedContact {
        self.cache.slot(slot)
    }

    /// The contact row `w_c = nᵀ Σ_i b_i U_i` of `slot` (length m).
    pub fn row(&self, slot: u32) -> &[f64] {
        self.cache.row(slot)
    }

    /// Changes whenever a slot's content changes (see [`ContactCache::generation`]).
    pub fn generation(&self) -> u64 {
        self.cache.generation()
    }

    /// Number of live cached contacts.
    pub fn len(&self) -> usize {
        self.cache.len()
    }
}
