//! Contact classification (paper §4.5): each step's contact reports split, per elastic object,
//! into impacts (new contacts whose impulse reaches the object's threshold) and resting
//! contacts (the distant contacts that may receive a response), with the energy each impact
//! dissipated (the energy bound's budget). The rules are in [`DcrWorld`]'s documentation,
//! "Impacts and resting contacts".

use super::energy_bound::{approach_speed, dissipated};
use super::DcrWorld;
use crate::math::{scale, sub};
use crate::response::{Impact, RestingContact};
use crate::world::pose::rotate_back;
use crate::world::{BodyState, ContactReport};

/// Steps between purges of the age table.
const PURGE_EVERY: u64 = 16;

/// Age record of one contact id.
#[derive(Clone, Copy, Debug)]
pub(super) struct ContactAge {
    first_step: u64,
    last_step: u64,
    /// Whether the contact has been an impact on the object on side 1 / side 2.
    fired: [bool; 2],
}

/// Where a resting contact's response goes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Source {
    /// Index of the receiving body in this step's `bodies`.
    pub(super) body: u32,
    /// Application point on the receiving body (m, world).
    pub(super) point: [f64; 3],
    /// Whether the contact carried an impulse this step (touching, not only predicted): only
    /// touching contacts carry a body under [`crate::Launch::SustainedPeak`].
    pub(super) touching: bool,
}

impl DcrWorld {
    /// Splits the step's contact reports into impacts and resting contacts per object.
    pub(super) fn classify(&mut self, contacts: &[ContactReport], bodies: &[BodyState]) {
        let step = self.step - 1;
        let cp = self.params.classify;
        // The last body looked up on each side: consecutive reports usually share their bodies
        // (an engine reports a pair's points together).
        let mut memo: [Option<(u64, Option<u32>)>; 2] = [None; 2];
        for c in contacts {
            let objs = [self.enabled_at(c.body1), self.enabled_at(c.body2)];
            if objs == [None, None] || c.body1 == c.body2 {
                continue;
            }
            self.info.contacts += 1;
            let lambda = c.impulse;
            let valid = lambda.is_finite() && lambda > 0.0;
            let mut fired_before: Option<&mut [bool; 2]> = None;
            // The step the contact id was first seen (its age's start); `step` under the
            // engine's newness rule, whose objects' settle windows are checked on `is_new`.
            let mut first_seen = step;
            let fresh_age = if cp.engine_newness {
                c.is_new && step >= cp.settle_steps && !recently_pushed(&self.pushed, c.id, step)
            } else {
                let hop = !(lambda > 0.0) && recently_pushed(&self.pushed, c.id, step);
                let fresh = ContactAge {
                    first_step: step,
                    last_step: step,
                    fired: [false; 2],
                };
                let age = self.ages.entry(c.id).or_insert(fresh);
                // Absent for a while, or touching with zero impulse: its age restarts — but not
                // in the step after a response pushed it off (see `recently_pushed`).
                if age.last_step + cp.new_after_missing_steps < step || (!(lambda > 0.0) && !hop) {
                    *age = fresh;
                }
                age.last_step = step;
                let f = step >= cp.settle_steps
                    && age.first_step >= cp.settle_steps
                    && step - age.first_step <= cp.fresh_steps;
                first_seen = age.first_step;
                fired_before = Some(&mut age.fired);
                f
            };
            let mut bidx = [None; 2];
            for (side, b) in [c.body1, c.body2].into_iter().enumerate() {
                bidx[side] = match memo[side] {
                    Some((id, i)) if id == b => i,
                    _ => {
                        let i = self.body_index.get(&b).copied();
                        memo[side] = Some((b, i));
                        i
                    }
                };
            }
            // Closed fast enough to be an impact (checked only where it could be one).
            let closing = cp.min_approach_speed <= 0.0
                || !(fresh_age && valid)
                || approach_speed(c, bidx, bodies) >= cp.min_approach_speed;
            let mut fired = [false; 2];
            for side in 0..2 {
                let Some(o) = objs[side] else { continue };
                let obj = &mut self.objects[o as usize];
                let other = 1 - side;
                let own_point = if side == 0 { c.point1 } else { c.point2 };
                let other_point = if side == 0 { c.point2 } else { c.point1 };
                let already = fired_before.as_ref().is_some_and(|f| f[side]);
                // Under ages, a contact first seen in the object's own settle window (added or
                // enabled again mid-run) belongs to its resting set.
                let settled = cp.engine_newness
                    || first_seen >= obj.active_since.saturating_add(cp.settle_steps);
                if fresh_age && settled && !already && valid && closing && lambda >= obj.threshold {
                    if let Some(f) = fired_before.as_mut() {
                        f[side] = true;
                    }
                    fired[side] = true;
                    // The impulse on this object: −λn on body1, +λn on body2.
                    let d = if side == 0 {
                        scale(c.normal, -1.0)
                    } else {
                        c.normal
                    };
                    obj.impacts.push(Impact {
                        point: rotate_back(&obj.rot, sub(own_point, obj.pose.translation)),
                        direction: rotate_back(&obj.rot, d),
                        impulse: lambda,
                    });
                    obj.info.impacts += 1;
                    self.info.impacts += 1;
                } else if valid {
                    if let Some(b) = bidx[other].filter(|&b| bodies[b as usize].is_dynamic()) {
                        obj.resting.push(RestingContact {
                            id: c.id,
                            point: rotate_back(&obj.rot, sub(own_point, obj.pose.translation)),
                        });
                        obj.sources.push(Source {
                            body: b,
                            point: other_point,
                            touching: c.impulse > 0.0,
                        });
                        obj.info.resting += 1;
                        self.info.resting += 1;
                    }
                }
            }
            let nfired = fired.iter().filter(|&&f| f).count();
            if nfired > 0 {
                let lost = dissipated(c, bidx, bodies) / nfired as f64;
                for side in 0..2 {
                    if fired[side] {
                        let o = objs[side].expect("fired side has an object") as usize;
                        self.objects[o].info.energy.dissipated += lost;
                    }
                }
            }
        }
    }

    /// Forgets the ids absent long enough to be new anyway, every [`PURGE_EVERY`] steps (a
    /// bounded table that stops growing once warm).
    pub(super) fn purge_ages(&mut self, step: u64) {
        if step >= self.next_purge {
            self.next_purge = step + PURGE_EVERY;
            let gap = self.params.classify.new_after_missing_steps;
            self.ages.retain(|_, a| a.last_step + gap >= step);
        }
    }

    /// Records this step's events for [`recently_pushed`] (the events of the last two steps).
    pub(super) fn remember_pushed(&mut self, step: u64) {
        self.pushed.retain(|&(_, s)| s + 2 > step);
        self.pushed
            .extend(self.events.iter().map(|e| (e.contact, step)));
    }
}

/// Whether contact `id` received a response event one or two steps before `step`. A body
/// pushed off its resting contact after step N (the support compensation gives it the
/// response's Δv at the end of N+1, so its contact carries no impulse at N+1) and caught again
/// by the same contact at N+1 or N+2 has hopped by at most Δv·h: that contact is neither new
/// nor an impact. A body that stays off longer lands as a new contact. A short scan: the
/// events of two steps.
#[inline]
fn recently_pushed(pushed: &[(u64, u64)], id: u64, step: u64) -> bool {
    !pushed.is_empty()
        && pushed
            .iter()
            .any(|&(c, s)| c == id && s + 2 >= step && s < step)
}
