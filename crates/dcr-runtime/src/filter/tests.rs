//! Filter laws: the sampled bank output equals the analytic impulse / step response in every
//! damping regime; energy never grows; the notes' two-sample coefficients agree.

use super::*;

const XIS: [f64; 8] = [0.0, 0.01, 0.3, 0.999999, 1.0, 1.000001, 2.0, 10.0];
const WTS: [f64; 5] = [1e-4, 1e-2, 0.3, 1.0, 3.0];

/// Bank output after an impulse r equals r·g(kT) for k = 1..N to 1e-12 of its peak.
#[test]
fn impulse_response_is_exact_in_every_regime() {
    let omega = 37.0;
    let r = 1.7;
    for &xi in &XIS {
        for &wt in &WTS {
            let t = wt / omega;
            let n = 1000;
            let mut bank = ModalBank::new(&[omega], &[xi], t);
            bank.apply_impulse(&[r]);
            let mut out = vec![0.0; n];
            bank.run(n, None, &mut out);
            let f = bank.filters()[0];
            let exact: Vec<f64> = (1..=n)
                .map(|k| r * f.impulse_response(k as f64 * t))
                .collect();
            let peak = exact.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            assert!(peak > 0.0);
            for (k, (a, b)) in out.iter().zip(&exact).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-12 * peak,
                    "ξ={xi} ωT={wt} k={}: {a} vs {b} (peak {peak})",
                    k + 1
                );
            }
        }
    }
}

/// The closed forms themselves agree with a fine RK4 integration of q̈ + 2ξωq̇ + ω²q = 0 from
/// (0, 1) and (1, 0) (independent of the stable rewrites).
#[test]
fn closed_forms_match_rk4() {
    let omega = 5.0;
    for &xi in &XIS {
        let f = ModeFilter::new(omega, xi, 0.01);
        let rhs = |y: [f64; 2]| [y[1], -2.0 * xi * omega * y[1] - omega * omega * y[0]];
        for (y0, which) in [([0.0, 1.0], 0), ([1.0, 0.0], 1)] {
            let mut y = y0;
            let dt = 1e-5;
            let steps = 100_000; // t = 1 s
            for _ in 0..steps {
                let k1 = rhs(y);
                let k2 = rhs([y[0] + 0.5 * dt * k1[0], y[1] + 0.5 * dt * k1[1]]);
                let k3 = rhs([y[0] + 0.5 * dt * k2[0], y[1] + 0.5 * dt * k2[1]]);
                let k4 = rhs([y[0] + dt * k3[0], y[1] + dt * k3[1]]);
                for i in 0..2 {
                    y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                }
            }
            let exact = if which == 0 {
                f.impulse_response(1.0)
            } else {
                f.free_response(1.0)
            };
            let scale = if which == 0 { 1.0 / omega } else { 1.0 };
            assert!(
                (y[0] - exact).abs() <= 1e-9 * scale,
                "ξ={xi} which={which}: rk4 {} vs {exact}",
                y[0]
            );
        }
    }
}

/// A force held constant from rest follows the analytic step response and settles at F/ω².
#[test]
fn zero_order_hold_settles_at_static_deflection() {
    let omega = 37.0;
    let force = 2.5;
    for &xi in &XIS[1..] {
        for &wt in &WTS {
            let t = wt / omega;
            let f = ModeFilter::new(omega, xi, t);
            // Static gain of the notes' two-sample form is exact (1 − a1 + a2 formed directly
            // here, so the check loses ε/(ωT)²).
            let gain = (f.b1 + f.b2) / (1.0 - f.a1 + f.a2);
            let tol = 1e-9f64.max(1e-14 / (wt * wt));
            assert!(
                (gain * omega * omega - 1.0).abs() < tol,
                "ξ={xi} ωT={wt}: gain {gain}"
            );
            let n = 2000;
            let mut bank = ModalBank::new(&[omega], &[xi], t);
            let mut out = vec![0.0; n];
            bank.run(n, Some(&[force]), &mut out);
            let stat = force / (omega * omega);
            for (k, q) in out.iter().enumerate() {
                let exact = force * f.step_response((k + 1) as f64 * t);
                assert!(
                    (q - exact).abs() <= 1e-10 * stat,
                    "ξ={xi} ωT={wt} k={k}: {q} vs {exact}"
                );
            }
            // Long enough to settle: decay e^{-ξ' ω t} with the slow rate.
            let slow = if xi < 1.0 {
                xi * omega
            } else {
                omega / (xi + (xi * xi - 1.0).sqrt())
            };
            let horizon = 60.0 / slow;
            let extra = ((horizon / t) as usize).min(20_000_000);
            let mut one = [0.0];
            for _ in 0..extra {
                bank.run(1, Some(&[force]), &mut one);
            }
            if slow * (extra as f64 + n as f64) * t > 40.0 {
                assert!(
                    (one[0] - stat).abs() <= 1e-9 * stat,
                    "ξ={xi} ωT={wt}: settled {} vs {stat}",
                    one[0]
                );
            }
        }
    }
}

