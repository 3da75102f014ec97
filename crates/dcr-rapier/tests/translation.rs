//! The rapier translation, for both backends (`f32` and `f64`), on small real rapier worlds.
//!
//! Expectations:
//! - contact reports are in the world frame with rapier's conventions, also on a rotated and
//!   translated elastic body: `point1` lies on body 1's collider surface, `point2` on body 2's,
//!   `normal` points from body 1 to body 2, and the reported impulses of a body resting on the
//!   object sum to its weight × h;
//! - contact ids are distinct and stay the same from step to step while a body rests;
//! - after the step, each event's impulse changes the receiving body's velocity at the contact
//!   along the object's outward normal by the event's Δv (Eq. 17–18, pushed away from the
//!   surface) plus the support g·h along it that the contact no longer gives;
//! - in the solver, the replay gives a single contact the requested separation velocity plus
//!   its support by the end of the next step, to the solver's tolerance;
//! - the f32 and f64 backends give the same outcome on the same small scene (largest lift of
//!   the resting boxes within 1 %, the same number of response events to the impact);
//! - the impact-step gate reads only the steps around impacts and issues the same events as
//!   reading every step.

use std::sync::Arc;

use dcr_rapier::dcr_runtime::testing::plate_base;
use dcr_rapier::{ElasticObjectDesc, ModalModel, WorldParams};

fn model() -> Arc<ModalModel> {
    Arc::new(ModalModel::from_base(plate_base()).expect("plate base loads"))
}

