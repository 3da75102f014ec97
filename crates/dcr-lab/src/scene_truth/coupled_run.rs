//! One coupled elastic–rigid run of a scene at a fixed coupling step (see the module doc of
//! [`super`] for the coupling and why).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use dcr_scenes::runner::{measure_outcome, unit_of, Trajectory};
use dcr_scenes::scene::{build_world, BodyKind, BuiltWorld, SceneDesc};
use modal_bake::full_order::{FullOrderSystem, ModalAll};
use rapier3d_f64::math::Vector;
use rapier3d_f64::parry::query::{
    ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher, PersistentQueryDispatcher,
};
use rapier3d_f64::prelude::*;

use super::contact_solve::solve_penalty_block;
use super::elastic_body::ElasticBody;

/// How the contact forces of a coupling step are found (module doc of [`super`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CouplingScheme {
    /// Implicit in the forces: each prop's point forces are the clamped spring–dashpot of the
    /// *end-of-step* gaps, which are affine in the held forces through the elastic step
    /// compliance and the bodies' inverse effective masses; one small complementarity solve
    /// per prop and step. Stable for any stiffness and step.
    #[default]
    Implicit,
    /// The start-of-step gap and velocities set the forces (explicit exchange): stable only
    /// while k times the surface's step compliance is small. Kept to show the difference.
    Explicit,
}

/// Settings of one coupled run.
#[derive(Clone, Debug)]
pub struct CoupledParams {
    /// Coupling step (s): rapier's step and the sampling of the contact forces. Must divide the
    /// scene's h into a whole number of steps.
    pub dt: f64,
    /// Simulated time (s).
    pub seconds: f64,
    /// Elastic modes summed (`None`: every mode of the dense solve).
    pub modes: Option<usize>,
    /// Normal penalty stiffness per contact point (N/m).
    pub contact_stiffness: f64,
    /// Slip speed (m/s) below which Coulomb friction is regularised (viscous).
    pub friction_velocity: f64,
    /// Rayleigh damping [α0 (1/s), α1 (s)] of the elastic object.
    pub rayleigh: [f64; 2],
    /// Restitution the contact dashpot reproduces against a rigid surface (the scene's).
    pub restitution: f64,
    /// Progress lines on stderr.
    pub progress: bool,
    /// How the contact forces are found. Default [`CouplingScheme::Implicit`].
    pub scheme: CouplingScheme,
    /// Ensemble member and placement distance (m): the launched bodies start moved as
    /// [`dcr_scenes::scene::BuiltWorld::perturb_placement`] says (`(0, 0.0)`: as written).
    pub perturbation: (usize, f64),
    /// Whether the props load the elastic object. `true` (the reference): every contact's
    /// force acts on the object's modes. `false`: only the scene's sources do — the launched
    /// bodies (a non-zero initial velocity) and the driven ones — while every other prop's
    /// contacts see the surface move without pushing on it (its forces leave the modes out,
    /// and its points' compliance is the prop's alone): the distant response's assumption that
    /// resting bodies give the object no feedback, to measure what it costs. A dynamic object's
    /// rigid body still takes every contact's force, and the energy account then misses the
    /// work the props' forces would have done on the modes.
    pub prop_feedback: bool,
}

