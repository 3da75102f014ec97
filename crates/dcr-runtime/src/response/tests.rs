//! Physics laws of the distant response: linearity, superposition, reciprocity, zero in → zero
//! out, threshold, energy decay and sleep, Eq. 13, ZOH statics, caching, attenuation (Eq. 15–16),
//! effective mass (Eq. 17–19).

use std::sync::Arc;

use super::*;
use crate::attenuation::{AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind};
use crate::filter::Sampling;
use crate::math::{norm, scale, sub};
use crate::model::ModalModel;
use crate::testing::{box_surface, geometric_omegas, plate_base, synthetic_base};

fn plate() -> Arc<ModalModel> {
    Arc::new(ModalModel::from_base(plate_base()).unwrap())
}

fn boxy() -> Arc<ModalModel> {
    let om = geometric_omegas(12, 80.0, 2000.0);
    Arc::new(
        ModalModel::from_base(synthetic_base(
            box_surface(6, [1.0, 0.6, 0.4]),
            &om,
            [1.0, 2e-6],
            11,
        ))
        .unwrap(),
    )
}

fn hit(p: [f64; 3], lambda: f64) -> Impact {
    Impact {
        point: p,
        direction: [0.0, 0.0, -1.0],
        impulse: lambda,
    }
}

fn contacts() -> Vec<RestingContact> {
    [
        [0.1, 0.1],
        [0.9, 0.5],
        [0.5, 0.55],
        [0.25, 0.4],
        [0.75, 0.05],
    ]
    .iter()
    .enumerate()
    .map(|(i, xy)| RestingContact {
        id: 100 + i as u64,
        point: [xy[0], xy[1], 0.002],
    })
    .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
}

/// Doubling the impulse doubles every response (both variants).
#[test]
fn response_is_linear() {
    for variant in [Variant::PerContact, Variant::PerNode] {
        let params = ResponseParams {
            variant,
            ..Default::default()
        };
        let mut a = DistantResponse::new(plate(), params.clone()).unwrap();
        let mut b = DistantResponse::new(plate(), params).unwrap();
        let ra: Vec<_> = a.step(&[hit([0.4, 0.3, 0.0], 1.5)], &contacts()).to_vec();
        let rb: Vec<_> = b.step(&[hit([0.4, 0.3, 0.0], 3.0)], &contacts()).to_vec();
        for (x, y) in ra.iter().zip(&rb) {
            assert!(x.peak_displacement > 0.0);
            assert!(rel(2.0 * x.peak_displacement, y.peak_displacement) < 1e-13);
            assert!(rel(2.0 * x.delta_v, y.delta_v) < 1e-13);
        }
    }
}

/// Two simultaneous impacts give the sum of the two displacement time series.
#[test]
fn simultaneous_impacts_superpose() {
    for carry_over in [false, true] {
        let params = ResponseParams {
            carry_over,
            ..Default::default()
        };
        let (ia, ib) = (hit([0.2, 0.3, 0.0], 1.0), hit([0.8, 0.45, 0.01], 2.5));
        let run = |imps: &[Impact]| {
            let mut r = DistantResponse::new(plate(), params.clone()).unwrap();
            r.step(imps, &contacts());
            r.modal_samples().to_vec()
        };
        let (qa, qb, qab) = (run(&[ia]), run(&[ib]), run(&[ia, ib]));
        let peak = qab.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(peak > 0.0);
        for k in 0..qab.len() {
            assert!((qab[k] - qa[k] - qb[k]).abs() <= 1e-13 * peak);
        }
    }
}

