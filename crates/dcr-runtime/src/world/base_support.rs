//! [`BaseSupport`]: whether an elastic object's base is held the way its engine body is.

/// How an elastic object's base is supported compared with the engine body carrying it, checked
/// by [`crate::DcrWorld::add_object`] (a warning through the `log` crate when it is not
/// [`BaseSupport::Consistent`]; read it back with [`crate::DcrWorld::base_support`]).
///
/// A base's modes are those of the mesh with its fixed nodes held (`modal-bake bake --fixed`)
/// or of the free-floating mesh (no fixed nodes; the six rigid-body modes are excluded). Which
/// one fits depends on what holds the object in the scene, not on whether the engine moves
/// its body: a table standing on a floor is held at its feet even when its body is dynamic,
/// and a free-floating base under-states its response there (the feet cannot move, so the
/// top's modes are stiffer and larger at the top). Neither mismatch is refused; the
/// warning asks the integrator to check the choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BaseSupport {
    /// A static body with fixed nodes, or a dynamic body with a free-floating base.
    Consistent,
    /// A dynamic body carries a base baked with fixed nodes: right for an object standing on
    /// something that holds those nodes (a table on a floor), wrong for one in flight or
    /// sliding freely (its modes assume the nodes held).
    DynamicBodyFixedBase {
        /// Number of fixed volume-mesh nodes in the base.
        fixed_nodes: usize,
    },
    /// A static body carries a free-floating base (no fixed nodes): its modes assume nothing
    /// holds the object, so where it really is held (a table's feet on the ground) the
    /// response is that of a floating object.
    StaticBodyFreeBase,
}
