//! Filter sampling period T and the number of samples per rigid-body step S = ⌈h/T⌉.

use std::f64::consts::FRAC_PI_2;

/// How the filter period T is chosen (paper §4.2: T = π/(2 ω_max), four samples per period of the
/// highest kept mode).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Sampling {
    /// The paper's T = π/(2 ω_max) (ω_max in rad/s) (default).
    #[default]
    PaperT,
    /// T = π/(2 ω_max)/K with K ≥ 1 (finer peak search).
    Oversample(f64),
    /// T given in seconds.
    Substep(f64),
}

impl Sampling {
    /// Requested period T (s) for the highest angular frequency `omega_max` (rad/s); the period
    /// actually used is `h / samples_per_step(h, T)` (never longer).
    pub fn period(&self, omega_max: f64) -> f64 {
        match *self {
            Sampling::PaperT => FRAC_PI_2 / omega_max,
            Sampling::Oversample(k) => FRAC_PI_2 / omega_max / k,
            Sampling::Substep(t) => t,
        }
    }
}

/// S = ⌈h/T⌉ with a relative tolerance of 1e-9 (so h/T = 20.0000000001 gives 20), at least 1.
pub fn samples_per_step(h: f64, t: f64) -> usize {
    let x = h / t;
    let n = x.round();
    if n >= 1.0 && (x - n).abs() <= 1e-9 * x {
        n as usize
    } else {
        x.ceil().max(1.0) as usize
    }
}
