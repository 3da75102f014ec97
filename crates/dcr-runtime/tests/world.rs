//! `DcrWorld`: the engine contract, tested through its public API only.
//!
//! Expectations: contacts are classified by the documented rules (a zero-impulse predictive
//! contact is not an impact but fires when its impulse arrives; an id back after a gap is a
//! new contact; the settle window's contacts never fire; stale fresh contacts do not fire);
//! a rotated and translated object gives the identity pose's world impulses rotated, to
//! rounding; one Gauss–Seidel pass gives a body on four contacts the largest single Δv, not
//! the sum; an impulse on a dynamic elastic object chains to the body resting on it in the
//! same step, forward only; cache eviction counts world steps; the transfer-table policy
//! refuses with the numbers or falls back with a counter and a reason; the lateral kick is the
//! tangential peak of the modal response.

use std::sync::Arc;

use dcr_runtime::format::{ModesFile, TransferTable};
use dcr_runtime::response::{
    Impact, ParamsError, RestingContact, ServedBy, TableFallback, TablePolicy, TableStatus,
};
use dcr_runtime::testing::{plate_base, SplitMix64};
use dcr_runtime::{
    BodyState, ContactReport, DcrWorld, DistantResponse, ElasticHandle, ElasticObjectDesc, Launch,
    Method, ModalModel, Pose, ResponseParams, WorldError, WorldParams,
};

const PLATE: u64 = 1;

fn model() -> Arc<ModalModel> {
    Arc::new(ModalModel::from_base(plate_base()).unwrap())
}

fn world_params(eta: Option<f64>) -> WorldParams {
    WorldParams {
        energy_eta: eta,
        gravity: [0.0; 3],
        ..Default::default()
    }
}

/// A world with the plate (static, body [`PLATE`]) at `pose`.
fn plate_world(
    pose: Pose,
    eta: Option<f64>,
    response: ResponseParams,
) -> (DcrWorld, ElasticHandle) {
    let mut w = DcrWorld::new(world_params(eta)).unwrap();
    let mut desc = ElasticObjectDesc::new(model(), PLATE);
    desc.pose = pose;
    desc.response = response;
    let h = w.add_object(desc).unwrap();
    (w, h)
}

/// A contact of body `other` on the plate (posed `pose`) at object point `p` (on the plate's
/// z = 0 face): body1 = the plate, normal = its +z in the world.
fn on_plate(pose: &Pose, id: u64, other: u64, p: [f64; 3], impulse: f64) -> ContactReport {
    let r = pose.rotation_matrix();
    let wp = pose.transform_point(p);
    ContactReport {
        id,
        body1: PLATE,
        body2: other,
        point1: wp,
        point2: wp,
        normal: [r[0][2], r[1][2], r[2][2]],
        impulse,
        is_new: false,
    }
}

fn body(id: u64, inv_mass: f64, com: [f64; 3]) -> BodyState {
    BodyState {
        inv_mass,
        center_of_mass: com,
        ..BodyState::fixed(id)
    }
}

/// Classification: settle window, predictive zero-impulse contacts, stale fresh contacts,
/// recycled ids, and which contacts are resting.
#[test]
fn classification_follows_the_documented_rules() {
    let (mut w, plate) = plate_world(Pose::IDENTITY, None, ResponseParams::default());
    let id = Pose::IDENTITY;
    let bodies = [body(7, 1.0, [0.5, 0.3, 0.1]), body(9, 2.0, [0.2, 0.2, 0.1])];
    let c = |cid: u64, other: u64, lambda: f64| on_plate(&id, cid, other, [0.2, 0.2, 0.0], lambda);
    let impacts_at = |w: &mut DcrWorld, contacts: &[ContactReport]| {
        w.step(contacts, &bodies);
        (w.step_info().impacts, w.object_info(plate).resting)
    };
    // Settle window (steps 0–2): big impulses never fire, even after the window (A appeared
    // in it).
    for _ in 0..3 {
        assert_eq!(impacts_at(&mut w, &[c(1, 9, 5.0)]).0, 0);
    }
    assert_eq!(impacts_at(&mut w, &[c(1, 9, 5.0)]).0, 0); // step 3: A is old
                                                          // Predictive: B appears with zero impulse at step 4 (not an impact, not resting), fires at
                                                          // step 5 when its impulse arrives, not again at step 6.
    assert_eq!(impacts_at(&mut w, &[c(1, 9, 5.0), c(2, 9, 0.0)]), (0, 1));
    assert_eq!(impacts_at(&mut w, &[c(1, 9, 5.0), c(2, 9, 2.0)]), (1, 1));
    assert_eq!(impacts_at(&mut w, &[c(1, 9, 5.0), c(2, 9, 2.0)]), (0, 2));
    // A contact that only ever has zero impulse never fires.
    for _ in 0..4 {
        assert_eq!(impacts_at(&mut w, &[c(3, 9, 0.0)]), (0, 0));
    }
    // Recycled id: D fires, disappears for one step, comes back: it is new and fires again.
    assert_eq!(impacts_at(&mut w, &[c(4, 9, 2.0)]).0, 1);
    assert_eq!(impacts_at(&mut w, &[]).0, 0);
    assert_eq!(impacts_at(&mut w, &[c(4, 9, 2.0)]).0, 1);
    // Present without a gap it does not fire again.
    assert_eq!(impacts_at(&mut w, &[c(4, 9, 2.0)]).0, 0);
    // A zero-impulse contact stays fresh however long it waits (a body lifted within the
    // prediction distance): E fires when it lands; after firing, one step at zero impulse makes
    // it new again (it lands a second time).
    for _ in 0..3 {
        impacts_at(&mut w, &[c(5, 9, 0.0)]);
    }
    assert_eq!(impacts_at(&mut w, &[c(5, 9, 2.0)]), (1, 0));
    assert_eq!(impacts_at(&mut w, &[c(5, 9, 2.0)]), (0, 1));
    impacts_at(&mut w, &[c(5, 9, 0.0)]);
    assert_eq!(impacts_at(&mut w, &[c(5, 9, 2.0)]), (1, 0));
    // Stale: F touches with an impulse below the threshold for longer than fresh_steps = 2;
    // its late big impulse is not an impact (it is a resting contact of the dynamic body 9).
    for _ in 0..3 {
        impacts_at(&mut w, &[c(10, 9, 1e-4)]);
    }
    assert_eq!(impacts_at(&mut w, &[c(10, 9, 2.0)]), (0, 1));
    // Below the object's threshold (1e-3 N·s): not an impact; a body without state (static)
    // is never resting.
    assert_eq!(impacts_at(&mut w, &[c(6, 9, 1e-4)]), (0, 1));
    assert_eq!(impacts_at(&mut w, &[c(7, 99, 2.0)]).0, 1);
    assert_eq!(impacts_at(&mut w, &[c(8, 99, 0.5)]), (1, 0));
    assert_eq!(impacts_at(&mut w, &[c(8, 99, 0.5)]), (0, 0));
}