/// What a coupled run measured.
#[derive(Clone, Debug)]
pub struct CoupledRun {
    /// The trajectory at the scene's step h (rows t = k·h), dynamic bodies as `dcr-scenes run`.
    pub trajectory: Trajectory,
    /// Outcome figures: name → (value, unit).
    pub outcomes: BTreeMap<String, (f64, String)>,
    /// Work (J) the elastic surface's motion did on each prop, largest over time of the
    /// running sum, by body name.
    pub delivered: BTreeMap<String, f64>,
    /// Largest upward speed (m/s, along the contact normal) of the elastic surface under each
    /// prop's contacts while they touch, by body name: what the distant response's Δv (Eq. 12)
    /// stands for.
    pub surface_speed: BTreeMap<String, f64>,
    /// Largest penetration of a penalty contact (m).
    pub max_penetration: f64,
    /// Energy at each recorded row (J): rigid kinetic + gravity potential + elastic + penalty
    /// springs.
    pub energy: Vec<f64>,
    /// Linear momentum Σ m v of the dynamic bodies at the start and at the end (N·s, world).
    pub momentum: [[f64; 3]; 2],
    /// Coupling steps taken.
    pub steps: usize,
    /// Contact blocks whose active-set solve fell back to projected Gauss–Seidel.
    pub solver_fallbacks: usize,
    /// Wall time (s).
    pub wall_s: f64,
}

/// The prepared elastic object: the full-order system and every mode of it.
pub struct ElasticPrep {
    /// The full-order system (object frame = the mesh frame = the body frame).
    pub sys: FullOrderSystem,
    /// Every elastic mode (dense solve).
    pub all: ModalAll,
}

/// A prop's first contact points deeper than this (m) inside the surface are checked against
/// [`START_OVERLAP_RISE_M`]: below it, a start is on the surface (the repository's scenes start
/// their props about 1e-9 m deep, one substep of gravity).
pub const START_OVERLAP_FLOOR_M: f64 = 1e-8;

/// A prop whose first contact springs hold more than the energy that lifts it this far (m)
/// starts inside the surface and is refused: a 10 g pebble 76 µm deep under 1e9 N/m springs
/// holds enough to throw it 30 m.
pub const START_OVERLAP_RISE_M: f64 = 1e-4;

/// Surface points cached beyond this many are dropped (memory: 3 rows of the modes each).
const CACHE_MAX: usize = 4096;

fn arr(v: Vector) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// One penalty contact point between a prop and the elastic object in a coupling step.
struct ContactPoint {
    /// The prop.
    ob: RigidBodyHandle,
    /// Unit normal from the object towards the prop (world).
    n: Vector,
    /// The normal in the object frame.
    nl: [f64; 3],
    /// The contact point on the prop and on the object's rigid surface (world, m).
    x_o: Vector,
    x_e: Vector,
    /// Rigid gap along `n` (m, negative: overlap).
    dist: f64,
    /// Key of the surface point's cached modal rows.
    key: [i64; 3],
    /// Friction coefficient.
    mu: f64,
    /// Dashpot (N·s/m).
    damp: f64,
}

/// A rigid body's inverse mass (1/kg), world inverse inertia (1/(kg·m²)) and centre of mass.
struct BodyMass {
    inv_mass: f64,
    inv_inertia: [[f64; 3]; 3],
    com: Vector,
}

impl BodyMass {
    /// Velocity change along `na` at `xa` per unit impulse along `nb` at `xb` (1/kg):
    /// `na·nb/m + (ra × na)ᵀ I⁻¹ (rb × nb)` (Eq. 17 off the diagonal; symmetric).
    fn coupling(&self, xa: Vector, na: Vector, xb: Vector, nb: Vector) -> f64 {
        let ra = arr((xa - self.com).cross(na));
        let rb = arr((xb - self.com).cross(nb));
        let mut quad = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                quad += ra[i] * self.inv_inertia[i][j] * rb[j];
            }
        }
        self.inv_mass * na.dot(nb) + quad
    }
}

fn body_mass(rb: &RigidBody) -> BodyMass {
    if !rb.is_dynamic() {
        return BodyMass {
            inv_mass: 0.0,
            inv_inertia: [[0.0; 3]; 3],
            com: rb.center_of_mass(),
        };
    }
    let mp = rb.mass_properties();
    let ii = mp.effective_world_inv_inertia;
    BodyMass {
        inv_mass: mp.effective_inv_mass.x,
        inv_inertia: [
            [ii.m11, ii.m12, ii.m13],
            [ii.m12, ii.m22, ii.m23],
            [ii.m13, ii.m23, ii.m33],
        ],
        com: rb.center_of_mass(),
    }
}

