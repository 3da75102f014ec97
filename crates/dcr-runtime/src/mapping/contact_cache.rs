//! [`ContactCache`]: resting contacts by id → surface mapping + modal row, evicted when unseen.

use std::collections::HashMap;

use super::id_hasher::BuildIdHasher;
use crate::math::{norm, sub};
use crate::model::{ModalModel, SurfacePoint};
use crate::response::prepared_vec;

/// One cached resting contact.
#[derive(Clone, Copy, Debug)]
pub struct CachedContact {
    /// The caller's stable contact id.
    pub id: u64,
    /// The query point it was mapped from (m, object frame).
    pub query: [f64; 3],
    /// Its surface point, `None` when farther than the mapping distance (no response).
    pub surface: Option<SurfacePoint>,
    /// Step index at which it was last seen.
    pub last_seen: u64,
    live: bool,
}

/// Resting contacts keyed by id. Storage (slots, rows, hash table) grows on first sight of more
/// contacts and is reused afterwards: steady-state lookups do not allocate.
#[derive(Debug)]
pub struct ContactCache {
    map: HashMap<u64, u32, BuildIdHasher>,
    slots: Vec<CachedContact>,
    rows: Vec<f64>,
    free: Vec<u32>,
    m: usize,
    remap_tolerance: f64,
    /// Number of mappings computed (first sights and re-maps).
    pub misses: u64,
    generation: u64,
}

impl ContactCache {
    /// An empty cache for an m-mode model; a contact whose query point moves farther than
    /// `remap_tolerance` (m) from the point it was mapped from is mapped again. Storage for
    /// `contacts` contacts is allocated now (the hash table; the slots, rows and free list also
    /// written once), so the first steps with up to that many contacts neither allocate nor
    /// touch fresh memory.
    pub fn new(m: usize, remap_tolerance: f64, contacts: usize) -> Self {
        let empty = CachedContact {
            id: 0,
            query: [0.0; 3],
            surface: None,
            last_seen: 0,
            live: false,
        };
        ContactCache {
            map: HashMap::with_capacity_and_hasher(contacts, BuildIdHasher::default()),
            slots: prepared_vec(contacts, empty),
            rows: prepared_vec(contacts * m, 0.0),
            free: prepared_vec(contacts, 0),
            m,
            remap_tolerance,
            misses: 0,
            generation: 0,
        }
    }

    /// Incremented whenever a slot's content changes (mapping, re-mapping, eviction): equal
    /// generations and slot lists mean every row read from the cache is unchanged.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Number of live cached contacts.
    pub fn len(&self) -> usize {
        self.map.len()
    }

    /// The cached contact in `slot`.
    pub fn slot(&self, slot: u32) -> &CachedContact {
        &self.slots[slot as usize]
    }

    /// The contact row `w_c = nᵀ Σ_i b_i U_i` (length m, m·kg^-1/2) of `slot`.
    pub fn row(&self, slot: u32) -> &[f64] {
        &self.rows[slot as usize * self.m..(slot as usize + 1) * self.m]
    }

    /// Finds or maps contact `id` at `point` (m, object frame) for step `step`; returns its slot
    /// and whether it was (re)mapped now. Slot `hint` is tried first (e.g. the slot this contact had at
    /// the same position of last step's list): a live slot holding `id` is the one the hash
    /// table would return, so steady-state steps skip the hashing. Same results either way.
    pub fn lookup_with_hint(
        &mut self,
        model: &ModalModel,
        id: u64,
        point: [f64; 3],
        step: u64,
        max_distance: f64,
        hint: u32,
    ) -> (u32, bool) {
        let hinted = self
            .slots
            .get(hint as usize)
            .is_some_and(|c| c.live && c.id == id);
        let found = if hinted {
            Some(hint)
        } else {
            self.map.get(&id).copied()
        };
        if let Some(s) = found {
            let c = &mut self.slots[s as usize];
            c.last_seen = step;
            if norm(sub(c.query, point)) <= self.remap_tolerance {
                return (s, false);
            }
            self.map_into(model, s, point, max_distance);
            return (s, true);
        }
        let s = match self.free.pop() {
            Some(s) => s,
            None => {
                self.slots.push(CachedContact {
                    id,
                    query: point,
                    surface: None,
                    last_seen: step,
                    live: true,
                });
                self.rows.resize(self.rows.len() + self.m, 0.0);
                // Keep the free list able to hold every slot, so eviction never allocates.
                self.free
                    .reserve(self.slots.len().saturating_sub(self.free.len()));
                (self.slots.len() - 1) as u32
            }
        };
        self.slots[s as usize].id = id;
        self.slots[s as usize].live = true;
        self.slots[s as usize].last_seen = step;
        self.map.insert(id, s);
        self.map_into(model, s, point, max_distance);
        (s, true)
    }

    fn map_into(&mut self, model: &ModalModel, s: u32, point: [f64; 3], max_distance: f64) {
        self.misses += 1;
        self.generation += 1;
        let sp = model.project(point, max_distance);
        let c = &mut self.slots[s as usize];
        c.query = point;
        c.surface = sp;
        let row = &mut self.rows[s as usize * self.m..(s as usize + 1) * self.m];
        match sp {
            Some(sp) => model.contact_row(&sp, row),
            None => row.iter_mut().for_each(|x| *x = 0.0),
        }
    }

    /// Evicts contacts unseen for more than `after` steps, calling `on_evict(slot)` for each.
    pub fn evict_unseen(&mut self, step: u64, after: u32, mut on_evict: impl FnMut(u32)) {
        for (s, c) in self.slots.iter_mut().enumerate() {
            if c.live && step.saturating_sub(c.last_seen) > u64::from(after) {
                c.live = false;
                self.generation += 1;
                self.map.remove(&c.id);
                self.free.push(s as u32);
                on_evict(s as u32);
            }
        }
    }
}
