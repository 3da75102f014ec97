//! The impulse pass (paper Eq. 17–18): an object's response, a normal velocity change `Δv` per
//! resting contact, issued as impulses `j = m_eff (g Δv − a) n` on the resting bodies in one
//! Gauss–Seidel pass per body (`a` what the impulses already issued this step produce at the
//! point), with the support compensation for gravity. Under [`Launch::SustainedPeak`] `Δv` is a
//! target: `a` also counts the body's normal velocity at the point relative to the object's
//! rigid motion, so the body is raised to it, not pushed by it. The rules are
//! in [`DcrWorld`]'s documentation, "Impulses (Eq. 17–18) and one Gauss–Seidel pass per body".

use super::energy_bound::velocity_at;
use super::lateral_kick::add_lateral_impulse;
use super::DcrWorld;
use crate::math::{add, cross, dot, mat_vec, scale, sub};
use crate::response::{effective_mass, Launch};
use crate::world::pose::rotate;
use crate::world::{BodyState, ImpulseEvent};

/// Per-body velocity change from the impulses issued this step (world frame).
#[derive(Clone, Copy, Debug)]
pub(super) struct Tracked {
    /// Linear velocity change (m/s).
    pub(super) dlin: [f64; 3],
    /// Angular velocity change (rad/s).
    pub(super) dang: [f64; 3],
    /// Support velocity (m/s, world) already in `dlin`: given once per body and step, at its
    /// centre of mass, with its first response.
    pub(super) support: [f64; 3],
    /// Index into `touched` while the current object is processed, else `u32::MAX`.
    pub(super) touch: u32,
}

impl Tracked {
    /// A body no impulse has reached yet this step.
    pub(super) const UNTOUCHED: Tracked = Tracked {
        dlin: [0.0; 3],
        dang: [0.0; 3],
        support: [0.0; 3],
        touch: u32::MAX,
    };
}

/// A body pushed by the current object: its velocity change before the object and the
/// object's summed impulse on it.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Touched {
    /// Index of the body in this step's `bodies`.
    pub(super) body: u32,
    /// The body's linear velocity change (m/s) before this object's impulses.
    pub(super) dlin0: [f64; 3],
    /// The body's angular velocity change (rad/s) before this object's impulses.
    pub(super) dang0: [f64; 3],
    /// This object's summed linear impulse on the body (N·s).
    pub(super) p_lin: [f64; 3],
    /// This object's summed angular impulse about the body's centre of mass (N·m·s).
    pub(super) p_ang: [f64; 3],
    /// The body's (A, B) energy terms (`body_energy_terms`), once its impulses are summed.
    pub(super) energy: (f64, f64),
}

impl DcrWorld {
    /// Whether object `o`'s response runs this step: it is enabled and has impacts, or its
    /// carry-over filters still ring.
    pub(super) fn is_due(&self, o: usize) -> bool {
        let obj = &self.objects[o];
        obj.enabled && (!obj.impacts.is_empty() || obj.response.needs_step())
    }