/// The notes' two-sample recursion q(k) = a1 q(k−1) − a2 q(k−2) (+ g(T) r at k = 1, or
/// b1 f + b2 f for a held force) reproduces the same samples (direct form: looser tolerance).
#[test]
fn two_sample_recursion_agrees() {
    let omega = 11.0;
    for &xi in &XIS {
        for &wt in &[1e-2, 0.3, 1.0, 3.0] {
            let f = ModeFilter::new(omega, xi, wt / omega);
            let (mut q1, mut q2) = (0.0, 0.0); // q(k-1), q(k-2)
            let (mut s1, mut s2) = (0.0, 0.0);
            let mut peak = 0.0f64;
            for k in 1..=300 {
                let q = f.a1 * q1 - f.a2 * q2 + if k == 1 { f.g } else { 0.0 };
                let s = f.a1 * s1 - f.a2 * s2 + f.b1 + if k == 1 { 0.0 } else { f.b2 };
                let t = k as f64 * f.period;
                peak = peak.max(q.abs());
                assert!(
                    (q - f.impulse_response(t)).abs() <= 1e-9 * peak.max(f.g.abs()),
                    "ξ={xi} ωT={wt} k={k}"
                );
                assert!(
                    (s - f.step_response(t)).abs() <= 1e-9 / (omega * omega),
                    "ξ={xi} ωT={wt} k={k}"
                );
                (q2, q1, s2, s1) = (q1, q, s1, s);
            }
        }
    }
}

/// A free-running bank's energy never grows (ξ ≥ 0), and is conserved for ξ = 0.
#[test]
fn free_energy_never_grows() {
    let omega = [3.0, 40.0, 400.0, 2000.0];
    for &xi in &XIS {
        let xis = [xi; 4];
        let mut bank = ModalBank::new(&omega, &xis, std::f64::consts::FRAC_PI_2 / 2000.0);
        bank.apply_impulse(&[1.0, -2.0, 0.5, 3.0]);
        let e0 = bank.energy();
        assert!((e0 - 0.5 * (1.0 + 4.0 + 0.25 + 9.0)).abs() < 1e-12);
        let mut prev = e0;
        let mut row = [0.0; 4];
        for _ in 0..20_000 {
            bank.run(1, None, &mut row);
            let e = bank.energy();
            assert!(
                e <= prev * (1.0 + 1e-12),
                "ξ={xi}: energy grew {prev} → {e}"
            );
            prev = e;
        }
        if xi == 0.0 {
            assert!(
                (prev - e0).abs() <= 1e-9 * e0,
                "undamped energy drifted {e0} → {prev}"
            );
        } else {
            assert!(prev < e0);
        }
    }
}

#[test]
fn samples_per_step_tolerates_rounding() {
    assert_eq!(samples_per_step(0.01, 0.01 / 20.0), 20);
    assert_eq!(samples_per_step(0.01, 0.01 / 20.0 * (1.0 + 1e-12)), 20);
    assert_eq!(samples_per_step(0.01, 0.01 / 20.0 * (1.0 + 1e-6)), 20);
    assert_eq!(samples_per_step(0.01, 0.01 / 20.0 * (1.0 - 1e-6)), 21);
    assert_eq!(samples_per_step(0.01, 1.0), 1);
}
