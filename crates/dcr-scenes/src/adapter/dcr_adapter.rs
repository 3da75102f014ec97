//! [`DcrAdapter`]: per-step contact classification, response query and impulse application.

use std::collections::HashMap;
use std::time::Instant;

use super::engine::{effective_mass, response_impulse, DistantResponse, Impact, RestingContact};
use rapier3d_f64::geometry::NEW_CONTACT_BIT;
use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::prelude::*;

use super::contact_key::contact_key;
use crate::scene::BuiltWorld;

/// Adapter settings shared by every elastic object of a run.
#[derive(Clone, Debug)]
pub struct AdapterParams {
    /// Apply the responses (false: classify and measure only — the "off" run).
    pub enabled: bool,
    /// A contact counts as an impact if its first appearance is at most this many steps
    /// old and it has not fired yet (rapier creates contacts predictively, one step before
    /// the impulse; see docs/scenes.md). Default 2.
    pub fresh_steps: u64,
    /// Contacts that exist in the first `settle_steps` steps are the initial resting set,
    /// never impacts. Default 3.
    pub settle_steps: u64,
    /// Coefficient of restitution (for the dissipated-energy estimate).
    pub restitution: f64,
}

impl Default for AdapterParams {
    fn default() -> Self {
        AdapterParams {
            enabled: true,
            fresh_steps: 2,
            settle_steps: 3,
            restitution: 0.15,
        }
    }
}

/// What one elastic object saw and did over a run.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ModelStats {
    /// Model (elastic object) name.
    pub name: String,
    /// Response queries (steps with at least one impact), each one's time (µs).
    #[serde(skip)]
    pub query_us: Vec<f64>,
    /// Resting contacts at each query.
    #[serde(skip)]
    pub query_resting: Vec<usize>,
    /// Impacts over the run.
    pub impacts: usize,
    /// Impacts that came from another model's responses (a dynamic elastic object).
    pub chained_impacts: usize,
    /// Sum of the impacts' normal impulses (N·s).
    pub impact_impulse: f64,
    /// Responses with Δv > 0 applied (or that would have been, when off).
    pub responses_applied: usize,
    /// Largest Δv asked for at a resting contact (m/s).
    pub max_delta_v: f64,
    /// Kinetic energy the applied responses added to the resting bodies (J; net).
    pub injected_ke: f64,
    /// Energy the impacts dissipated, estimated as Σ ½ λ v⁻ (1 − e) (J).
    pub dissipated: f64,
}

/// One response impulse applied to a resting body (what a viewer marks).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct ResponseEvent {
    /// Trajectory row at whose time the impulse was applied: it is applied right after step
    /// `row − 1`'s solve, i.e. at t = row · h (s).
    pub row: usize,
    /// Elastic object (slot, scene order) whose response it is.
    pub model: usize,
    /// Receiving body (index into `BuiltWorld::bodies`).
    pub body: usize,
    /// Point of application (m, world frame).
    pub point: [f64; 3],
    /// Impulse (N·s, world frame).
    pub impulse: [f64; 3],
}

/// Per-step timing of the adapter.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepStats {
    /// Wall time of the whole adapter step (classification, queries, impulses), µs.
    pub adapter_us: f64,
    /// Impacts this step, all models.
    pub impacts: usize,
}

#[derive(Clone, Copy, Debug)]
struct ContactAge {
    first_step: u64,
    last_step: u64,
    fired: bool,
}

/// Where a resting contact came from, to apply its response.
#[derive(Clone, Copy, Debug)]
struct RestingSource {
    /// Index of the resting body in `BuiltWorld::bodies`.
    body: usize,
    /// Contact point on the resting body, world frame (post-step pose).
    world_point: Vector,
}

struct Slot {
    body: usize,
    colliders: Vec<ColliderHandle>,
    response: Option<DistantResponse>,
    threshold: f64,
    gain: f64,
    stats: ModelStats,
    ages: HashMap<u64, ContactAge>,
    impacts: Vec<Impact>,
    resting: Vec<RestingContact>,
    sources: HashMap<u64, RestingSource>,
    /// Impacts handed over from other models' responses this step (object frame).
    chained: Vec<Impact>,
}

#[derive(Clone, Copy, Default)]
struct Kin {
    linvel: Vector,
    angvel: Vector,
    com: Vector,
}

