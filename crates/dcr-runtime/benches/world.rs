//! Per-step cost of `DcrWorld::step` against the number of resting contacts.
//!
//! A static floor (a synthetic closed box surface with the dinner table's ~1000 surface
//! vertices, 20 modes, 11 samples per step) carrying N dynamic bodies, one resting contact
//! each, reported every step:
//! - `world/quiet/N`: no impact — the cost every step pays (classification, body index);
//! - `world/impact/N`: one new impact every step on top — classification, the response query
//!   (contacts cached), one Gauss–Seidel pass, the energy bound;
//! - `world/advance`: a quiet step passed with `DcrWorld::advance` instead (engine newness).
//!
//! Expected: linear in N.

use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use dcr_runtime::filter::Sampling;
use dcr_runtime::testing::{box_surface, geometric_omegas, synthetic_base, SplitMix64};
use dcr_runtime::{BodyState, ContactReport, DcrWorld, ElasticObjectDesc, ModalModel, WorldParams};

const FLOOR: u64 = 1;

struct Scene {
    world: DcrWorld,
    contacts: Vec<ContactReport>,
    bodies: Vec<BodyState>,
}

/// N bodies resting on the floor's top face (z = 0.6 m), after the settle window.
fn scene(n: usize) -> Scene {
    let base = synthetic_base(
        box_surface(13, [1.2, 0.8, 0.6]),
        &geometric_omegas(20, 60.0, 3000.0),
        [1.0, 1e-6],
        17,
    );
    let model = Arc::new(ModalModel::from_base(base).unwrap());
    let mut world = DcrWorld::new(WorldParams::with_gravity([0.0; 3])).unwrap();
    let mut desc = ElasticObjectDesc::new(model, FLOOR);
    desc.response.sampling = Sampling::Substep(0.01 / 11.0);
    world.add_object(desc).unwrap();
    let mut rng = SplitMix64(3);
    let mut contacts = Vec::with_capacity(n + 1);
    let mut bodies = Vec::with_capacity(n + 1);
    for i in 0..n {
        let p = [rng.range(0.05, 1.15), rng.range(0.05, 0.75), 0.6];
        let id = 100 + i as u64;
        bodies.push(BodyState {
            id,
            inv_mass: 2.0,
            inv_inertia: [[50.0, 0.0, 0.0], [0.0, 50.0, 0.0], [0.0, 0.0, 50.0]],
            center_of_mass: [p[0], p[1], 0.65],
            linvel: [0.0; 3],
            angvel: [0.0; 3],
        });
        contacts.push(ContactReport {
            id: 10_000 + i as u64,
            body1: FLOOR,
            body2: id,
            point1: p,
            point2: p,
            normal: [0.0, 0.0, 1.0],
            impulse: 0.02,
            is_new: false,
        });
    }
    // The impactor: a 1 kg ball bouncing off the middle.
    bodies.push(BodyState {
        id: 9,
        inv_mass: 1.0,
        inv_inertia: [[400.0, 0.0, 0.0], [0.0, 400.0, 0.0], [0.0, 0.0, 400.0]],
        center_of_mass: [0.6, 0.4, 0.65],
        linvel: [0.0, 0.0, 0.5],
        angvel: [0.0; 3],
    });
    for _ in 0..5 {
        world.step(&contacts, &bodies);
    }
    Scene {
        world,
        contacts,
        bodies,
    }
}

fn quiet_and_impact(c: &mut Criterion) {
    for n in [100usize, 300, 1000] {
        let mut s = scene(n);
        c.bench_function(&format!("world/quiet/{n}"), |b| {
            b.iter(|| black_box(s.world.step(&s.contacts, &s.bodies).len()))
        });
        let mut s = scene(n);
        let mut id = 1u64 << 40;
        let mut all = s.contacts.clone();
        all.push(s.contacts[0]);
        c.bench_function(&format!("world/impact/{n}"), |b| {
            b.iter(|| {
                id += 1;
                let last = all.len() - 1;
                all[last] = ContactReport {
                    id,
                    body1: FLOOR,
                    body2: 9,
                    point1: [0.6, 0.4, 0.6],
                    point2: [0.6, 0.4, 0.6],
                    normal: [0.0, 0.0, 1.0],
                    impulse: 2.0,
                    is_new: true,
                };
                black_box(s.world.step(&all, &s.bodies).len())
            })
        });
    }
    let mut s = scene(100);
    c.bench_function("world/advance", |b| {
        b.iter(|| {
            s.world.advance(1);
            black_box(s.world.needs_step())
        })
    });
}

criterion_group!(benches, quiet_and_impact);
criterion_main!(benches);
