//! The coupled elastic–rigid reference (`dcr_lab::scene_truth`) on a 1 × 0.1 × 0.1 m beam
//! (`data/meshes/beam.msh`) with a ball: the physics laws it must keep.
//!
//! - momentum: free-floating beam, no gravity, a ball hits it: Σ m v is conserved;
//! - energy: with damping off and an elastic contact (restitution 1, no friction) the total
//!   energy is conserved to the coupling's first order (the error halves with the step); with
//!   Rayleigh damping on it is dissipated, and never grows once the ball has left;
//! - rigid limit: with the beam made 10³ times stiffer, the ball's rebound equals the rigid
//!   scene's (rapier, restitution 0.15).

use std::path::{Path, PathBuf};

use dcr_lab::scene_truth::{
    prepare_elastic, run_coupled, CoupledParams, CoupledRun, CouplingScheme,
};
use dcr_scenes::runner::{run_scene, RunParams, Trajectory};
use dcr_scenes::scene::SceneDesc;

fn beam_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/beam.msh")
}

/// A scene: the beam (`body`: "static" clamped at x = 0, or free-floating dynamic) and one
/// ball of radius 3 cm, 0.5 kg at `ball` with velocity `vel`.
fn scene(
    body_dynamic: bool,
    gravity: f64,
    restitution: f64,
    friction: f64,
    ball: [f64; 3],
    vel: [f64; 3],
) -> SceneDesc {
    let (body, fixed) = if body_dynamic {
        (
            serde_json::json!({"dynamic": {"mass": 10.0}}),
            serde_json::json!([]),
        )
    } else {
        (serde_json::json!("static"), serde_json::json!(["clamp"]))
    };
    let json = serde_json::json!({
        "name": "beam_ball",
        "h": 0.01,
        "gravity": [0.0, gravity, 0.0],
        "restitution": restitution,
        "seconds": 0.1,
        "elastic": [{
            "name": "beam",
            "mesh": beam_path().display().to_string(),
            "material": {"youngs": 2e8, "poisson": 0.3, "density": 1000.0},
            "fixed": fixed,
            "modes": 20,
            "body": body,
            "colliders": [{"shape": {"cuboid": {"half_extents": [0.5, 0.05, 0.05]}},
                           "offset": {"translation": [0.5, 0.05, 0.05]}}],
            "friction": friction
        }],
        "props": [{
            "name": "ball",
            "colliders": [{"shape": {"ball": {"radius": 0.03}}}],
            "mass": 0.5,
            "pose": {"translation": ball},
            "linvel": vel,
            "friction": friction
        }],
        "outcomes": [{"name": "ball_lift", "kind": "max_lift", "bodies": "ball"}]
    });
    serde_json::from_value(json).expect("test scene parses")
}

fn params(dt: f64, seconds: f64, rayleigh: [f64; 2], restitution: f64) -> CoupledParams {
    CoupledParams {
        dt,
        seconds,
        modes: None,
        contact_stiffness: 1e6,
        friction_velocity: 1e-3,
        rayleigh,
        restitution,
        progress: false,
        scheme: CouplingScheme::Implicit,
        perturbation: (0, 0.0),
        prop_feedback: true,
    }
}

fn run(desc: &SceneDesc, youngs_scale: f64, p: &CoupledParams) -> CoupledRun {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let prep = prepare_elastic(desc, &root, youngs_scale, 6000, None).expect("beam modes");
    run_coupled(desc, &root, &prep, p).expect("coupled run")
}

/// Free-floating beam hit by a ball, no gravity: the total linear momentum is the ball's
/// initial momentum throughout (the contact force acts equally and oppositely on the ball and
/// on the beam's rigid body; the elastic modes carry none), and the beam did take some.
#[test]
fn free_floating_conserves_momentum() {
    let desc = scene(true, 0.0, 0.15, 0.5, [0.8, 0.2, 0.05], [0.3, -2.0, 0.1]);
    let r = run(&desc, 1.0, &params(2e-5, 0.1, [10.0, 1e-7], 0.15));
    let [p0, p1] = r.momentum;
    let scale = (p0[0].powi(2) + p0[1].powi(2) + p0[2].powi(2)).sqrt();
    for k in 0..3 {
        assert!(
            (p1[k] - p0[k]).abs() < 1e-9 * scale,
            "momentum axis {k}: {} → {}",
            p0[k],
            p1[k]
        );
    }
    // The ball bounced: its velocity changed sign, so the momentum test was not vacuous.
    let (t, b) = (&r.trajectory, 0usize);
    let ball = t.names.iter().position(|n| n == "ball").expect("ball");
    let y_end = t.pos(t.rows() - 1, ball)[1];
    let y_min = (0..t.rows())
        .map(|k| t.pos(k, ball)[1])
        .fold(f64::INFINITY, f64::min);
    let _ = b;
    assert!(
        y_end > y_min + 1e-3,
        "the ball should rebound: min {y_min}, end {y_end}"
    );
}

