//! Fitting the spatial attenuation law (paper Eq. 14): the fitter recovers known parameters
//! from synthetic data, respects α, β ≥ 0, and on a small mesh the measured attenuation
//! (peak at the contact / local peak at the impact) decays with distance (β > 0) and agrees
//! with `run_truth` at the same points.
//!
//! Run with `cargo test --release -p dcr-lab --test fit_attenuation`.

use dcr_lab::attenuation_fit::{
    fit_attenuation_mesh, fit_eq14, fit_eq14_fixed_r0, fit_simplified, sample_attenuation,
    AttenuationFitParams, FitTruth, SurfaceResponse,
};
use dcr_lab::truth::{run_truth, CrossCheck, SystemParams, TruthImpact, TruthMethod, TruthParams};
use dcr_runtime::rng::SplitMix64;
use modal_bake::full_order::{FullOrderSystem, ModalAll, RefineParams};
use modal_bake::mesh::TetMesh;

/// Eq. 14.
fn eq14(r: f64, alpha: f64, beta: f64, r0: f64) -> f64 {
    (-alpha * (r - r0)).exp() * (r / r0).powf(-beta)
}

/// Distances 0.05 … 3 m (random, seeded) and s with multiplicative noise e^(σ·N(0,1)).
fn synthetic(alpha: f64, beta: f64, r0: f64, sigma: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut rng = SplitMix64(7);
    let r: Vec<f64> = (0..n).map(|_| 0.05 + 2.95 * rng.next_f64()).collect();
    let s = r
        .iter()
        .map(|&r| {
            // Box–Muller.
            let (u1, u2) = (rng.next_f64().max(1e-300), rng.next_f64());
            let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            eq14(r, alpha, beta, r0) * (sigma * z).exp()
        })
        .collect();
    (r, s)
}

#[test]
fn recovers_known_parameters_exactly_without_noise() {
    // The paper's scaffold fit (Fig. 10) and two other regimes.
    for (alpha, beta, r0) in [(0.048, 0.8, 0.033), (1.5, 0.5, 0.2), (0.0, 1.0, 0.05)] {
        let (r, s) = synthetic(alpha, beta, r0, 0.0, 200);
        let f = fit_eq14(&r, &s).unwrap();
        assert!((f.alpha - alpha).abs() < 1e-7, "{f:?}");
        assert!((f.beta - beta).abs() < 1e-7, "{f:?}");
        assert!((f.r0 - r0).abs() < 1e-7 * r0.max(1.0), "{f:?}");
        assert!(f.r2_log > 1.0 - 1e-12 && f.rms_log < 1e-8, "{f:?}");
        assert_eq!(f.n, 200);
    }
}

#[test]
fn recovers_known_parameters_from_noisy_samples() {
    // 10% log-normal scatter, 2000 samples: parameters within a few standard errors.
    let (alpha, beta, r0) = (0.5, 0.8, 0.033);
    let (r, s) = synthetic(alpha, beta, r0, 0.1, 2000);
    let f = fit_eq14(&r, &s).unwrap();
    assert!((f.alpha - alpha).abs() < 0.05, "{f:?}");
    assert!((f.beta - beta).abs() < 0.05, "{f:?}");
    assert!((f.r0 / r0 - 1.0).abs() < 0.15, "{f:?}");
    assert!((f.rms_log - 0.1).abs() < 0.01, "{f:?}");
    // The fitted law is what the runtime evaluates.
    let law = dcr_runtime::response::AttenuationLaw::Full {
        alpha: f.alpha,
        beta: f.beta,
        r0: f.r0,
    };
    assert!((law.factor(1.0) - f.factor(1.0)).abs() < 1e-12);
}

#[test]
fn fixed_r0_and_simplified_fits_recover_their_parameters() {
    let (r, s) = synthetic(0.3, 0.7, 0.1, 0.0, 100);
    let f = fit_eq14_fixed_r0(&r, &s, 0.1).unwrap();
    assert!(
        (f.alpha - 0.3).abs() < 1e-9 && (f.beta - 0.7).abs() < 1e-9,
        "{f:?}"
    );
    let s2: Vec<f64> = r.iter().map(|r| 0.6 * r.powf(-1.2)).collect();
    let g = fit_simplified(&r, &s2).unwrap();
    assert!(
        (g.c - 0.6).abs() < 1e-9 && (g.beta - 1.2).abs() < 1e-9,
        "{g:?}"
    );
}

