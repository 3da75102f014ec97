//! [`ModeFilter`]: exact discretisation of one mass-normalised damped mode (implementation notes
//! §1), in numerically stable forms (expm1 / half-angle) for every damping regime.

/// Rayleigh damping ratio ξ_j = ½(α0/ω_j + α1 ω_j) of a mode with angular frequency `omega`
/// (rad/s) for `rayleigh = [α0 (1/s), α1 (s)]`.
pub fn damping_ratio(omega: f64, rayleigh: [f64; 2]) -> f64 {
    0.5 * (rayleigh[0] / omega + rayleigh[1] * omega)
}

/// |ξ − 1| below which a mode is treated as critically damped. The stable forms used for the
/// other regimes stay accurate right down to this gap (they never divide by √|ξ² − 1| unguarded).
const CRITICAL_BAND: f64 = 1e-12;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Regime {
    /// ω_d = ω√(1 − ξ²).
    Under {
        wd: f64,
    },
    Critical,
    /// Real poles λ1 = −ω/(ξ + s) (slow), λ2 = −ω(ξ + s) (fast), Δ = λ1 − λ2 = 2ωs, s = √(ξ² − 1).
    Over {
        l1: f64,
        l2: f64,
        d: f64,
    },
}

/// One mode's exact sampled response over a period T (s): impulse response g, free response φ,
/// step response, the state-transition entries and the equivalent two-sample coefficients.
///
/// Mass-normalised: `q̈ + 2ξω q̇ + ω² q = u(t)`, q in kg^1/2·m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeFilter {
    /// Undamped angular frequency ω (rad/s).
    pub omega: f64,
    /// Damping ratio ξ ≥ 0.
    pub xi: f64,
    /// Sampling period T (s).
    pub period: f64,
    /// φ(T): free response from (q = 1, q̇ = 0) after T.
    pub phi: f64,
    /// g(T): impulse response (free response from q = 0, q̇ = 1) after T (s).
    pub g: f64,
    /// ġ(T) = φ(T) − 2ξω g(T).
    pub g_dot: f64,
    /// (1 − φ(T))/ω²: response to a unit force held over one period (s²).
    pub step: f64,
    /// Two-sample recursion coefficient a1 = z1 + z2 (Eq. 10).
    pub a1: f64,
    /// Two-sample recursion coefficient a2 = z1 z2 = e^{−2ξωT} (Eq. 10).
    pub a2: f64,
    /// Zero-order-hold input coefficient b1 = (1 − φ)/ω² (s²).
    pub b1: f64,
    /// Zero-order-hold input coefficient b2 = (a2 − a1 + φ)/ω² (s²), computed as
    /// `(1 − a1 + a2)/ω² − b1` with 1 − a1 + a2 = (1 − z1)(1 − z2) formed without cancellation.
    pub b2: f64,
    regime: Regime,
}

impl ModeFilter {
    /// Coefficients for angular frequency `omega` > 0 (rad/s), damping ratio `xi` ≥ 0 and
    /// period `period` > 0 (s).
    pub fn new(omega: f64, xi: f64, period: f64) -> ModeFilter {
        let regime = if (xi - 1.0).abs() < CRITICAL_BAND {
            Regime::Critical
        } else if xi < 1.0 {
            Regime::Under {
                wd: omega * ((1.0 - xi) * (1.0 + xi)).sqrt(),
            }
        } else {
            let s = ((xi - 1.0) * (xi + 1.0)).sqrt();
            Regime::Over {
                l1: -omega / (xi + s),
                l2: -omega * (xi + s),
                d: 2.0 * omega * s,
            }
        };
        let mut f = ModeFilter {
            omega,
            xi,
            period,
            phi: 0.0,
            g: 0.0,
            g_dot: 0.0,
            step: 0.0,
            a1: 0.0,
            a2: 0.0,
            b1: 0.0,
            b2: 0.0,
            regime,
        };
        let t = period;
        f.phi = f.free_response(t);
        f.g = f.impulse_response(t);
        f.g_dot = f.phi - 2.0 * xi * omega * f.g;
        f.step = f.one_minus_phi(t) / (omega * omega);
        f.a1 = f.phi + f.g_dot;
        f.a2 = (-2.0 * xi * omega * t).exp();
        // 1 − a1 + a2 = (1 − z1)(1 − z2).
        let one_m_a1_a2 = match regime {
            Regime::Under { wd } => {
                let e = (-xi * omega * t).exp();
                (-xi * omega * t).exp_m1().powi(2) + 4.0 * e * (0.5 * wd * t).sin().powi(2)
            }
            Regime::Critical => (-omega * t).exp_m1().powi(2),
            Regime::Over { l1, l2, .. } => (l1 * t).exp_m1() * (l2 * t).exp_m1(),
        };
        f.b1 = f.step;
        f.b2 = one_m_a1_a2 / (omega * omega) - f.b1;
        f
    }

