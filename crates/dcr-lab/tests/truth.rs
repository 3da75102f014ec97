//! Full-order truth: the two independent methods agree, and the sum over the lowest modes
//! equals a baked base read through the runtime (conventions: mapping, normals, weights,
//! direction, mass normalisation).
//!
//! Run with `cargo test --release -p dcr-lab --test truth`.

use std::sync::Arc;

use dcr_lab::truth::{run_truth, SystemParams, TruthImpact, TruthMethod, TruthParams};
use dcr_runtime::filter::{damping_ratio, ModeFilter};
use dcr_runtime::ModalModel;
use modal_bake::bake::{bake_mesh, BakeParams, MaterialSi, ModeRequest};
use modal_bake::mesh::TetMesh;

/// 1 m × 0.2 m × 0.15 m: a rectangular section, so bending pairs are not degenerate and "the
/// lowest 20 modes" is one well-defined subspace.
fn cantilever() -> TetMesh {
    TetMesh::structured_box([8, 2, 2], [1.0, 0.2, 0.15])
}

const CONTACTS: [[f64; 3]; 4] = [
    [0.5, 0.1, 0.15],
    [0.75, 0.2, 0.1],
    [1.0, 0.05, 0.15],
    [0.3, 0.0, 0.05],
];

fn impact() -> TruthImpact {
    TruthImpact {
        point: [0.9, 0.12, 0.2],
        impulse: 2.0,
        direction: None,
    }
}