/// Runs `desc` with its elastic object coupled to the rigid bodies through penalty contacts.
///
/// # Errors
/// The scene has not exactly one elastic object, `dt` does not divide h, the world cannot be
/// built, a prop starts inside the surface (its first contact points more than
/// [`START_OVERLAP_FLOOR_M`] deep, holding a spring energy that would lift it more than
/// [`START_OVERLAP_RISE_M`]), or the run blows up (non-finite state).
pub fn run_coupled(
    desc: &SceneDesc,
    root: &Path,
    prep: &ElasticPrep,
    p: &CoupledParams,
) -> Result<CoupledRun> {
    if desc.elastic.len() != 1 {
        bail!(
            "scene {}: the coupled reference takes exactly one elastic object, the scene has {}",
            desc.name,
            desc.elastic.len()
        );
    }
    let sub = (desc.h / p.dt).round() as usize;
    if sub == 0 || ((sub as f64) * p.dt - desc.h).abs() > 1e-9 * desc.h {
        bail!(
            "coupling step {} s must divide the scene's h = {} s into whole steps",
            p.dt,
            desc.h
        );
    }
    let steps_h = (p.seconds / desc.h).round() as usize;
    let mut built: BuiltWorld = build_world(desc, root)?;
    // The sources: launched bodies and driven ones (CoupledParams::prop_feedback).
    let mut sources: Vec<RigidBodyHandle> = built
        .bodies
        .iter()
        .filter(|b| b.dynamic && built.world.bodies[b.handle].linvel().length() > 0.0)
        .map(|b| b.handle)
        .collect();
    for d in &desc.drivers {
        if let Some(i) = built.body_index(&d.body) {
            sources.push(built.bodies[i].handle);
        }
    }
    built.perturb_placement(p.perturbation.0, p.perturbation.1);
    built.world.integration_parameters.dt = p.dt;
    let eb = built.elastic_body[0];
    let e_handle = built.bodies[eb].handle;
    let e_dynamic = matches!(desc.elastic[0].body, BodyKind::Dynamic { .. });
    // Rapier detects the elastic object's contacts but does not solve them: the penalty
    // coupling below does.
    let mut e_colliders = Vec::new();
    for (&ch, &b) in &built.collider_body {
        if b == eb {
            e_colliders.push(ch);
        }
    }
    e_colliders.sort_by_key(|c| c.into_raw_parts());
    for &ch in &e_colliders {
        built.world.colliders[ch].set_solver_groups(InteractionGroups::none());
    }
    // Small steps resolve every contact; continuous collision detection would act on the
    // unsolved pairs' geometry only.
    let handles: Vec<RigidBodyHandle> = built.bodies.iter().map(|b| b.handle).collect();
    for &h in &handles {
        built.world.bodies[h].enable_ccd(false);
    }

    let mut elastic = ElasticBody::new(&prep.sys, &prep.all, p.modes, p.rayleigh, p.dt);
    let surface = &prep.sys.surface;
    let mut cache: HashMap<[i64; 3], Vec<f64>> = HashMap::new();
    let zeta = dashpot_ratio(p.restitution);
    let rec: Vec<usize> = (0..built.bodies.len())
        .filter(|&i| built.bodies[i].dynamic)
        .collect();
    let mut traj = Trajectory {
        names: rec.iter().map(|&i| built.bodies[i].name.clone()).collect(),
        ..Default::default()
    };
    let record = |built: &BuiltWorld, traj: &mut Trajectory, t: f64| {
        traj.time.push(t);
        for &i in &rec {
            let pos = built.world.bodies[built.bodies[i].handle].position();
            traj.positions
                .extend([pos.translation.x, pos.translation.y, pos.translation.z]);
            traj.rotations.extend([
                pos.rotation.x,
                pos.rotation.y,
                pos.rotation.z,
                pos.rotation.w,
            ]);
        }
    };
    record(&built, &mut traj, 0.0);
    let body_of: HashMap<RigidBodyHandle, usize> =
        handles.iter().enumerate().map(|(i, &h)| (h, i)).collect();
    let mut work = vec![0.0f64; built.bodies.len()];
    let mut work_max = vec![0.0f64; built.bodies.len()];
    let mut max_pen = 0.0f64;
    let mut speed = vec![0.0f64; built.bodies.len()];
    let gravity = Vector::new(desc.gravity[0], desc.gravity[1], desc.gravity[2]);
    let mut energy = vec![0.0];
    let mut spring_energy = 0.0;

    let drivers: Vec<(RigidBodyHandle, dcr_scenes::scene::DriverDesc)> = desc
        .drivers
        .iter()
        .map(|d| {
            built
                .body_index(&d.body)
                .map(|i| (built.bodies[i].handle, d.clone()))
                .with_context(|| format!("driver: no body {}", d.body))
        })
        .collect::<Result<_>>()?;

    let momentum0 = momentum(&built);
    let wall = Instant::now();
    let mut last = Instant::now();
    let mut forces: Vec<(RigidBodyHandle, Vector, Vector, Vector, f64, f64)> = Vec::new();
    let mut pts: Vec<ContactPoint> = Vec::new();
    let mut blocks: Vec<(RigidBodyHandle, Vec<usize>)> = Vec::new();
    let mut nrows: Vec<f64> = Vec::new();
    let mut solver_fallbacks = 0usize;
    let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
    // Props whose first contact points were checked for a start inside the surface.
    let mut first_seen: Vec<RigidBodyHandle> = Vec::new();
    let energy0 = total_energy(&built, gravity, &elastic, 0.0);
    energy[0] = energy0;
    for kh in 0..steps_h {
        let t_h = kh as f64 * desc.h;
        apply_drivers(&drivers, &mut built, t_h);
        for ks in 0..sub {
            forces.clear();
            pts.clear();
            spring_energy = 0.0;
            let e_pose = *built.world.bodies[e_handle].position();
            let prediction = built.world.integration_parameters.prediction_distance();
            // Bounded memory: the cache is emptied between steps, never within one (the
            // step's points index it).
            if cache.len() >= CACHE_MAX {
                cache.clear();
            }
            for &ech in &e_colliders {
                for pair in built.world.narrow_phase.contact_pairs_with(ech) {
                    let other = if pair.collider1 == ech {
                        pair.collider2
                    } else {
                        pair.collider1
                    };
                    let (Some(co_e), Some(co_o)) = (
                        built.world.colliders.get(ech),
                        built.world.colliders.get(other),
                    ) else {
                        continue;
                    };
                    let Some(ob) = co_o.parent() else { continue };
                    if !built.world.bodies[ob].is_dynamic() {
                        continue;
                    }
                    let mu = 0.5 * (co_e.friction() + co_o.friction());
                    let (pe, po) = (*co_e.position(), *co_o.position());
                    let prop_mass = built.world.bodies[ob].mass();
                    // Fresh manifolds of the pair (object first): rapier's narrow phase keeps
                    // a manifold's points while the pair turns by less than 1° and slides by
                    // less than 1 mm, so the true deepest point of a curved prop (a plate's
                    // rim between the points of its cap's square) can sink unseen and then
                    // appear at once up to a millimetre deep; recomputed every step, the
                    // deepest point is always one of the points (its gap continuous in time).
                    manifolds.clear();
                    let mut workspace: Option<ContactManifoldsWorkspace> = None;
                    if DefaultQueryDispatcher
                        .contact_manifolds(
                            &pe.inv_mul(&po),
                            co_e.shape(),
                            co_o.shape(),
                            prediction,
                            &mut manifolds,
                            &mut workspace,
                        )
                        .is_err()
                    {
                        bail!(
                            "scene {}: no contact manifold between the elastic object and {}'s \
                             collider shape",
                            desc.name,
                            built.bodies[body_of[&ob]].name
                        );
                    }
                    for m in &manifolds {
                        let first = pts.len();
                        let npts = m.points.len().max(1) as f64;
                        let n = (pe.rotation * m.local_n1).normalize();
                        let damp = 2.0 * zeta * (p.contact_stiffness * prop_mass / npts).sqrt();
                        for c in &m.points {
                            let x_e = pe.transform_point(c.local_p1);
                            let x_o = po.transform_point(c.local_p2);
                            // The manifold's extra closest point can repeat a clipped one.
                            if pts[first..].iter().any(|q| (q.x_o - x_o).length() < 1e-9) {
                                continue;
                            }
                            // Every point within the prediction distance (2 cm by default) is
                            // taken: the elastic surface can rise by more than a small rigid
                            // gap, and a point skipped there would wake up deep inside the
                            // surface and pop the prop out.
                            let dist = (x_o - x_e).dot(n);
                            // The contact on the elastic surface, in the object frame.
                            let xl = e_pose.inverse_transform_point(x_e);
                            let key = [xl.x, xl.y, xl.z].map(|v| (v * 2e3).round() as i64);
                            if let std::collections::hash_map::Entry::Vacant(slot) =
                                cache.entry(key)
                            {
                                let sp = surface
                                    .project(arr(xl))
                                    .context("contact point off the elastic surface")?;
                                let verts = surface.triangles[sp.triangle as usize];
                                slot.insert(elastic.axis_rows(verts, sp.bary));
                            }
                            pts.push(ContactPoint {
                                ob,
                                n,
                                nl: arr(e_pose.rotation.inverse() * n),
                                x_o,
                                x_e,
                                dist,
                                key,
                                mu,
                                damp,
                            });
                        }
                    }
                }
            }
            // A prop that starts inside the surface would be thrown by its contact springs.
            for c in &pts {
                if !first_seen.contains(&c.ob) {
                    first_seen.push(c.ob);
                    let deepest = pts
                        .iter()
                        .filter(|q| q.ob == c.ob)
                        .min_by(|a, b| a.dist.total_cmp(&b.dist))
                        .expect("this point");
                    let depth = -deepest.dist;
                    let m = built.world.bodies[c.ob].mass();
                    let spring = 0.5 * p.contact_stiffness * depth * depth;
                    if depth > START_OVERLAP_FLOOR_M
                        && spring > m * gravity.length() * START_OVERLAP_RISE_M
                    {
                        let x = deepest.x_o;
                        bail!(
                            "scene {}: {} starts {:.4} mm inside elastic object {}'s surface (at \
                             ({:.4}, {:.4}, {:.4}) m, world): the reference's contact spring ({:.1e} \
                             N/m a point) would hold {:.2e} J there and throw it about {:.0} mm; \
                             place it on the surface (its lowest point at or just above it)",
                            desc.name,
                            built.bodies[body_of[&c.ob]].name,
                            depth * 1e3,
                            desc.elastic[0].name,
                            x.x,
                            x.y,
                            x.z,
                            p.contact_stiffness,
                            spring,
                            spring / (m * gravity.length().max(1e-12)) * 1e3
                        );
                    }
                }
            }
            // Blocks: each prop's points, in the order the props first appear.
            blocks.clear();
            for (i, c) in pts.iter().enumerate() {
                match blocks.iter_mut().find(|(b, _)| *b == c.ob) {
                    Some((_, v)) => v.push(i),
                    None => blocks.push((c.ob, vec![i])),
                }
            }
            for (ob, idx) in &blocks {
                let nb = idx.len();
                let mm = elastic.modes();
                nrows.resize(nb * mm, 0.0);
                let (mut g0, mut gfree, mut vn_surf, mut kap, mut bb) = (
                    vec![0.0; nb],
                    vec![0.0; nb],
                    vec![0.0; nb],
                    vec![0.0; nb],
                    vec![0.0; nb],
                );
                let rb_o = &built.world.bodies[*ob];
                let rb_e = &built.world.bodies[e_handle];
                let loads = p.prop_feedback || sources.contains(ob);
                for (a, &i) in idx.iter().enumerate() {
                    let c = &pts[i];
                    let r = &mut nrows[a * mm..(a + 1) * mm];
                    elastic.normal_row(&cache[&c.key], c.nl, r);
                    let (u, v, u_end) = elastic.motion_normal(r);
                    g0[a] = c.dist - u;
                    vn_surf[a] = v;
                    let v_o = rb_o.velocity_at_point(c.x_o) + gravity * rb_o.gravity_scale() * p.dt;
                    let mut v_e = rb_e.velocity_at_point(c.x_e);
                    if e_dynamic {
                        v_e += gravity * rb_e.gravity_scale() * p.dt;
                    }
                    gfree[a] = c.dist + p.dt * (v_o - v_e).dot(c.n) - u_end;
                    kap[a] = p.contact_stiffness + c.damp / p.dt;
                    bb[a] = -kap[a] * gfree[a] + c.damp / p.dt * g0[a].min(0.0);
                }
                let mut fnv = vec![0.0; nb];
                match p.scheme {
                    CouplingScheme::Implicit => {
                        let mut amat = vec![0.0; nb * nb];
                        let (bo, be) = (body_mass(rb_o), body_mass(rb_e));
                        for a in 0..nb {
                            for b in a..nb {
                                let (ca, cb) = (&pts[idx[a]], &pts[idx[b]]);
                                let mut v = if loads {
                                    elastic.step_compliance(
                                        &nrows[a * mm..(a + 1) * mm],
                                        &nrows[b * mm..(b + 1) * mm],
                                    )
                                } else {
                                    0.0
                                };
                                v += p.dt * p.dt * bo.coupling(ca.x_o, ca.n, cb.x_o, cb.n);
                                if e_dynamic {
                                    v += p.dt * p.dt * be.coupling(ca.x_e, ca.n, cb.x_e, cb.n);
                                }
                                amat[a * nb + b] = v;
                                amat[b * nb + a] = v;
                            }
                        }
                        let info = solve_penalty_block(&amat, &kap, &bb, &mut fnv);
                        solver_fallbacks += usize::from(info.fallback);
                    }
                    CouplingScheme::Explicit => {
                        for a in 0..nb {
                            let c = &pts[idx[a]];
                            if g0[a] >= 0.0 {
                                continue;
                            }
                            let v_surf = rb_e.velocity_at_point(c.x_e) + c.n * vn_surf[a];
                            let vn = (rb_o.velocity_at_point(c.x_o) - v_surf).dot(c.n);
                            fnv[a] = (p.contact_stiffness * (-g0[a]) - c.damp * vn).max(0.0);
                        }
                    }
                }
                for a in 0..nb {
                    let c = &pts[idx[a]];
                    if g0[a] < 0.0 {
                        max_pen = max_pen.max(-g0[a]);
                        spring_energy += 0.5 * p.contact_stiffness * g0[a] * g0[a];
                    }
                    let fn_ = fnv[a];
                    if fn_ <= 0.0 {
                        continue;
                    }
                    let v_surf = rb_e.velocity_at_point(c.x_e) + c.n * vn_surf[a];
                    let rel = rb_o.velocity_at_point(c.x_o) - v_surf;
                    let vt = rel - c.n * rel.dot(c.n);
                    let s = vt.length();
                    let ft = if s > 0.0 {
                        // Regularised Coulomb, η = μ f / max(|v_t|, v_s), implicit in the
                        // prop's slip: f_t = −η v_t / (1 + η Δt n_b W_t), W_t the inverse
                        // effective mass along the slip shared by the block's n_b points, so
                        // friction never reverses the slip within a step.
                        let eta = c.mu * fn_ / s.max(p.friction_velocity);
                        let t = vt / s;
                        let mut wt = body_mass(rb_o).coupling(c.x_o, t, c.x_o, t);
                        if e_dynamic {
                            wt += body_mass(rb_e).coupling(c.x_e, t, c.x_e, t);
                        }
                        vt * (-eta / (1.0 + eta * p.dt * nb as f64 * wt))
                    } else {
                        Vector::ZERO
                    };
                    forces.push((c.ob, c.n * fn_ + ft, c.x_o, c.x_e, vn_surf[a], fn_));
                    // On the elastic modes: −f at the surface point (object frame), the
                    // normal part along the point's normal row.
                    if loads {
                        elastic.add_force_normal(&nrows[a * mm..(a + 1) * mm], -fn_);
                        let ftl = e_pose.rotation.inverse() * (-ft);
                        elastic.add_force_rows(&cache[&c.key], arr(ftl));
                    }
                }
            }
            for &(ob, f, x_o, x_e, v_n, fn_) in &forces {
                built.world.bodies[ob].apply_impulse_at_point(f * p.dt, x_o, true);
                if e_dynamic {
                    built.world.bodies[e_handle].apply_impulse_at_point(-f * p.dt, x_e, true);
                }
                // Work of the surface's elastic motion on the prop: f_n v_n dt.
                if let Some(&b) = body_of.get(&ob) {
                    speed[b] = speed[b].max(v_n);
                    work[b] += fn_ * v_n * p.dt;
                    work_max[b] = work_max[b].max(work[b]);
                }
            }
            built.world.step_with_events(&(), &());
            elastic.step();
            if !elastic.energy().is_finite() {
                bail!(
                    "the coupled run blew up at t = {:.6} s (coupling step {} s): lower \
                     --contact-stiffness or the step",
                    t_h + (ks + 1) as f64 * p.dt,
                    p.dt
                );
            }
        }
        let t = (kh + 1) as f64 * desc.h;
        record(&built, &mut traj, t);
        energy.push(total_energy(&built, gravity, &elastic, spring_energy));
        if p.progress && last.elapsed().as_secs_f64() > 10.0 {
            last = Instant::now();
            eprintln!(
                "[scene-truth] {} dt {:.2e} s: t = {:.3}/{:.3} s ({:.0} s wall)",
                desc.name,
                p.dt,
                t,
                p.seconds,
                wall.elapsed().as_secs_f64()
            );
        }
    }
    if p.progress {
        // Each dynamic body's largest lift (mm) and slide (mm), to see which body an outcome is.
        let lifts: Vec<String> = (0..traj.names.len())
            .map(|b| {
                let y0 = traj.pos(0, b)[1];
                let lift = (0..traj.rows())
                    .map(|k| traj.pos(k, b)[1] - y0)
                    .fold(0.0f64, f64::max);
                format!("{} {:.1}", traj.names[b], lift * 1e3)
            })
            .collect();
        eprintln!(
            "[scene-truth] {} dt {:.2e} s, k {:.1e} N/m: lift (mm) {}; largest penetration {:.3} mm, {} solver fallbacks",
            desc.name,
            p.dt,
            p.contact_stiffness,
            lifts.join(", "),
            max_pen * 1e3,
            solver_fallbacks
        );
    }
    let mut outcomes = BTreeMap::new();
    for o in &desc.outcomes {
        if let Some(v) = measure_outcome(o, &traj) {
            outcomes.insert(o.name.clone(), (v, unit_of(&o.kind).to_string()));
        }
    }
    let delivered = built
        .bodies
        .iter()
        .enumerate()
        .filter(|(i, _)| work_max[*i] > 0.0)
        .map(|(i, b)| (b.name.clone(), work_max[i]))
        .collect();
    let surface_speed = built
        .bodies
        .iter()
        .enumerate()
        .filter(|(i, _)| speed[*i] > 0.0)
        .map(|(i, b)| (b.name.clone(), speed[i]))
        .collect();
    Ok(CoupledRun {
        surface_speed,
        trajectory: traj,
        outcomes,
        delivered,
        max_penetration: max_pen,
        energy,
        momentum: [momentum0, momentum(&built)],
        steps: steps_h * sub,
        solver_fallbacks,
        wall_s: wall.elapsed().as_secs_f64(),
    })
}

