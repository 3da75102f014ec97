//! The energy bound of `DcrWorld`: per elastic object and step, the kinetic energy its
//! responses inject is at most η × (the energy the step's impacts on it dissipated + the
//! kinetic energy chained impulses gave its body).
//!
//! Property test over seeded random scenes: a static floor and a dynamic fridge (both elastic,
//! randomly posed, random gains up to 100 so responses are strong), dynamic bodies with random
//! mass, world inverse inertia and post-step velocities, and every step random new impacts
//! (some between the floor and the fridge, which share their dissipation) and resting contacts.
//! The injected energy is measured independently by applying the step's events in order to the
//! bodies and differencing their kinetic energies ½ m v² + ½ ωᵀIω (I inverted from I⁻¹); the
//! dissipation is recomputed from the reports, `max(0, ½ k λ² − λ u⁺)`. For η ∈ {1, 0.5, 0.1}
//! the bound holds to rounding, the world's own account matches the measurement, and the bound
//! is active in some steps (so the test can fail).

use std::sync::Arc;

use dcr_runtime::testing::{plate_base, SplitMix64};
use dcr_runtime::{
    BodyState, ContactReport, DcrWorld, ElasticObjectDesc, ModalModel, Pose, ResponseParams,
    WorldParams,
};

const FLOOR: u64 = 1;
const FRIDGE: u64 = 2;

type M3 = [[f64; 3]; 3];

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn mv(m: &M3, v: [f64; 3]) -> [f64; 3] {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

fn inverse(m: &M3) -> M3 {
    let c = [cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1])];
    let det = dot(m[0], c[0]);
    // inverse = adjugate / det, adjugate columns are the cofactor rows above.
    let mut inv = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            inv[i][j] = c[j][i] / det;
        }
    }
    inv
}

fn random_rotation(rng: &mut SplitMix64) -> Pose {
    let axis = [
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
    ];
    Pose::from_axis_angle(axis, rng.range(0.0, 3.0), [0.0; 3])
}

/// A random dynamic body: mass 0.5–10 kg, a random symmetric positive definite world inertia.
fn random_body(id: u64, rng: &mut SplitMix64) -> BodyState {
    let r = random_rotation(rng).rotation_matrix();
    let d = [
        rng.range(0.5, 5.0),
        rng.range(0.5, 5.0),
        rng.range(0.5, 5.0),
    ];
    let mut inv_i = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            inv_i[i][j] = (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum();
        }
    }
    BodyState {
        id,
        inv_mass: 1.0 / rng.range(0.5, 10.0),
        inv_inertia: inv_i,
        center_of_mass: [
            rng.range(0.0, 1.0),
            rng.range(0.0, 0.6),
            rng.range(0.0, 0.3),
        ],
        linvel: [0.0; 3],
        angvel: [0.0; 3],
    }
}

fn kinetic_energy(b: &BodyState, v: [f64; 3], w: [f64; 3]) -> f64 {
    0.5 * dot(v, v) / b.inv_mass + 0.5 * dot(w, mv(&inverse(&b.inv_inertia), w))
}

fn velocity_at(b: &BodyState, p: [f64; 3]) -> [f64; 3] {
    let r = sub(p, b.center_of_mass);
    let w = cross(b.angvel, r);
    [b.linvel[0] + w[0], b.linvel[1] + w[1], b.linvel[2] + w[2]]
}

fn inverse_effective_mass(b: &BodyState, p: [f64; 3], n: [f64; 3]) -> f64 {
    let rn = cross(sub(p, b.center_of_mass), n);
    b.inv_mass + dot(rn, mv(&b.inv_inertia, rn))
}