/// Peak at B from an impact at A along −n_A equals the peak at A from B along −n_B.
#[test]
fn response_is_reciprocal() {
    let model = boxy();
    let pts = [
        [0.3, 0.2, 0.4],
        [0.8, 0.5, 0.4],
        [1.0, 0.3, 0.1],
        [0.0, 0.1, 0.35],
        [0.5, 0.0, 0.2],
    ];
    for a in 0..pts.len() {
        for b in 0..pts.len() {
            if a == b {
                continue;
            }
            let peak = |from: usize, to: usize| {
                let mut r =
                    DistantResponse::new(Arc::clone(&model), ResponseParams::default()).unwrap();
                let sp = model.project(pts[from], 1.0).unwrap();
                let imp = Impact {
                    point: pts[from],
                    direction: scale(sp.normal, -1.0),
                    impulse: 1.0,
                };
                r.step(
                    &[imp],
                    &[RestingContact {
                        id: 1,
                        point: pts[to],
                    }],
                )[0]
                .peak_displacement
            };
            let (ab, ba) = (peak(a, b), peak(b, a));
            assert!(ab > 0.0 && rel(ab, ba) < 1e-12, "{a}->{b}: {ab} vs {ba}");
        }
    }
}

/// No impact, a zero impulse or one below the threshold gives exactly zero; far impacts and far
/// contacts are not mapped.
#[test]
fn zero_threshold_and_unmapped() {
    let mut r = DistantResponse::new(plate(), ResponseParams::default()).unwrap();
    let out = r.step(&[], &contacts());
    assert!(out
        .iter()
        .all(|c| c.mapped && c.peak_displacement == 0.0 && c.delta_v == 0.0));
    let out = r.step(&[hit([0.5, 0.3, 0.0], 0.0)], &contacts());
    assert!(out.iter().all(|c| c.delta_v == 0.0));
    let out = r.step(&[hit([0.5, 0.3, 0.0], 0.999e-3)], &contacts());
    assert!(out.iter().all(|c| c.delta_v == 0.0));
    assert_eq!(r.last_step_info().impacts_below_threshold, 1);
    let out = r.step(&[hit([0.5, 0.3, 0.0], 1.0e-3)], &contacts());
    assert!(out.iter().all(|c| c.delta_v > 0.0));
    assert_eq!(r.last_step_info().impacts_applied, 1);
    // Far impact (default limit: 5% of the diagonal ≈ 5.8 cm) and far contact.
    let far = [RestingContact {
        id: 9,
        point: [0.5, 0.3, 0.5],
    }];
    let out = r.step(&[hit([0.5, 0.3, 0.3], 5.0)], &far);
    assert!(!out[0].mapped && out[0].delta_v == 0.0);
    assert_eq!(r.last_step_info().impacts_unmapped, 1);
    assert_eq!(r.last_step_info().contacts_unmapped, 1);
}

/// Eq. 13: PerNode Δv = Σ b_i max_k |n_iᵀU_i q(k)| / h, checked against a direct computation.
#[test]
fn per_node_follows_eq13() {
    let model = plate();
    let params = ResponseParams {
        variant: Variant::PerNode,
        ..Default::default()
    };
    let mut r = DistantResponse::new(Arc::clone(&model), params).unwrap();
    let cs = contacts();
    let out = r.step(&[hit([0.3, 0.35, 0.0], 2.0)], &cs).to_vec();
    let (m, s) = (model.num_modes(), r.samples_per_step());
    let q = r.modal_samples();
    let rows = model.normal_mode_rows();
    for (c, o) in cs.iter().zip(&out) {
        let sp = model.project(c.point, 1.0).unwrap();
        let vs = model.triangle(sp.triangle);
        let mut dv = 0.0;
        for i in 0..3 {
            let mut d = 0.0f64;
            for k in 0..s {
                let y: f64 = (0..m).map(|j| rows[vs[i] * m + j] * q[k * m + j]).sum();
                d = d.max(y.abs());
            }
            dv += sp.bary[i] * d / 0.01;
        }
        assert!(rel(dv, o.delta_v) < 1e-12, "{dv} vs {}", o.delta_v);
    }
}