/// The adapter: one slot per elastic object, in scene order (a dynamic elastic object that
/// rests on another must come after it, so the chained impacts arrive the same step).
pub struct DcrAdapter {
    params: AdapterParams,
    slots: Vec<Slot>,
    step: u64,
    pre: Vec<Kin>,
    events: Vec<ResponseEvent>,
}

fn body_kin(rb: &RigidBody) -> Kin {
    Kin {
        linvel: rb.linvel(),
        angvel: rb.angvel(),
        com: rb.center_of_mass(),
    }
}

fn vel_at(k: &Kin, p: Vector) -> Vector {
    k.linvel + k.angvel.cross(p - k.com)
}

fn arr(v: Vector) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn vecf(a: [f64; 3]) -> Vector {
    Vector::new(a[0], a[1], a[2])
}

fn ke(rb: &RigidBody) -> f64 {
    rb.kinetic_energy()
}

impl DcrAdapter {
    /// An adapter for `world`'s elastic objects. `responses[i]` is elastic object i's
    /// response (None: measured only); `thresholds`/`gains` per object (N·s, scale).
    pub fn new(
        world: &BuiltWorld,
        responses: Vec<Option<DistantResponse>>,
        thresholds: &[f64],
        gains: &[f64],
        names: &[String],
        params: AdapterParams,
    ) -> DcrAdapter {
        let mut slots = Vec::new();
        for (i, response) in responses.into_iter().enumerate() {
            let body = world.elastic_body[i];
            let mut colliders: Vec<ColliderHandle> = world
                .collider_body
                .iter()
                .filter(|(_, &b)| b == body)
                .map(|(&c, _)| c)
                .collect();
            colliders.sort_by_key(|c| c.into_raw_parts());
            slots.push(Slot {
                body,
                colliders,
                response,
                threshold: thresholds[i],
                gain: gains[i],
                stats: ModelStats {
                    name: names[i].clone(),
                    ..Default::default()
                },
                ages: HashMap::new(),
                impacts: Vec::new(),
                resting: Vec::new(),
                sources: HashMap::new(),
                chained: Vec::new(),
            });
        }
        DcrAdapter {
            params,
            slots,
            step: 0,
            pre: vec![Kin::default(); world.bodies.len()],
            events: Vec::new(),
        }
    }

    /// Records every body's velocity before `step()` (for the dissipated-energy estimate).
    pub fn before_step(&mut self, built: &BuiltWorld) {
        for (i, b) in built.bodies.iter().enumerate() {
            self.pre[i] = body_kin(&built.world.bodies[b.handle]);
        }
    }

    /// Every response impulse applied so far, in application order (empty when off).
    pub fn events(&self) -> &[ResponseEvent] {
        &self.events
    }

    /// The per-model statistics so far.
    pub fn stats(&self) -> Vec<ModelStats> {
        self.slots.iter().map(|s| s.stats.clone()).collect()
    }

    /// Runs the response for this step (call right after `PhysicsWorld::step`).
    pub fn after_step(&mut self, built: &mut BuiltWorld) -> StepStats {
        let t0 = Instant::now();
        let mut out = StepStats::default();
        for si in 0..self.slots.len() {
            self.collect(si, built);
            let slot = &mut self.slots[si];
            // Chained impacts from earlier models' responses (dynamic elastic objects).
            let chained = std::mem::take(&mut slot.chained);
            slot.stats.chained_impacts += chained.len();
            slot.impacts.extend(chained);
            out.impacts += slot.impacts.len();
            if slot.impacts.is_empty() {
                continue;
            }
            slot.stats.impacts += slot.impacts.len();
            slot.stats.impact_impulse += slot.impacts.iter().map(|i| i.impulse).sum::<f64>();
            let Some(resp) = slot.response.as_mut() else {
                continue;
            };
            let tq = Instant::now();
            let responses = resp.step(&slot.impacts, &slot.resting);
            let q_us = tq.elapsed().as_secs_f64() * 1e6;
            slot.stats.query_us.push(q_us);
            slot.stats.query_resting.push(slot.resting.len());
            // Copy out what we need (the response buffer borrows `resp`).
            let resps: Vec<(u64, [f64; 3], f64)> = responses
                .iter()
                .filter(|r| r.mapped && r.delta_v > 0.0)
                .map(|r| (r.id, r.normal, r.delta_v))
                .collect();
            let elastic_pose = *built.world.bodies[built.bodies[slot.body].handle].position();
            let gain = slot.gain;
            let sources = std::mem::take(&mut slot.sources);
            let (injected, applied, maxdv, handed) =
                self.apply(built, si, &elastic_pose, &resps, &sources, gain);
            let slot = &mut self.slots[si];
            slot.sources = sources;
            slot.stats.injected_ke += injected;
            slot.stats.responses_applied += applied;
            slot.stats.max_delta_v = slot.stats.max_delta_v.max(maxdv);
            // Hand impulses given to bodies that carry a base to those models as impacts.
            for (target_slot, imp) in handed {
                self.slots[target_slot].chained.push(imp);
            }
        }
        self.step += 1;
        out.adapter_us = t0.elapsed().as_secs_f64() * 1e6;
        out
    }