/// The engine's newness rule with quiet steps passed by `advance`: impacts are the reports
/// flagged new with impulse ≥ threshold after the settle window (counted in engine steps), and
/// cache eviction counts the advanced steps.
#[test]
fn engine_newness_and_advance() {
    let mut wp = world_params(None);
    wp.classify.engine_newness = true;
    let mut w = DcrWorld::new(wp).unwrap();
    let mut desc = ElasticObjectDesc::new(model(), PLATE);
    desc.response.evict_after_steps = 5;
    let plate = w.add_object(desc).unwrap();
    let id = Pose::IDENTITY;
    let bodies = [body(7, 1.0, [0.5, 0.3, 0.1]), body(9, 2.0, [0.2, 0.2, 0.1])];
    let c = |cid: u64, lambda: f64, is_new: bool| ContactReport {
        is_new,
        ..on_plate(&id, cid, 9, [0.2, 0.2, 0.0], lambda)
    };
    let rest = on_plate(&id, 70, 7, [0.8, 0.4, 0.0], 0.1);
    // Steps 0 and 1: the settle window.
    w.step(&[c(1, 2.0, true), rest], &bodies);
    assert_eq!(w.step_info().impacts, 0);
    w.advance(1);
    assert!(!w.needs_step());
    w.step(&[c(2, 2.0, true)], &bodies); // step 2
    assert_eq!(w.step_info().impacts, 0);
    // Step 3 on: new and strong → impact (the resting contact is mapped at this query); not
    // new, weak or zero → not.
    let events = w.step(&[c(3, 2.0, true), rest], &bodies).len();
    assert_eq!(
        (w.step_info().step, w.step_info().impacts, events),
        (3, 1, 1)
    );
    assert_eq!(w.response(plate).cached_contacts(), 1);
    for (lambda, is_new) in [(2.0, false), (0.0, true), (1e-4, true)] {
        w.step(&[c(3, lambda, is_new)], &bodies);
        assert_eq!(w.step_info().impacts, 0, "λ {lambda} new {is_new}");
    }
    // Twenty quiet steps: the resting contact, unseen, is evicted at the next query.
    w.advance(20);
    assert_eq!(w.events().len(), 0);
    w.step(&[c(4, 2.0, true)], &bodies);
    assert_eq!((w.step_info().step, w.step_info().impacts), (27, 1));
    assert_eq!(w.response(plate).cached_contacts(), 0);
}

/// A non-trivial world inverse inertia (symmetric positive definite), 1/(kg·m²).
fn inv_inertia() -> [[f64; 3]; 3] {
    [[2.0, 0.3, -0.2], [0.3, 1.5, 0.1], [-0.2, 0.1, 3.0]]
}

fn mat_mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn transpose(a: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}

fn rot(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| (0..3).map(|k| r[i][k] * v[k]).sum())
}

/// A body's state in the frame of `pose` (given in the identity frame).
fn posed_body(b: &BodyState, pose: &Pose) -> BodyState {
    let r = pose.rotation_matrix();
    BodyState {
        center_of_mass: pose.transform_point(b.center_of_mass),
        inv_inertia: mat_mul(&mat_mul(&r, &b.inv_inertia), &transpose(&r)),
        linvel: rot(&r, b.linvel),
        angvel: rot(&r, b.angvel),
        ..*b
    }
}

