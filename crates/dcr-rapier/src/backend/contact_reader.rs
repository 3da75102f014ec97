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
//!
//! Newness (`ContactReport::is_new`: no impulse at the previous step) comes from the set of
//! points that carried an impulse at the previous step (see [`super::StepGate::ImpactSteps`]);
//! rapier's own `NEW_CONTACT_BIT` is not used: on recycled steps rapier leaves it as it was at
//! the pair's last full contact update.

use dcr_runtime::ContactReport;

use super::arr;
use super::contact_id::{collider_pair_key, manifold_seed, point_id};
use super::rapier::geometry::NEW_CONTACT_BIT;
use super::rapier::prelude::{Collider, ColliderHandle, ContactPair};
use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// Where a report came from in rapier (to find its contact again in the solver hook).
#[derive(Clone, Copy, Debug)]
pub(super) struct ReportSource {
    /// `collider_pair_key` of the pair.
    pub pair: u64,
    /// The pair's colliders, in rapier's order (`ContactPair::collider1/2`).
    pub colliders: [ColliderHandle; 2],
}

/// Which contact points carried a normal impulse at the previous step and at this one, for
/// newness (see [`super::StepGate::ImpactSteps`]): per collider pair, two 64-bit masks over the
/// point slots (solver manifold < 16, point index < 8; manifolds 0–7 in the first word, 8–15 in
/// the second), points beyond them in a set.
///
/// The pairs' masks sit in a vector in the order the light pass visits the pairs, which is the
/// same from step to step (rapier's contact graph), so a pair is found by comparing its key with
/// the entry under a cursor (compared by collider handles, so the pair key is hashed only on a
/// miss); a hash index by key catches the pairs that moved. Masks are 64-bit words because a
/// variable shift of a 128-bit mask compiles to a dozen instructions and branches; the cursor
/// and the words replace rapier's `contact_pairs_with` and a key hashed every step (the
/// instruction counts are in docs/benchmarks.md, "Design measurements").
#[derive(Debug, Default)]
pub(super) struct LoadMemory {
    entries: Vec<PairLoad>,
    index: HashMap<u64, u32, BuildHasherDefault<KeyHasher>>,
    cursor: usize,
    overflow_before: HashSet<u64, BuildHasherDefault<KeyHasher>>,
    overflow_now: HashSet<u64, BuildHasherDefault<KeyHasher>>,
    step: u64,
}

/// One pair's loaded-point masks.
#[derive(Clone, Copy, Debug)]
struct PairLoad {
    key: u64,
    /// The pair's colliders in rapier's order: the cursor compares them, so the key is
    /// computed only when the pair is not under the cursor.
    colliders: [ColliderHandle; 2],
    /// Step of `now`.
    step: u64,
    before: [u64; 2],
    now: [u64; 2],
}

impl LoadMemory {
    /// Starts step `step` (call once per step before the pairs).
    pub(super) fn begin_step(&mut self, step: u64) {
        self.step = step;
        self.cursor = 0;
        std::mem::swap(&mut self.overflow_before, &mut self.overflow_now);
        self.overflow_now.clear();
        // Pairs unseen for a step are gone: forget them (bounded by the live pairs).
        if step.is_multiple_of(64) && self.entries.iter().any(|p| p.step + 1 < step) {
            self.entries.retain(|p| p.step + 1 >= step);
            self.index.clear();
            for (i, p) in self.entries.iter().enumerate() {
                self.index.insert(p.key, i as u32);
            }
        }
    }

    /// The masks of the pair of colliders `colliders` (rapier's order) for this step, its
    /// previous-step mask rolled into `before`.
    #[inline(always)]
    fn pair(&mut self, colliders: [ColliderHandle; 2]) -> &mut PairLoad {
        let at = match self.entries.get(self.cursor) {
            Some(p) if p.colliders == colliders => self.cursor,
            _ => {
                let key = collider_pair_key(colliders[0], colliders[1]);
                match self.index.get(&key) {
                    Some(&i) => {
                        self.entries[i as usize].colliders = colliders;
                        i as usize
                    }
                    None => {
                        self.index.insert(key, self.entries.len() as u32);
                        self.entries.push(PairLoad {
                            key,
                            colliders,
                            step: 0,
                            before: [0; 2],
                            now: [0; 2],
                        });
                        self.entries.len() - 1
                    }
                }
            }
        };
        self.cursor = at + 1;
        let step = self.step;
        let p = &mut self.entries[at];
        if p.step != step {
            p.before = if p.step + 1 == step { p.now } else { [0; 2] };
            p.now = [0; 2];
            p.step = step;
        }
        p
    }

    /// Starts reading this step's reports (after the light pass): pairs are looked up under a
    /// cursor again, in the light pass's order.
    pub(super) fn begin_read(&mut self) {
        self.cursor = 0;
    }