/// Energy drift |E_end − E_0| / E_0 of a run (damping off: should vanish with the step).
fn drift(r: &CoupledRun) -> f64 {
    let e0 = r.energy[0];
    (r.energy[r.energy.len() - 1] - e0).abs() / e0
}

/// Damping off, elastic contact, no friction: the total energy (kinetic, elastic, penalty
/// springs) is conserved to the coupling's first order: the implicit contact force (the
/// end-of-step gap, held over the step) loses energy in proportion to the step, so the drift
/// is a loss that halves (ratio 0.35–0.65) when the step halves. Damping on: the same impact
/// loses energy to the elastic vibration's damping (more than five times the undamped loss),
/// and the energy never grows after the ball has left.
#[test]
fn energy_conserved_undamped_dissipated_damped() {
    let desc = scene(true, 0.0, 1.0, 0.0, [0.5, 0.2, 0.05], [0.0, -2.0, 0.0]);
    let coarse = run(&desc, 1.0, &params(2e-5, 0.1, [0.0, 0.0], 1.0));
    let fine = run(&desc, 1.0, &params(1e-5, 0.1, [0.0, 0.0], 1.0));
    let (dc, df) = (drift(&coarse), drift(&fine));
    eprintln!("undamped energy drift: {dc} at 2e-5 s, {df} at 1e-5 s");
    for r in [&coarse, &fine] {
        let e = &r.energy;
        assert!(e[e.len() - 1] <= e[0], "the implicit contact gained energy");
    }
    assert!(dc < 0.1, "undamped energy drift {dc} at 2e-5 s");
    assert!(
        df > 0.35 * dc && df < 0.65 * dc,
        "drift should halve with the step (first order): {dc} → {df}"
    );
    let damped = run(&desc, 1.0, &params(1e-5, 0.1, [200.0, 1e-5], 1.0));
    let e = &damped.energy;
    let lost = 1.0 - e[e.len() - 1] / e[0];
    assert!(
        lost > 5.0 * df,
        "damping should dissipate energy: lost {lost}, drift {df}"
    );
    // After the contact (the last 5 rows: the ball has left) energy only decreases.
    for k in e.len() - 5..e.len() {
        assert!(
            e[k] <= e[k - 1] * (1.0 + 1e-12),
            "energy grew at row {k}: {} → {}",
            e[k - 1],
            e[k]
        );
    }
}

/// First rebound height (m): the highest centre after the first impact (the first row where
/// the ball rises) minus the centre there.
fn rebound(t: &Trajectory) -> f64 {
    let b = t.names.iter().position(|n| n == "ball").expect("ball");
    let ys: Vec<f64> = (0..t.rows()).map(|k| t.pos(k, b)[1]).collect();
    let Some(k0) = (1..ys.len()).find(|&k| ys[k] > ys[k - 1]) else {
        return 0.0;
    };
    let ymin = ys[k0 - 1];
    ys[k0..].iter().fold(ymin, |a, &y| a.max(y)) - ymin
}