/// Frames: the same scene with the plate rotated and translated gives the identity pose's
/// events with points transformed and impulses rotated, to rounding (energy bound and lateral
/// kick on, so their scaling is covered too).
#[test]
fn a_posed_object_gives_the_rotated_impulses() {
    let pose = Pose::from_axis_angle([0.3, 0.5, 0.8], 0.7, [1.0, -2.0, 0.5]);
    let r = pose.rotation_matrix();
    let params = ResponseParams {
        lateral_kick: true,
        ..Default::default()
    };
    let mut resting_body = body(7, 0.5, [0.85, 0.47, 0.05]);
    resting_body.inv_inertia = inv_inertia();
    resting_body.linvel = [0.01, -0.02, 0.005];
    resting_body.angvel = [0.1, 0.0, -0.05];
    // The ball leaves almost as fast as the 3 N·s impulse would throw it from rest: the impact
    // dissipates ½kλ² − λu⁺ = 9 − 8.997 = 3 mJ, so η = 0.1 limits the response (~0.4 mJ).
    let mut ball = body(9, 2.0, [0.5, 0.3, 0.06]);
    ball.linvel = [0.0, 0.0, 2.999];
    let run = |pose: &Pose| {
        let (mut w, _) = plate_world(*pose, Some(0.1), params.clone());
        let bodies = [posed_body(&resting_body, pose), posed_body(&ball, pose)];
        let rest = [
            on_plate(pose, 70, 7, [0.9, 0.5, 0.0], 0.01),
            on_plate(pose, 71, 7, [0.8, 0.45, 0.0], 0.01),
        ];
        for _ in 0..4 {
            w.step(&rest, &bodies);
        }
        let hit = on_plate(pose, 90, 9, [0.5, 0.3, 0.0], 3.0);
        let events = w.step(&[rest[0], rest[1], hit], &bodies).to_vec();
        (events, w.step_info())
    };
    let (ident, info_i) = run(&Pose::IDENTITY);
    let (posed, info_p) = run(&pose);
    assert_eq!(ident.len(), 2);
    assert_eq!(posed.len(), ident.len());
    assert!(info_i.energy_limited == 1 && info_p.energy_limited == 1);
    let scale = ident.iter().map(|e| norm(e.impulse)).fold(0.0, f64::max);
    for (a, b) in ident.iter().zip(&posed) {
        assert_eq!(
            (a.body, a.contact, a.served_by),
            (b.body, b.contact, b.served_by)
        );
        let want_p = pose.transform_point(a.point);
        let want_j = rot(&r, a.impulse);
        for k in 0..3 {
            assert!(
                (b.point[k] - want_p[k]).abs() < 1e-14,
                "{:?} vs {want_p:?}",
                b.point
            );
            assert!(
                (b.impulse[k] - want_j[k]).abs() < 1e-12 * scale,
                "{:?} vs {want_j:?}",
                b.impulse
            );
        }
        // The lateral kick gives the impulse a tangential part.
        let along_n = dot(a.impulse, a.normal);
        assert!(norm(a.impulse) > along_n * (1.0 + 1e-9));
        assert!((a.delta_v - b.delta_v).abs() < 1e-12 * a.delta_v);
    }
    assert!((info_i.injected - info_p.injected).abs() < 1e-12 * info_i.injected);
    assert!((info_i.dissipated - info_p.dissipated).abs() < 1e-12 * info_i.dissipated);
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Gauss–Seidel: a body (no rotation) on four contacts ends up with the largest of the four
/// responses' Δv along the normal, not their sum; alone on one contact it gets that contact's.
#[test]
fn a_body_on_four_contacts_gets_one_contacts_velocity() {
    let m = model();
    let corners =
        [[0.78, 0.38], [0.82, 0.38], [0.78, 0.42], [0.82, 0.42]].map(|[x, y]| [x, y, 0.0]);
    let hit_point = [0.3, 0.25, 0.0];
    // The four responses, from a standalone response at the identity pose.
    let mut resp = DistantResponse::new(m, ResponseParams::default()).unwrap();
    let resting: Vec<RestingContact> = corners
        .iter()
        .enumerate()
        .map(|(i, &p)| RestingContact {
            id: i as u64,
            point: p,
        })
        .collect();
    let imp = [Impact {
        point: hit_point,
        direction: [0.0, 0.0, -1.0],
        impulse: 2.0,
    }];
    let dv: Vec<f64> = resp
        .step(&imp, &resting)
        .iter()
        .map(|c| c.delta_v)
        .collect();
    let dv_max = dv.iter().copied().fold(0.0, f64::max);
    assert!(dv.iter().all(|&x| x > 0.2 * dv_max));

    let id = Pose::IDENTITY;
    let plate_body = body(7, 0.5, [0.8, 0.4, 0.05]);
    let run = |n: usize| {
        let (mut w, _) = plate_world(id, None, ResponseParams::default());
        let rest: Vec<ContactReport> = corners[..n]
            .iter()
            .enumerate()
            .map(|(i, &p)| on_plate(&id, i as u64, 7, p, 0.01))
            .collect();
        for _ in 0..4 {
            w.step(&rest, &[plate_body]);
        }
        let mut all = rest.clone();
        all.push(on_plate(&id, 90, 9, hit_point, 2.0));
        let events = w.step(&all, &[plate_body]).to_vec();
        // The body's velocity change along +z from all events.
        events
            .iter()
            .map(|e| e.impulse[2] * plate_body.inv_mass)
            .sum::<f64>()
    };
    let four = run(4);
    assert!((four - dv_max).abs() < 1e-12 * dv_max, "{four} vs {dv_max}");
    let one = run(1);
    assert!((one - dv[0]).abs() < 1e-12 * dv[0]);
    assert!(four < 1.5 * one, "four contacts {four} vs one {one}");
}

/// The floor → fridge → plant chain: an impact on the (static) floor pushes the (dynamic)
/// fridge, which becomes an impact on the fridge in the same step and pushes the plant.
/// Objects are processed static first whatever the order they were added in; between dynamic
/// objects a chain only goes forward (a backward one is counted, not followed).
#[test]
fn an_impulse_on_the_fridge_reaches_the_plant_in_the_same_step() {
    const FLOOR: u64 = 1;
    const FRIDGE: u64 = 2;
    const PLANT: u64 = 3;
    const BALL: u64 = 9;
    let fridge_pose = Pose::from_axis_angle([0.0, 0.0, 1.0], 0.3, [0.1, 0.0, 0.02]);
    let fridge_body = body(FRIDGE, 0.2, [0.5, 0.3, 0.2]);
    let plant_body = body(PLANT, 1.0, [0.3, 0.4, 0.3]);
    let ball = body(BALL, 1.0, [0.2, 0.2, 0.05]);
    let bodies = [fridge_body, plant_body, ball];
    let floor_contact = ContactReport {
        id: 12,
        body1: FLOOR,
        body2: FRIDGE,
        point1: [0.55, 0.3, 0.0],
        point2: [0.55, 0.3, 0.0],
        normal: [0.0, 0.0, 1.0],
        impulse: 0.5,
        is_new: false,
    };
    let plant_contact = on_fridge(&fridge_pose, 23, PLANT, [0.3, 0.35, 0.0]);
    let hit = ContactReport {
        id: 91,
        body1: FLOOR,
        body2: BALL,
        point1: [0.2, 0.2, 0.0],
        point2: [0.2, 0.2, 0.0],
        normal: [0.0, 0.0, 1.0],
        impulse: 3.0,
        is_new: false,
    };
    for fridge_first in [false, true] {
        let mut w = DcrWorld::new(world_params(Some(1.0))).unwrap();
        let add = |w: &mut DcrWorld, body: u64, dynamic: bool, pose: Pose| {
            let mut d = ElasticObjectDesc::new(model(), body);
            d.dynamic = dynamic;
            d.pose = pose;
            w.add_object(d).unwrap()
        };
        let (floor, fridge) = if fridge_first {
            let fr = add(&mut w, FRIDGE, true, fridge_pose);
            (add(&mut w, FLOOR, false, Pose::IDENTITY), fr)
        } else {
            let fl = add(&mut w, FLOOR, false, Pose::IDENTITY);
            (fl, add(&mut w, FRIDGE, true, fridge_pose))
        };
        for _ in 0..4 {
            w.set_pose(fridge, fridge_pose);
            assert!(w.step(&[floor_contact, plant_contact], &bodies).is_empty());
        }
        w.set_pose(fridge, fridge_pose);
        let events = w
            .step(&[floor_contact, plant_contact, hit], &bodies)
            .to_vec();
        let info = w.step_info();
        assert_eq!(info.chained_impacts, 1, "fridge first: {fridge_first}");
        assert_eq!(info.chains_dropped, 0);
        let on_fridge_ev = events
            .iter()
            .find(|e| e.body == FRIDGE)
            .expect("fridge pushed");
        assert_eq!((on_fridge_ev.object, on_fridge_ev.chained), (floor, false));
        let on_plant = events
            .iter()
            .find(|e| e.body == PLANT)
            .expect("plant pushed");
        assert_eq!((on_plant.object, on_plant.chained), (fridge, true));
        let fi = w.object_info(fridge);
        assert_eq!((fi.impacts, fi.chained_impacts), (0, 1));
        assert!(fi.energy.received > 0.0 && fi.energy.injected <= fi.energy.received);
        assert!(fi.energy.dissipated == 0.0);
    }
    // Two dynamic objects, the one resting on the other added first: its chain would go
    // backward, so it is dropped and counted.
    let mut w = DcrWorld::new(world_params(None)).unwrap();
    let mut upper = ElasticObjectDesc::new(model(), PLANT);
    upper.dynamic = true;
    upper.pose = Pose::from_translation([0.0, 0.0, 0.5]);
    w.add_object(upper).unwrap();
    let mut lower = ElasticObjectDesc::new(model(), FRIDGE);
    lower.dynamic = true;
    let lower_h = w.add_object(lower).unwrap();
    let on_lower = |id, other, p: [f64; 3], lambda| ContactReport {
        id,
        body1: FRIDGE,
        body2: other,
        point1: p,
        point2: p,
        normal: [0.0, 0.0, 1.0],
        impulse: lambda,
        is_new: false,
    };
    let bodies = [fridge_body, plant_body, ball];
    let rest = on_lower(33, PLANT, [0.6, 0.4, 0.0], 0.2);
    for _ in 0..4 {
        w.step(&[rest], &bodies);
    }
    let events = w.step(&[rest, on_lower(34, BALL, [0.2, 0.2, 0.0], 3.0)], &bodies);
    assert!(events
        .iter()
        .any(|e| e.body == PLANT && e.object == lower_h));
    let info = w.step_info();
    assert_eq!((info.chained_impacts, info.chains_dropped), (0, 1));
}

/// A contact of body `other` on the fridge (posed `pose`), body1 = the fridge.
fn on_fridge(pose: &Pose, id: u64, other: u64, p: [f64; 3]) -> ContactReport {
    let r = pose.rotation_matrix();
    let wp = pose.transform_point(p);
    ContactReport {
        id,
        body1: 2,
        body2: other,
        point1: wp,
        point2: wp,
        normal: [r[0][2], r[1][2], r[2][2]],
        impulse: 0.1,
        is_new: false,
    }
}

/// Eviction counts world steps: a resting contact seen at one query and absent at the next,
/// 20 steps later, is evicted with `evict_after_steps = 5`, though only two queries ran.
#[test]
fn eviction_is_counted_in_world_steps() {
    let params = ResponseParams {
        evict_after_steps: 5,
        ..Default::default()
    };
    let (mut w, plate) = plate_world(Pose::IDENTITY, None, params);
    let id = Pose::IDENTITY;
    let bodies = [body(7, 1.0, [0.8, 0.4, 0.1]), body(8, 1.0, [0.7, 0.2, 0.1])];
    let a = on_plate(&id, 1, 7, [0.8, 0.4, 0.0], 0.1);
    let b = on_plate(&id, 2, 8, [0.7, 0.2, 0.0], 0.1);
    for _ in 0..4 {
        w.step(&[a], &bodies);
    }
    w.step(&[a, on_plate(&id, 50, 9, [0.3, 0.3, 0.0], 2.0)], &bodies);
    assert_eq!(w.response(plate).cached_contacts(), 1);
    for _ in 0..20 {
        w.step(&[b], &bodies);
    }
    w.step(&[b, on_plate(&id, 51, 9, [0.3, 0.3, 0.0], 2.0)], &bodies);
    assert_eq!(w.step_info().queries, 1);
    assert_eq!(
        w.response(plate).cached_contacts(),
        1,
        "contact a not evicted"
    );
}

/// The plate base with a synthetic table over x ≤ 0.5 m, baked for h = 0.01 s.
fn base_with_table() -> ModesFile {
    let mut b = plate_base();
    let vertices: Vec<u32> = (0..b.surface_vertices.len())
        .filter(|&v| b.surface_vertices[v][0] <= 0.5 + 1e-12)
        .map(|v| v as u32)
        .collect();
    let np = vertices.len();
    b.transfer = Some(TransferTable {
        h: 0.01,
        rayleigh: b.rayleigh,
        modes: 40,
        samples: 100,
        vertices,
        order: 1,
        edges: Vec::new(),
        faces: Vec::new(),
        peaks: (0..TransferTable::packed_len(np))
            .map(|k| 1e-5 * (1 + k % 5) as f32)
            .collect(),
    });
    b
}

/// The transfer-table policy: `Refuse` fails at set-up with the numbers; `FallBackToModal`
/// serves with the modal method, counts every contact and says why.
#[test]
fn a_table_that_does_not_apply_is_refused_or_counted() {
    let m = Arc::new(ModalModel::from_base(base_with_table()).unwrap());
    let h = 1.0 / 60.0;
    let mut w = DcrWorld::new(WorldParams {
        h,
        gravity: [0.0; 3],
        ..Default::default()
    })
    .unwrap();
    let mut desc = ElasticObjectDesc::new(Arc::clone(&m), PLATE);
    desc.response.table_policy = TablePolicy::Refuse;
    let err = w.add_object(desc.clone()).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(
            err,
            WorldError::Response {
                body: PLATE,
                source: ParamsError::TableRefused {
                    status: TableStatus::StepMismatch { .. }
                }
            }
        ),
        "{msg}"
    );
    assert!(msg.contains("0.01 s") && msg.contains("0.016666"), "{msg}");
    assert_eq!(w.num_objects(), 0);

    desc.response.table_policy = TablePolicy::FallBackToModal;
    let plate = w.add_object(desc).unwrap();
    assert_eq!(
        w.response(plate).table_status(),
        TableStatus::StepMismatch { table_h: 0.01, h }
    );
    let id = Pose::IDENTITY;
    let bodies = [body(7, 1.0, [0.2, 0.3, 0.1])];
    let rest = on_plate(&id, 1, 7, [0.2, 0.3, 0.0], 0.1);
    for _ in 0..4 {
        w.step(&[rest], &bodies);
    }
    let events = w.step(&[rest, on_plate(&id, 2, 9, [0.3, 0.2, 0.0], 2.0)], &bodies);
    assert_eq!(events[0].served_by, ServedBy::Modal);
    let info = w.object_info(plate).response;
    assert_eq!(info.contacts_table_fallback, 1);
    assert_eq!(info.table_fallback, Some(TableFallback::Unavailable));

    // At the table's h it serves; a contact outside its region is counted with its reason.
    let mut w = DcrWorld::new(WorldParams::with_gravity([0.0; 3])).unwrap();
    let mut desc = ElasticObjectDesc::new(m, PLATE);
    desc.response.table_policy = TablePolicy::Refuse;
    let plate = w.add_object(desc).unwrap();
    assert_eq!(w.response(plate).table_status(), TableStatus::Active);
    let outside = on_plate(&id, 3, 7, [0.9, 0.3, 0.0], 0.1);
    for _ in 0..4 {
        w.step(&[rest, outside], &bodies);
    }
    let events = w
        .step(
            &[rest, outside, on_plate(&id, 2, 9, [0.3, 0.2, 0.0], 2.0)],
            &bodies,
        )
        .to_vec();
    let served: Vec<ServedBy> = events.iter().map(|e| e.served_by).collect();
    assert!(served.contains(&ServedBy::TransferTable));
    let info = w.object_info(plate).response;
    assert_eq!(
        (info.contacts_by_table, info.contacts_table_fallback),
        (1, 1)
    );
    assert_eq!(
        info.table_fallback,
        Some(TableFallback::ContactsOutsideRegion)
    );
}

