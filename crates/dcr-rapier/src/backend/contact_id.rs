//! Stable `u64` ids for rapier handles and contact points, as the world API takes them.

use super::rapier::prelude::{ColliderHandle, RigidBodyHandle};

/// The body id of contacts whose collider has no parent body (a free-standing static collider):
/// the world treats it as immovable and at rest.
pub const NO_BODY: u64 = u64::MAX;

/// splitmix64 step over a running hash: cheap, well spread, deterministic.
#[inline]
fn mix(mut h: u64, x: u64) -> u64 {
    h ^= x
        .wrapping_add(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(h << 6)
        .wrapping_add(h >> 2);
    let mut z = h;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[inline]
fn collider_bits(c: ColliderHandle) -> u64 {
    let (i, g) = c.into_raw_parts();
    i as u64 | (g as u64) << 32
}

/// The world API id of a rapier body: its arena index in the low 32 bits, its generation in
/// the high 32 bits (so a removed body's recycled slot gets a new id). Inverse: [`body_handle`].
///
/// ```
/// use dcr_rapier::f64::{body_handle, body_id, rapier::prelude::*};
/// let mut bodies = RigidBodySet::new();
/// let h = bodies.insert(RigidBodyBuilder::dynamic());
/// assert_eq!(body_handle(body_id(h)), h);
/// ```
#[inline]
pub fn body_id(handle: RigidBodyHandle) -> u64 {
    let (i, g) = handle.into_raw_parts();
    i as u64 | (g as u64) << 32
}

/// The rapier body of a world API id made by [`body_id`].
#[inline]
pub fn body_handle(id: u64) -> RigidBodyHandle {
    RigidBodyHandle::from_raw_parts(id as u32, (id >> 32) as u32)
}

/// An id of the unordered collider pair `{a, b}` (the same for `(a, b)` and `(b, a)`): the two
/// handles' bits folded and multiplied once (Fibonacci hashing), well mixed in the high bits
/// as hash tables want them. Cheap: it is computed for every pair on every step.
#[inline]
pub fn collider_pair_key(a: ColliderHandle, b: ColliderHandle) -> u64 {
    let (x, y) = (collider_bits(a), collider_bits(b));
    let (lo, hi) = if x <= y { (x, y) } else { (y, x) };
    let h = (lo ^ hi.rotate_left(29)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    h ^ (h >> 32)
}

/// The stable id of one rapier contact point: a hash of the ordered collider pair of the
/// contact pair, the manifold's subshape pair (`ContactManifold::subshape1/2`), the manifold's
/// index in `ContactPair::solver_manifolds()` and the point's index in `manifold.points`
/// (`SolverContact::contact_id` without `NEW_CONTACT_BIT`). It stays the same while rapier keeps
/// tracking the point from step to step; a point rapier drops and re-creates at the same
/// manifold slot gets the same id back (the world tells it is new by its absence in between).
pub fn contact_id(
    collider1: ColliderHandle,
    collider2: ColliderHandle,
    subshapes: (u32, u32),
    manifold: u32,
    point: u32,
) -> u64 {
    point_id(
        manifold_seed(collider1, collider2, subshapes),
        manifold,
        point,
    )
}

/// The part of [`contact_id`] shared by the points of one manifold (the colliders and the
/// subshape pair), hashed once per manifold; [`point_id`] finishes it per point.
#[inline]
pub fn manifold_seed(
    collider1: ColliderHandle,
    collider2: ColliderHandle,
    subshapes: (u32, u32),
) -> u64 {
    let mut h = 0x243F_6A88_85A3_08D3;
    for x in [
        collider_bits(collider1),
        collider_bits(collider2),
        subshapes.0 as u64 | (subshapes.1 as u64) << 32,
    ] {
        h = mix(h, x);
    }
    h
}

/// [`contact_id`] from its manifold's [`manifold_seed`].
#[inline]
pub fn point_id(seed: u64, manifold: u32, point: u32) -> u64 {
    mix(seed, point as u64 | (manifold as u64) << 16)
}
