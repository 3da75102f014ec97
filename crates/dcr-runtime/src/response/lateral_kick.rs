//! [`LateralKick`]: the tangential part of the distant response (paper §5.4, "lateral kick").
//!
//! The paper's response pushes resting bodies along the surface normal only and names the
//! tangential motion of the surface as the missing part. With the step's reduced impulse r
//! (Eq. 9) and the sampled impulse responses, q(k) = g(kT) ∘ r, the full displacement of a
//! contact point is `u(k) = W q(k)` with W the 3 × m interpolated mode rows
//! `Σ_i b_i U_i` (3 rows per vertex); its tangential part is `u_t(k) = u(k) − (n·u(k)) n`. The
//! kick is `Δv_t = u_t(k*) / h` at the sample k* of largest |u_t| (the tangential analogue of
//! Eq. 11–12). It is computed from the modal base whichever method serves the normal part,
//! with the filters at rest at the step's start (the reset mode of §4.5).

use super::step_ctx::StepCtx;
use super::Impact;
use crate::math::{dot, normalize};

/// Buffers of the lateral kick of one response.
#[derive(Debug)]
pub(crate) struct LateralKick {
    m: usize,
    samples: usize,
    /// g_j(kT), row-major S × m.
    g_table: Vec<f64>,
    r: Vec<f64>,
    /// This step's q(k), row-major S × m.
    q: Vec<f64>,
    /// One contact's interpolated rows, 3 × m (x, y, z).
    w: Vec<f64>,
}

impl LateralKick {
    /// Buffers over the impulse-response table `g_table` (row-major S × m).
    pub fn new(g_table: Vec<f64>, samples: usize, m: usize) -> LateralKick {
        LateralKick {
            m,
            samples,
            q: vec![0.0; g_table.len()],
            g_table,
            r: vec![0.0; m],
            w: vec![0.0; 3 * m],
        }
    }

    /// Sets `lateral_delta_v` (m/s, object frame) of the mapped responses in `ctx.out` from the
    /// step's applied `impacts` (same acceptance as the methods; not counted again).
    pub fn apply(&mut self, ctx: &mut StepCtx<'_>, impacts: &[Impact]) {
        let (m, model) = (self.m, ctx.model);
        self.r.iter_mut().for_each(|x| *x = 0.0);
        let mut any = false;
        for imp in impacts {
            let ok = ctx.applies(imp.impulse);
            if !ok {
                continue;
            }
            if let Some(sp) = model.project(imp.point, ctx.max_map) {
                model.add_reduced_impulse(&sp, normalize(imp.direction), imp.impulse, &mut self.r);
                any = true;
            }
        }
        if !any {
            return;
        }
        for (qk, gk) in self.q.chunks_exact_mut(m).zip(self.g_table.chunks_exact(m)) {
            for ((q, g), r) in qk.iter_mut().zip(gk).zip(&self.r) {
                *q = g * r;
            }
        }
        let modes = &model.base().modes;
        let h = ctx.params.h;
        let contacts = ctx.contacts;
        for (o, &s) in ctx.out.iter_mut().zip(contacts.slots()) {
            let Some(sp) = contacts.slot(s).surface.filter(|_| o.mapped) else {
                continue;
            };
            self.w.iter_mut().for_each(|x| *x = 0.0);
            for (i, v) in model.triangle(sp.triangle).into_iter().enumerate() {
                for axis in 0..3 {
                    let row = &modes[(v * 3 + axis) * m..(v * 3 + axis + 1) * m];
                    for (w, u) in self.w[axis * m..(axis + 1) * m].iter_mut().zip(row) {
                        *w += sp.bary[i] * u;
                    }
                }
            }
            o.lateral_delta_v = self.peak_tangential(sp.normal, h);
        }
    }

    /// `u_t(k*) / h` for the current rows `w` and samples `q`.
    fn peak_tangential(&self, n: [f64; 3], h: f64) -> [f64; 3] {
        let m = self.m;
        let (wx, rest) = self.w.split_at(m);
        let (wy, wz) = rest.split_at(m);
        let (mut best, mut best_ut) = (0.0, [0.0; 3]);
        for qk in self.q[..self.samples * m].chunks_exact(m) {
            let u = [dot_slice(wx, qk), dot_slice(wy, qk), dot_slice(wz, qk)];
            let un = dot(u, n);
            let ut = [u[0] - un * n[0], u[1] - un * n[1], u[2] - un * n[2]];
            let mag = dot(ut, ut);
            if mag > best {
                best = mag;
                best_ut = ut;
            }
        }
        best_ut.map(|x| x / h)
    }
}

#[inline]
fn dot_slice(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