/// Kinetic energy of every body + gravity potential (−m g·x, J) + elastic energy + `springs`.
fn total_energy(built: &BuiltWorld, gravity: Vector, elastic: &ElasticBody, springs: f64) -> f64 {
    let mut e = elastic.energy() + springs;
    for b in &built.bodies {
        let rb = &built.world.bodies[b.handle];
        if rb.is_dynamic() {
            e += rb.kinetic_energy() - rb.mass() * gravity.dot(rb.center_of_mass());
        }
    }
    e
}

/// Applies the scene's scripted impulses due at `t` (s), as `dcr-scenes run` does.
fn apply_drivers(
    drivers: &[(RigidBodyHandle, dcr_scenes::scene::DriverDesc)],
    built: &mut BuiltWorld,
    t: f64,
) {
    for (h, d) in drivers {
        dcr_scenes::runner::apply_driver(d, &mut built.world.bodies[*h], t);
    }
}

/// Σ m v over the dynamic bodies (N·s, world).
fn momentum(built: &BuiltWorld) -> [f64; 3] {
    let mut p = Vector::ZERO;
    for b in &built.bodies {
        let rb = &built.world.bodies[b.handle];
        if rb.is_dynamic() {
            p += rb.linvel() * rb.mass();
        }
    }
    arr(p)
}

