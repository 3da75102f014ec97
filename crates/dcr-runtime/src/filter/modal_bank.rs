//! [`ModalBank`]: m independent mode filters stepped together (paper Eq. 10), state (q, q̇).

use super::ModeFilter;

/// A bank of m mode filters sharing one period T, stored structure-of-arrays for SIMD.
///
/// State per mode: q (kg^1/2·m) and q̇ (kg^1/2·m/s). One sample advances the exact transition
/// `[q, q̇] ← Φ(T) [q, q̇] + Γ(T) f` (Φ = [[φ, g], [−ω²g, ġ]], Γ = [(1 − φ)/ω², g]) with the
/// reduced force f (kg^1/2·m/s²) held constant over the sample (zero-order hold); an impulse r
/// (kg^1/2·m/s) adds to q̇. Sampled outputs equal `g(kT)·r` (impulse) and the exact step
/// response (force), so a held force settles exactly at the static deflection f/ω².
#[derive(Clone, Debug)]
pub struct ModalBank {
    filters: Vec<ModeFilter>,
    phi: Vec<f64>,
    g: Vec<f64>,
    g_dot: Vec<f64>,
    step: Vec<f64>,
    omega2: Vec<f64>,
    q: Vec<f64>,
    qd: Vec<f64>,
}

impl ModalBank {
    /// A bank at rest for angular frequencies `omega` (rad/s), damping ratios `xi` and period T (s).
    ///
    /// # Panics
    /// If `omega` and `xi` differ in length.
    pub fn new(omega: &[f64], xi: &[f64], period: f64) -> ModalBank {
        assert_eq!(omega.len(), xi.len());
        let filters: Vec<ModeFilter> = omega
            .iter()
            .zip(xi)
            .map(|(&w, &x)| ModeFilter::new(w, x, period))
            .collect();
        let m = filters.len();
        ModalBank {
            phi: filters.iter().map(|f| f.phi).collect(),
            g: filters.iter().map(|f| f.g).collect(),
            g_dot: filters.iter().map(|f| f.g_dot).collect(),
            step: filters.iter().map(|f| f.step).collect(),
            omega2: omega.iter().map(|w| w * w).collect(),
            filters,
            q: vec![0.0; m],
            qd: vec![0.0; m],
        }
    }

    /// The per-mode coefficients.
    pub fn filters(&self) -> &[ModeFilter] {
        &self.filters
    }

    /// Modal displacements q (kg^1/2·m) at the current sample.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Modal velocities q̇ (kg^1/2·m/s) at the current sample.
    pub fn q_dot(&self) -> &[f64] {
        &self.qd
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.q.iter_mut().for_each(|x| *x = 0.0);
        self.qd.iter_mut().for_each(|x| *x = 0.0);
    }

    /// Applies a reduced impulse `r` (length m) at the current instant: q̇ += r.
    pub fn apply_impulse(&mut self, r: &[f64]) {
        for (v, x) in self.qd.iter_mut().zip(r) {
            *v += x;
        }
    }

    /// Advances `samples` periods with the reduced force `force` (length m, or `None` for zero)
    /// held constant, writing q after each sample into row k of `table` (row-major
    /// `samples × m`). Does not allocate.
    ///
    /// # Panics
    /// If `table` is shorter than `samples × m`.
    pub fn run(&mut self, samples: usize, force: Option<&[f64]>, table: &mut [f64]) {
        let m = self.q.len();
        for row in table[..samples * m].chunks_exact_mut(m) {
            match force {
                None => {
                    for j in 0..m {
                        let (q, v) = (self.q[j], self.qd[j]);
                        self.q[j] = self.phi[j] * q + self.g[j] * v;
                        self.qd[j] = self.g_dot[j] * v - self.omega2[j] * self.g[j] * q;
                    }
                }
                Some(f) => {
                    for j in 0..m {
                        let (q, v) = (self.q[j], self.qd[j]);
                        self.q[j] = self.phi[j] * q + self.g[j] * v + self.step[j] * f[j];
                        self.qd[j] =
                            self.g_dot[j] * v - self.omega2[j] * self.g[j] * q + self.g[j] * f[j];
                    }
                }
            }
            row.copy_from_slice(&self.q);
        }
    }

    /// Sets the state directly (lengths m): used to restore a state computed elsewhere.
    pub fn set_state(&mut self, q: &[f64], q_dot: &[f64]) {
        self.q.copy_from_slice(q);
        self.qd.copy_from_slice(q_dot);
    }

    /// Scales the state (q, q̇) by `s`: the modal energy by s², the phase of every mode kept.
    pub fn scale_state(&mut self, s: f64) {
        self.q.iter_mut().for_each(|x| *x *= s);
        self.qd.iter_mut().for_each(|x| *x *= s);
    }

    /// Modal energy ½ Σ (q̇² + ω² q²) (J for the mass-normalised base: kg·m²/s²).
    pub fn energy(&self) -> f64 {
        0.5 * self
            .q
            .iter()
            .zip(&self.qd)
            .zip(&self.omega2)
            .map(|((q, v), w2)| v * v + w2 * q * q)
            .sum::<f64>()
    }
}
