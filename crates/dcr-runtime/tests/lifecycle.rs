//! `DcrWorld` object lifecycle and run-time settings, through the public API.
//!
//! Expectations: a removed object's handle is an error for ever, even after its slot is reused
//! by a new object (with the next generation), and the other objects keep answering; a
//! disabled object issues no events and classifies nothing, and answers again once enabled;
//! the gain scales every Δv and impulse linearly; a new threshold changes which impacts count;
//! `set_h` re-derives the responses so that the world answers exactly as one built with that h,
//! and a table baked for another h is refused (policy Refuse, world unchanged) or served by the
//! modal method with a counter (policy FallBackToModal); per-step counters read zero on quiet
//! steps while totals keep counting; a base held differently from its body is reported.

use std::sync::Arc;

use dcr_runtime::format::{ModesFile, TransferTable};
use dcr_runtime::response::TablePolicy;
use dcr_runtime::testing::plate_base;
use dcr_runtime::world::BaseSupport;
use dcr_runtime::{
    BodyState, ContactReport, DcrWorld, ElasticHandle, ElasticObjectDesc, ImpulseEvent, Method,
    ModalModel, ResponseParams, WorldError, WorldParams,
};

fn model_of(base: ModesFile) -> Arc<ModalModel> {
    Arc::new(ModalModel::from_base(base).unwrap())
}

fn params() -> WorldParams {
    WorldParams {
        energy_eta: None,
        gravity: [0.0; 3],
        ..Default::default()
    }
}

/// A resting contact of body `other` on plate body `plate` at object point `p` (z = 0 face,
/// identity pose): normal +z from the plate.
fn contact(id: u64, plate: u64, other: u64, p: [f64; 3], impulse: f64) -> ContactReport {
    ContactReport {
        id,
        body1: plate,
        body2: other,
        point1: p,
        point2: p,
        normal: [0.0, 0.0, 1.0],
        impulse,
        is_new: false,
    }
}

fn boxy(id: u64) -> BodyState {
    BodyState {
        inv_mass: 1.0,
        center_of_mass: [0.9, 0.5, 0.05],
        ..BodyState::fixed(id)
    }
}

/// Settles a box (body 7) on plate body `plate`, then hits the plate's middle with 2 N·s;
/// returns the hit step's events (owned).
fn hit(w: &mut DcrWorld, plate: u64) -> Vec<ImpulseEvent> {
    let rest = contact(70 + plate, plate, 7, [0.9, 0.5, 0.0], 0.01);
    for _ in 0..4 {
        w.step(&[rest], &[boxy(7)]);
    }
    let mut ball = contact(90 + plate, plate, 9, [0.5, 0.3, 0.0], 2.0);
    ball.normal = [0.0, 0.0, -1.0];
    ball.body1 = 9;
    ball.body2 = plate;
    w.step(&[rest, ball], &[boxy(7)]).to_vec()
}

fn plate_world(rp: ResponseParams) -> (DcrWorld, ElasticHandle) {
    let mut w = DcrWorld::new(params()).unwrap();
    let mut desc = ElasticObjectDesc::new(model_of(plate_base()), 1);
    desc.response = rp;
    let h = w.add_object(desc).unwrap();
    (w, h)
}