/// Rebound ratio of a unit spring–dashpot contact with damping ratio ζ whose force is clamped
/// at zero (no pull): p̈ = −max(0, p + 2ζ ṗ) from p = 0, ṗ = 1 until p < 0 (RK4).
fn clamped_restitution(zeta: f64) -> f64 {
    let f = |p: f64, v: f64| -(p + 2.0 * zeta * v).max(0.0);
    let (mut p, mut v, dt) = (0.0f64, 1.0f64, 1e-3);
    for _ in 0..200_000 {
        let (k1p, k1v) = (v, f(p, v));
        let (k2p, k2v) = (
            v + 0.5 * dt * k1v,
            f(p + 0.5 * dt * k1p, v + 0.5 * dt * k1v),
        );
        let (k3p, k3v) = (
            v + 0.5 * dt * k2v,
            f(p + 0.5 * dt * k2p, v + 0.5 * dt * k2v),
        );
        let (k4p, k4v) = (v + dt * k3v, f(p + dt * k3p, v + dt * k3v));
        p += dt / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
        v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if p < 0.0 {
            break;
        }
    }
    (-v).max(0.0)
}

/// The damping ratio ζ whose clamped spring–dashpot contact rebounds with ratio `e` (bisection
/// on [`clamped_restitution`], which decreases with ζ); 0 for e ≥ 1.
pub(crate) fn dashpot_ratio(e: f64) -> f64 {
    if e >= 1.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0f64, 20.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if clamped_restitution(mid) > e {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The calibrated dashpot rebounds with the restitution asked for, and an undamped contact
    /// is elastic.
    #[test]
    fn dashpot_gives_the_restitution() {
        for e in [0.05, 0.15, 0.5, 0.9] {
            let z = dashpot_ratio(e);
            assert!((clamped_restitution(z) - e).abs() < 1e-6, "e {e}: ζ {z}");
        }
        assert!((clamped_restitution(0.0) - 1.0).abs() < 1e-6);
    }
}