    /// Applies responses `(resting id, outward normal in the object frame, Δv)`; returns
    /// (KE injected, count applied, max Δv, impacts handed to other models).
    fn apply(
        &mut self,
        built: &mut BuiltWorld,
        si: usize,
        elastic_pose: &Pose,
        resps: &[(u64, [f64; 3], f64)],
        sources: &HashMap<u64, RestingSource>,
        gain: f64,
    ) -> (f64, usize, f64, Vec<(usize, Impact)>) {
        let mut handed = Vec::new();
        let mut maxdv: f64 = 0.0;
        let mut applied = 0;
        // Group by body, in response order (deterministic: responses follow the resting order).
        let mut before: HashMap<usize, (Kin, f64)> = HashMap::new();
        for &(id, normal, dv) in resps {
            let Some(src) = sources.get(&id) else {
                continue;
            };
            maxdv = maxdv.max(dv);
            applied += 1;
            if !self.params.enabled {
                continue;
            }
            let handle = built.bodies[src.body].handle;
            let n = elastic_pose.rotation * vecf(normal);
            let rb = &mut built.world.bodies[handle];
            let entry = before
                .entry(src.body)
                .or_insert_with(|| (body_kin(rb), ke(rb)));
            let start = entry.0;
            // One Gauss–Seidel pass: only the Δv not yet produced at this point by the
            // impulses already applied to this body this step (see docs/scenes.md).
            let now = body_kin(rb);
            let achieved = (vel_at(&now, src.world_point) - vel_at(&start, src.world_point)).dot(n);
            let need = gain * dv - achieved;
            if need <= 0.0 {
                continue;
            }
            let mp = rb.mass_properties();
            let inv_mass = mp.effective_inv_mass.x;
            let ii = mp.effective_world_inv_inertia;
            let inv_i = [
                [ii.m11, ii.m12, ii.m13],
                [ii.m12, ii.m22, ii.m23],
                [ii.m13, ii.m23, ii.m33],
            ];
            let r = src.world_point - rb.center_of_mass();
            let m_eff = effective_mass(inv_mass, inv_i, arr(r), arr(n));
            let j = vecf(response_impulse(m_eff, need, arr(n)));
            rb.apply_impulse_at_point(j, src.world_point, true);
            self.events.push(ResponseEvent {
                row: self.step as usize + 1,
                model: si,
                body: src.body,
                point: arr(src.world_point),
                impulse: arr(j),
            });
            // A body with its own base receives this impulse as an impact on its model.
            if let Some(ts) = self.slots.iter().position(|s| s.body == src.body) {
                if ts != si {
                    let pose = *rb.position();
                    let mag = j.length();
                    if mag > 0.0 {
                        handed.push((
                            ts,
                            Impact {
                                point: arr(pose.inverse_transform_point(src.world_point)),
                                direction: arr(pose.rotation.inverse() * (j / mag)),
                                impulse: mag,
                            },
                        ));
                    }
                }
            }
        }
        let mut injected = 0.0;
        let mut bodies: Vec<_> = before.into_iter().collect();
        bodies.sort_by_key(|(b, _)| *b);
        for (b, (_, ke0)) in bodies {
            injected += ke(&built.world.bodies[built.bodies[b].handle]) - ke0;
        }
        (injected, applied, maxdv, handed)
    }