/// The lateral kick is the tangential peak of the modal displacement: recomputed here from the
/// response's own samples q(k) and the base's three mode rows per vertex; zero when off.
#[test]
fn the_lateral_kick_is_the_tangential_peak() {
    let m = model();
    let params = ResponseParams {
        method: Method::Modal,
        lateral_kick: true,
        ..Default::default()
    };
    let mut resp = DistantResponse::new(Arc::clone(&m), params.clone()).unwrap();
    let mut rng = SplitMix64(4);
    let resting: Vec<RestingContact> = (0..6)
        .map(|i| RestingContact {
            id: i,
            point: [rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.0],
        })
        .collect();
    let imp = [Impact {
        point: [0.4, 0.2, 0.0],
        direction: [0.3, -0.2, -1.0],
        impulse: 1.5,
    }];
    let out = resp.step(&imp, &resting).to_vec();
    let q = resp.modal_samples().to_vec();
    let nm = m.num_modes();
    let modes = &m.base().modes;
    for (o, rc) in out.iter().zip(&resting) {
        let sp = m.project(rc.point, 1.0).unwrap();
        let (mut best, mut want) = (0.0, [0.0; 3]);
        for qk in q.chunks_exact(nm) {
            let mut u = [0.0; 3];
            for (i, v) in m.triangle(sp.triangle).into_iter().enumerate() {
                for axis in 0..3 {
                    for j in 0..nm {
                        u[axis] += sp.bary[i] * modes[(v * 3 + axis) * nm + j] * qk[j];
                    }
                }
            }
            let un = dot(u, sp.normal);
            let ut = [0, 1, 2].map(|k| u[k] - un * sp.normal[k]);
            if dot(ut, ut) > best {
                best = dot(ut, ut);
                want = ut.map(|x| x / params.h);
            }
        }
        assert!(best > 0.0);
        assert!(dot(o.lateral_delta_v, sp.normal).abs() < 1e-12 * norm(want));
        for k in 0..3 {
            assert!((o.lateral_delta_v[k] - want[k]).abs() < 1e-10 * norm(want));
        }
    }
    let mut off = DistantResponse::new(m, ResponseParams::default()).unwrap();
    assert!(off
        .step(&imp, &resting)
        .iter()
        .all(|o| o.lateral_delta_v == [0.0; 3]));
}

