//! Per-mode IIR filters (paper Eq. 8–10) with the exact impulse-invariant discretisation of the
//! damped oscillator `q̈ + 2ξω q̇ + ω² q = r δ(t) + f(t)` (implementation notes §1), for the
//! underdamped, critical and overdamped regimes, plus the paper's sampling rule T = π/(2 ω_max).
//!
//! The bank steps the exact state transition of (q, q̇) — the same poles as the two-sample
//! recursion `q(k) = a1 q(k−1) − a2 q(k−2)` (a1, a2 are exposed on [`ModeFilter`]) but well
//! conditioned when ωT ≪ 1, so the sampled output equals the analytic `g(kT)·r` to ~k·ε; it also
//! yields the modal energy ½(q̇² + ω²q²) exactly.

mod modal_bank;
mod mode_filter;
mod sampling;

pub use modal_bank::ModalBank;
pub use mode_filter::{damping_ratio, ModeFilter};
pub use sampling::{samples_per_step, Sampling};

#[cfg(test)]
mod tests;