/// The same tests for one backend module (`f32` or `f64`).
macro_rules! backend_tests {
    ($m:ident) => {
        mod $m {
            use super::*;
            use dcr_rapier::$m::rapier::math::{Pose, Rotation, Vector};
            use dcr_rapier::$m::rapier::prelude::*;
            use dcr_rapier::$m::{body_id, AdapterParams, ApplyMode, DcrRapier, Real, StepGate};

            const H: f64 = 0.01;

            /// The plate base on a fixed body posed `pose` (object frame = body frame; the
            /// base's 1 × 0.6 m face is the z = 0 plane of that frame, outward +z), gravity
            /// along −(pose's z), a slab collider under the face.
            struct Scene {
                world: PhysicsWorld,
                dcr: DcrRapier,
                plate: RigidBodyHandle,
                pose: Pose,
            }

            fn up(pose: &Pose) -> Vector {
                pose.rotation * Vector::Z
            }

            fn scene(pose: Pose, apply: ApplyMode, eta: Option<f64>) -> Scene {
                scene_gated(pose, apply, eta, StepGate::EveryStep)
            }

            fn scene_gated(
                pose: Pose,
                apply: ApplyMode,
                eta: Option<f64>,
                gate: StepGate,
            ) -> Scene {
                let mut world = PhysicsWorld::default();
                world.integration_parameters.dt = H as Real;
                world.gravity = up(&pose) * -9.81;
                let plate = world.insert_body(RigidBodyBuilder::fixed().pose(pose));
                let slab = ColliderBuilder::cuboid(0.5, 0.3, 0.05)
                    .translation(Vector::new(0.5, 0.3, -0.05))
                    .friction(0.6);
                world.insert_collider(slab, Some(plate));
                let params = WorldParams {
                    h: H,
                    energy_eta: eta,
                    ..WorldParams::default()
                };
                let mut dcr = DcrRapier::new(
                    params,
                    AdapterParams {
                        apply,
                        gate,
                        ..AdapterParams::default()
                    },
                )
                .expect("adapter");
                dcr.add_object(
                    &world.bodies,
                    &mut world.colliders,
                    plate,
                    ElasticObjectDesc::new(model(), 0),
                )
                .expect("object added");
                Scene {
                    world,
                    dcr,
                    plate,
                    pose,
                }
            }

            impl Scene {
                /// A dynamic body with `collider` at object-frame point `p` (m).
                fn add(&mut self, p: Vector, collider: ColliderBuilder) -> RigidBodyHandle {
                    let pose = self.pose * Pose::from_translation(p);
                    let b = self
                        .world
                        .insert_body(RigidBodyBuilder::dynamic().pose(pose));
                    self.world.insert_collider(collider, Some(b));
                    b
                }

                /// A heavy ball falling onto the plate at object point (x, y) from 0.3 m above
                /// at 3 m/s.
                fn drop_ball(&mut self, x: Real, y: Real) -> RigidBodyHandle {
                    let b = self.add(
                        Vector::new(x, y, 0.3),
                        ColliderBuilder::ball(0.1).density(5000.0),
                    );
                    let v = up(&self.pose) * -3.0;
                    self.world.bodies[b].set_linvel(v, true);
                    b
                }

                /// A 0.2 kg ball (one contact) resting near the plate's edge for 30 steps, then
                /// a heavy ball falling on the plate; returns the resting ball.
                fn resting_ball_then_impact(&mut self) -> RigidBodyHandle {
                    let ball = self.add(
                        Vector::new(0.85, 0.3, 0.03),
                        ColliderBuilder::ball(0.03).mass(0.2),
                    );
                    for _ in 0..30 {
                        self.step();
                    }
                    self.drop_ball(0.25, 0.3);
                    ball
                }

                fn step(&mut self) -> usize {
                    self.dcr.step(&mut self.world).len()
                }
            }

            fn rot(axis: Vector, deg: Real) -> Rotation {
                Rotation::from_axis_angle(axis.normalize(), deg.to_radians())
            }

            /// A posed plate: 30° about (1, 2, 0.5), moved by (2, 1, -0.5).
            fn posed() -> Pose {
                Pose::from_parts(
                    Vector::new(2.0, 1.0, -0.5),
                    rot(Vector::new(1.0, 2.0, 0.5), 30.0),
                )
            }

            /// Reports are world-frame with rapier's conventions on a posed object; their
            /// impulses carry the resting body's weight; ids are stable and distinct.
            #[test]
            fn reports_are_world_frame_and_ids_stable() {
                for pose in [Pose::IDENTITY, posed()] {
                    let mut s = scene(pose, ApplyMode::AfterStep, None);
                    let mass: Real = 2.0;
                    let cube = s.add(
                        Vector::new(0.6, 0.3, 0.05),
                        ColliderBuilder::cuboid(0.05, 0.05, 0.05).mass(mass),
                    );
                    for _ in 0..30 {
                        s.step();
                    }
                    let (pid, cid) = (body_id(s.plate), body_id(cube));
                    let mut ids: Vec<u64> = Vec::new();
                    for k in 0..10 {
                        s.step();
                        let reports = s.dcr.reports();
                        assert!(!reports.is_empty(), "the resting cube is reported");
                        let mut now: Vec<u64> = reports.iter().map(|r| r.id).collect();
                        now.sort_unstable();
                        let n = now.len();
                        now.dedup();
                        assert_eq!(now.len(), n, "contact ids are distinct");
                        if k > 0 {
                            assert_eq!(now, ids, "ids stay the same while the cube rests");
                        }
                        ids = now;
                        let mut total = 0.0;
                        let n_up = up(&s.pose);
                        for r in reports {
                            let (plate_side, cube_side, sign) = if r.body1 == pid {
                                (r.point1, r.point2, 1.0)
                            } else {
                                (r.point2, r.point1, -1.0)
                            };
                            assert_eq!([r.body1, r.body2].contains(&cid), true);
                            // Object-frame z of each point: the plate face at 0, the cube's
                            // bottom face at 0 too (resting, within rapier's slop).
                            let to_obj = |p: [f64; 3]| {
                                s.pose.inverse_transform_point(Vector::new(
                                    p[0] as Real,
                                    p[1] as Real,
                                    p[2] as Real,
                                ))
                            };
                            assert!(
                                to_obj(plate_side).z.abs() < 2e-3,
                                "{:?}",
                                to_obj(plate_side)
                            );
                            assert!(to_obj(cube_side).z.abs() < 2e-3, "{:?}", to_obj(cube_side));
                            let n = Vector::new(
                                r.normal[0] as Real,
                                r.normal[1] as Real,
                                r.normal[2] as Real,
                            );
                            assert!(
                                (n.dot(n_up) as f64 - sign).abs() < 1e-4,
                                "normal from body 1 to body 2: {n:?} vs up {n_up:?}, sign {sign}"
                            );
                            total += r.impulse;
                        }
                        let weight = f64::from(mass) * 9.81 * H;
                        assert!(
                            (total - weight).abs() < 0.03 * weight,
                            "impulses {total} N·s carry the weight × h = {weight} N·s"
                        );
                    }
                }
            }

            /// After the step: the event's impulse gives the receiving body exactly Δv along
            /// the outward normal at the contact.
            #[test]
            fn after_step_events_give_their_delta_v() {
                for pose in [Pose::IDENTITY, posed()] {
                    let mut s = scene(pose, ApplyMode::AfterStep, None);
                    let ball = s.resting_ball_then_impact();
                    let bid = body_id(ball);
                    let mut checked = 0;
                    for _ in 0..20 {
                        s.world.step();
                        let p_before = *s.world.bodies[ball].position();
                        let v_before = s.world.bodies[ball].linvel();
                        let w_before = s.world.bodies[ball].angvel();
                        let events: Vec<_> = s
                            .dcr
                            .after_step(
                                &mut s.world.bodies,
                                &s.world.colliders,
                                &s.world.narrow_phase,
                            )
                            .iter()
                            .filter(|e| e.body == bid)
                            .copied()
                            .collect();
                        if events.is_empty() {
                            continue;
                        }
                        // The response's event, then its support at the centre of mass
                        // (Δv ≥ g·h) when the push lifts the ball off.
                        let e = events[0];
                        let support_given = events.len() == 2;
                        assert!(events.len() == 1 || (support_given && events[1].delta_v == 0.0));
                        let rb = &s.world.bodies[ball];
                        assert_eq!(*rb.position(), p_before);
                        let p =
                            Vector::new(e.point[0] as Real, e.point[1] as Real, e.point[2] as Real);
                        let n = Vector::new(
                            e.normal[0] as Real,
                            e.normal[1] as Real,
                            e.normal[2] as Real,
                        );
                        assert!(n.dot(up(&s.pose)) > 0.999, "pushed away from the surface");
                        let com = rb.center_of_mass();
                        let dv = (rb.linvel() - v_before) + (rb.angvel() - w_before).cross(p - com);
                        let got = dv.dot(n) as f64;
                        // The support compensation: gravity's share along n over one step.
                        let gh = 9.81 * H * (n.dot(up(&s.pose)) as f64).max(0.0);
                        assert_eq!(support_given, e.delta_v >= gh, "support iff Δv ≥ g·h");
                        let support = if support_given { gh } else { 0.0 };
                        assert!(e.delta_v > 0.0);
                        assert!(
                            (got - support - e.delta_v).abs() < 1e-4 * (e.delta_v + support),
                            "Δv along n {got} vs event {} + support {support}",
                            e.delta_v
                        );
                        checked += 1;
                    }
                    assert!(checked > 0, "the impact reached the resting ball");
                }
            }

            /// In the solver: the step after the impact, the replay leaves the single-contact
            /// ball with the event's Δv plus its support (g·h along n, replayed with it) as
            /// separation velocity.
            #[test]
            fn in_solver_replay_gives_the_requested_separation_velocity() {
                let mut s = scene(Pose::IDENTITY, ApplyMode::InSolver, None);
                let ball = s.resting_ball_then_impact();
                let bid = body_id(ball);
                let mut checked = 0;
                for _ in 0..20 {
                    s.step();
                    let Some(e) = s.dcr.events().iter().find(|e| e.body == bid).copied() else {
                        continue;
                    };
                    let gh = 9.81 * H;
                    let support = s
                        .dcr
                        .events()
                        .iter()
                        .filter(|s| s.body == bid && s.delta_v == 0.0)
                        .count();
                    assert_eq!(
                        support,
                        usize::from(e.delta_v >= gh),
                        "support iff Δv ≥ g·h"
                    );
                    let want = e.delta_v + support as f64 * gh;
                    // The next step replays it: the ball's normal velocity at its end.
                    s.step();
                    assert_eq!(s.dcr.step_info().replay_missed, 0);
                    let n = Vector::new(
                        e.normal[0] as Real,
                        e.normal[1] as Real,
                        e.normal[2] as Real,
                    );
                    let got = s.world.bodies[ball].linvel().dot(n) as f64;
                    let tol = if std::mem::size_of::<Real>() == 4 {
                        1e-3
                    } else {
                        1e-6
                    };
                    assert!(
                        (got - want).abs() < tol * want.max(1e-3) + 1e-6,
                        "separation velocity {got} m/s vs requested {} m/s + support",
                        e.delta_v
                    );
                    checked += 1;
                    break;
                }
                assert_eq!(checked, 1, "the impact reached the resting ball");
            }

            /// The impact-step gate reads only the steps around impacts and issues the same
            /// responses as reading every step: a ball dropped twice on the plate with three
            /// boxes resting on it.
            #[test]
            fn impact_step_gate_reads_only_impact_steps() {
                let run = |gate: StepGate| {
                    let mut s = scene_gated(Pose::IDENTITY, ApplyMode::AfterStep, None, gate);
                    for &(x, y) in &[(0.7, 0.15), (0.8, 0.45), (0.15, 0.45)] {
                        s.add(
                            Vector::new(x, y, 0.04),
                            ColliderBuilder::cuboid(0.04, 0.04, 0.04).mass(0.3),
                        );
                    }
                    let mut events: Vec<(usize, u64, f64)> = Vec::new();
                    let mut stepped = 0;
                    for k in 0..200 {
                        if k == 30 || k == 120 {
                            s.drop_ball(0.35, 0.3);
                        }
                        // The responses that move a box visibly (≥ 1 mm/s): the hopping boxes'
                        // landings may add µm/s responses on which the two classifications can
                        // differ (ages vs engine newness, see StepGate::ImpactSteps).
                        for e in s
                            .dcr
                            .step(&mut s.world)
                            .iter()
                            .filter(|e| e.delta_v >= 1e-3)
                        {
                            events.push((k, e.body, e.delta_v));
                        }
                        stepped += usize::from(s.dcr.step_info().world_stepped);
                    }
                    (events, stepped)
                };
                let (every, n_every) = run(StepGate::EveryStep);
                let (gated, n_gated) = run(StepGate::ImpactSteps);
                assert_eq!(n_every, 200);
                assert!(n_gated < 30, "the gate read {n_gated} of 200 steps");
                assert!(every.len() >= 6, "both drops reach the boxes: {every:?}");
                assert_eq!(every.len(), gated.len(), "{every:?}\n{gated:?}");
                for (a, b) in every.iter().zip(&gated) {
                    assert_eq!((a.0, a.1), (b.0, b.1));
                    assert!(
                        (a.2 - b.2).abs() <= 1e-9 * a.2.abs().max(1.0),
                        "{a:?} vs {b:?}"
                    );
                }
            }

            /// Largest rise (m, along the plate's normal) of three resting boxes of the small
            /// scene after a ball hits the plate, with the response on.
            pub fn small_scene_lift(apply: ApplyMode) -> (f64, usize) {
                let mut s = scene(Pose::IDENTITY, apply, Some(1.0));
                let boxes: Vec<_> = [(0.7, 0.15), (0.8, 0.45), (0.15, 0.45)]
                    .iter()
                    .map(|&(x, y)| {
                        s.add(
                            Vector::new(x, y, 0.04),
                            ColliderBuilder::cuboid(0.04, 0.04, 0.04).mass(0.3),
                        )
                    })
                    .collect();
                for _ in 0..30 {
                    s.step();
                }
                let z0: Vec<f64> = boxes
                    .iter()
                    .map(|&b| s.world.bodies[b].translation().z as f64)
                    .collect();
                s.drop_ball(0.35, 0.3);
                let mut lift: f64 = 0.0;
                let mut events = 0;
                let mut first = None;
                for k in 0..60 {
                    let n = s.step();
                    // The responses to the ball's impact: the first three steps with events.
                    if n > 0 && first.is_none() {
                        first = Some(k);
                    }
                    if first.is_some_and(|f| k < f + 3) {
                        events += n;
                    }
                    for (i, &b) in boxes.iter().enumerate() {
                        lift = lift.max(s.world.bodies[b].translation().z as f64 - z0[i]);
                    }
                }
                (lift, events)
            }
        }
    };
}

backend_tests!(f32);
backend_tests!(f64);

/// The f32 and f64 backends agree on the small scene's outcome: the boxes' largest lift within
/// 1 % (f32 rounding in rapier's solver and contact geometry, amplified by the boxes'
/// free flight) and the same response events to the ball's impact (the boxes' later landings
/// are re-impacts whose count f32 rounding may change).
#[test]
fn f32_and_f64_give_the_same_outcome() {
    use dcr_rapier::f64::ApplyMode;
    for apply in [ApplyMode::AfterStep, ApplyMode::InSolver] {
        let (lift64, ev64) = f64::small_scene_lift(apply);
        let apply32 = match apply {
            ApplyMode::AfterStep => dcr_rapier::f32::ApplyMode::AfterStep,
            _ => dcr_rapier::f32::ApplyMode::InSolver,
        };
        let (lift32, ev32) = f32::small_scene_lift(apply32);
        assert!(lift64 > 1e-4, "{apply:?}: the boxes jump ({lift64} m)");
        assert!(
            (lift32 - lift64).abs() <= 0.01 * lift64,
            "{apply:?}: lift f32 {lift32} m vs f64 {lift64} m"
        );
        assert_eq!(ev32, ev64, "{apply:?}: response events");
    }
}