/// Removal: the handle is stale (error, never another object), the slot is reused with the
/// next generation, and a stale copy of the old handle still fails after the reuse.
#[test]
fn a_removed_handle_is_stale_even_after_its_slot_is_reused() {
    let mut w = DcrWorld::new(params()).unwrap();
    let m = model_of(plate_base());
    let a = w.add_object(ElasticObjectDesc::new(m.clone(), 1)).unwrap();
    let b = w.add_object(ElasticObjectDesc::new(m.clone(), 2)).unwrap();
    assert_eq!((a.index(), a.generation()), (0, 0));
    assert_eq!((b.index(), b.generation()), (1, 0));
    w.remove_object(a).unwrap();
    assert!(!w.contains(a) && w.contains(b));
    assert_eq!(w.num_objects(), 1);
    assert!(matches!(
        w.remove_object(a),
        Err(WorldError::StaleHandle { .. })
    ));
    assert!(matches!(
        w.set_gain(a, 2.0),
        Err(WorldError::StaleHandle { .. })
    ));
    assert!(matches!(
        w.set_enabled(a, false),
        Err(WorldError::StaleHandle { .. })
    ));
    // Body 1 is free again; the new object takes slot 0 with generation 1.
    let c = w.add_object(ElasticObjectDesc::new(m.clone(), 1)).unwrap();
    assert_eq!((c.index(), c.generation()), (0, 1));
    assert_ne!(c, a);
    assert!(
        !w.contains(a),
        "the old handle must not name the new object"
    );
    assert!(matches!(
        w.set_impact_threshold(a, 1.0),
        Err(WorldError::StaleHandle { .. })
    ));
    assert_eq!(w.body_of(c), 1);
    assert_eq!(w.body_of(b), 2);
    assert_eq!(w.object_of_body(1), Some(c));
    // A handle beyond the slots is stale too.
    assert!(!w.contains(ElasticHandle::from_index(7)));
    // The accessors panic on a stale handle rather than read another object.
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| w.body_of(a)));
    assert!(r.is_err());
    // Both live objects answer, with their own handle in the events.
    let ev = hit(&mut w, 1);
    assert!(!ev.is_empty() && ev.iter().all(|e| e.object == c));
    let ev = hit(&mut w, 2);
    assert!(!ev.is_empty() && ev.iter().all(|e| e.object == b));
}

/// Disable → no events and no impacts classified; enable → events again.
#[test]
fn a_disabled_object_is_silent_and_answers_again_when_enabled() {
    let (mut w, h) = plate_world(ResponseParams::default());
    assert!(!hit(&mut w, 1).is_empty());
    w.set_enabled(h, false).unwrap();
    assert!(!w.is_enabled(h));
    let ev = hit(&mut w, 1);
    assert!(ev.is_empty());
    assert_eq!(w.object_info(h).impacts, 0);
    assert_eq!(w.step_info().impacts, 0);
    assert!(w.object_totals(h).disabled_steps >= 5);
    w.set_enabled(h, true).unwrap();
    // The bouncing contact ids are new again after a gap of one step.
    w.step(&[], &[]);
    let ev = hit(&mut w, 1);
    assert!(!ev.is_empty());
    assert_eq!(w.object_info(h).impacts, 1);
}

/// The gain scales Δv and the impulse linearly (property over several gains).
#[test]
fn the_gain_scales_the_response_linearly() {
    let (mut w, h) = plate_world(ResponseParams::default());
    let base = hit(&mut w, 1);
    assert_eq!(base.len(), 1);
    for &g in &[0.0, 0.25, 1.0, 2.5, 7.0] {
        let (mut w2, h2) = plate_world(ResponseParams::default());
        w2.set_gain(h2, g).unwrap();
        assert_eq!(w2.gain(h2), g);
        let ev = hit(&mut w2, 1);
        if g == 0.0 {
            assert!(ev.is_empty());
            continue;
        }
        assert_eq!(ev.len(), 1);
        let rel = (ev[0].delta_v - g * base[0].delta_v).abs() / (g * base[0].delta_v);
        assert!(
            rel < 1e-12,
            "gain {g}: Δv {} vs {}",
            ev[0].delta_v,
            base[0].delta_v
        );
        for k in 0..3 {
            assert!((ev[0].impulse[k] - g * base[0].impulse[k]).abs() <= 1e-12 * g);
        }
    }
    assert!(w.set_gain(h, -1.0).is_err());
    assert!(w.set_gain(h, f64::NAN).is_err());
    assert_eq!(w.gain(h), 1.0, "a refused gain leaves the old one");
}

/// A threshold above the hit's impulse stops the response; back below, it answers.
#[test]
fn the_threshold_changes_at_run_time() {
    let (mut w, h) = plate_world(ResponseParams::default());
    w.set_impact_threshold(h, 3.0).unwrap();
    assert!(hit(&mut w, 1).is_empty());
    assert_eq!(w.object_info(h).impacts, 0);
    assert!(w.set_impact_threshold(h, -1.0).is_err());
    assert_eq!(w.impact_threshold(h), 3.0);
    w.set_impact_threshold(h, 1.0).unwrap();
    w.step(&[], &[]);
    assert!(!hit(&mut w, 1).is_empty());
}