/// The precomputed-table path (reset every step) and the running bank give the same peaks.
#[test]
fn table_path_equals_recursion_path() {
    let cs = contacts();
    let mut a = DistantResponse::new(plate(), ResponseParams::default()).unwrap();
    let mut b = DistantResponse::new(
        plate(),
        ResponseParams {
            carry_over: true,
            ..Default::default()
        },
    )
    .unwrap();
    let imps = [hit([0.6, 0.2, 0.0], 1.3)];
    let ra = a.step(&imps, &cs).to_vec();
    let rb = b.step(&imps, &cs).to_vec();
    for (x, y) in ra.iter().zip(&rb) {
        assert!(rel(x.peak_displacement, y.peak_displacement) < 1e-12);
    }
    assert!(rel(a.modal_energy(), b.modal_energy()) < 1e-12);
    // Without carry-over the next step starts from rest again: no response without impacts.
    assert!(a.step(&[], &cs).iter().all(|c| c.delta_v == 0.0));
    assert!(b.step(&[], &cs).iter().all(|c| c.delta_v > 0.0));
}

/// With carry-over a free-running bank's energy never grows over many steps, then sleeps
/// (zero output) once below the relative threshold, and wakes on the next impact.
#[test]
fn carried_energy_decays_then_sleeps() {
    let params = ResponseParams {
        carry_over: true,
        sleep_energy_rel: 1e-6,
        ..Default::default()
    };
    let mut r = DistantResponse::new(plate(), params).unwrap();
    let cs = contacts();
    r.step(&[hit([0.5, 0.3, 0.0], 1.0)], &cs);
    let mut prev = r.modal_energy();
    assert!(prev > 0.0);
    let mut slept = false;
    for _ in 0..2000 {
        let out = r.step(&[], &cs).to_vec();
        let e = r.modal_energy();
        assert!(e <= prev * (1.0 + 1e-12), "energy grew {prev} → {e}");
        prev = e;
        if r.last_step_info().asleep {
            slept = true;
            assert!(out.iter().all(|c| c.delta_v == 0.0));
            assert_eq!(e, 0.0);
        }
    }
    assert!(slept, "bank never slept");
    assert!(r
        .step(&[hit([0.5, 0.3, 0.0], 1.0)], &cs)
        .iter()
        .all(|c| c.delta_v > 0.0));
}

/// A force held over many steps (carry-over) settles each mode at the static deflection f/ω².
#[test]
fn held_force_settles_at_static_deflection() {
    let model = plate();
    let params = ResponseParams {
        carry_over: true,
        ..Default::default()
    };
    let mut r = DistantResponse::new(Arc::clone(&model), params).unwrap();
    let force = [ForceInput {
        point: [0.45, 0.3, 0.0],
        force: [0.0, 0.0, -20.0],
    }];
    for _ in 0..3000 {
        r.step_with_forces(&[], &force, &contacts());
    }
    let sp = model.project(force[0].point, 1.0).unwrap();
    let mut fr = vec![0.0; model.num_modes()];
    model.add_reduced_impulse(&sp, force[0].force, 1.0, &mut fr);
    for (j, q) in r.modal_state().iter().enumerate() {
        let stat = fr[j] / model.omega()[j].powi(2);
        assert!(
            (q - stat).abs() <= 1e-9 * stat.abs().max(1e-12),
            "mode {j}: {q} vs {stat}"
        );
    }
}

/// Cached contacts: mapped once, re-mapped when moved, evicted after `evict_after_steps`.
#[test]
fn resting_contacts_are_cached_and_evicted() {
    let params = ResponseParams {
        evict_after_steps: 3,
        ..Default::default()
    };
    let mut r = DistantResponse::new(plate(), params).unwrap();
    let cs = contacts();
    r.step(&[], &cs);
    assert_eq!(r.last_step_info().contacts_mapped_now, 5);
    r.step(&[], &cs);
    assert_eq!(r.last_step_info().contacts_mapped_now, 0);
    let mut moved = cs.clone();
    moved[0].point[0] += 0.05;
    r.step(&[], &moved);
    assert_eq!(r.last_step_info().contacts_mapped_now, 1);
    for _ in 0..4 {
        r.step(&[], &cs[..2]);
    }
    assert_eq!(r.cached_contacts(), 2);
}

