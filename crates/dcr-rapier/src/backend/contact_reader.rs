//! Rapier's contact manifolds after `step()` as the world API's [`ContactReport`]s.
//!
//! Read after the step from `ContactPair::solver_manifolds()` (what the solver saw: contact
//! clustering is on by default, so these are not `pair.manifolds`), one report per
//! `SolverContact`: the manifold point is `points[contact_id & !NEW_CONTACT_BIT]`, its normal
//! impulse `data.impulse` (this step's, N·s, ≥ 0; zero for a predictive contact inside the
//! prediction distance that did not touch).
//!
//! Frames. The manifold geometry (`local_p1/2`, the normal) is the narrow phase's, computed
//! from the poses at the start of the step, while the impulses are this step's. Each contact
//! point is therefore taken on its own body, in its collider's frame (through the manifold's
//! sub-shape pose for compound and mesh shapes), and moved with that collider's post-step pose:
//! the same material point of each body where the constraint acted, wherever integration moved
//! it. On a static elastic object this is exactly where the impulse acted; on the receiving
//! body it is where the response impulse must be applied. The normal is the manifold's world
//! normal (from collider 1 toward collider 2), which the world only uses for impacts'
//! directions and the energy estimate (responses use the base's own surface normal).

use dcr_runtime::ContactReport;

use super::arr;
use super::contact_id::contact_id;
use super::rapier::geometry::NEW_CONTACT_BIT;
use super::rapier::prelude::{Collider, ColliderHandle, ContactPair};

/// Where a report came from in rapier (to find its contact again in the solver hook).
#[derive(Clone, Copy, Debug)]
pub(super) struct ReportSource {
    /// `collider_pair_key` of the pair.
    pub pair: u64,
    /// The pair's colliders, in rapier's order (`ContactPair::collider1/2`).
    pub colliders: [ColliderHandle; 2],
}

/// Appends one report per solver contact of `pair` (whose colliders are `colliders`, on the
/// bodies of ids `bodies`, pair key `pair_key`); returns how many it appended.
pub(super) fn read_pair(
    pair: &ContactPair,
    colliders: [&Collider; 2],
    [body1, body2]: [u64; 2],
    pair_key: u64,
    out: &mut Vec<ContactReport>,
    sources: &mut Vec<ReportSource>,
) -> usize {
    let pose1 = colliders[0].position();
    let pose2 = colliders[1].position();
    let mut n = 0;
    for (mi, m) in pair.solver_manifolds().iter().enumerate() {
        let normal = arr(m.data.normal);
        let sub1 = m.subshape_pos1();
        let sub2 = m.subshape_pos2();
        for sc in m.data.solver_contacts.iter() {
            let idx = (sc.contact_id[0] & !NEW_CONTACT_BIT) as usize;
            let Some(pt) = m.points.get(idx) else {
                continue;
            };
            let local1 = match sub1 {
                Some(sp) => sp.transform_point(pt.local_p1),
                None => pt.local_p1,
            };
            let local2 = match sub2 {
                Some(sp) => sp.transform_point(pt.local_p2),
                None => pt.local_p2,
            };
            out.push(ContactReport {
                id: contact_id(
                    pair.collider1,
                    pair.collider2,
                    (m.subshape1, m.subshape2),
                    mi as u32,
                    idx as u32,
                ),
                body1,
                body2,
                point1: arr(pose1.transform_point(local1)),
                point2: arr(pose2.transform_point(local2)),
                normal,
                impulse: super::to_f64(pt.data.impulse),
            });
            sources.push(ReportSource {
                pair: pair_key,
                colliders: [pair.collider1, pair.collider2],
            });
            n += 1;
        }
    }
    n
}
