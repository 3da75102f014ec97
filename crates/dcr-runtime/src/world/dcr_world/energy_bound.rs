//! The energy bound: per object and step, the kinetic energy its impulses inject,
//! `E_in = Σ_bodies (P·V + ½ PᵀM⁻¹P)`, is at most `η (D + R)` (D the energy the step's impacts
//! on the object dissipated, R what chained impulses gave its body); over it, every impulse of
//! the object is scaled by the largest s ∈ [0, 1] with `s A + s² B ≤ η (D + R)`. The rules and
//! the estimate of D are in [`DcrWorld`]'s documentation, "Energy bound". Under
//! [`Launch::SustainedPeak`] the budget also holds the object's modal energy at the step's end,
//! `η (D + R + E_modal)`: the ringing the props draw on; and what the step's impulses injected
//! is then drained from the carried filters ([`crate::DistantResponse::drain`]), so the
//! ringing pays for what it lifts: the pushes of later steps never take energy the filters no
//! longer hold.

use super::impulse_pass::Touched;
use super::DcrWorld;
use crate::math::{add, cross, dot, mat_vec, scale, sub};
use crate::response::{self, Launch};
use crate::world::{BodyState, ContactReport};

impl DcrWorld {
    /// Bounds the energy of object `o`'s impulses (the events from `first_event` on): sums
    /// each touched body's (A, B) terms, scales the events and the bodies' tracked velocity
    /// changes by s when `A + B > η (D + R)`, and records the energy injected; the energy given
    /// to a dynamic elastic object's body later in the order becomes that object's chain budget
    /// R. Clears the touched bodies' marks.
    pub(super) fn bound_energy(&mut self, o: usize, bodies: &[BodyState], first_event: usize) {
        let obj = &mut self.objects[o];
        let (mut a, mut bq) = (0.0, 0.0);
        for tc in &mut self.touched {
            let b = &bodies[tc.body as usize];
            tc.energy = body_energy_terms(b, tc);
            a += tc.energy.0;
            bq += tc.energy.1;
        }
        let requested = a + bq;
        // Launch::SustainedPeak draws on the ringing object: its modal energy counts too.
        let ringing = if obj.response.params().launch != Launch::PeakOverStep {
            obj.response.modal_energy()
        } else {
            0.0
        };
        let budget = self
            .params
            .energy_eta
            .map(|eta| eta * (obj.info.energy.dissipated + obj.info.energy.received + ringing));
        let s = match budget {
            Some(budget) if requested > budget => {
                self.info.energy_limited += 1;
                bound_scale(a, bq, budget)
            }
            _ => 1.0,
        };
        obj.info.energy.requested = requested;
        obj.info.energy.scale = s;
        if s != 1.0 {
            for e in &mut self.events[first_event..] {
                e.impulse = scale(e.impulse, s);
                e.delta_v *= s;
            }
        }
        let mut injected = 0.0;
        let depth = obj.depth;
        for tc in &self.touched {
            let b = &bodies[tc.body as usize];
            let t = &mut self.tracked[tc.body as usize];
            if s != 1.0 {
                t.dlin = add(tc.dlin0, scale(sub(t.dlin, tc.dlin0), s));
                t.dang = add(tc.dang0, scale(sub(t.dang, tc.dang0), s));
            }
            t.touch = u32::MAX;
            let (ea, eb) = tc.energy;
            let e_b = s * ea + s * s * eb;
            injected += e_b;
            if !self.any_dynamic {
                continue;
            }
            // Energy given to a dynamic elastic object's body: its chain budget.
            if let Some(target) = self.object_at(b.id) {
                if self.forward(o, target as usize, depth) {
                    self.objects[target as usize].info.energy.received += e_b.max(0.0);
                }
            }
        }
        let obj = &mut self.objects[o];
        obj.info.energy.injected = injected;
        // Launch::SustainedPeak: the ringing pays for the kinetic energy its pushes gave.
        if obj.response.params().launch != Launch::PeakOverStep {
            obj.response.drain(injected);
        }
    }
}

/// Velocity of body `b` at world point `p` (m/s; zero for a body without state).
#[inline]
pub(super) fn velocity_at(b: Option<&BodyState>, p: [f64; 3]) -> [f64; 3] {
    match b {
        Some(b) => add(b.linvel, cross(b.angvel, sub(p, b.center_of_mass))),
        None => [0.0; 3],
    }
}