/// S = ⌈h/T⌉ with T = h/S given exactly or with rounding; T_eff = h/S; bad parameters refused.
#[test]
fn sampling_and_parameter_validation() {
    let model = plate();
    for s in [1usize, 2, 21, 117] {
        let params = ResponseParams {
            sampling: Sampling::Substep(0.01 / s as f64),
            ..Default::default()
        };
        let r = DistantResponse::new(Arc::clone(&model), params).unwrap();
        assert_eq!(r.samples_per_step(), s);
        assert!(rel(r.substep(), 0.01 / s as f64) < 1e-15);
    }
    let r = DistantResponse::new(Arc::clone(&model), ResponseParams::default()).unwrap();
    let t = std::f64::consts::FRAC_PI_2 / 900.0;
    assert_eq!(r.samples_per_step(), (0.01 / t).ceil() as usize);
    let bad = [
        ResponseParams {
            h: 0.0,
            ..Default::default()
        },
        ResponseParams {
            sampling: Sampling::Substep(1e-12),
            ..Default::default()
        },
        ResponseParams {
            rayleigh: Some([-1.0, 0.0]),
            ..Default::default()
        },
        ResponseParams {
            method: Method::Attenuation(AttenuationParams {
                amplitude: AmplitudeKind::MeanOver(vec![100_000]),
                ..Default::default()
            }),
            ..Default::default()
        },
    ];
    for p in bad {
        assert!(DistantResponse::new(Arc::clone(&model), p).is_err());
    }
}

/// Attenuation, Euclidean + Full law: Δv_p = s(r) q̂ λ_N / h with q̂ interpolated (Eq. 15–16),
/// and the mean-amplitude variant uses the mean.
#[test]
fn attenuation_follows_eq15_16() {
    let model = plate();
    let law = AttenuationLaw::Full {
        alpha: 0.3,
        beta: 1.0,
        r0: 0.05,
    };
    for amplitude in [
        AmplitudeKind::PerVertex,
        AmplitudeKind::Mean,
        AmplitudeKind::MeanOver(vec![0, 5, 9]),
    ] {
        let params = ResponseParams {
            method: Method::Attenuation(AttenuationParams {
                law,
                distance: DistanceKind::Euclidean,
                amplitude: amplitude.clone(),
                cache_capacity: 4,
                parallel_heat: false,
            }),
            ..Default::default()
        };
        let mut r = DistantResponse::new(Arc::clone(&model), params).unwrap();
        let q = r.local_amplitudes().unwrap().to_vec();
        assert!(q.iter().all(|&x| x > 0.0));
        let imp = Impact {
            point: [0.33, 0.27, 0.0],
            direction: scale([0.6, 0.0, -0.8], 1.0),
            impulse: 2.0,
        };
        let cs = contacts();
        let out = r.step(&[imp], &cs).to_vec();
        let sp = model.project(imp.point, 1.0).unwrap();
        let vs = model.triangle(sp.triangle);
        let qhat = match &amplitude {
            AmplitudeKind::PerVertex => (0..3).map(|i| sp.bary[i] * q[vs[i]]).sum::<f64>(),
            AmplitudeKind::Mean => q.iter().sum::<f64>() / q.len() as f64,
            AmplitudeKind::MeanOver(s) => {
                s.iter().map(|&v| q[v as usize]).sum::<f64>() / s.len() as f64
            }
        };
        let dx = qhat * 2.0 * 0.8;
        for (c, o) in cs.iter().zip(&out) {
            let cp = model.project(c.point, 1.0).unwrap();
            let expect = law.factor(norm(sub(cp.point, sp.point))) * dx / 0.01;
            assert!(rel(expect, o.delta_v) < 1e-12, "{expect} vs {}", o.delta_v);
        }
    }
}