#[test]
fn constraints_hold_when_data_grow_with_distance() {
    // s increasing with r: the unconstrained optimum has α < 0 or β < 0; the fit must not.
    let r: Vec<f64> = (1..50).map(|i| 0.05 * i as f64).collect();
    let s: Vec<f64> = r.iter().map(|r| 0.2 * (1.0 + r)).collect();
    let f = fit_eq14(&r, &s);
    if let Ok(f) = f {
        assert!(f.alpha >= 0.0 && f.beta >= 0.0 && f.r0 > 0.0, "{f:?}");
    }
    let g = fit_simplified(&r, &s).unwrap();
    assert!(g.beta >= 0.0);
}

#[test]
fn too_few_or_unusable_samples_are_errors() {
    assert!(fit_eq14(&[1.0, 2.0], &[0.5, 0.2]).is_err());
    assert!(fit_eq14(&[1.0, 2.0, 0.0, 3.0, 4.0], &[0.5, 0.0, 0.3, f64::NAN, 0.1]).is_err());
    assert!(fit_eq14_fixed_r0(&[1.0; 5], &[0.5; 5], -1.0).is_err());
}

/// A clamped slab (the ground's configuration at small size): 1 × 1 × 0.1 m, bottom fixed.
fn slab() -> TetMesh {
    TetMesh::structured_box([10, 10, 2], [1.0, 1.0, 0.1])
}

#[test]
fn measured_samples_match_run_truth_at_the_same_points() {
    // The fast sampler (modal rows + two-term recursion) equals the truth module's modal-all
    // sum for the same impact, contact, window and sample period.
    let tp = TruthParams {
        system: SystemParams {
            fixed: vec!["zmin".into()],
            ..Default::default()
        },
        h: 2e-3,
        method: TruthMethod::ModalAll,
        ..Default::default()
    };
    let sys = FullOrderSystem::new(slab(), &tp.system, "slab").unwrap();
    let ma = ModalAll::new(&sys, 6000).unwrap();
    let resp = SurfaceResponse::from_modal_all(&sys, &ma, None);
    let (samples, kind, dt, _) =
        sample_attenuation(&resp, tp.system.rayleigh, tp.h, None, 4, 3, &mut |_| {}).unwrap();
    assert_eq!(kind, "geodesic");
    for smp in &samples {
        // One run at exactly the sampler's period (no refinement), to compare like with like.
        let p = TruthParams {
            dt,
            refine: RefineParams {
                max_refinements: 0,
                ..RefineParams::default()
            },
            cross_check: CrossCheck::Off,
            ..tp.clone()
        };
        let imp = TruthImpact {
            point: smp.impact_point,
            impulse: 1.0,
            direction: None,
        };
        let t = run_truth(
            slab(),
            &p,
            &imp,
            &[smp.impact_point, smp.contact_point],
            "slab",
            &mut |_| {},
        )
        .unwrap();
        let (local, far) = (
            t.contacts[0].peak_displacement_m,
            t.contacts[1].peak_displacement_m,
        );
        assert!(
            (smp.local_peak_m / local - 1.0).abs() < 1e-6,
            "{smp:?} vs {local}"
        );
        assert!(
            (smp.contact_peak_m / far - 1.0).abs() < 1e-6,
            "{smp:?} vs {far}"
        );
        assert!((smp.distance_m - t.contacts[1].distance_m).abs() < 1e-9);
    }
}

