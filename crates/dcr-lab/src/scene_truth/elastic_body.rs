//! [`ElasticBody`]: the elastic object of a coupled run as the sum over its elastic modes, each
//! advanced exactly over a step under a force held constant during the step.
//!
//! Mode j (M-orthonormal, ω_j² = λ_j, ξ_j = ½(α0/ω_j + α1 ω_j), paper Eq. 8) obeys
//! q̈ + 2ξω q̇ + ω² q = r with r = φ_jᵀ f. With g the impulse response (g(0) = 0, ġ(0) = 1) the
//! exact transition over a step h is
//! q⁺ = (ġ + 2ξω g) q + g q̇ + (r/ω²)(1 − ġ − 2ξω g),  q̇⁺ = −ω² g q + ġ q̇ + r g,
//! in every damping regime (ξ < 1, = 1, > 1). The modal integration adds no error of its own:
//! what the step changes is only how often the contact forces are sampled.

use modal_bake::full_order::{FullOrderSystem, ModalAll};

/// The elastic object's modal state and the rows of its modes at the surface vertices.
#[derive(Clone, Debug)]
pub struct ElasticBody {
    /// ω_j (rad/s) of the modes kept, ascending.
    pub omega: Vec<f64>,
    /// Modal displacement q_j (m·kg^½).
    pub q: Vec<f64>,
    /// Modal velocity q̇_j.
    pub qd: Vec<f64>,
    /// Per-step transition coefficients per mode: [c, g, ġ, forced q, forced q̇] (see the module doc).
    coef: Vec<[f64; 5]>,
    /// Φ rows at the surface vertices: `rows[(s·3 + axis)·m + j]` (m·kg^-½); zero for fixed dofs.
    rows: Vec<f64>,
    /// Number of modes.
    m: usize,
    /// The modal force accumulated for the next step (N per unit modal mass).
    force: Vec<f64>,
    /// The forced-q coefficient of each mode, contiguous (`coef[j][3]`, the step compliance's
    /// weight).
    weight: Vec<f64>,
}

/// `Σ_j a_j b_j w_j` with eight independent partial sums (the compiler vectorises them; a
/// single running sum is bound by the adder's latency).
fn weighted_dot(a: &[f64], b: &[f64], w: &[f64]) -> f64 {
    const L: usize = 8;
    let n = a.len().min(b.len()).min(w.len());
    let (a, b, w) = (&a[..n], &b[..n], &w[..n]);
    let mut acc = [0.0f64; L];
    let (ac, bc, wc) = (a.chunks_exact(L), b.chunks_exact(L), w.chunks_exact(L));
    let tail: f64 = ac
        .remainder()
        .iter()
        .zip(bc.remainder())
        .zip(wc.remainder())
        .map(|((x, y), z)| x * y * z)
        .sum();
    for ((x, y), z) in ac.zip(bc).zip(wc) {
        for k in 0..L {
            acc[k] += x[k] * y[k] * z[k];
        }
    }
    acc.iter().sum::<f64>() + tail
}

impl ElasticBody {
    /// The lowest `modes` elastic modes of `all` (all if `None`), at rest, rows taken at the
    /// surface vertices of `sys`, stepped with `dt` (s) under Rayleigh `rayleigh`.
    pub fn new(
        sys: &FullOrderSystem,
        all: &ModalAll,
        modes: Option<usize>,
        rayleigh: [f64; 2],
        dt: f64,
    ) -> ElasticBody {
        let m = modes.unwrap_or(usize::MAX).min(all.eigenvalues.len());
        let omega: Vec<f64> = all.eigenvalues[..m]
            .iter()
            .map(|l| l.max(0.0).sqrt())
            .collect();
        let ns = sys.surface.surface_to_volume.len();
        let mut rows = vec![0.0; ns * 3 * m];
        for (s, &v) in sys.surface.surface_to_volume.iter().enumerate() {
            for axis in 0..3 {
                if let Some(i) = sys.map.free_index(3 * v + axis) {
                    let dst = &mut rows[(s * 3 + axis) * m..(s * 3 + axis + 1) * m];
                    for (j, d) in dst.iter_mut().enumerate() {
                        *d = all.vectors[(i, j)];
                    }
                }
            }
        }
        let coef: Vec<[f64; 5]> = omega
            .iter()
            .map(|&w| transition(w, damping(w, rayleigh), dt))
            .collect();
        let weight = coef.iter().map(|c| c[3]).collect();
        ElasticBody {
            weight,
            q: vec![0.0; m],
            qd: vec![0.0; m],
            force: vec![0.0; m],
            omega,
            coef,
            rows,
            m,
        }
    }