/// Attenuation with heat distances: distance fields cached per contact (computed once: three
/// impacts, so five new contacts are not more than twice the impacts), and the farther contact
/// gets the smaller response.
#[test]
fn attenuation_heat_fields_are_cached() {
    let params = ResponseParams {
        method: Method::Attenuation(AttenuationParams {
            law: AttenuationLaw::Full {
                alpha: 0.0,
                beta: 1.0,
                r0: 0.05,
            },
            amplitude: AmplitudeKind::Mean,
            ..Default::default()
        }),
        ..Default::default()
    };
    let mut r = DistantResponse::new(plate(), params).unwrap();
    let cs = contacts();
    let imp = [0.1, 0.11, 0.12].map(|x| hit([x, 0.1, 0.0], 1.0 / 3.0));
    let a = r.step(&imp, &cs).to_vec();
    assert_eq!(r.last_step_info().distance_fields_computed, 5);
    let b = r.step(&imp, &cs).to_vec();
    assert_eq!(r.last_step_info().distance_fields_computed, 0);
    assert_eq!(a, b);
    // Contact 0 sits next to the impact (s clamped to 1), contact 1 is ~0.9 m away.
    assert!(a[0].delta_v > a[1].delta_v && a[1].delta_v > 0.0);
}

/// Heat distances, one impact, five new contacts: each step solves at most 2 fields (one
/// contact's, cached, and the impact's, which serves the other new contacts) until all are
/// cached. Every response is the law at the distance read from the field that served it, and
/// an impact-served contact differs from its own-field response by the heat method's
/// asymmetry only (a few %).
#[test]
fn attenuation_heat_new_contacts_cost_two_fields_per_impact() {
    let law = AttenuationLaw::Full {
        alpha: 0.0,
        beta: 1.0,
        r0: 0.05,
    };
    let model = plate();
    let params = ResponseParams {
        method: Method::Attenuation(AttenuationParams {
            law,
            amplitude: AmplitudeKind::Mean,
            ..Default::default()
        }),
        ..Default::default()
    };
    let mut r = DistantResponse::new(Arc::clone(&model), params).unwrap();
    let cs = contacts();
    let imp = [hit([0.12, 0.1, 0.0], 1.0)];
    let mut steps = Vec::new();
    let mut computed = Vec::new();
    for _ in 0..5 {
        steps.push(r.step(&imp, &cs).to_vec());
        computed.push(r.last_step_info().distance_fields_computed);
    }
    assert_eq!(computed, [2, 2, 2, 2, 0]);
    // Distances from each contact's own field (read at the impact) and from the impact's
    // field (read at the contact).
    let heat = model.heat_geodesic().unwrap();
    let n = model.num_vertices();
    let hp = model.project(imp[0].point, 1.0).unwrap();
    let mut from_hit = vec![0.0; n];
    heat.distances_from_point(&hp, &mut from_hit);
    let mut field = vec![0.0; n];
    let (mut own, mut read) = (Vec::new(), Vec::new());
    for c in &cs {
        let sp = model.project(c.point, 1.0).unwrap();
        heat.distances_from_point(&sp, &mut field);
        own.push(law.factor(model.interpolate(&field, &hp)));
        read.push(law.factor(model.interpolate(&from_hit, &sp)));
    }
    // Step k caches contact k − 1 (in order) and serves contacts k.. from the impact's field;
    // by step 4 the last two are both computed, step 5 reads only the cache. All responses
    // share Δx_c / h, so each is that constant times the law.
    let unit = steps[4][0].delta_v / own[0];
    for (k, out) in steps.iter().enumerate() {
        for (c, o) in out.iter().enumerate() {
            let want = if c <= k || k >= 3 { own[c] } else { read[c] };
            assert!(
                rel(o.delta_v, unit * want) < 1e-12,
                "step {k} contact {c}: {} vs {}",
                o.delta_v,
                unit * want
            );
        }
    }
    for c in 0..cs.len() {
        assert!(
            rel(own[c], read[c]) < 0.1,
            "contact {c}: {} vs {}",
            own[c],
            read[c]
        );
    }
}

