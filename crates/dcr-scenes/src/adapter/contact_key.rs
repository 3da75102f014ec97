//! Stable ids for rapier contact points across steps.

use rapier3d_f64::prelude::ColliderHandle;

fn mix(mut h: u64, x: u64) -> u64 {
    // splitmix64 step over the running hash: cheap, well spread, deterministic.
    h ^= x
        .wrapping_add(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(h << 6)
        .wrapping_add(h >> 2);
    let mut z = h;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A stable id of one contact point: a hash of the collider pair, the manifold's subshape
/// pair and the manifold point index (the solver contact's `contact_id` without
/// `NEW_CONTACT_BIT`). Survives across steps while rapier keeps tracking the point.
pub fn contact_key(
    c1: ColliderHandle,
    c2: ColliderHandle,
    subshapes: (u32, u32),
    point: u32,
) -> u64 {
    let (i1, g1) = c1.into_raw_parts();
    let (i2, g2) = c2.into_raw_parts();
    let mut h = 0x243F_6A88_85A3_08D3;
    for x in [
        i1 as u64 | (g1 as u64) << 32,
        i2 as u64 | (g2 as u64) << 32,
        subshapes.0 as u64 | (subshapes.1 as u64) << 32,
        point as u64,
    ] {
        h = mix(h, x);
    }
    h
}