    /// Classifies this step's contact points of slot `si` into impacts and resting contacts.
    fn collect(&mut self, si: usize, built: &BuiltWorld) {
        let step = self.step;
        let params = self.params.clone();
        let slot = &mut self.slots[si];
        slot.impacts.clear();
        slot.resting.clear();
        slot.sources.clear();
        let world = &built.world;
        let e_handle = built.bodies[slot.body].handle;
        let e_pose = *world.bodies[e_handle].position();
        let e_pre = self.pre[slot.body];
        for &ec in &slot.colliders {
            for pair in world.narrow_phase.contact_pairs_with(ec) {
                let e_is_1 = pair.collider1 == ec;
                let other = if e_is_1 {
                    pair.collider2
                } else {
                    pair.collider1
                };
                let Some(&ob) = built.collider_body.get(&other) else {
                    continue;
                };
                if ob == slot.body {
                    continue;
                }
                let other_dynamic = built.bodies[ob].dynamic;
                let Some(oc) = world.colliders.get(other) else {
                    continue;
                };
                let oc_pose = *oc.position();
                let Some(ecol) = world.colliders.get(ec) else {
                    continue;
                };
                // The elastic collider's pose in the object (body) frame: fixed, so the
                // elastic-side contact point maps into the base's frame without any lag.
                let ec_in_obj = e_pose.inv_mul(ecol.position());
                for (mi, m) in pair.solver_manifolds().iter().enumerate() {
                    let (sub_other, sub_e) = if e_is_1 {
                        (m.subshape_pos2(), m.subshape_pos1())
                    } else {
                        (m.subshape_pos1(), m.subshape_pos2())
                    };
                    // Outward normal of the elastic object, world frame.
                    let n_out = if e_is_1 {
                        m.data.normal
                    } else {
                        -m.data.normal
                    };
                    for sc in m.data.solver_contacts.iter() {
                        let raw = sc.contact_id[0];
                        let idx = (raw & !NEW_CONTACT_BIT) as usize;
                        let Some(pt) = m.points.get(idx) else {
                            continue;
                        };
                        let lam = pt.data.impulse;
                        // The point on the other body's surface, riding with that body.
                        let local = if e_is_1 { pt.local_p2 } else { pt.local_p1 };
                        let local = match sub_other {
                            Some(sp) => sp.transform_point(local),
                            None => local,
                        };
                        let world_point = oc_pose.transform_point(local);
                        // The point on the elastic object's surface, in its frame: where the
                        // impulse acted on the base (pre-integration geometry, body-fixed).
                        let local_e = if e_is_1 { pt.local_p1 } else { pt.local_p2 };
                        let local_e = match sub_e {
                            Some(sp) => sp.transform_point(local_e),
                            None => local_e,
                        };
                        let p_obj = ec_in_obj.transform_point(local_e);
                        let key = contact_key(
                            pair.collider1,
                            pair.collider2,
                            (m.subshape1, m.subshape2),
                            idx as u32 | (mi as u32) << 16,
                        );
                        let age = slot.ages.entry(key).or_insert(ContactAge {
                            first_step: step,
                            last_step: step,
                            fired: false,
                        });
                        if age.last_step + 1 < step {
                            // Lost for a while and back: a new contact.
                            *age = ContactAge {
                                first_step: step,
                                last_step: step,
                                fired: false,
                            };
                        }
                        age.last_step = step;
                        let fresh = step >= params.settle_steps
                            && age.first_step >= params.settle_steps
                            && step - age.first_step <= params.fresh_steps
                            && !age.fired;
                        if fresh && lam >= slot.threshold {
                            age.fired = true;
                            let dir = e_pose.rotation.inverse() * (-n_out);
                            slot.impacts.push(Impact {
                                point: arr(p_obj),
                                direction: arr(dir),
                                impulse: lam,
                            });
                            // Dissipated energy estimate: ½ λ v⁻ (1 − e) with the pre-step
                            // approach speed at the point.
                            let vrel =
                                vel_at(&self.pre[ob], world_point) - vel_at(&e_pre, world_point);
                            let approach = (-vrel.dot(n_out)).max(0.0);
                            slot.stats.dissipated +=
                                0.5 * lam * approach * (1.0 - params.restitution);
                        } else if other_dynamic && lam > 0.0 {
                            slot.resting.push(RestingContact {
                                id: key,
                                point: arr(p_obj),
                            });
                            slot.sources.insert(
                                key,
                                RestingSource {
                                    body: ob,
                                    world_point,
                                },
                            );
                        }
                    }
                }
            }
        }
        // Forget contacts not seen for a while (bounded memory).
        if step.is_multiple_of(64) {
            slot.ages.retain(|_, a| a.last_step + 8 >= step);
        }
    }
}