/// Eq. 17: point mass → m; lever arm adds (r×n)ᵀI⁻¹(r×n); Eq. 18 impulse along n.
#[test]
fn effective_mass_and_impulse() {
    assert_eq!(
        effective_mass(0.5, [[0.0; 3]; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        2.0
    );
    let inv_i = [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]];
    // r × n = (1,0,0) × (0,0,1) = (0,−1,0): quad = 3.
    assert!(
        (effective_mass(0.5, inv_i, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]) - 1.0 / 3.5).abs() < 1e-15
    );
    assert_eq!(
        effective_mass(0.0, [[0.0; 3]; 3], [1.0; 3], [0.0, 0.0, 1.0]),
        0.0
    );
    assert_eq!(
        response_impulse(2.0, 0.25, [0.0, 0.6, 0.8]),
        [0.0, 0.3, 0.4]
    );
}

/// The blocked kernel equals a naive triple loop.
#[test]
fn peak_kernel_matches_naive() {
    let mut rng = crate::testing::SplitMix64(5);
    let (s, m, nch) = (13, 7, 24);
    let q: Vec<f64> = (0..s * m).map(|_| rng.range(-1.0, 1.0)).collect();
    let w: Vec<f64> = (0..m * nch).map(|_| rng.range(-1.0, 1.0)).collect();
    let mut peaks = vec![0.0; nch];
    peak_abs_projection(&q, s, m, &w, nch, &mut peaks);
    // Panel layout: W(j, c) = w[((c/8)·m + j)·8 + c%8].
    let wjc = |j: usize, c: usize| w[((c / 8) * m + j) * 8 + c % 8];
    for c in 0..nch {
        let naive = (0..s)
            .map(|k| (0..m).map(|j| q[k * m + j] * wjc(j, c)).sum::<f64>().abs())
            .fold(0.0, f64::max);
        assert!((naive - peaks[c]).abs() < 1e-14);
    }
    let mut base = vec![0.0; nch];
    super::peak_kernel::peak_abs_projection_baseline(&q, s, m, &w, nch, &mut base);
    for c in 0..nch {
        assert!((base[c] - peaks[c]).abs() < 1e-14);
    }
}

/// Heat distances read from the all-pairs table: the response is the law at the bilinear table
/// distance (no solve per step), and within 10 % of the per-contact heat fields away from
/// the impact (the heat method's discretisation on this coarse plate: 12 × 8 cells).
#[test]
fn attenuation_heat_table_reads_the_vertex_table() {
    let law = AttenuationLaw::Full {
        alpha: 0.0,
        beta: 1.0,
        r0: 0.05,
    };
    let model = plate();
    let with = |distance| ResponseParams {
        method: Method::Attenuation(AttenuationParams {
            law,
            distance,
            amplitude: AmplitudeKind::Mean,
            ..Default::default()
        }),
        ..Default::default()
    };
    let mut table =
        DistantResponse::new(Arc::clone(&model), with(DistanceKind::HeatTable)).unwrap();
    let mut heat = DistantResponse::new(Arc::clone(&model), with(DistanceKind::Heat)).unwrap();
    let cs = contacts();
    let imp = [hit([0.12, 0.1, 0.0], 1.0)];
    let a = table.step(&imp, &cs).to_vec();
    assert_eq!(table.last_step_info().distance_fields_computed, 0);
    let mut b = heat.step(&imp, &cs).to_vec();
    for _ in 0..4 {
        b = heat.step(&imp, &cs).to_vec(); // every contact's own field, cached
    }
    let tab = model.geodesic_table().unwrap();
    let hp = model.project(imp[0].point, 1.0).unwrap();
    let unit = a[1].delta_v
        / law.factor(tab.distance(
            &model.project(cs[1].point, 1.0).unwrap(),
            model.triangle(model.project(cs[1].point, 1.0).unwrap().triangle),
            &hp,
            model.triangle(hp.triangle),
        ));
    for ((c, x), y) in cs.iter().zip(&a).zip(&b) {
        let sp = model.project(c.point, 1.0).unwrap();
        let r = tab.distance(
            &sp,
            model.triangle(sp.triangle),
            &hp,
            model.triangle(hp.triangle),
        );
        assert!(rel(x.delta_v, unit * law.factor(r)) < 1e-12);
        if r > 0.3 {
            assert!(
                rel(x.delta_v, y.delta_v) < 0.1,
                "{} vs {}",
                x.delta_v,
                y.delta_v
            );
        }
    }
}