/// The 20-mode response with carried filters and the sustained launch.
fn sustained_modal() -> ResponseParams {
    ResponseParams {
        method: Method::Modal,
        carry_over: true,
        launch: Launch::SustainedPeak,
        ..Default::default()
    }
}

/// [`Launch::SustainedPeak`]: set-up refuses it without carry-over or with attenuation; on
/// the impact's step a resting body gets the paper's Δv = d/h; on the following steps, with no
/// impact, it gets the carried filters' d/h as a target for its normal velocity — the full
/// value at rest, the remainder when it already moves up, nothing when it moves faster or its
/// contact only predicted (zero impulse) — and the energy bound (η = 1) lets it through,
/// counting the ringing plate's modal energy. The paper's rule with carry-over adds instead.
#[test]
fn sustained_peak_raises_a_resting_body_to_the_carried_peak() {
    let sustained = sustained_modal();
    for bad in [
        ResponseParams {
            carry_over: false,
            ..sustained.clone()
        },
        ResponseParams {
            method: Method::Attenuation(Default::default()),
            ..sustained.clone()
        },
    ] {
        match DistantResponse::new(model(), bad) {
            Err(ParamsError::Invalid {
                field: "launch", ..
            }) => {}
            other => panic!("expected an invalid launch, got {other:?}"),
        }
    }

    let contact = [0.8, 0.4, 0.0];
    let hit_point = [0.3, 0.25, 0.0];
    let imp = [Impact {
        point: hit_point,
        direction: [0.0, 0.0, -1.0],
        impulse: 2.0,
    }];
    let resting = [RestingContact {
        id: 0,
        point: contact,
    }];
    // The standalone carried response: d/h on the impact's step and on the next one, the
    // filters drained in between by the kinetic energy the first push gives the 2 kg body at
    // rest (½ m Δv²; its contact is under its centre of mass, so no rotation).
    let mut resp = DistantResponse::new(model(), sustained.clone()).unwrap();
    let first = resp.step(&imp, &resting)[0].delta_v;
    let mut undrained = DistantResponse::new(model(), sustained.clone()).unwrap();
    undrained.step(&imp, &resting);
    resp.drain(0.5 * 2.0 * first * first);
    let second = resp.step(&[], &resting)[0].delta_v;
    let second_undrained = undrained.step(&[], &resting)[0].delta_v;
    assert!(second < second_undrained, "{second} vs {second_undrained}");
    assert!(first > 0.0 && second > 0.0, "{first} {second}");

    let id = Pose::IDENTITY;
    // The body's Δv along +z at the impact's step and the next, the next with the body moving
    // up at `v_up` (m/s) and its contact carrying `impulse` (N·s).
    let run = |params: &ResponseParams, eta: Option<f64>, v_up: f64, impulse: f64| {
        let (mut w, _) = plate_world(id, eta, params.clone());
        let mut b = body(7, 0.5, [0.8, 0.4, 0.05]);
        let rest = [on_plate(&id, 0, 7, contact, 0.01)];
        for _ in 0..4 {
            w.step(&rest, &[b]);
        }
        let dv = |events: &[dcr_runtime::ImpulseEvent]| {
            events.iter().map(|e| e.impulse[2] * 0.5).sum::<f64>()
        };
        let with_hit = [rest[0], on_plate(&id, 90, 9, hit_point, 2.0)];
        let dv1 = dv(w.step(&with_hit, &[b]));
        b.linvel = [0.0, 0.0, v_up];
        let dv2 = dv(w.step(&[on_plate(&id, 0, 7, contact, impulse)], &[b]));
        (dv1, dv2)
    };
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-300);
    let (dv1, dv2) = run(&sustained, None, 0.0, 0.01);
    assert!(close(dv1, first), "{dv1} vs {first}");
    assert!(close(dv2, second), "{dv2} vs {second}");
    let (_, half) = run(&sustained, None, 0.5 * second, 0.01);
    assert!(close(half, 0.5 * second), "{half} vs {}", 0.5 * second);
    assert_eq!(run(&sustained, None, 2.0 * second, 0.01).1, 0.0);
    assert_eq!(run(&sustained, None, 0.0, 0.0).1, 0.0);
    let (_, bounded) = run(&sustained, Some(1.0), 0.0, 0.01);
    assert!(close(bounded, second), "{bounded} vs {second}");
    // The paper's rule with carry-over: d/h of the undrained filters, added to the body's
    // own velocity.
    let paper = ResponseParams {
        launch: Launch::PeakOverStep,
        ..sustained
    };
    let (_, added) = run(&paper, None, 2.0 * second, 0.01);
    assert!(
        close(added, second_undrained),
        "{added} vs {second_undrained}"
    );
}

