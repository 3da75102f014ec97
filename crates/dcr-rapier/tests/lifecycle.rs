//! The adapter's object lifecycle, rails and separation velocity on small real rapier worlds,
//! for both backends.
//!
//! Expectations:
//! - a resting single-contact ball a response lifts off ends its first step off the plate with
//!   the event's Δv as normal velocity, gravity included, then flies freely, within 2 %, in
//!   both application modes, which lift it by the same height (the support event gives it the
//!   g h its contact no longer carries); a push below g h gets no support and leaves it on
//!   its contact;
//! - a removed object's handle is stale for every adapter call and its slot is reused with a
//!   new generation; a disabled object issues no events and answers again once enabled;
//! - rapier's dt different from the world's h re-derives the responses (the world's h becomes
//!   dt); a transfer table refused for dt keeps h and counts the mismatch on every step;
//! - removing rapier bodies that have pending contacts and events (the receiving ball right
//!   after an impact step, with in-solver replays pending, or the elastic body itself) is safe.

use std::sync::Arc;

use dcr_rapier::dcr_runtime::format::TransferTable;
use dcr_rapier::dcr_runtime::response::TablePolicy;
use dcr_rapier::dcr_runtime::testing::plate_base;
use dcr_rapier::dcr_runtime::Method;
use dcr_rapier::{ElasticObjectDesc, ModalModel, ResponseParams, WorldParams};

fn model() -> Arc<ModalModel> {
    Arc::new(ModalModel::from_base(plate_base()).expect("plate base"))
}

