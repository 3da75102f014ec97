//! [`ElasticHandle`]: an elastic object of a [`crate::DcrWorld`].

/// The handle of an elastic object in a [`crate::DcrWorld`], returned by
/// [`crate::DcrWorld::add_object`]. Handles are dense indices in the order objects were added
/// (0, 1, 2, …) and are never reused (objects are not removed), so a `u32` converts both ways
/// without a table (e.g. across a C boundary).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(transparent)]
pub struct ElasticHandle(pub(crate) u32);

impl ElasticHandle {
    /// The handle's index: the number of objects added before it.
    pub fn index(self) -> u32 {
        self.0
    }

    /// The handle with index `index` (valid in a world with more than `index` objects).
    pub fn from_index(index: u32) -> ElasticHandle {
        ElasticHandle(index)
    }
}