#[test]
fn injected_energy_is_bounded_by_eta_times_dissipated() {
    let model = Arc::new(ModalModel::from_base(plate_base()).unwrap());
    for eta in [1.0, 0.5, 0.1] {
        let (mut limited, mut steps_with_events) = (0, 0);
        for seed in 0..6u64 {
            let mut rng = SplitMix64(1000 + seed);
            let mut world = DcrWorld::new(WorldParams {
                energy_eta: Some(eta),
                gravity: [0.0; 3],
                ..Default::default()
            })
            .unwrap();
            let mut poses = Vec::new();
            for (body, dynamic) in [(FLOOR, false), (FRIDGE, true)] {
                let mut d = ElasticObjectDesc::new(Arc::clone(&model), body);
                d.dynamic = dynamic;
                d.gain = rng.range(1.0, 100.0);
                d.pose = random_rotation(&mut rng);
                d.pose.translation = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0];
                d.response = ResponseParams {
                    lateral_kick: seed % 2 == 1,
                    ..Default::default()
                };
                poses.push(d.pose);
                world.add_object(d).unwrap();
            }
            let mut bodies: Vec<BodyState> = (2..9).map(|id| random_body(id, &mut rng)).collect();
            let mut next_id = 100u64;
            for step in 0..80 {
                for b in bodies.iter_mut() {
                    b.linvel = [0, 1, 2].map(|_| rng.range(-1.0, 1.0));
                    b.angvel = [0, 1, 2].map(|_| rng.range(-2.0, 2.0));
                }
                // Contacts: body1 an elastic object (floor or fridge), body2 another body.
                let mut contacts = Vec::new();
                let mut impacts = Vec::new();
                let n_rest = 1 + (rng.next_u64() % 6) as usize;
                let n_imp = (rng.next_u64() % 3) as usize;
                for k in 0..n_rest + n_imp {
                    let on_fridge = rng.next_f64() < 0.4;
                    let (elastic, pose) = if on_fridge {
                        (FRIDGE, poses[1])
                    } else {
                        (FLOOR, poses[0])
                    };
                    let lo = if on_fridge { 3 } else { 2 };
                    let other = lo + rng.next_u64() % (9 - lo);
                    let p = pose.transform_point([rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.0]);
                    let r = pose.rotation_matrix();
                    let impact = k >= n_rest && step >= 3;
                    // Resting contacts keep their ids (per elastic side and slot), impacts
                    // are new ids.
                    let id = if impact {
                        next_id += 1;
                        next_id
                    } else {
                        (k as u64) * 2 + u64::from(on_fridge)
                    };
                    let c = ContactReport {
                        id,
                        body1: elastic,
                        body2: other,
                        point1: p,
                        point2: p,
                        normal: [r[0][2], r[1][2], r[2][2]],
                        impulse: if impact {
                            rng.range(0.1, 5.0)
                        } else {
                            rng.range(0.0, 5e-4) // below the threshold: never an impact
                        },
                        is_new: false,
                    };
                    if impact {
                        impacts.push(c);
                    }
                    contacts.push(c);
                }
                let events = world.step(&contacts, &bodies).to_vec();
                // Independent dissipation per object: every impact is new and ≥ threshold.
                let mut dissipated = [0.0f64; 2];
                for c in &impacts {
                    let b2 = bodies.iter().find(|b| b.id == c.body2).unwrap();
                    let (k1, v1) = if c.body1 == FRIDGE {
                        let b1 = bodies.iter().find(|b| b.id == FRIDGE).unwrap();
                        (
                            inverse_effective_mass(b1, c.point1, c.normal),
                            velocity_at(b1, c.point1),
                        )
                    } else {
                        (0.0, [0.0; 3])
                    };
                    let k = k1 + inverse_effective_mass(b2, c.point2, c.normal);
                    let u = dot(sub(velocity_at(b2, c.point2), v1), c.normal);
                    let lost = (0.5 * k * c.impulse * c.impulse - c.impulse * u).max(0.0);
                    let o1 = usize::from(c.body1 == FRIDGE);
                    if c.body2 == FRIDGE {
                        dissipated[o1] += 0.5 * lost;
                        dissipated[1] += 0.5 * lost;
                    } else {
                        dissipated[o1] += lost;
                    }
                }
                // Apply the events in order; measure each object's injected energy and what
                // the floor's events gave the fridge's body.
                let mut vel: Vec<([f64; 3], [f64; 3])> =
                    bodies.iter().map(|b| (b.linvel, b.angvel)).collect();
                let mut injected = [0.0f64; 2];
                let mut received_fridge = 0.0;
                for o in 0..2u32 {
                    let evs: Vec<_> = events.iter().filter(|e| e.object.index() == o).collect();
                    let touched: Vec<usize> = (0..bodies.len())
                        .filter(|&i| evs.iter().any(|e| e.body == bodies[i].id))
                        .collect();
                    let ke = |vel: &[([f64; 3], [f64; 3])], i: usize| {
                        kinetic_energy(&bodies[i], vel[i].0, vel[i].1)
                    };
                    let before: Vec<f64> = touched.iter().map(|&i| ke(&vel, i)).collect();
                    for e in &evs {
                        let i = bodies.iter().position(|b| b.id == e.body).unwrap();
                        let b = &bodies[i];
                        let r = sub(e.point, b.center_of_mass);
                        let dw = mv(&b.inv_inertia, cross(r, e.impulse));
                        for k in 0..3 {
                            vel[i].0[k] += b.inv_mass * e.impulse[k];
                            vel[i].1[k] += dw[k];
                        }
                    }
                    for (&i, &ke0) in touched.iter().zip(&before) {
                        let d = ke(&vel, i) - ke0;
                        injected[o as usize] += d;
                        if o == 0 && bodies[i].id == FRIDGE {
                            received_fridge += d.max(0.0);
                        }
                    }
                }
                if !events.is_empty() {
                    steps_with_events += 1;
                }
                limited += world.step_info().energy_limited;
                let received = [0.0, received_fridge];
                for o in 0..2 {
                    let info = world.object_info(dcr_runtime::ElasticHandle::from_index(o as u32));
                    let budget = eta * (dissipated[o] + received[o]);
                    let tol = 1e-9 * (budget + info.energy.requested.abs()) + 1e-12;
                    assert!(
                        injected[o] <= budget + tol,
                        "η {eta} seed {seed} step {step} object {o}: injected {} > η × ({} + {})",
                        injected[o],
                        dissipated[o],
                        received[o]
                    );
                    assert!(
                        (info.energy.injected - injected[o]).abs() <= tol,
                        "world's account {} vs measured {}",
                        info.energy.injected,
                        injected[o]
                    );
                    assert!(
                        (info.energy.dissipated - dissipated[o]).abs()
                            <= 1e-12 * (1.0 + dissipated[o])
                    );
                    assert!((info.energy.received - received[o]).abs() <= tol);
                }
            }
        }
        assert!(
            steps_with_events > 100,
            "η {eta}: only {steps_with_events} steps with events"
        );
        assert!(
            limited > 10,
            "η {eta}: the bound was active in only {limited} object-steps"
        );
    }
}
