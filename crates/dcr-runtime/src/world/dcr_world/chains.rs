//! Chains through dynamic elastic objects: an impulse issued to the body of a dynamic elastic
//! object later in the processing order becomes an impact on that object in the same step, at
//! most [`WorldParams::max_chain_depth`](crate::world::WorldParams::max_chain_depth) links
//! deep. See [`DcrWorld`]'s documentation, "Chains through dynamic elastic objects".

use super::DcrWorld;
use crate::math::{norm, scale, sub};
use crate::response::Impact;
use crate::world::pose::rotate_back;

impl DcrWorld {
    /// Hands object `o`'s impulses (the events from `first_event` on) that land on dynamic
    /// elastic objects later in the order to those objects as impacts (point and direction in
    /// their frame, magnitude |j|); counts the ones that cannot chain in
    /// [`crate::world::WorldStepInfo::chains_dropped`].
    pub(super) fn hand_on_chains(&mut self, o: usize, first_event: usize) {
        let depth = self.objects[o].depth;
        self.handed.clear();
        for e in &self.events[first_event..] {
            let Some(target) = self.object_at(e.body) else {
                continue;
            };
            let mag = norm(e.impulse);
            if !(mag > 0.0) {
                continue;
            }
            if !self.forward(o, target as usize, depth) {
                self.info.chains_dropped += 1;
                continue;
            }
            let t = &self.objects[target as usize];
            self.handed.push((
                target,
                Impact {
                    point: rotate_back(&t.rot, sub(e.point, t.pose.translation)),
                    direction: rotate_back(&t.rot, scale(e.impulse, 1.0 / mag)),
                    impulse: mag,
                },
                depth + 1,
            ));
        }
        for &(target, imp, d) in &self.handed {
            let t = &mut self.objects[target as usize];
            t.impacts.push(imp);
            t.depth = t.depth.max(d);
            t.info.chained_impacts += 1;
            self.info.chained_impacts += 1;
        }
    }

    /// Whether an impulse from object `from` (at chain depth `depth`) on object `to`'s body
    /// chains: `to` is dynamic, enabled, later in the order, and the chain is not at its limit.
    pub(super) fn forward(&self, from: usize, to: usize, depth: u32) -> bool {
        self.objects[to].dynamic
            && self.objects[to].enabled
            && self.rank[to] > self.rank[from]
            && depth < self.params.max_chain_depth
    }
}