/// A beam 10³ times stiffer: the coupled reference's rebound of a dropped ball equals the
/// rigid scene's (rapier's contact, restitution 0.15) within 15 %, and closer than with the
/// beam at its own stiffness (whose elasticity changes the rebound).
#[test]
fn very_stiff_object_reduces_to_rigid_contact() {
    let desc = scene(false, -9.81, 0.15, 0.5, [0.2, 0.3, 0.05], [0.0, 0.0, 0.0]);
    let tmp = tempfile::tempdir().expect("tempdir");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut rp = RunParams::new(root, false);
    rp.bases_dir = tmp.path().to_path_buf();
    rp.seconds = Some(0.3);
    let rigid = run_scene(&desc, &rp).expect("rigid run");
    let stiff = run(&desc, 1e3, &params(1e-5, 0.3, [10.0, 1e-7], 0.15));
    let (hr, hs) = (rebound(&rigid.trajectory), rebound(&stiff.trajectory));
    let soft = run(&desc, 1.0, &params(1e-5, 0.3, [10.0, 1e-7], 0.15));
    let hf = rebound(&soft.trajectory);
    eprintln!("rebound: rigid {hr} m, stiff {hs} m, scene stiffness {hf} m");
    assert!(hr > 1e-3, "the rigid ball should rebound, got {hr}");
    assert!(
        (hs - hr).abs() < 0.15 * hr,
        "stiff rebound {hs} vs rigid {hr}"
    );
    assert!(
        (hs - hr).abs() < (hf - hr).abs(),
        "the stiff beam should be closer to rigid than the scene's: {hs}, {hf} vs {hr}"
    );
}

/// Largest total energy of a run over its first (J).
fn energy_gain(r: &CoupledRun) -> f64 {
    let e0 = r.energy[0];
    r.energy.iter().fold(f64::NEG_INFINITY, |m, &e| m.max(e)) - e0
}

/// Regression guard for the coupling's stability: a ball dropped on the clamped beam with a
/// contact stiffness k = 1e9 N/m per point (k times the beam's step compliance under the ball
/// far above 1 at Δt = 2e-5 s). The explicit exchange (start-of-step gap) feeds energy into
/// the contact and blows up or gains more than the drop's energy; the implicit one never gains
/// energy, keeps the penetration below 0.1 mm, and moves the ball's rebound by less than 5 %
/// when k is doubled again (it tends to rigid contact).
#[test]
fn implicit_coupling_is_stable_at_any_stiffness() {
    let desc = scene(false, -9.81, 0.15, 0.5, [0.2, 0.3, 0.05], [0.0, 0.0, 0.0]);
    let mut p = params(2e-5, 0.3, [10.0, 1e-7], 0.15);
    p.contact_stiffness = 1e9;
    let drop = 0.5 * 9.81 * (0.3 - 0.13);
    p.scheme = CouplingScheme::Explicit;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let prep = prepare_elastic(&desc, &root, 1.0, 6000, None).expect("beam modes");
    match run_coupled(&desc, &root, &prep, &p) {
        Err(e) => eprintln!("explicit: {e}"),
        Ok(r) => {
            let g = energy_gain(&r);
            eprintln!("explicit: energy gain {g} J (drop {drop} J)");
            assert!(
                g > drop,
                "the explicit exchange should be unstable here: gain {g} J"
            );
        }
    }
    p.scheme = CouplingScheme::Implicit;
    let r = run_coupled(&desc, &root, &prep, &p).expect("implicit run");
    let g = energy_gain(&r);
    eprintln!(
        "implicit: energy gain {g} J, penetration {} m",
        r.max_penetration
    );
    assert!(g <= 1e-9 * drop, "the implicit coupling gained {g} J");
    assert!(
        r.max_penetration < 1e-4,
        "penetration {}",
        r.max_penetration
    );
    p.contact_stiffness = 2e9;
    let r2 = run_coupled(&desc, &root, &prep, &p).expect("implicit run, 2k");
    let (h1, h2) = (rebound(&r.trajectory), rebound(&r2.trajectory));
    eprintln!("rebound at k 1e9: {h1} m, 2e9: {h2} m");
    assert!(h1 > 1e-4, "the ball should rebound: {h1}");
    assert!(
        (h2 - h1).abs() < 0.05 * h1,
        "rebound moved with k: {h1} → {h2}"
    );
}

