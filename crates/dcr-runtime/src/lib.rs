//! `dcr-runtime`: distant collision response for rigid-body engines (paper §4.2–4.5).
//!
//! An impact on an elastic object (a table, a floor, a scaffold) makes the bodies resting
//! elsewhere on it jump: the runtime turns a rigid-body engine's contacts into the impulses
//! that do it. Load a baked `.modes` base once ([`ModalModel`], shared by `Arc`), describe the
//! elastic objects of the world ([`ElasticObjectDesc`] → [`DcrWorld::add_object`]), and after
//! every rigid-body step pass the step's contact reports and body states in the world frame to
//! [`DcrWorld::step`], which returns the impulses to apply ([`ImpulseEvent`]). The world
//! classifies impacts and resting contacts, converts frames, turns velocity changes into
//! impulses with one Gauss–Seidel pass per body (Eq. 17–18), chains responses through dynamic
//! elastic objects and bounds the injected energy; a step does not allocate after warm-up.
//! [`DistantResponse`] is the per-object response underneath (object frame, one call per step),
//! for callers that do this work themselves.
//!
//! ```
//! use std::sync::Arc;
//! use dcr_runtime::{testing, BodyState, ContactReport, DcrWorld, ElasticObjectDesc, ModalModel,
//!     Pose, WorldParams};
//!
//! // A base (real ones come from `ModalModel::load("table.modes")`): a 1 m × 0.6 m plate in its
//! // object frame's z = 0 plane, outward normal +z.
//! let model = Arc::new(ModalModel::from_base(testing::plate_base())?);
//! // The engine's step (s) and gravity (m/s², world frame; z up here), which the world must be
//! // told: a body a response lifts off gets back the g·h gravity takes in the step it leaves.
//! let mut world = DcrWorld::new(WorldParams { h: 0.01, gravity: [0.0, 0.0, -9.81],
//!     ..Default::default() })?;
//!
//! // The plate is a static elastic object on engine body 1, tilted 30° about the world x axis
//! // and lifted 0.8 m: object → world is x_w = R x_o + t.
//! let pose = Pose::from_axis_angle([1.0, 0.0, 0.0], 30f64.to_radians(), [0.0, 0.0, 0.8]);
//! let mut desc = ElasticObjectDesc::new(model, 1);
//! desc.pose = pose;
//! let plate = world.add_object(desc)?;
//!
//! // Its outward normal in the world, and world points on its surface.
//! let r = pose.rotation_matrix();
//! let n = [r[0][2], r[1][2], r[2][2]];
//! let at = |x: f64, y: f64| pose.transform_point([x, y, 0.0]);
//!
//! // A 2 kg cup (engine body 7) rests near a corner; give the world its state every step.
//! let mut cup = BodyState::fixed(7);
//! cup.inv_mass = 0.5; // 1/kg
//! cup.inv_inertia = [[400.0, 0.0, 0.0], [0.0, 400.0, 0.0], [0.0, 0.0, 400.0]]; // 1/(kg·m²)
//! cup.center_of_mass = [at(0.9, 0.5)[0], at(0.9, 0.5)[1] + 0.02, at(0.9, 0.5)[2] + 0.04];
//! // Contact reports: body1 = the plate, normal from body1 toward body2, impulse in N·s.
//! let resting = ContactReport { id: 17, body1: 1, body2: 7, point1: at(0.9, 0.5),
//!     point2: at(0.9, 0.5), normal: n, impulse: 0.02, is_new: false };
//! for _ in 0..4 {
//!     // The settle window: the cup's contact is part of the initial resting set.
//!     assert!(world.step(&[resting], &[cup]).is_empty());
//! }
//!
//! // A 3 kg pot (body 9) hits the middle with 5 N·s and leaves at 0.3 m/s: the impact
//! // dissipated ½·λ²/m − λ·u⁺ = 2.7 J, the budget of the energy bound (η = 1 by default).
//! let mut pot = BodyState::fixed(9);
//! pot.inv_mass = 1.0 / 3.0;
//! pot.center_of_mass = at(0.5, 0.3);
//! pot.linvel = n.map(|x| 0.3 * x);
//! let hit = ContactReport { id: 90, body1: 1, body2: 9, point1: at(0.5, 0.3),
//!     point2: at(0.5, 0.3), normal: n, impulse: 5.0, is_new: true };
//! let events = world.step(&[resting, hit], &[cup, pot]);
//! // One impulse, on the cup, at its contact point, pushing it off the plate (world frame).
//! assert_eq!(events.len(), 1);
//! let e = events[0];
//! assert_eq!((e.body, e.contact, e.object), (7, 17, plate));
//! let along_n: f64 = (0..3).map(|k| e.impulse[k] * n[k]).sum();
//! assert!(along_n > 0.0);
//! // Apply with the engine: rapier's `apply_impulse_at_point(e.impulse, e.point, true)`.
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Pipeline, one module per stage:
//! [`model`] (validated base, vertex normals, surface BVH) → `mapping` (impacts and resting
//! contacts onto the surface, per-contact cache) → [`filter`] (exact modal IIR filters, Eq. 10)
//! or [`attenuation`] (spatial attenuation over heat-method geodesics, Eq. 14–16) →
//! [`response`] (peak displacement, Δv, Eq. 11–13, one type per method) → [`world`] (the
//! engine contract: classification, frames, impulses Eq. 17–18, chains, energy bound).
//!
//! Frames and units: SI units (m, s, kg, N·s) everywhere. The world API takes and returns the
//! world frame; [`DistantResponse`] and the types under it work in the base's object frame.
//! Engine-boundary types are plain data (`[f64; 3]`, `u64` ids, slices).
//!
//! Features (none by default): `write` (`format::ModesFile::write_atomic`, the `.modes` encoder,
//! through the tools' writer crate `dcr-files`; engines that only read bases leave it off),
//! `testing` (synthetic bases such as `testing::plate_base`, for tests and doctests, also of
//! other crates), `bench-internals` (the peak kernels, for benchmarks). [`math`] is the
//! workspace's small `[f64; 3]` kit. The crate is pure Rust: fill-reducing orderings that need
//! METIS are planned by the baker and stored in the base (`surface_order`).

pub mod attenuation;
pub mod filter;
pub mod format;
pub(crate) mod mapping;
pub mod math;
pub mod model;
pub mod response;
pub mod rng;
mod surface_point;
#[cfg(any(test, feature = "testing"))]
pub mod testing;
pub mod world;

// The integrator's surface: a base, the world and its per-step data, and the per-object
// response underneath. The response layer's knobs (methods, variants, table policy, attenuation
// and sampling settings, per-step diagnostics) live under `response`, the world's other types
// (classification settings, energy reports, totals) under `world`.
pub use model::{LoadError, ModalModel};
pub use response::{DistantResponse, Launch, Method, ResponseParams};
pub use world::{
    BodyState, ContactReport, DcrWorld, ElasticHandle, ElasticObjectDesc, ImpulseEvent,
    ObjectStepInfo, Pose, WorldError, WorldParams, WorldStepInfo,
};