    /// Number of modes.
    pub fn modes(&self) -> usize {
        self.m
    }

    /// The three axis rows (x, y, z, object frame) of the surface point (`verts`, `bary`):
    /// `Σ_i b_i Φ[(v_i, a), ·]`, concatenated (length 3m).
    pub fn axis_rows(&self, verts: [u32; 3], bary: [f64; 3]) -> Vec<f64> {
        let m = self.m;
        let mut out = vec![0.0; 3 * m];
        for (vi, b) in verts.iter().zip(bary) {
            for axis in 0..3 {
                let r = &self.rows[(*vi as usize * 3 + axis) * m..][..m];
                for (o, x) in out[axis * m..(axis + 1) * m].iter_mut().zip(r) {
                    *o += b * x;
                }
            }
        }
        out
    }

    /// Displacement (m) and velocity (m/s) along `d` (object frame) of the point whose
    /// [`ElasticBody::axis_rows`] are `rows`.
    pub fn motion_along(&self, rows: &[f64], d: [f64; 3]) -> (f64, f64) {
        let m = self.m;
        let (mut u, mut v) = (0.0, 0.0);
        for (axis, da) in d.iter().enumerate() {
            if *da == 0.0 {
                continue;
            }
            let r = &rows[axis * m..(axis + 1) * m];
            let (mut du, mut dv) = (0.0, 0.0);
            for ((x, q), qd) in r.iter().zip(&self.q).zip(&self.qd) {
                du += x * q;
                dv += x * qd;
            }
            u += da * du;
            v += da * dv;
        }
        (u, v)
    }

    /// Adds a force `f` (N, object frame) at the point whose [`ElasticBody::axis_rows`] are
    /// `rows` to the next step's load (Eq. 9 with the force).
    pub fn add_force_rows(&mut self, rows: &[f64], f: [f64; 3]) {
        let m = self.m;
        for (axis, fa) in f.iter().enumerate() {
            if *fa == 0.0 {
                continue;
            }
            let r = &rows[axis * m..(axis + 1) * m];
            for (acc, x) in self.force.iter_mut().zip(r) {
                *acc += fa * x;
            }
        }
    }

    /// The modal row of the surface point whose [`ElasticBody::axis_rows`] are `rows` along the
    /// unit direction `d` (object frame): `Σ_a d_a rows_a`, written into `out` (length m).
    pub fn normal_row(&self, rows: &[f64], d: [f64; 3], out: &mut [f64]) {
        let m = self.m;
        out.fill(0.0);
        for (axis, da) in d.iter().enumerate() {
            if *da == 0.0 {
                continue;
            }
            for (o, x) in out.iter_mut().zip(&rows[axis * m..(axis + 1) * m]) {
                *o += da * x;
            }
        }
    }

    /// Along a [`ElasticBody::normal_row`] `r`: the displacement now (m), the velocity now
    /// (m/s) and the displacement at the end of the next step (m) under the force accumulated
    /// so far, `Σ_j r_j (c_j q_j + g_j q̇_j + F_j r̃_j)` (module doc, F_j the forced-q coefficient).
    pub fn motion_normal(&self, r: &[f64]) -> (f64, f64, f64) {
        let (mut u, mut v, mut e) = (0.0, 0.0, 0.0);
        for j in 0..self.m {
            let [c, g, _, fq, _] = self.coef[j];
            let (q, qd) = (self.q[j], self.qd[j]);
            u += r[j] * q;
            v += r[j] * qd;
            e += r[j] * (c * q + g * qd + fq * self.force[j]);
        }
        (u, v, e)
    }

    /// The step compliance between two points (m/N): the displacement along `ra` at the end of
    /// the next step per unit force held along `rb` during it, `Σ_j ra_j rb_j (1 − c_j)/ω_j²`
    /// (for an undamped mode `(1 − cos ω_j Δt)/ω_j²`). Symmetric and positive semi-definite
    /// over any set of points.
    pub fn step_compliance(&self, ra: &[f64], rb: &[f64]) -> f64 {
        weighted_dot(ra, rb, &self.weight)
    }

    /// Adds a force of `s` N along the [`ElasticBody::normal_row`] `r` to the next step's load.
    pub fn add_force_normal(&mut self, r: &[f64], s: f64) {
        for (acc, x) in self.force.iter_mut().zip(r) {
            *acc += s * x;
        }
    }

