//! [`ElasticHandle`]: an elastic object of a [`crate::DcrWorld`].

/// The handle of an elastic object in a [`crate::DcrWorld`], returned by
/// [`crate::DcrWorld::add_object`]: a slot index and the slot's generation (rapier's arena
/// handles, Box2D's ids with a revision). Removing an object ([`crate::DcrWorld::remove_object`])
/// frees its slot and bumps the slot's generation, so a handle of a removed object is *stale*:
/// every call that takes it reports an error (or panics, for the accessors documented so),
/// never another object, even after the slot is reused.
///
/// Slots are filled in order (0, 1, 2, …) while nothing is removed, and the first object of a
/// slot has generation 0: in a world where no object was removed, the handle of the k-th
/// object added is [`ElasticHandle::from_index`]`(k)`. The 64-bit value
/// ([`ElasticHandle::to_bits`]: index in the low 32 bits, generation in the high 32 bits) is the
/// C ABI's `DcrElasticHandle`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(transparent)]
pub struct ElasticHandle(pub(crate) u64);

impl ElasticHandle {
    /// The handle's slot index.
    pub fn index(self) -> u32 {
        self.0 as u32
    }

    /// The generation of the handle's slot when the object was added (0 for the first object
    /// in a slot; each removal from the slot adds 1, wrapping).
    pub fn generation(self) -> u32 {
        (self.0 >> 32) as u32
    }

    /// The handle with slot index `index` and generation 0: the `index`-th object added to a
    /// world from which nothing was removed.
    pub fn from_index(index: u32) -> ElasticHandle {
        ElasticHandle(u64::from(index))
    }

    /// The handle with slot `index` and `generation`.
    pub fn from_raw_parts(index: u32, generation: u32) -> ElasticHandle {
        ElasticHandle(u64::from(index) | (u64::from(generation) << 32))
    }

    /// The handle as one `u64`: index in the low 32 bits, generation in the high 32 bits.
    pub fn to_bits(self) -> u64 {
        self.0
    }

    /// The handle whose [`ElasticHandle::to_bits`] is `bits`.
    pub fn from_bits(bits: u64) -> ElasticHandle {
        ElasticHandle(bits)
    }
}

impl std::fmt::Display for ElasticHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}v{}", self.index(), self.generation())
    }
}