    /// The pair's previous-step masks as recorded by this step's light pass (None: the pair
    /// was not scanned at this step), for [`LoadMemory::is_new`].
    fn before(&mut self, key: u64) -> Option<[u64; 2]> {
        let i = match self.entries.get(self.cursor) {
            Some(p) if p.key == key => self.cursor,
            _ => *self.index.get(&key)? as usize,
        };
        self.cursor = i + 1;
        let p = &self.entries[i];
        (p.step == self.step).then_some(p.before)
    }

    /// Whether point (`manifold`, `point`) of a pair whose [`LoadMemory::before`] is `before`
    /// (pair key `key`) carried no impulse at the previous step, as recorded by the previous
    /// step's light pass.
    #[inline]
    fn is_new(&self, before: Option<[u64; 2]>, key: u64, manifold: usize, point: usize) -> bool {
        match slot(manifold, point) {
            Some((word, bit)) => before.is_none_or(|b| b[word] & bit == 0),
            None => !self
                .overflow_before
                .contains(&point_key(key, manifold, point)),
        }
    }
}

/// The mask word and bit of a point slot, if it fits.
#[inline]
fn slot(manifold: usize, point: usize) -> Option<(usize, u64)> {
    (manifold < 16 && point < 8).then(|| (manifold >> 3, 1u64 << ((manifold & 7) * 8 + point)))
}

/// Hashes a pair key to itself: the keys are splitmix outputs already, so the standard SipHash
/// (several times the cost of the map's probe) would add nothing.
#[derive(Default, Clone, Copy, Debug)]
pub(super) struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = x;
    }
}

/// A key of a contact point beyond the masks: the pair key with the manifold and point indices
/// folded into its low bits (pair keys are well mixed).
#[inline]
fn point_key(pair_key: u64, manifold: usize, point: usize) -> u64 {
    pair_key ^ ((manifold as u64) << 8 | point as u64)
}

/// Appends one report per solver contact of `pair` (whose colliders are `colliders`, on the
/// bodies of ids `bodies`, pair key `pair_key`; newness from `memory`); returns how many it
/// appended.
pub(super) fn read_pair(
    pair: &ContactPair,
    colliders: [&Collider; 2],
    [body1, body2]: [u64; 2],
    pair_key: u64,
    memory: &mut LoadMemory,
    out: &mut Vec<ContactReport>,
    sources: &mut Vec<ReportSource>,
) -> usize {
    let pose1 = colliders[0].position();
    let pose2 = colliders[1].position();
    let before = memory.before(pair_key);
    let mut n = 0;
    for (mi, m) in pair.solver_manifolds().iter().enumerate() {
        if m.data.solver_contacts.is_empty() {
            continue;
        }
        let normal = arr(m.data.normal);
        let sub1 = m.subshape_pos1();
        let sub2 = m.subshape_pos2();
        let seed = manifold_seed(pair.collider1, pair.collider2, (m.subshape1, m.subshape2));
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
            let id = point_id(seed, mi as u32, idx as u32);
            out.push(ContactReport {
                id,
                body1,
                body2,
                point1: arr(pose1.transform_point(local1)),
                point2: arr(pose2.transform_point(local2)),
                normal,
                impulse: super::to_f64(pt.data.impulse),
                is_new: memory.is_new(before, pair_key, mi, idx),
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

/// The light pass over one pair: records its loaded points in `memory` and returns whether one
/// of them is an impact candidate — new with impulse ≥ `threshold` (N·s).
#[inline(always)]
pub(super) fn scan_pair(pair: &ContactPair, threshold: f64, memory: &mut LoadMemory) -> bool {
    let mut hot = false;
    let mut overflow = false;
    let load = memory.pair([pair.collider1, pair.collider2]);
    for (mi, m) in pair.solver_manifolds().iter().enumerate() {
        // The slot's word and the manifold's first bit in it (see `slot`).
        let (fits, word, base) = (mi < 16, (mi >> 3) & 1, (mi & 7) * 8);
        for sc in m.data.solver_contacts.iter() {
            let idx = (sc.contact_id[0] & !NEW_CONTACT_BIT) as usize;
            let Some(pt) = m.points.get(idx) else {
                continue;
            };
            let lambda = super::to_f64(pt.data.impulse);
            if !(lambda > 0.0) {
                continue;
            }
            if fits && idx < 8 {
                let bit = 1u64 << (base + idx);
                load.now[word] |= bit;
                hot |= lambda >= threshold && load.before[word] & bit == 0;
            } else {
                overflow = true;
            }
        }
    }
    if overflow {
        let pair_key = collider_pair_key(pair.collider1, pair.collider2);
        for (mi, m) in pair.solver_manifolds().iter().enumerate() {
            for sc in m.data.solver_contacts.iter() {
                let idx = (sc.contact_id[0] & !NEW_CONTACT_BIT) as usize;
                let lambda = m
                    .points
                    .get(idx)
                    .map_or(0.0, |pt| super::to_f64(pt.data.impulse));
                if lambda > 0.0 && slot(mi, idx).is_none() {
                    let key = point_key(pair_key, mi, idx);
                    memory.overflow_now.insert(key);
                    hot |= lambda >= threshold && !memory.overflow_before.contains(&key);
                }
            }
        }
    }
    hot
}