/// The sustained launch is paid for by the ringing: a heavy prop held at rest on a ringing plate
/// is pushed on every step, and each push's kinetic energy is drained from the carried filters,
/// so the energy given over all the steps after the impact never exceeds the modal energy the
/// impact left (without the drain the same pushes would give it several times over).
#[test]
fn sustained_pushes_drain_the_ringing_that_pays_for_them() {
    let sustained = sustained_modal();
    let id = Pose::IDENTITY;
    let contact = [0.8, 0.4, 0.0];
    let hit_point = [0.3, 0.25, 0.0];
    // The default energy bound (η = 1): a step gives at most the ringing it holds.
    let (mut w, plate) = plate_world(id, Some(1.0), sustained.clone());
    // 500 kg held at rest: the pushes draw a lot from a 2 N·s impact's ringing.
    let heavy = body(7, 0.002, [0.8, 0.4, 0.05]);
    let rest = [on_plate(&id, 0, 7, contact, 0.5)];
    for _ in 0..4 {
        w.step(&rest, &[heavy]);
    }
    w.step(&[rest[0], on_plate(&id, 90, 9, hit_point, 2.0)], &[heavy]);
    let after_impact = w.response(plate).modal_energy();
    assert!(after_impact > 0.0);
    let mut given = 0.0;
    let mut pushed = 0;
    for _ in 0..200 {
        let e_before = w.response(plate).modal_energy();
        let pushes = w.step(&rest, &[heavy]).len();
        let info = w.object_info(plate);
        if pushes > 0 {
            pushed += 1;
            // The kinetic energy of a push from rest, ½ m Δv² = Σ |j|² / (2 m), is what left
            // the filters this step (beside the damping of the step's own ringing).
            let injected = info.energy.injected;
            assert!(injected > 0.0);
            assert!(
                w.response(plate).modal_energy() <= e_before - injected + 1e-12 * e_before,
                "step drained less than it gave: {} -> {} with {injected} J given",
                e_before,
                w.response(plate).modal_energy()
            );
        }
        given += info.energy.injected;
    }
    assert!(pushed > 3, "the ringing pushed on {pushed} steps");
    assert!(
        given <= after_impact * (1.0 + 1e-9),
        "{given} J given after the impact from {after_impact} J of ringing"
    );
    // The same run without the drain: the standalone response, stepped alike, keeps
    // asking for pushes whose energies add up past the ringing it started from.
    let mut resp = DistantResponse::new(model(), sustained).unwrap();
    let resting = [RestingContact {
        id: 0,
        point: contact,
    }];
    resp.step(
        &[Impact {
            point: hit_point,
            direction: [0.0, 0.0, -1.0],
            impulse: 2.0,
        }],
        &resting,
    );
    let start = resp.modal_energy();
    let undrained: f64 = (0..200)
        .map(|_| {
            let dv = resp.step(&[], &resting)[0].delta_v;
            0.5 * 500.0 * dv * dv
        })
        .sum();
    assert!(undrained > 2.0 * start, "{undrained} J vs {start} J");
}