/// Inverse effective mass `m⁻¹ + (r × n)ᵀ I⁻¹ (r × n)` (1/kg) of body `b` at `p` along `n`
/// (Eq. 17's denominator, [`response::inverse_effective_mass`]), 0 for a body without state.
#[inline]
fn body_inverse_effective_mass(b: Option<&BodyState>, p: [f64; 3], n: [f64; 3]) -> f64 {
    match b {
        Some(b) => {
            response::inverse_effective_mass(b.inv_mass, b.inv_inertia, sub(p, b.center_of_mass), n)
        }
        None => 0.0,
    }
}

/// A contact's pair: `(k, u⁺)`, the inverse effective mass along the normal (1/kg) and the
/// separation speed after the step (m/s), from the reported body states (a body without a
/// state is immovable and at rest).
fn pair_terms(c: &ContactReport, bidx: [Option<u32>; 2], bodies: &[BodyState]) -> (f64, f64) {
    let b1 = bidx[0].map(|i| &bodies[i as usize]);
    let b2 = bidx[1].map(|i| &bodies[i as usize]);
    let u_plus = dot(
        sub(velocity_at(b2, c.point2), velocity_at(b1, c.point1)),
        c.normal,
    );
    let k = body_inverse_effective_mass(b1, c.point1, c.normal)
        + body_inverse_effective_mass(b2, c.point2, c.normal);
    (k, u_plus)
}

/// The normal speed at which a contact's bodies closed before its impulse (m/s): `k λ − u⁺`
/// ([`crate::world::ClassifyParams::min_approach_speed`]).
pub(super) fn approach_speed(
    c: &ContactReport,
    bidx: [Option<u32>; 2],
    bodies: &[BodyState],
) -> f64 {
    let (k, u_plus) = pair_terms(c, bidx, bodies);
    k * c.impulse - u_plus
}

/// Energy an impact dissipated (J): `max(0, ½ k λ² − λ u⁺)` (see [`DcrWorld`], "Energy bound").
pub(super) fn dissipated(c: &ContactReport, bidx: [Option<u32>; 2], bodies: &[BodyState]) -> f64 {
    let (k, u_plus) = pair_terms(c, bidx, bodies);
    let lambda = c.impulse;
    let lost = 0.5 * k * lambda * lambda - lambda * u_plus;
    if lost.is_finite() {
        lost.max(0.0)
    } else {
        0.0
    }
}

/// (A, B) of a body's kinetic-energy change `A + B` from the summed impulse of `tc`: A = P·V
/// with V the body's velocity before them (after the step plus earlier objects' impulses),
/// B = ½ PᵀM⁻¹P.
#[inline]
fn body_energy_terms(b: &BodyState, tc: &Touched) -> (f64, f64) {
    let v = add(b.linvel, tc.dlin0);
    let w = add(b.angvel, tc.dang0);
    let a = dot(tc.p_lin, v) + dot(tc.p_ang, w);
    let bq = 0.5
        * (b.inv_mass * dot(tc.p_lin, tc.p_lin) + dot(tc.p_ang, mat_vec(&b.inv_inertia, tc.p_ang)));
    (a, bq)
}

/// The largest s ∈ [0, 1] with `s a + s² b ≤ budget`, given `a + b > budget ≥ 0` and b ≥ 0.
fn bound_scale(a: f64, b: f64, budget: f64) -> f64 {
    let budget = budget.max(0.0);
    let s = if b > 0.0 {
        let disc = (a * a + 4.0 * b * budget).sqrt();
        if a >= 0.0 {
            // 2·budget / (a + √…): no cancellation.
            if a + disc > 0.0 {
                2.0 * budget / (a + disc)
            } else {
                0.0
            }
        } else {
            (disc - a) / (2.0 * b)
        }
    } else if a > 0.0 {
        budget / a
    } else {
        1.0
    };
    s.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::bound_scale;

    /// The scale meets the budget exactly (to rounding) and is the largest such.
    #[test]
    fn bound_scale_is_the_largest_root() {
        for &(a, b, budget) in &[
            (2.0, 1.0, 1.0),
            (0.0, 3.0, 0.5),
            (-1.0, 2.0, 0.1),
            (-1.0, 2.0, 0.0),
            (4.0, 0.0, 1.0),
            (1e-3, 1e3, 1e-6),
        ] {
            let s = bound_scale(a, b, budget);
            let e = s * a + s * s * b;
            assert!(
                e <= budget * (1.0 + 1e-12) + 1e-300,
                "{a} {b} {budget}: {e}"
            );
            let s2 = (s * (1.0 + 1e-9)).min(1.0) + 1e-12;
            assert!(
                s2 * a + s2 * s2 * b > budget,
                "{a} {b} {budget}: not the largest"
            );
        }
    }
}