/// Ensemble statistics: the mean and the sample standard deviation over members, and a
/// level change counted as converged when it is within the tolerance or within two standard
/// errors of the difference of the means, not otherwise.
#[test]
fn ensemble_means_and_noise_rule() {
    use dcr_lab::scene_truth::{ensemble_stats, level_change, TruthLevel};
    use std::collections::BTreeMap;
    let o = |v: f64| BTreeMap::from([("lift".to_string(), (v, "mm".to_string()))]);
    let runs = [o(10.0), o(12.0), o(14.0), o(16.0)];
    let (mean, spread) = ensemble_stats(&runs.iter().collect::<Vec<_>>());
    assert!((mean["lift"].0 - 13.0).abs() < 1e-12);
    // Sample variance: (9 + 1 + 1 + 9) / 3.
    assert!((spread["lift"] - (20.0f64 / 3.0).sqrt()).abs() < 1e-12);
    let level = |m: f64, s: f64, n: usize| TruthLevel {
        dt: 1e-5,
        modes: 10,
        contact_stiffness: 1e9,
        outcomes: o(m),
        spread: BTreeMap::from([("lift".to_string(), s)]),
        members: n,
        change: None,
        within_noise: None,
        max_penetration: 0.0,
        wall_s: 0.0,
    };
    // 10 % apart with no spread: not converged at 2 %.
    let (c, within) = level_change(&level(10.0, 0.0, 1), &level(11.0, 0.0, 1), 0.02);
    assert!((c - 1.0 / 11.0).abs() < 1e-12 && !within);
    // The same gap inside the noise (2·sqrt(2·2²/4) = 2.83 mm > 1 mm): converged.
    let (_, within) = level_change(&level(10.0, 2.0, 4), &level(11.0, 2.0, 4), 0.02);
    assert!(within);
    // Outside the noise (2·sqrt(2·0.2²/4) = 0.28 mm < 1 mm): not converged.
    let (_, within) = level_change(&level(10.0, 0.2, 4), &level(11.0, 0.2, 4), 0.02);
    assert!(!within);
    // Within the tolerance whatever the noise.
    let (_, within) = level_change(&level(10.0, 0.0, 4), &level(10.1, 0.0, 4), 0.02);
    assert!(within);
    // Uncertainty: 2 s / sqrt(N) / max(|mean|, 1).
    assert!((level(10.0, 2.0, 4).uncertainty() - 0.2).abs() < 1e-12);
}

/// The advanced start: dinner's pot is placed where the rigid scene at h has it after the
/// skipped steps, so the first contact of the advanced scene comes `ADVANCE_MARGIN_STEPS`
/// steps in, as in the original minus the skipped steps.
#[test]
fn advanced_start_keeps_the_first_contact() {
    use dcr_lab::scene_truth::{advance_steps, first_contact_step, ADVANCE_MARGIN_STEPS};
    let root = dcr_scenes::repo_root();
    let desc = dcr_lab::scene_truth::load_scene(&root, "dinner").expect("dinner loads");
    let first = first_contact_step(&desc, &root)
        .expect("world builds")
        .expect("the pot lands");
    let skip = advance_steps(&desc, &root)
        .expect("world builds")
        .expect("dinner can be advanced");
    assert_eq!(skip, first - ADVANCE_MARGIN_STEPS);
    let adv = dcr_lab::soft_body::with_projectiles_advanced(&desc, skip, 1).expect("advances");
    let again = first_contact_step(&adv, &root)
        .expect("world builds")
        .expect("the pot still lands");
    assert_eq!(
        again, ADVANCE_MARGIN_STEPS,
        "first contact {first}, skipped {skip}"
    );
}

/// Without prop feedback a ball resting on the clamped beam does not bend it (it sinks only
/// into its penalty contact, mg/k = 4.9 µm), where the two-way reference lets it sink by the
/// beam's static deflection under it (≈ 0.5 mm for a 0.5 kg ball 0.8 m out on this 1 m
/// cantilever, 3EI/x³ ≈ 10⁴ N/m); a launched ball is a source and loads the beam either way
/// (bit-identical runs).
#[test]
fn without_prop_feedback_a_resting_prop_does_not_load_the_object() {
    let sink = |feedback: bool| {
        // Placed on the top face (y = 0.1 m) at rest.
        let desc = scene(false, -9.81, 0.15, 0.5, [0.8, 0.13, 0.05], [0.0, 0.0, 0.0]);
        let mut p = params(2e-5, 0.05, [10.0, 1e-7], 0.15);
        p.prop_feedback = feedback;
        let r = run(&desc, 1.0, &p);
        let t = &r.trajectory;
        let ball = t.names.iter().position(|n| n == "ball").expect("ball");
        let y0 = t.pos(0, ball)[1];
        (0..t.rows())
            .map(|k| y0 - t.pos(k, ball)[1])
            .fold(0.0f64, f64::max)
    };
    let (on, off) = (sink(true), sink(false));
    assert!(
        on > 2e-4,
        "two-way: the ball sinks {on} m with the bent beam"
    );
    assert!(
        off < 2e-5,
        "no feedback: the ball sinks {off} m, the beam unbent"
    );
    // A launched ball (the scene's source) hits the beam: the same run either way.
    let desc = scene(false, -9.81, 0.15, 0.5, [0.8, 0.2, 0.05], [0.0, -2.0, 0.0]);
    let mut p = params(2e-5, 0.05, [10.0, 1e-7], 0.15);
    let two_way = run(&desc, 1.0, &p);
    p.prop_feedback = false;
    let one_way = run(&desc, 1.0, &p);
    assert_eq!(two_way.trajectory.positions, one_way.trajectory.positions);
    // It did hit the beam: in free fall it would be below y = 0.09 m by the end; the beam's
    // top (y = 0.1 m) stopped its centre within a few mm of 0.13 m.
    let t = &two_way.trajectory;
    let ball = t.names.iter().position(|n| n == "ball").expect("ball");
    let y_min = (0..t.rows())
        .map(|k| t.pos(k, ball)[1])
        .fold(f64::INFINITY, f64::min);
    assert!(
        y_min > 0.125,
        "the ball went down to {y_min} m: it missed the beam"
    );
}

