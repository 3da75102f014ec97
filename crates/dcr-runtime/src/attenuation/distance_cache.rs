//! Bounded cache of distance fields, one per resting-contact slot, least recently used evicted.
//! Storage grows on first sight of more contacts up to the capacity, then is reused.

const NONE: u32 = u32::MAX;

#[derive(Debug)]
pub(crate) struct DistanceCache {
    ns: usize,
    capacity: usize,
    fields: Vec<f64>,
    owner: Vec<u32>,
    last_used: Vec<u64>,
    slot_field: Vec<u32>,
    scratch: Vec<f64>,
    /// Fields computed so far (cache misses).
    pub computed: u64,
}

impl DistanceCache {
    pub(crate) fn new(ns: usize, capacity: usize) -> Self {
        DistanceCache {
            ns,
            capacity,
            fields: Vec::new(),
            owner: Vec::new(),
            last_used: Vec::new(),
            slot_field: Vec::new(),
            scratch: if capacity == 0 {
                vec![0.0; ns]
            } else {
                Vec::new()
            },
            computed: 0,
        }
    }

    /// Forgets the field of contact slot `slot` (contact evicted or re-mapped).
    pub(crate) fn invalidate(&mut self, slot: u32) {
        if let Some(f) = self.slot_field.get_mut(slot as usize) {
            if *f != NONE {
                self.owner[*f as usize] = NONE;
                self.last_used[*f as usize] = 0;
                *f = NONE;
            }
        }
    }

    /// Whether `slot`'s field is cached (a [`DistanceCache::get`] would not compute).
    pub(crate) fn contains(&self, slot: u32) -> bool {
        self.capacity > 0
            && self
                .slot_field
                .get(slot as usize)
                .is_some_and(|&f| f != NONE)
    }

    /// Whether fields are kept across steps at all (capacity > 0).
    pub(crate) fn caches(&self) -> bool {
        self.capacity > 0
    }

    /// The field of `slot`, computing it with `compute` on a miss.
    pub(crate) fn get(&mut self, slot: u32, step: u64, compute: impl FnOnce(&mut [f64])) -> &[f64] {
        let ns = self.ns;
        if self.capacity == 0 {
            compute(&mut self.scratch);
            self.computed += 1;
            return &self.scratch;
        }
        if self.slot_field.len() <= slot as usize {
            self.slot_field.resize(slot as usize + 1, NONE);
        }
        let f = self.slot_field[slot as usize];
        if f != NONE {
            self.last_used[f as usize] = step;
            return &self.fields[f as usize * ns..(f as usize + 1) * ns];
        }
        let f = if let Some(free) = self.owner.iter().position(|&o| o == NONE) {
            free
        } else if self.owner.len() < self.capacity {
            self.fields.resize(self.fields.len() + ns, 0.0);
            self.owner.push(NONE);
            self.last_used.push(0);
            self.owner.len() - 1
        } else {
            let lru = (0..self.owner.len())
                .min_by_key(|&i| self.last_used[i])
                .unwrap_or(0);
            let prev = self.owner[lru];
            self.slot_field[prev as usize] = NONE;
            lru
        };
        self.owner[f] = slot;
        self.last_used[f] = step;
        self.slot_field[slot as usize] = f as u32;
        let field = &mut self.fields[f * ns..(f + 1) * ns];
        compute(field);
        self.computed += 1;
        field
    }
}