macro_rules! backend_tests {
    ($m:ident) => {
        mod $m {
            use super::*;
            use dcr_rapier::$m::rapier::prelude::*;
            use dcr_rapier::$m::{body_id, AdapterParams, ApplyMode, DcrRapier, Real, StepGate};

            const H: f64 = 0.01;

            struct Scene {
                world: PhysicsWorld,
                dcr: DcrRapier,
                plate: RigidBodyHandle,
                handle: dcr_rapier::ElasticHandle,
            }

            /// The plate base on a fixed body (face z = 0, outward +z), a slab under it,
            /// gravity −z, the world's h = `h`, rapier's dt = 0.01 s.
            fn scene_with(
                apply: ApplyMode,
                h: f64,
                desc: impl Fn(&mut ElasticObjectDesc),
            ) -> Scene {
                let mut world = PhysicsWorld::default();
                world.integration_parameters.dt = H as Real;
                world.gravity = Vector::new(0.0, 0.0, -9.81);
                let plate = world.insert_body(RigidBodyBuilder::fixed());
                let slab = ColliderBuilder::cuboid(0.5, 0.3, 0.05)
                    .translation(Vector::new(0.5, 0.3, -0.05))
                    .friction(0.6);
                world.insert_collider(slab, Some(plate));
                let params = WorldParams {
                    h,
                    energy_eta: None,
                    ..WorldParams::default()
                };
                let adapter = AdapterParams {
                    apply,
                    gate: StepGate::EveryStep,
                    ..AdapterParams::default()
                };
                let mut dcr = DcrRapier::new(params, adapter).expect("adapter");
                let mut d = ElasticObjectDesc::new(model(), 0);
                desc(&mut d);
                let handle = dcr
                    .add_object(&world.bodies, &mut world.colliders, plate, d)
                    .expect("object added");
                Scene {
                    world,
                    dcr,
                    plate,
                    handle,
                }
            }

            fn scene(apply: ApplyMode) -> Scene {
                scene_with(apply, H, |_| {})
            }

            impl Scene {
                fn add(&mut self, p: Vector, collider: ColliderBuilder) -> RigidBodyHandle {
                    let b = self
                        .world
                        .insert_body(RigidBodyBuilder::dynamic().translation(p));
                    self.world.insert_collider(collider, Some(b));
                    b
                }

                /// A 0.2 kg ball resting near the plate's edge for 30 steps.
                fn resting_ball(&mut self) -> RigidBodyHandle {
                    let ball = self.add(
                        Vector::new(0.85, 0.3, 0.03),
                        ColliderBuilder::ball(0.03).mass(0.2),
                    );
                    for _ in 0..30 {
                        self.step();
                    }
                    ball
                }

                /// A heavy ball falling on the plate at (x, 0.3) from 0.3 m at 3 m/s.
                fn drop_ball_at(&mut self, x: Real) -> RigidBodyHandle {
                    let b = self.add(
                        Vector::new(x, 0.3, 0.3),
                        ColliderBuilder::ball(0.1).density(5000.0),
                    );
                    self.world.bodies[b].set_linvel(Vector::new(0.0, 0.0, -3.0), true);
                    b
                }

                /// [`Scene::drop_ball_at`] x = 0.25 m.
                fn drop_ball(&mut self) -> RigidBodyHandle {
                    self.drop_ball_at(0.25)
                }

                fn step(&mut self) -> usize {
                    self.dcr.step(&mut self.world).len()
                }

                /// Steps until an event reaches `body`; returns it (`None` after 40 steps).
                fn until_event(
                    &mut self,
                    body: RigidBodyHandle,
                ) -> Option<dcr_rapier::ImpulseEvent> {
                    for _ in 0..40 {
                        self.step();
                        if let Some(e) = self.dcr.events().iter().find(|e| e.body == body_id(body))
                        {
                            return Some(*e);
                        }
                    }
                    None
                }
            }

            /// The ball a response lifts off ends its first step off the plate with the event's
            /// Δv as normal velocity, gravity included (its support: m g h at its centre of mass),
            /// then flies freely (Δv − (k − 1) g h at the end of its k-th step), within 2 % of Δv
            /// in both modes, and both modes lift it by the same height (within 1 %), the
            /// solver's a step later. Without the support it would end each step g h slower.
            #[test]
            fn a_resting_ball_leaves_with_the_response_velocity() {
                let g = 9.81;
                let mut lift = [0.0; 2];
                for (m, apply) in [ApplyMode::AfterStep, ApplyMode::InSolver]
                    .into_iter()
                    .enumerate()
                {
                    let mut s = scene(apply);
                    let ball = s.resting_ball();
                    s.drop_ball();
                    let e = s.until_event(ball).expect("the impact reaches the ball");
                    let dv = e.delta_v;
                    assert!(dv > g * H, "{apply:?}: Δv {dv} m/s is not above g h");
                    let support: Vec<_> = s
                        .dcr
                        .events()
                        .iter()
                        .filter(|s| s.body == e.body && s.delta_v == 0.0)
                        .collect();
                    assert_eq!(support.len(), 1, "{apply:?}: one support event");
                    let want = 0.2 * g * H;
                    assert!(
                        (support[0].impulse[2] - want).abs() < 1e-6 * want,
                        "{apply:?}: support {:?} N·s vs m g h = {want}",
                        support[0].impulse
                    );
                    if apply == ApplyMode::InSolver {
                        // The replay: the ball is held through it and sent off at its end.
                        s.step();
                    }
                    let z0 = s.world.bodies[ball].translation().z as f64;
                    let steps = (dv / (g * H)).floor().max(1.0) as usize;
                    for k in 1..=steps {
                        s.step();
                        let vz = s.world.bodies[ball].linvel().z as f64;
                        let free = dv - (k - 1) as f64 * g * H;
                        assert!(
                            (vz - free).abs() < 0.02 * dv,
                            "{apply:?}: {vz} m/s at the end of step {k} off the plate, a free \
                             flight from Δv = {dv} m/s has {free} m/s"
                        );
                        lift[m] = lift[m].max(s.world.bodies[ball].translation().z as f64 - z0);
                    }
                }
                assert!(
                    (lift[0] - lift[1]).abs() < 0.01 * lift[0],
                    "lift after the step {} m vs in the solver {} m",
                    lift[0],
                    lift[1]
                );
            }

            /// A push below g h (the object's gain set to give Δv ≈ g h / 2) gets no support
            /// event and leaves the ball on its contact, in both modes: gravity takes it back
            /// within the step, so the ball ends the next steps at rest, below a quarter of the
            /// Δv h it would have risen off the plate. The
            /// threshold is what keeps µm/s responses (a hopping body's landings) from lifting
            /// bodies off and landing them as new impacts, step after step.
            #[test]
            fn a_push_below_g_h_leaves_the_ball_on_its_contact() {
                let g = 9.81;
                let mut full = scene(ApplyMode::AfterStep);
                let ball = full.resting_ball();
                full.drop_ball();
                let dv1 = full
                    .until_event(ball)
                    .expect("the impact reaches the ball")
                    .delta_v;
                let gain = 0.5 * g * H / dv1;
                for apply in [ApplyMode::AfterStep, ApplyMode::InSolver] {
                    let mut s = scene(apply);
                    s.dcr.set_object_gain(s.handle, gain).unwrap();
                    let ball = s.resting_ball();
                    s.drop_ball();
                    let e = s.until_event(ball).expect("the impact reaches the ball");
                    assert!(
                        e.delta_v > 0.4 * g * H && e.delta_v < 0.6 * g * H,
                        "{apply:?}: Δv {} m/s, g h {} m/s",
                        e.delta_v,
                        g * H
                    );
                    let support = s
                        .dcr
                        .events()
                        .iter()
                        .filter(|s| s.body == e.body && s.delta_v == 0.0)
                        .count();
                    assert_eq!(support, 0, "{apply:?}: no support below g h");
                    if apply == ApplyMode::InSolver {
                        // The replay, which ends with the ball sent off at Δv.
                        s.step();
                    }
                    let z0 = s.world.bodies[ball].translation().z as f64;
                    for k in 1..=5 {
                        s.step();
                        let b = &s.world.bodies[ball];
                        let (vz, dz) = (b.linvel().z as f64, b.translation().z as f64 - z0);
                        // Off the plate at Δv it would be Δv h higher after step 1; rapier's
                        // substeps let it rise a little before gravity has taken Δv back.
                        assert!(
                            vz.abs() < 0.05 * g * H && dz.abs() < 0.25 * e.delta_v * H,
                            "{apply:?}: {vz} m/s, {dz} m above its start at the end of step {k}"
                        );
                    }
                }
            }

            /// Remove → stale handle for every call, slot reused with a new generation;
            /// disable → no events; enable → events.
            #[test]
            fn remove_disable_enable_through_the_adapter() {
                let mut s = scene(ApplyMode::AfterStep);
                let h = s.handle;
                s.dcr.set_object_enabled(h, false).unwrap();
                let ball = s.resting_ball();
                s.drop_ball();
                assert!(s.until_event(ball).is_none(), "disabled: no events");
                s.dcr.set_object_enabled(h, true).unwrap();
                s.drop_ball_at(0.5);
                assert!(s.until_event(ball).is_some(), "enabled again: events");
                s.dcr.set_object_gain(h, 0.5).unwrap();
                s.dcr.set_object_threshold(h, 0.2).unwrap();
                assert!(s.dcr.set_object_gain(h, -1.0).is_err());
                s.dcr.remove_object(h).unwrap();
                assert!(s.dcr.remove_object(h).is_err());
                assert!(s.dcr.set_object_enabled(h, true).is_err());
                assert!(s.dcr.set_object_gain(h, 1.0).is_err());
                assert!(s.dcr.set_object_threshold(h, 1.0).is_err());
                assert_eq!(s.dcr.object_of_body(s.plate), None);
                // No object: stepping reads nothing and issues nothing.
                s.drop_ball_at(0.1);
                assert!(s.until_event(ball).is_none());
                let h2 = s
                    .dcr
                    .add_object(
                        &s.world.bodies,
                        &mut s.world.colliders,
                        s.plate,
                        ElasticObjectDesc::new(model(), 0),
                    )
                    .unwrap();
                assert_eq!(
                    (h2.index(), h2.generation()),
                    (h.index(), h.generation() + 1)
                );
                assert!(
                    s.dcr.set_object_gain(h, 1.0).is_err(),
                    "the old handle stays stale"
                );
                for _ in 0..30 {
                    s.step();
                }
                s.drop_ball_at(0.65);
                let e = s.until_event(ball).expect("the new object answers");
                assert_eq!(e.object, h2);
            }

            /// rapier's dt ≠ h: the responses are re-derived for dt.
            #[test]
            fn a_step_other_than_h_rederives_the_responses() {
                let mut s = scene_with(ApplyMode::AfterStep, 1.0 / 60.0, |_| {});
                s.step();
                let dt = f64::from(H as Real);
                assert_eq!(s.dcr.world().params().h, dt);
                assert_eq!(s.dcr.world().response(s.handle).params().h, dt);
                assert!(!s.dcr.step_info().h_mismatch);
                assert_eq!(s.dcr.h_mismatch_steps(), 0);
            }

            /// A table baked for h = 1/60 s under `Refuse`: rapier's 0.01 s is refused, the
            /// world keeps 1/60 and every step counts the mismatch.
            #[test]
            fn a_refused_table_keeps_h_and_counts_every_step() {
                let mut base = plate_base();
                let vertices: Vec<u32> = (0..base.surface_vertices.len() as u32).collect();
                let np = vertices.len();
                base.transfer = Some(TransferTable {
                    h: 1.0 / 60.0,
                    rayleigh: base.rayleigh,
                    modes: 40,
                    samples: 100,
                    vertices,
                    order: 1,
                    edges: Vec::new(),
                    faces: Vec::new(),
                    peaks: vec![1e-5; TransferTable::packed_len(np)],
                });
                let model = Arc::new(ModalModel::from_base(base).unwrap());
                let mut s = scene_with(ApplyMode::AfterStep, 1.0 / 60.0, |d| {
                    d.model = model.clone();
                    d.response = ResponseParams {
                        method: Method::Transfer,
                        table_policy: TablePolicy::Refuse,
                        ..ResponseParams::default()
                    };
                });
                for k in 1..=5 {
                    s.step();
                    assert!(s.dcr.step_info().h_mismatch);
                    assert_eq!(s.dcr.h_mismatch_steps(), k);
                }
                assert_eq!(s.dcr.world().params().h, 1.0 / 60.0);
                assert!(s.dcr.world().response(s.handle).transfer_active());
                // Set up for rapier's step, the table is refused at once.
                assert!(s.dcr.set_timestep(f64::from(H as Real)).is_err());
            }

            /// Removing the receiving ball right after the step that gave it an event (in-solver
            /// replays pending, contacts in the narrow phase), and then the elastic body itself,
            /// is safe.
            #[test]
            fn removing_bodies_with_pending_events_is_safe() {
                for apply in [ApplyMode::AfterStep, ApplyMode::InSolver] {
                    let mut s = scene(apply);
                    let ball = s.resting_ball();
                    let other = s.add(
                        Vector::new(0.7, 0.5, 0.03),
                        ColliderBuilder::ball(0.03).mass(0.2),
                    );
                    for _ in 0..10 {
                        s.step();
                    }
                    s.drop_ball();
                    s.until_event(ball).expect("event");
                    // Pending: in-solver seeds and marks for the ball, its contacts.
                    s.world.remove_body(ball);
                    for _ in 0..5 {
                        s.step();
                    }
                    // Removed between rapier's step and the adapter's read.
                    s.world.step();
                    s.world.remove_body(other);
                    s.dcr.after_step(
                        &mut s.world.bodies,
                        &s.world.colliders,
                        &s.world.narrow_phase,
                    );
                    // The elastic body itself.
                    s.world.remove_body(s.plate);
                    s.drop_ball();
                    for _ in 0..10 {
                        assert_eq!(s.step(), 0, "{apply:?}: no elastic body, no events");
                    }
                    s.dcr.remove_object(s.handle).unwrap();
                }
            }
        }
    };
}

#[cfg(feature = "f32")]
backend_tests!(f32);
#[cfg(feature = "f64")]
backend_tests!(f64);