fn params(fixed: bool, method: TruthMethod) -> TruthParams {
    TruthParams {
        system: SystemParams {
            fixed: if fixed { vec!["xmin".into()] } else { vec![] },
            ..Default::default()
        },
        h: 0.005,
        dt: 1e-6,
        method,
        ..Default::default()
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Newmark (β = ¼, γ = ½, Δt = 1 µs) and the all-mode sum agree to 1 % on every contact peak
/// of a clamped cantilever, and the response is not trivially zero.
#[test]
fn newmark_matches_modal_all_clamped() {
    let nm = run_truth(
        cantilever(),
        &params(true, TruthMethod::Newmark),
        &impact(),
        &CONTACTS,
        "c",
        &mut |_| {},
    )
    .unwrap();
    let ma = run_truth(
        cantilever(),
        &params(true, TruthMethod::ModalAll),
        &impact(),
        &CONTACTS,
        "c",
        &mut |_| {},
    )
    .unwrap();
    for (a, b) in nm.contacts.iter().zip(&ma.contacts) {
        assert!(b.peak_displacement_m > 1e-9, "{b:?}");
        let e = rel(a.peak_displacement_m, b.peak_displacement_m);
        println!(
            "newmark {:.6e}  modal-all {:.6e}  rel {:.2e}",
            a.peak_displacement_m, b.peak_displacement_m, e
        );
        assert!(e < 0.01, "newmark {a:?} vs modal-all {b:?}: {e:.3e}");
        assert_eq!((a.triangle, a.bary), (b.triangle, b.bary));
    }
}

/// Free-free: both methods report the elastic displacement (rigid part projected out) and agree.
#[test]
fn newmark_matches_modal_all_free_free() {
    let nm = run_truth(
        cantilever(),
        &params(false, TruthMethod::Newmark),
        &impact(),
        &CONTACTS,
        "c",
        &mut |_| {},
    )
    .unwrap();
    let ma = run_truth(
        cantilever(),
        &params(false, TruthMethod::ModalAll),
        &impact(),
        &CONTACTS,
        "c",
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(ma.info.rigid_modes_dropped, 6);
    for (a, b) in nm.contacts.iter().zip(&ma.contacts) {
        let e = rel(a.peak_displacement_m, b.peak_displacement_m);
        println!(
            "newmark {:.6e}  modal-all {:.6e}  rel {:.2e}",
            a.peak_displacement_m, b.peak_displacement_m, e
        );
        assert!(e < 0.01, "newmark {a:?} vs modal-all {b:?}: {e:.3e}");
    }
}

/// Heavy Rayleigh damping (α1 = 1e-4 s: modes above ω = 2·10⁴ rad/s are overdamped, some near
/// critical): the per-regime impulse responses of the modal sum still match Newmark.
#[test]
fn newmark_matches_modal_all_overdamped() {
    let mut p = params(true, TruthMethod::Newmark);
    p.system.rayleigh = [200.0, 1e-4];
    let nm = run_truth(cantilever(), &p, &impact(), &CONTACTS, "c", &mut |_| {}).unwrap();
    p.method = TruthMethod::ModalAll;
    let ma = run_truth(cantilever(), &p, &impact(), &CONTACTS, "c", &mut |_| {}).unwrap();
    for (a, b) in nm.contacts.iter().zip(&ma.contacts) {
        let e = rel(a.peak_displacement_m, b.peak_displacement_m);
        println!(
            "newmark {:.6e}  modal-all {:.6e}  rel {:.2e}",
            a.peak_displacement_m, b.peak_displacement_m, e
        );
        assert!(e < 0.01, "newmark {a:?} vs modal-all {b:?}: {e:.3e}");
    }
}

/// The truncated sum (lowest 20 modes) equals a 20-mode base baked by `bake_mesh` and
/// evaluated through `dcr_runtime::ModalModel` (its projection, vertex normals, reduced impulse
/// and contact rows) with the exact filters at the same samples: to 1e-7 relative clamped,
/// 1e-5 free-free (the baked free-free modes carry the shift-invert rounding of the rigid block).
#[test]
fn modal_all_truncated_equals_baked_base() {
    for fixed in [true, false] {
        let p = TruthParams {
            modes: Some(20),
            ..params(fixed, TruthMethod::ModalAll)
        };
        let ma = run_truth(cantilever(), &p, &impact(), &CONTACTS, "c", &mut |_| {}).unwrap();
        assert_eq!(ma.info.modes_used, 20);
        let bp = BakeParams {
            material: MaterialSi {
                youngs: 1.1e9,
                poisson: 0.3,
                density: 770.0,
            },
            modes: ModeRequest::Count(20),
            fixed: p.system.fixed.clone(),
            ..Default::default()
        };
        let (base, _) = bake_mesh(cantilever(), &bp, "c", &mut |_| {}).unwrap();
        let model = Arc::new(ModalModel::from_base(base).unwrap());
        let m = model.num_modes();
        let isp = model.project(impact().point, 1.0).unwrap();
        let mut r = vec![0.0; m];
        model.add_reduced_impulse(&isp, isp.normal.map(|x| -x), impact().impulse, &mut r);
        // The samples the truth's refinement reached.
        let (steps, dt) = (ma.info.samples, ma.info.dt);
        assert!((dt * steps as f64 - p.h).abs() < 1e-12 * p.h);
        for (c, truth) in CONTACTS.iter().zip(&ma.contacts) {
            let sp = model.project(*c, 1.0).unwrap();
            let mut w = vec![0.0; m];
            model.contact_row(&sp, &mut w);
            let filters: Vec<ModeFilter> = model
                .omega()
                .iter()
                .map(|&om| ModeFilter::new(om, damping_ratio(om, p.system.rayleigh), dt))
                .collect();
            let mut peak = 0.0f64;
            for k in 1..=steps {
                let y: f64 = (0..m)
                    .map(|j| w[j] * r[j] * filters[j].impulse_response(k as f64 * dt))
                    .sum();
                peak = peak.max(y.abs());
            }
            let e = rel(truth.peak_displacement_m, peak);
            println!(
                "fixed {fixed}: truth(20) {:.9e}  base {:.9e}  rel {e:.2e}",
                truth.peak_displacement_m, peak
            );
            assert!(
                e < if fixed { 1e-7 } else { 1e-5 },
                "fixed {fixed}: {e:.3e}"
            );
            for k in 0..3 {
                assert!((sp.point[k] - truth.point[k]).abs() < 1e-12);
            }
        }
    }
}

/// Linearity in the impulse and Δv = peak/h.
#[test]
fn truth_is_linear_in_the_impulse() {
    let p = TruthParams {
        h: 0.002,
        dt: 1e-5,
        ..params(true, TruthMethod::Newmark)
    };
    let a = run_truth(cantilever(), &p, &impact(), &CONTACTS, "c", &mut |_| {}).unwrap();
    let big = TruthImpact {
        impulse: 2e6,
        ..impact()
    };
    let b = run_truth(cantilever(), &p, &big, &CONTACTS, "c", &mut |_| {}).unwrap();
    for (x, y) in a.contacts.iter().zip(&b.contacts) {
        assert!(rel(y.peak_displacement_m, 1e6 * x.peak_displacement_m) < 1e-9);
        assert!(rel(x.delta_v_mps, x.peak_displacement_m / p.h) < 1e-15);
    }
}

/// Extreme materials through the truth: E 1e13 Pa with ρ 1 kg/m³ (ω_max ≈ 1e8 rad/s, ωΔt ≫ 1
/// for the top modes at Δt = 1e-8 s) and E 1e3 Pa with ρ 2e4 (ω ≈ 1e-1 rad/s): finite, and
/// Newmark (unconditionally stable) agrees with the all-mode sum to 2 %.
#[test]
fn truth_extreme_materials_agree() {
    for (e, rho, h, dt) in [(1e13, 1.0, 2e-6, 1e-9), (1e3, 2e4, 20.0, 2e-3)] {
        let mut p = params(true, TruthMethod::Newmark);
        p.system.material = MaterialSi {
            youngs: e,
            poisson: 0.3,
            density: rho,
        };
        p.h = h;
        p.dt = dt;
        let nm = run_truth(cantilever(), &p, &impact(), &CONTACTS, "c", &mut |_| {}).unwrap();
        p.method = TruthMethod::ModalAll;
        let ma = run_truth(cantilever(), &p, &impact(), &CONTACTS, "c", &mut |_| {}).unwrap();
        for (a, b) in nm.contacts.iter().zip(&ma.contacts) {
            assert!(a.peak_displacement_m.is_finite() && b.peak_displacement_m > 0.0);
            let err = rel(a.peak_displacement_m, b.peak_displacement_m);
            println!(
                "E {e:e} ρ {rho}: newmark {:.6e} modal-all {:.6e} rel {err:.2e}",
                a.peak_displacement_m, b.peak_displacement_m
            );
            assert!(err < 0.02, "E {e:e}: {err:.3e}");
        }
    }
}

/// Static correction (residual flexibility) on a held force, heavily damped so the response
/// settles to the static deflection within the window: 20 modes + correction equal the
/// all-mode peak (= wᵀK⁻¹f) to 1e-4, while 20 modes alone are off by more than that.
#[test]
fn static_correction_recovers_static_deflection() {
    use modal_bake::full_order::{FullOrderSystem, ModalAll, ModalInput};
    let mut p = params(true, TruthMethod::ModalAll);
    p.system.rayleigh = [2000.0, 0.0];
    let sys = FullOrderSystem::new(cantilever(), &p.system, "c").unwrap();
    let ma = ModalAll::new(&sys, 6000).unwrap();
    let isp = sys.surface.project(impact().point).unwrap();
    let f = sys.load_vector(&isp, isp.normal.map(|x| -x), 100.0);
    let w: Vec<Vec<f64>> = CONTACTS
        .iter()
        .map(|c| ma.project(&sys.contact_row(&sys.surface.project(*c).unwrap())))
        .collect();
    let r = ma.project(&f);
    let (h, dt) = (0.1, 1e-5);
    let steps = (h / dt) as usize;
    let all = ma.response_peaks(
        &r,
        &w,
        p.system.rayleigh,
        dt,
        steps,
        None,
        ModalInput::Step,
        false,
    );
    let m20 = ma.response_peaks(
        &r,
        &w,
        p.system.rayleigh,
        dt,
        steps,
        Some(20),
        ModalInput::Step,
        false,
    );
    let c20 = ma.response_peaks(
        &r,
        &w,
        p.system.rayleigh,
        dt,
        steps,
        Some(20),
        ModalInput::Step,
        true,
    );
    for c in 0..CONTACTS.len() {
        println!(
            "all {:.6e}  20 {:.6e}  20+static {:.6e}",
            all[c], m20[c], c20[c]
        );
        assert!(
            rel(c20[c], all[c]) < 1e-4,
            "contact {c}: {} vs {}",
            c20[c],
            all[c]
        );
    }
    assert!((0..CONTACTS.len()).any(|c| rel(m20[c], all[c]) > 1e-3));
}

/// The truth checks itself: from a coarse step (1e-4 s, 50 samples over 5 ms) Newmark halves the
/// step until no peak changes by 0.5 % twice running, each level's step is half the previous one, and the
/// converged peaks match the all-mode sum at a fine step to well within the tolerance — while
/// the coarse single run is off by more, so the refinement is what makes them right.
#[test]
fn refinement_converges_and_reports_the_step() {
    use modal_bake::full_order::RefineParams;
    let coarse = TruthParams {
        dt: 1e-4,
        refine: RefineParams {
            max_refinements: 9,
            ..RefineParams::default()
        },
        ..params(true, TruthMethod::Newmark)
    };
    let run = run_truth(
        cantilever(),
        &coarse,
        &impact(),
        &CONTACTS,
        "c",
        &mut |_| {},
    )
    .unwrap();
    let c = &run.convergence;
    assert!(c.converged, "{c:?}");
    assert!(c.history.len() >= 3, "{c:?}");
    for w in c.history.windows(2) {
        assert!((w[1].dt - 0.5 * w[0].dt).abs() < 1e-12 * w[0].dt, "{c:?}");
    }
    // Converged means the last two changes are below the tolerance; the estimate is the larger.
    let n = c.history.len();
    let (a, b) = (
        c.history[n - 2].change_pct.unwrap(),
        c.history[n - 1].change_pct.unwrap(),
    );
    assert!(
        a < 0.5 && b < 0.5 && c.estimated_error_pct.unwrap() == a.max(b),
        "{c:?}"
    );
    assert!(c.history[1].change_pct.unwrap() >= 0.5);
    assert_eq!(run.info.dt, c.dt_reached);
    // The independent check ran (a small mesh) and agrees.
    let x = c.cross_check.as_ref().expect("cross-check on a small mesh");
    assert_eq!(x.method, "modal-all");
    assert!(x.max_diff_pct < 0.5, "{x:?}");
    let exact = TruthParams {
        dt: 2.5e-7,
        refine: RefineParams {
            max_refinements: 0,
            ..RefineParams::default()
        },
        ..params(true, TruthMethod::ModalAll)
    };
    let exact = run_truth(cantilever(), &exact, &impact(), &CONTACTS, "c", &mut |_| {}).unwrap();
    let single = TruthParams {
        refine: RefineParams {
            max_refinements: 0,
            ..RefineParams::default()
        },
        ..coarse
    };
    let single = run_truth(
        cantilever(),
        &single,
        &impact(),
        &CONTACTS,
        "c",
        &mut |_| {},
    )
    .unwrap();
    let worst = |r: &dcr_lab::truth::TruthResult| {
        r.contacts
            .iter()
            .zip(&exact.contacts)
            .map(|(a, b)| rel(a.peak_displacement_m, b.peak_displacement_m))
            .fold(0.0f64, f64::max)
    };
    assert!(worst(&run) < 0.005, "converged vs exact {}", worst(&run));
    assert!(worst(&single) > 0.005, "coarse vs exact {}", worst(&single));
}

/// A run that cannot meet its tolerance within its refinements says so: `converged` is false
/// and the last change is reported.
#[test]
fn unconverged_run_is_not_called_converged() {
    use modal_bake::full_order::RefineParams;
    let p = TruthParams {
        dt: 1e-4,
        refine: RefineParams {
            tolerance: 1e-9,
            max_refinements: 2,
            ..RefineParams::default()
        },
        ..params(true, TruthMethod::Newmark)
    };
    let run = run_truth(cantilever(), &p, &impact(), &CONTACTS, "c", &mut |_| {}).unwrap();
    let c = &run.convergence;
    assert!(!c.converged, "{c:?}");
    assert_eq!(c.history.len(), 3);
    assert!(c.last_change_pct.unwrap() > 1e-7);
}

/// Several impulses in one Newmark run (block back-solves with one factorization each of M and
/// K_eff) give each impulse's own peaks, free-free (the factors' solve paths differ) and
/// clamped.
#[test]
fn newmark_runs_several_impulses_as_one() {
    use modal_bake::full_order::{newmark_peaks, newmark_peaks_multi, FullOrderSystem};
    for fixed in [false, true] {
        let p = params(fixed, TruthMethod::Newmark);
        let sys = FullOrderSystem::new(cantilever(), &p.system, "c").unwrap();
        let rows: Vec<Vec<f64>> = CONTACTS
            .iter()
            .map(|c| sys.contact_row(&sys.surface.project(*c).unwrap()))
            .collect();
        let loads: Vec<Vec<f64>> = [[0.9, 0.12, 0.2], [0.2, 0.0, 0.1], [0.6, 0.2, 0.05]]
            .iter()
            .map(|x| {
                let s = sys.surface.project(*x).unwrap();
                sys.load_vector(&s, s.normal.map(|v| -v), 1.5)
            })
            .collect();
        let (all, _) = newmark_peaks_multi(&sys, &loads, &rows, 2e-6, 600).unwrap();
        for (f, got) in loads.iter().zip(&all) {
            let (one, _) = newmark_peaks(&sys, f, &rows, 2e-6, 600).unwrap();
            for (a, b) in got.iter().zip(&one) {
                assert!(rel(*a, *b) < 1e-12 && *b > 0.0, "fixed {fixed}: {a} vs {b}");
            }
        }
    }
}