    /// Advances every mode by one step under the accumulated force, then clears it.
    pub fn step(&mut self) {
        for j in 0..self.m {
            let [c, g, gd, fq, fv] = self.coef[j];
            let w2 = self.omega[j] * self.omega[j];
            let (q, v, r) = (self.q[j], self.qd[j], self.force[j]);
            self.q[j] = c * q + g * v + fq * r;
            self.qd[j] = -w2 * g * q + gd * v + fv * r;
            self.force[j] = 0.0;
        }
    }

    /// Elastic energy ½ Σ (q̇² + ω² q²) (J).
    pub fn energy(&self) -> f64 {
        0.5 * self
            .q
            .iter()
            .zip(&self.qd)
            .zip(&self.omega)
            .map(|((q, v), w)| v * v + w * w * q * q)
            .sum::<f64>()
    }
}

fn damping(omega: f64, rayleigh: [f64; 2]) -> f64 {
    if omega > 0.0 {
        dcr_runtime::filter::damping_ratio(omega, rayleigh)
    } else {
        0.0
    }
}

/// [c, g, ġ, forced q, forced q̇] of one mode over `dt` (module doc): c = ġ + 2ξω g.
fn transition(omega: f64, xi: f64, dt: f64) -> [f64; 5] {
    let (g, gd) = impulse_response(omega, xi, dt);
    let c = gd + 2.0 * xi * omega * g;
    let fq = if omega > 0.0 {
        (1.0 - c) / (omega * omega)
    } else {
        0.5 * dt * dt
    };
    [c, g, gd, fq, g]
}

/// g(t) and ġ(t) of q̈ + 2ξω q̇ + ω² q = δ(t) (unit modal mass).
fn impulse_response(omega: f64, xi: f64, t: f64) -> (f64, f64) {
    if omega == 0.0 {
        return (t, 1.0);
    }
    let a = xi * omega;
    if (xi - 1.0).abs() < 1e-9 {
        let e = (-omega * t).exp();
        (t * e, (1.0 - omega * t) * e)
    } else if xi < 1.0 {
        let wd = omega * (1.0 - xi * xi).sqrt();
        let e = (-a * t).exp();
        let (s, c) = (wd * t).sin_cos();
        (e * s / wd, e * (c - a * s / wd))
    } else {
        let r = omega * (xi * xi - 1.0).sqrt();
        let (s1, s2) = (-a + r, -a - r);
        let (e1, e2) = ((s1 * t).exp(), (s2 * t).exp());
        ((e1 - e2) / (s1 - s2), (s1 * e1 - s2 * e2) / (s1 - s2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eight-way sum equals the plain sum (to rounding) at every length, tails included.
    #[test]
    fn weighted_dot_is_the_plain_sum() {
        for n in [0usize, 1, 7, 8, 9, 31, 1000] {
            let a: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 1.13).cos()).collect();
            let w: Vec<f64> = (0..n).map(|i| 1.0 / (1.0 + i as f64)).collect();
            let plain: f64 = (0..n).map(|i| a[i] * b[i] * w[i]).sum();
            let scale: f64 = (0..n).map(|i| (a[i] * b[i] * w[i]).abs()).sum::<f64>() + 1e-300;
            assert!(
                (weighted_dot(&a, &b, &w) - plain).abs() <= 1e-14 * scale,
                "n {n}"
            );
        }
    }

    /// The transition reproduces the closed-form free response and the static deflection of a
    /// held force, in each damping regime, over many steps.
    #[test]
    fn transition_matches_closed_form() {
        for &xi in &[0.0, 0.3, 1.0, 2.5] {
            let (w, dt, n) = (7.0, 0.013, 50);
            let [c, g, gd, fq, fv] = transition(w, xi, dt);
            // Free response from q = 0, q̇ = 1 equals g(t).
            let (mut q, mut v) = (0.0, 1.0);
            for _ in 0..n {
                let qn = c * q + g * v;
                v = -w * w * g * q + gd * v;
                q = qn;
            }
            let (ge, gde) = impulse_response(w, xi, n as f64 * dt);
            assert!((q - ge).abs() < 1e-10 && (v - gde).abs() < 1e-10, "ξ {xi}");
            // A held force r from rest: q(t) = (r/ω²)(1 − ġ − 2ξω g).
            let (mut q, mut v, r) = (0.0, 0.0, 3.0);
            for _ in 0..n {
                let qn = c * q + g * v + fq * r;
                v = -w * w * g * q + gd * v + fv * r;
                q = qn;
            }
            let want = r / (w * w) * (1.0 - gde - 2.0 * xi * w * ge);
            assert!((q - want).abs() < 1e-10, "ξ {xi}: {q} vs {want}");
        }
    }
}