/// The default gravity is unset and refused with the fix (an engine's gravity or zero), so no
/// world silently loses g·h of every lifting push; a set one is kept, and `set_gravity` keeps
/// the old value when given a non-finite one.
#[test]
fn gravity_must_be_given() {
    let err = match DcrWorld::new(WorldParams::default()) {
        Ok(_) => panic!("the default (unset) gravity is accepted"),
        Err(e) => e.to_string(),
    };
    for needle in ["gravity", "is not set", "[0, -9.81, 0]", "[0, 0, 0]", "g·h"] {
        assert!(err.contains(needle), "`{needle}` not in `{err}`");
    }
    let mut w = DcrWorld::new(WorldParams::with_gravity([0.0, -9.81, 0.0])).unwrap();
    assert_eq!(w.params().gravity, [0.0, -9.81, 0.0]);
    assert!(w.set_gravity([f64::NAN, 0.0, 0.0]).is_err());
    assert_eq!(w.params().gravity, [0.0, -9.81, 0.0]);
    assert!(DcrWorld::new(WorldParams::with_gravity([0.0; 3])).is_ok());
    assert!(DcrWorld::new(WorldParams::with_gravity([0.0, f64::INFINITY, 0.0])).is_err());
}

/// `min_approach_speed`: a fresh contact carrying a resting weight's impulse (it closed at
/// about g·h) is an impact without a minimum and resting with one of 2 g h, while a contact
/// that closed fast (an impulse stopping a falling body) stays an impact; a negative or
/// non-finite minimum is refused.
#[test]
fn a_minimum_approach_speed_leaves_out_new_points_of_a_resting_weight() {
    let g_h = 9.81 * 0.01;
    for (min, weight_fires) in [(0.0, true), (2.0 * g_h, false)] {
        let mut wp = world_params(None);
        wp.classify.min_approach_speed = min;
        let mut w = DcrWorld::new(wp).unwrap();
        let plate = w
            .add_object(ElasticObjectDesc::new(model(), PLATE))
            .unwrap();
        // A 30 kg body at rest after the step whose new point carries its weight over one step
        // (λ = m g h = 2.94 N·s, closing at λ/m = g h), and a 1 kg body stopped from 2 m/s
        // (λ = 2 N·s, closing at 2 m/s).
        let heavy = body(7, 1.0 / 30.0, [0.5, 0.3, 0.1]);
        let light = body(9, 1.0, [0.2, 0.2, 0.1]);
        let at = |id: u64, other: u64, p: [f64; 3], lambda: f64| {
            on_plate(&Pose::IDENTITY, id, other, p, lambda)
        };
        for _ in 0..4 {
            w.step(&[], &[heavy, light]);
        }
        w.step(&[at(1, 7, [0.5, 0.3, 0.0], 30.0 * g_h)], &[heavy, light]);
        assert_eq!(
            w.step_info().impacts == 1,
            weight_fires,
            "min {min} m/s: the weight's new point"
        );
        assert_eq!(w.object_info(plate).resting, u32::from(!weight_fires));
        w.step(&[at(2, 9, [0.2, 0.2, 0.0], 2.0)], &[heavy, light]);
        assert_eq!(w.step_info().impacts, 1, "min {min} m/s: the fall");
    }
    for bad in [-0.1, f64::NAN, f64::INFINITY] {
        let mut wp = world_params(None);
        wp.classify.min_approach_speed = bad;
        let err = match DcrWorld::new(wp) {
            Ok(_) => panic!("min_approach_speed {bad} accepted"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains("min_approach_speed"), "{err}");
    }
}