/// The reference fixes the object with the scene's half-spaces and boxes as a bake does: the
/// beam held at x ≤ 0 m (its `clamp` group's nodes) has the clamped beam's free dofs and
/// eigenvalues, and the same coupled run bit for bit.
#[test]
fn a_half_space_clamps_the_beam_as_its_group_does() {
    use dcr_scenes::scene::{AxisDesc, FixedBelowDesc};
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let grouped = scene(false, -9.81, 0.15, 0.5, [0.8, 0.2, 0.05], [0.0, -2.0, 0.0]);
    let mut below = grouped.clone();
    below.elastic[0].fixed.clear();
    below.elastic[0].fixed_below = vec![FixedBelowDesc {
        axis: AxisDesc::X,
        value: 0.0,
    }];
    let a = prepare_elastic(&grouped, &root, 1.0, 6000, None).expect("clamped beam");
    let b = prepare_elastic(&below, &root, 1.0, 6000, None).expect("beam held at x ≤ 0");
    assert_eq!(a.sys.n(), b.sys.n());
    assert_eq!(a.all.eigenvalues, b.all.eigenvalues);
    let p = params(2e-5, 0.02, [10.0, 1e-7], 0.15);
    let ra = run_coupled(&grouped, &root, &a, &p).expect("coupled run");
    let rb = run_coupled(&below, &root, &b, &p).expect("coupled run");
    assert_eq!(ra.trajectory.positions, rb.trajectory.positions);
    // A half-space that holds no node is refused, naming the mesh's extent.
    below.elastic[0].fixed_below[0].value = -1.0;
    let err = prepare_elastic(&below, &root, 1.0, 6000, None)
        .err()
        .expect("refused")
        .to_string();
    assert!(
        err.contains("fixes no node") && err.contains("the mesh spans"),
        "{err}"
    );
}

/// A prop placed inside the object's surface is refused before its contact springs throw it:
/// the 0.5 kg ball resting 0.1 mm deep in the clamped beam's top (y = 0.1 m) would hold
/// ½·k·d² = 5 J under a 1e9 N/m spring, enough to lift it a metre. Resting on the surface it
/// runs, as do the repository's scenes (their props start about 1e-9 m deep).
#[test]
fn a_prop_starting_inside_the_surface_is_refused() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let p = CoupledParams {
        contact_stiffness: 1e9,
        ..params(2e-5, 0.01, [10.0, 1e-7], 0.15)
    };
    let inside = scene(
        false,
        -9.81,
        0.15,
        0.5,
        [0.8, 0.1299, 0.05],
        [0.0, 0.0, 0.0],
    );
    let prep = prepare_elastic(&inside, &root, 1.0, 6000, None).expect("beam modes");
    let err = run_coupled(&inside, &root, &prep, &p)
        .expect_err("a ball 0.1 mm deep is refused")
        .to_string();
    assert!(
        err.contains("ball starts 0.1000 mm inside elastic object beam's surface")
            && err.contains("place it on the surface"),
        "{err}"
    );
    let on = scene(false, -9.81, 0.15, 0.5, [0.8, 0.13, 0.05], [0.0, 0.0, 0.0]);
    run_coupled(&on, &root, &prep, &p).expect("a ball on the surface runs");
}