/// `set_h(dt)` gives exactly the response of a world built with `h = dt`.
#[test]
fn set_h_rederives_the_responses_exactly() {
    for &dt in &[1.0 / 60.0, 0.004, 0.02] {
        let (mut a, ha) = plate_world(ResponseParams::default());
        a.set_h(dt).unwrap();
        assert_eq!(a.params().h, dt);
        assert_eq!(a.response(ha).params().h, dt);
        let mut b = DcrWorld::new(WorldParams { h: dt, ..params() }).unwrap();
        let hb = b
            .add_object(ElasticObjectDesc::new(model_of(plate_base()), 1))
            .unwrap();
        assert_eq!(
            a.response(ha).samples_per_step(),
            b.response(hb).samples_per_step()
        );
        let (ea, eb) = (hit(&mut a, 1), hit(&mut b, 1));
        assert_eq!(ea.len(), 1);
        assert_eq!(ea, eb, "dt = {dt}");
    }
    let (mut a, _) = plate_world(ResponseParams::default());
    assert!(a.set_h(0.0).is_err() && a.set_h(f64::NAN).is_err());
    assert_eq!(a.params().h, 0.01);
}

/// A table baked for h = 0.01: a new h is refused under `Refuse` (world unchanged) and served
/// by the modal method with a counter under `FallBackToModal`.
#[test]
fn a_table_for_another_h_is_refused_or_counted() {
    // A table over the whole plate, baked for h = 0.01 s.
    let mut base = plate_base();
    let vertices: Vec<u32> = (0..base.surface_vertices.len() as u32).collect();
    let np = vertices.len();
    base.transfer = Some(TransferTable {
        h: 0.01,
        rayleigh: base.rayleigh,
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
    let world_with = |policy| {
        let mut w = DcrWorld::new(params()).unwrap();
        let mut desc = ElasticObjectDesc::new(model_of(base.clone()), 1);
        desc.response = ResponseParams {
            method: Method::Transfer,
            table_policy: policy,
            ..Default::default()
        };
        let h = w.add_object(desc).unwrap();
        assert!(w.response(h).transfer_active());
        (w, h)
    };
    let (mut w, h) = world_with(TablePolicy::Refuse);
    let e = w.set_h(1.0 / 60.0).unwrap_err();
    assert!(e.to_string().contains("table"), "{e}");
    assert_eq!(w.params().h, 0.01);
    assert!(w.response(h).transfer_active());
    let (mut w, h) = world_with(TablePolicy::FallBackToModal);
    w.set_h(1.0 / 60.0).unwrap();
    assert!(!w.response(h).transfer_active());
    let ev = hit(&mut w, 1);
    assert!(!ev.is_empty());
    assert!(w.object_info(h).response.contacts_table_fallback > 0);
    assert!(w.object_totals(h).contacts_table_fallback > 0);
}

/// Per-step counters are zero on steps passed with `advance`; totals keep the sum.
#[test]
fn step_counters_reset_on_quiet_steps_and_totals_accumulate() {
    let (mut w, h) = plate_world(ResponseParams::default());
    let rest = contact(71, 1, 7, [0.9, 0.5, 0.0], 0.01);
    let mut ball = contact(91, 9, 1, [0.5, 0.3, 0.0], 2.0);
    ball.normal = [0.0, 0.0, -1.0];
    let (mut impacts, mut events) = (0, 0);
    let mut sum = |w: &DcrWorld| {
        impacts += w.object_info(h).impacts;
        events += w.object_info(h).events;
    };
    for _ in 0..4 {
        w.step(&[rest], &[boxy(7)]);
        sum(&w);
    }
    for round in 0..3 {
        w.step(&[rest, ball], &[boxy(7)]);
        assert_eq!(w.object_info(h).impacts, 1, "round {round}");
        sum(&w);
        // Quiet steps: the counters read zero, so a per-step sum counts the impact once.
        w.advance(1);
        assert_eq!(w.object_info(h).impacts, 0, "round {round}");
        assert_eq!(w.step_info().impacts, 0);
        sum(&w);
        w.advance(3);
        sum(&w);
        w.step(&[rest], &[boxy(7)]);
        sum(&w);
    }
    let t = w.object_totals(h);
    assert!(impacts >= 3);
    assert_eq!(u64::from(impacts), t.impacts);
    assert_eq!(u64::from(events), t.events);
    assert!(t.events >= 3 && t.queries >= 3);
    // Energy totals survive quiet steps.
    w.advance(1);
    assert!(w.object_info(h).energy.total_dissipated > 0.0);
}

/// Contacts far from the base's surface (e.g. a wrong frame) are counted per object.
#[test]
fn unmapped_contacts_are_counted() {
    let (mut w, h) = plate_world(ResponseParams {
        max_map_distance: 0.01,
        ..Default::default()
    });
    // The box 0.5 m above the plate: a y-up base in a z-up world would look like this.
    let far = contact(71, 1, 7, [0.9, 0.5, 0.5], 0.01);
    for _ in 0..4 {
        w.step(&[far], &[boxy(7)]);
    }
    let mut ball = contact(91, 9, 1, [0.5, 0.3, 0.0], 2.0);
    ball.normal = [0.0, 0.0, -1.0];
    assert!(w.step(&[far, ball], &[boxy(7)]).is_empty());
    assert_eq!(w.object_info(h).response.contacts_unmapped, 1);
    assert_eq!(w.object_totals(h).contacts_unmapped, 1);
}

/// A dynamic body with a fixed-node base, and a static body with a free-floating one, are
/// reported; the consistent pairs are not.
#[test]
fn base_support_mismatches_are_reported() {
    let mut free = plate_base();
    free.fixed_nodes.clear();
    let mut held = plate_base();
    held.fixed_nodes = vec![0, 1, 2];
    let mut w = DcrWorld::new(params()).unwrap();
    let support = |w: &mut DcrWorld, base: &ModesFile, body: u64, dynamic: bool| {
        let mut d = ElasticObjectDesc::new(model_of(base.clone()), body);
        d.dynamic = dynamic;
        let h = w.add_object(d).unwrap();
        w.base_support(h)
    };
    assert_eq!(support(&mut w, &held, 1, false), BaseSupport::Consistent);
    assert_eq!(support(&mut w, &free, 2, true), BaseSupport::Consistent);
    assert_eq!(
        support(&mut w, &held, 3, true),
        BaseSupport::DynamicBodyFixedBase { fixed_nodes: 3 }
    );
    assert_eq!(
        support(&mut w, &free, 4, false),
        BaseSupport::StaticBodyFreeBase
    );
}

/// A body resting on an object while it is disabled (with a load above the threshold) is not
/// an impact when the object is enabled again, nor on an object added mid-run under it; a
/// real hit after the settle window still is.
#[test]
fn bodies_resting_on_a_reenabled_or_added_object_are_not_impacts() {
    let heavy = contact(70, 1, 7, [0.9, 0.5, 0.0], 0.0981);
    let (mut w, h) = plate_world(ResponseParams::default());
    w.set_impact_threshold(h, 0.05).unwrap();
    for _ in 0..5 {
        w.step(&[heavy], &[boxy(7)]);
    }
    assert_eq!(w.object_totals(h).impacts, 0, "the initial resting set");
    w.set_enabled(h, false).unwrap();
    for _ in 0..6 {
        w.step(&[heavy], &[boxy(7)]);
    }
    w.set_enabled(h, true).unwrap();
    for _ in 0..6 {
        let ev = w.step(&[heavy], &[boxy(7)]);
        assert!(ev.is_empty());
        assert_eq!(w.object_info(h).impacts, 0, "re-enabled: resting, not new");
    }
    // An object added under a body that already rests on its body.
    let mut w = DcrWorld::new(params()).unwrap();
    for _ in 0..6 {
        w.step(&[heavy], &[boxy(7)]);
    }
    let h = w
        .add_object(ElasticObjectDesc::new(model_of(plate_base()), 1))
        .unwrap();
    w.set_impact_threshold(h, 0.05).unwrap();
    for _ in 0..6 {
        let ev = w.step(&[heavy], &[boxy(7)]);
        assert!(ev.is_empty());
        assert_eq!(
            w.object_info(h).impacts,
            0,
            "added mid-run: resting, not new"
        );
    }
    // A hit after the window is an impact and moves the resting box.
    let mut ball = contact(90, 9, 1, [0.5, 0.3, 0.0], 2.0);
    ball.normal = [0.0, 0.0, -1.0];
    let ev = w.step(&[heavy, ball], &[boxy(7)]).to_vec();
    assert_eq!(w.object_info(h).impacts, 1);
    assert!(!ev.is_empty());
}
