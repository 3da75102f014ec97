//! Runtime stability at the extremes, end to end through `DistantResponse`: up to 10⁵ filter
//! samples per step, damping ratios up to 100 (and exactly critical), impulses from 1e-12 to
//! 1e9 N·s. Each case: no panic, no NaN/Inf, and the peak equals a direct evaluation of
//! max_k |Σ_j w_j r_j g_j(kT)| (the modal sum at the same samples) to 1e-9 relative, or a
//! clear parameter error.
//!
//! Run with `cargo test --release -p dcr-runtime --test extremes`.

use std::sync::Arc;

use dcr_runtime::filter::{damping_ratio, samples_per_step, ModeFilter};
use dcr_runtime::response::{Impact, ParamsError, RestingContact, Sampling};
use dcr_runtime::{testing, DistantResponse, ModalModel, ResponseParams};

const HIT: [f64; 3] = [0.5, 0.3, 0.0];
const DOWN: [f64; 3] = [0.0, 0.0, -1.0];
const CONTACT: [f64; 3] = [0.9, 0.5, 0.0];

fn model() -> Arc<ModalModel> {
    Arc::new(ModalModel::from_base(testing::plate_base()).unwrap())
}

/// Direct modal sum at the runtime's samples (independent of its tables and peak kernel).
fn reference_peak(model: &ModalModel, rayleigh: [f64; 2], h: f64, t_req: f64, impulse: f64) -> f64 {
    let m = model.num_modes();
    let s = samples_per_step(h, t_req);
    let t = h / s as f64;
    let sp = model.project(HIT, 1.0).unwrap();
    let cp = model.project(CONTACT, 1.0).unwrap();
    let (mut r, mut w) = (vec![0.0; m], vec![0.0; m]);
    model.add_reduced_impulse(&sp, DOWN, impulse, &mut r);
    model.contact_row(&cp, &mut w);
    let f: Vec<ModeFilter> = model
        .omega()
        .iter()
        .map(|&om| ModeFilter::new(om, damping_ratio(om, rayleigh), t))
        .collect();
    let mut peak = 0.0f64;
    for k in 1..=s {
        let y: f64 = (0..m)
            .map(|j| w[j] * r[j] * f[j].impulse_response(k as f64 * t))
            .sum();
        peak = peak.max(y.abs());
    }
    peak
}