    /// Analytic impulse response g(t) (s): response at time `t` ≥ 0 to a unit impulse at t = 0
    /// from rest (e^{−ξωt} sin(ω_d t)/ω_d, t e^{−ωt}, or (e^{λ1 t} − e^{λ2 t})/(λ1 − λ2)).
    pub fn impulse_response(&self, t: f64) -> f64 {
        match self.regime {
            Regime::Under { wd } => {
                let e = (-self.xi * self.omega * t).exp();
                if wd * t == 0.0 {
                    e * t
                } else {
                    e * (wd * t).sin() / wd
                }
            }
            Regime::Critical => t * (-self.omega * t).exp(),
            Regime::Over { l1, l2, d } => exp_difference(l1, l2, d, t) / d,
        }
    }

    /// Analytic free response φ(t) from (q = 1, q̇ = 0).
    pub fn free_response(&self, t: f64) -> f64 {
        let (xi, w) = (self.xi, self.omega);
        match self.regime {
            Regime::Under { wd } => {
                let e = (-xi * w * t).exp();
                let sinc = if wd * t == 0.0 {
                    t
                } else {
                    (wd * t).sin() / wd
                };
                e * ((wd * t).cos() + xi * w * sinc)
            }
            Regime::Critical => (-w * t).exp() * (1.0 + w * t),
            Regime::Over { l1, l2, d } => (l2 * t).exp() - l2 * exp_difference(l1, l2, d, t) / d,
        }
    }

    /// Analytic step response (1 − φ(t))/ω² (s²): response to a unit force switched on at t = 0.
    pub fn step_response(&self, t: f64) -> f64 {
        self.one_minus_phi(t) / (self.omega * self.omega)
    }

    fn one_minus_phi(&self, t: f64) -> f64 {
        let (xi, w) = (self.xi, self.omega);
        match self.regime {
            Regime::Under { wd } => {
                let e = (-xi * w * t).exp();
                let sinc = if wd * t == 0.0 {
                    t
                } else {
                    (wd * t).sin() / wd
                };
                -(-xi * w * t).exp_m1() + 2.0 * e * (0.5 * wd * t).sin().powi(2) - e * xi * w * sinc
            }
            Regime::Critical => -(-w * t).exp_m1() - w * t * (-w * t).exp(),
            Regime::Over { l1, l2, d } => (l2 * (l1 * t).exp_m1() - l1 * (l2 * t).exp_m1()) / d,
        }
    }
}

/// e^{λ1 t} − e^{λ2 t} (λ1 > λ2, Δ = λ1 − λ2) without cancellation when Δt is small and without
/// 0·∞ when λ2 t underflows.
fn exp_difference(l1: f64, l2: f64, d: f64, t: f64) -> f64 {
    if d * t < 1.0 {
        (l2 * t).exp() * (d * t).exp_m1()
    } else {
        (l1 * t).exp() - (l2 * t).exp()
    }
}