#[test]
fn small_mesh_fit_is_finite_and_decays_with_distance() {
    let p = AttenuationFitParams {
        system: SystemParams {
            fixed: vec!["zmin".into()],
            material: dcr_lab::truth::MaterialSi {
                youngs: 10e9,
                poisson: 0.3,
                density: 500.0,
            },
            ..Default::default()
        },
        h: 5e-3,
        pairs: 60,
        seed: 11,
        ..Default::default()
    };
    let rep = fit_attenuation_mesh(slab(), &p, "slab", &mut |_| {}).unwrap();
    let f = rep.fit;
    assert!(
        f.alpha.is_finite() && f.beta.is_finite() && f.r0.is_finite(),
        "{f:?}"
    );
    assert!(f.beta > 0.0, "amplitude must decay with distance: {f:?}");
    assert!(f.r0 > 0.0 && f.r2_log.is_finite() && f.rms_log.is_finite());
    assert_eq!(rep.samples.len(), 60);
    assert_eq!(rep.info.method, "modal-all");
    // Same seed, same samples.
    let again = fit_attenuation_mesh(slab(), &p, "slab", &mut |_| {}).unwrap();
    assert_eq!(again.samples, rep.samples);
}

#[test]
fn sparse_truth_runs_and_decays_with_distance() {
    let p = AttenuationFitParams {
        system: SystemParams {
            fixed: vec!["zmin".into()],
            ..Default::default()
        },
        h: 5e-3,
        pairs: 40,
        truth: FitTruth::Modes,
        modes: Some(60),
        ..Default::default()
    };
    let rep = fit_attenuation_mesh(slab(), &p, "slab", &mut |_| {}).unwrap();
    assert_eq!(rep.info.method, "modes");
    assert_eq!(rep.info.modes, 60);
    assert!(
        rep.fit.beta > 0.0 && rep.fit.alpha.is_finite(),
        "{:?}",
        rep.fit
    );
}

/// `dcr-lab fit-attenuation` through the binary: text and JSON output, and a clean error.
#[test]
fn cli_runs_on_a_small_mesh() {
    let beam = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/beam.msh");
    let run = |extra: &[&str]| {
        let mut argv = vec!["fit-attenuation", beam.to_str().unwrap()];
        argv.extend_from_slice(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_dcr-lab"))
            .args(&argv)
            .output()
            .unwrap()
    };
    let base = [
        "--fixed",
        "clamp",
        "--pairs",
        "30",
        "--h",
        "2e-3",
        "--seed",
        "5",
        "--rayleigh",
        "10,1e-7",
    ];
    let text = run(&base);
    let err = String::from_utf8_lossy(&text.stderr);
    assert!(text.status.success(), "{err}");
    // stderr is not a terminal here: progress comes as plain lines, ending with the last pair.
    assert!(
        err.contains("fit-attenuation: solving for the modes"),
        "{err}"
    );
    assert!(
        err.contains("fit-attenuation: pair responses 30/30"),
        "{err}"
    );
    let mut with_json = base.to_vec();
    with_json.push("--json");
    let o = run(&with_json);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    let text = v.to_string();
    assert!(text.contains("beta"), "{text}");
    // An absurd pair count is refused at once, naming the limit (it would need gigabytes).
    let absurd = run(&["--fixed", "clamp", "--pairs", "1000000000"]);
    let err = String::from_utf8_lossy(&absurd.stderr);
    assert!(!absurd.status.success() && err.contains("100000"), "{err}");
    assert!(
        err.contains("1000000000") && !err.contains("panicked"),
        "{err}"
    );
    // A user error is a clean error, not a panic.
    let bad = run(&["--fixed", "nope"]);
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && err.contains("nope") && !err.contains("panicked"),
        "{err}"
    );
    // The mesh is read as the bake reads it: read in millimetres the 1 m beam is 1 mm long,
    // so a box over its far half (x ≥ 0.5 m, in metres) holds no node; a piece it does not
    // have is refused with the list.
    let mm = run(&["--units", "mm", "--fixed-box", "0.5,-1,-1,2,1,1"]);
    let err = String::from_utf8_lossy(&mm.stderr);
    assert!(
        !mm.status.success() && err.contains("fixes no node"),
        "{err}"
    );
    let piece = run(&["--fixed", "clamp", "--piece", "2"]);
    let err = String::from_utf8_lossy(&piece.stderr);
    assert!(
        !piece.status.success() && err.contains("no piece 2: the mesh has 1 connected piece(s)"),
        "{err}"
    );
}