    /// Runs object `o`'s response to its impacts (Eq. 9–16: a `Δv` per resting contact) and
    /// issues the impulses (Eq. 17–18, with the lateral kick and the support compensation),
    /// appending them to `events` and their velocity changes to `tracked`.
    pub(super) fn respond(&mut self, o: usize, bodies: &[BodyState]) {
        let step = self.step - 1;
        let obj = &mut self.objects[o];
        // Launch::SustainedPeak: Δv is a target for the body's normal velocity relative to the
        // object's rigid motion (the object's own body state, when it is dynamic).
        let target = obj.response.params().launch != Launch::PeakOverStep;
        let object_state = if target && obj.dynamic {
            self.body_index.get(&obj.body).map(|&i| bodies[i as usize])
        } else {
            None
        };
        if let Some(last) = obj.last_called {
            obj.response.skip_steps(step - last - 1);
        }
        obj.last_called = Some(step);
        obj.info.queried = true;
        self.info.queries += 1;
        let first_event = self.events.len();
        let mut supports = 0;
        let t0 = std::time::Instant::now();
        let out = obj.response.step(&obj.impacts, &obj.resting);
        obj.info.response_time_ns = t0.elapsed().as_nanos() as u64;
        self.touched.clear();
        for (resp, src) in out.iter().zip(&obj.sources) {
            let lateral = resp.lateral_delta_v != [0.0; 3];
            if !resp.mapped || !(resp.delta_v > 0.0 || lateral) || (target && !src.touching) {
                continue;
            }
            let b = &bodies[src.body as usize];
            let n = rotate(&obj.rot, resp.normal);
            let r = sub(src.point, b.center_of_mass);
            let t = &mut self.tracked[src.body as usize];
            let mut want = obj.gain * resp.delta_v;
            if target {
                let v_rel = sub(
                    velocity_at(Some(b), src.point),
                    velocity_at(object_state.as_ref(), src.point),
                );
                want -= dot(v_rel, n);
            }
            let (mut j, need) = normal_impulse(want, b, r, n, t);
            if lateral {
                let tw = rotate(&obj.rot, resp.lateral_delta_v);
                j = add_lateral_impulse(j, tw, obj.gain, b, r, t.dlin, t.dang);
            }
            if j == [0.0; 3] {
                continue;
            }
            if t.touch == u32::MAX {
                t.touch = self.touched.len() as u32;
                self.touched.push(Touched {
                    body: src.body,
                    dlin0: t.dlin,
                    dang0: t.dang,
                    ..Default::default()
                });
            }
            let tc = &mut self.touched[t.touch as usize];
            let rj = cross(r, j);
            tc.p_lin = add(tc.p_lin, j);
            tc.p_ang = add(tc.p_ang, rj);
            t.dlin = add(t.dlin, scale(j, b.inv_mass));
            t.dang = add(t.dang, mat_vec(&b.inv_inertia, rj));
            let event = ImpulseEvent {
                body: b.id,
                point: src.point,
                impulse: j,
                normal: n,
                delta_v: need,
                object: obj.handle,
                served_by: resp.served_by,
                contact: resp.id,
                chained: obj.depth > 0,
            };
            self.events.push(event);
            // Support compensation (WorldParams::gravity), once per body and step: the normal
            // velocity gravity takes off during the next step, at the centre of mass — for a
            // push that lifts the body off (Δv ≥ g_n h); a smaller one leaves it on its contact.
            let g_n = -dot(self.params.gravity, n);
            let gh = g_n * self.params.h;
            if gh > 0.0 && need >= gh && t.support == [0.0; 3] && b.inv_mass > 0.0 {
                let dv = scale(n, gh);
                let js = scale(dv, 1.0 / b.inv_mass);
                t.support = dv;
                t.dlin = add(t.dlin, dv);
                tc.p_lin = add(tc.p_lin, js);
                self.events.push(ImpulseEvent {
                    point: b.center_of_mass,
                    impulse: js,
                    delta_v: 0.0,
                    ..event
                });
                supports += 1;
            }
        }
        obj.info.response = obj.response.last_step_info();
        obj.info.events = (self.events.len() - first_event - supports) as u32;
    }
}

/// The normal part of a resting contact's impulse (N·s, world) and the velocity change it asks
/// for (m/s): the `Δv` (`want_dv`, gain applied) not yet produced at the point along unit `n` by
/// the impulses already issued to body `b` this step (`t`; their support is not a response),
/// times Eq. 17's effective mass. Zero when that is already reached or the body is immovable.
#[inline]
fn normal_impulse(
    want_dv: f64,
    b: &BodyState,
    r: [f64; 3],
    n: [f64; 3],
    t: &Tracked,
) -> ([f64; 3], f64) {
    let achieved = dot(sub(add(t.dlin, cross(t.dang, r)), t.support), n);
    let want = want_dv - achieved;
    if want > 0.0 {
        let m_eff = effective_mass(b.inv_mass, b.inv_inertia, r, n);
        if m_eff > 0.0 {
            return (scale(n, m_eff * want), want);
        }
    }
    ([0.0; 3], 0.0)
}