fn run(params: ResponseParams, impulse: f64) -> f64 {
    let mut resp = DistantResponse::new(model(), params).unwrap();
    let out = resp.step(
        &[Impact {
            point: HIT,
            direction: DOWN,
            impulse,
        }],
        &[RestingContact {
            id: 1,
            point: CONTACT,
        }],
    );
    assert!(out[0].mapped);
    assert!(
        out[0].peak_displacement.is_finite() && out[0].delta_v.is_finite(),
        "{:?}",
        out[0]
    );
    out[0].peak_displacement
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// h/T from 1 to 10⁵ samples per step: finite, equal to the direct sum to 1e-9; h/T > 10⁶ is a
/// clear `TooManySamples` error at set-up, never a per-step failure.
#[test]
fn samples_per_step_up_to_1e5() {
    let rayleigh = testing::plate_base().rayleigh;
    let h = 0.01;
    for ratio in [1.0, 3.0, 20.0, 1e3, 1e4, 1e5] {
        let t = h / ratio;
        let p = ResponseParams {
            h,
            sampling: Sampling::Substep(t),
            ..Default::default()
        };
        let got = run(p, 2.0);
        let want = reference_peak(&model(), rayleigh, h, t, 2.0);
        assert!(want > 0.0);
        assert!(rel(got, want) <= 1e-9, "h/T = {ratio}: {got} vs {want}");
    }
    let p = ResponseParams {
        h,
        sampling: Sampling::Substep(h / 2e6),
        ..Default::default()
    };
    match DistantResponse::new(model(), p) {
        Err(ParamsError::TooManySamples { .. }) => {}
        other => panic!("expected TooManySamples, got {other:?}"),
    }
}

/// Damping ratios from 0 (undamped) through exactly critical to 100 (every mode heavily
/// overdamped): finite and equal to the direct sum to 1e-9; heavier damping never raises the
/// peak above the undamped one.
#[test]
fn damping_ratio_up_to_100() {
    let m = model();
    let omega = m.omega().to_vec();
    let (wmin, wmax) = (omega[0], *omega.last().unwrap());
    let h = 0.01;
    let undamped = run(
        ResponseParams {
            h,
            rayleigh: Some([0.0, 0.0]),
            ..Default::default()
        },
        2.0,
    );
    let cases: Vec<[f64; 2]> = vec![
        [0.0, 0.0],
        [0.0, 2.0 / omega[3]], // mode 3 exactly critical (ξ = ½·α1·ω = 1)
        [2.0 * wmin, 0.0],     // mode 0 critical via α0
        [0.0, 200.0 / wmax],   // ξ = 100 at ω_max, ≥ 6 everywhere
        [200.0 * wmin, 200.0 / wmax], // ξ ≥ 100 for every mode
    ];
    for rayleigh in cases {
        let xis: Vec<f64> = omega.iter().map(|&w| damping_ratio(w, rayleigh)).collect();
        let got = run(
            ResponseParams {
                h,
                rayleigh: Some(rayleigh),
                ..Default::default()
            },
            2.0,
        );
        let t = Sampling::PaperT.period(wmax);
        let want = reference_peak(&m, rayleigh, h, t, 2.0);
        assert!(
            rel(got, want) <= 1e-9,
            "rayleigh {rayleigh:?} (ξ {xis:?}): {got} vs {want}"
        );
        assert!(
            got <= undamped * (1.0 + 1e-12),
            "rayleigh {rayleigh:?}: {got} > undamped {undamped}"
        );
        assert!(got > 0.0, "rayleigh {rayleigh:?}: zero response");
    }
}

/// Impulses from 1e-12 to 1e9 N·s (threshold 0): the peak is exactly linear (1e-12 relative)
/// and finite; a non-finite impulse is ignored, never propagated.
#[test]
fn impulse_range_is_linear() {
    let h = 0.01;
    let p = || ResponseParams {
        h,
        impact_threshold: 0.0,
        ..Default::default()
    };
    let unit = run(p(), 1.0);
    for lambda in [1e-12, 1e-9, 1e-6, 1e-3, 1e3, 1e6, 1e9] {
        let got = run(p(), lambda);
        assert!(
            rel(got / lambda, unit) <= 1e-12,
            "λ = {lambda:e}: {got} vs {}",
            unit * lambda
        );
    }
    let mut resp = DistantResponse::new(model(), p()).unwrap();
    for bad in [f64::NAN, f64::INFINITY, -1.0] {
        let out = resp.step(
            &[Impact {
                point: HIT,
                direction: DOWN,
                impulse: bad,
            }],
            &[RestingContact {
                id: 1,
                point: CONTACT,
            }],
        );
        assert_eq!(out[0].peak_displacement, 0.0, "impulse {bad}");
        assert_eq!(resp.last_step_info().impacts_below_threshold, 1);
    }
}

/// The corners at once: ξ = 100, 10⁵ samples, 1e9 N·s and 1e-12 N·s.
#[test]
fn combined_extremes() {
    let m = model();
    let wmax = *m.omega().last().unwrap();
    let rayleigh = [200.0 * m.omega()[0], 200.0 / wmax];
    let h = 0.01;
    for lambda in [1e-12, 1e9] {
        let p = ResponseParams {
            h,
            rayleigh: Some(rayleigh),
            impact_threshold: 0.0,
            sampling: Sampling::Substep(h / 1e5),
            ..Default::default()
        };
        let got = run(p, lambda);
        let want = reference_peak(&m, rayleigh, h, h / 1e5, lambda);
        assert!(rel(got, want) <= 1e-9, "λ {lambda:e}: {got} vs {want}");
    }
}
