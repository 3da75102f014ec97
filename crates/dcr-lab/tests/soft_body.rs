//! The rapier FEM soft body built from a tetrahedral mesh (`dcr_lab::soft_body`): the builder
//! keeps the mesh, pinned particles stay put, a cantilever sags as linear elasticity says, and
//! the dinner scene with a soft table and nothing hitting it keeps its plates at rest, a
//! projectile started k steps into its flight continues rapier's own flight, ensemble members
//! differ only by where the projectile starts, and the substep sweep converges within an
//! ensemble's noise only when the noise covers the change.

use std::collections::BTreeMap;

use dcr_lab::soft_body::{
    run_side, run_soft_scene, sweep_substeps, tet_soft_body, with_projectiles_advanced,
    EnsembleParams, SideMethod, SideRow, SoftSceneParams, SweepParams, TetSoftBodyDesc,
};
use faer::linalg::solvers::Solve;
use modal_bake::fem::{assemble_clamped, Material};
use modal_bake::mesh::TetMesh;
use rapier3d_f64::prelude::*;

/// A cantilever: 1 m × 0.1 m × 0.1 m along x, 20 × 2 × 2 cubes of 6 tetrahedra, clamped at
/// x = 0 (group `xmin`). E = 1e7 Pa, ν = 0, ρ = 100 kg/m³.
fn cantilever_mesh() -> TetMesh {
    TetMesh::structured_box([20, 2, 2], [1.0, 0.1, 0.1])
}

fn cantilever_desc() -> TetSoftBodyDesc {
    TetSoftBodyDesc {
        youngs: 1.0e7,
        poisson: 0.0,
        density: 100.0,
        // Mass damping only: the beam settles to its static sag within a second.
        rayleigh: [20.0, 0.0],
        fixed: vec!["xmin".into()],
        ..TetSoftBodyDesc::default()
    }
}

/// Steps a world holding only the cantilever (rapier's default step and substeps, the
/// conjugate gradient capped at `cg` iterations per substep); returns the world, the body and
/// its particles' start positions.
fn settle_cantilever(steps: usize, cg: usize) -> (PhysicsWorld, SoftBodyHandle, Vec<[f64; 3]>) {
    let mesh = cantilever_mesh();
    let sb = tet_soft_body(&mesh, &cantilever_desc()).unwrap();
    let mut world = PhysicsWorld::new();
    world
        .integration_parameters
        .soft_bodies
        .fem
        .max_linear_iterations = cg;
    let start: Vec<[f64; 3]> = sb
        .builder
        .particle_positions()
        .iter()
        .map(|p| [p.x, p.y, p.z])
        .collect();
    let h = world.insert_soft_body(sb.builder.no_surface_collider());
    for _ in 0..steps {
        world.step();
    }
    (world, h, start)
}

/// The builder keeps every node as a particle and every tetrahedron as a cell, in mesh order;
/// lumped masses sum to ρV; pinned particles are exactly the fixed group, or the same nodes
/// given by a half-space or a box. A second-order mesh keeps its corner nodes only.
#[test]
fn builder_preserves_nodes_and_tets() {
    let mesh = cantilever_mesh();
    let sb = tet_soft_body(&mesh, &cantilever_desc()).unwrap();
    assert_eq!(sb.particle_node, (0..mesh.nodes.len()).collect::<Vec<_>>());
    assert_eq!(sb.builder.cells.len(), mesh.tets.len());
    for (c, t) in sb.builder.cells.iter().zip(&mesh.tets) {
        assert_eq!(c.map(|i| i as usize), *t);
    }
    let total: f64 = sb.builder.masses.iter().sum();
    let rho_v = 100.0 * 1.0 * 0.1 * 0.1;
    assert!(
        (total - rho_v).abs() < 1e-12 * rho_v,
        "Σm = {total}, ρV = {rho_v}"
    );
    assert!((sb.mass - rho_v).abs() < 1e-12 * rho_v);
    let fixed: Vec<u32> = mesh.groups["xmin"].iter().map(|&n| n as u32).collect();
    assert_eq!(sb.pinned, fixed);

    let p2 = mesh.to_quadratic();
    assert!(p2.nodes.len() > mesh.nodes.len());
    let sb2 = tet_soft_body(&p2, &cantilever_desc()).unwrap();
    assert_eq!(sb2.particle_node.len(), mesh.nodes.len());
    assert_eq!(sb2.builder.cells.len(), p2.tets.len());
    assert_eq!(sb2.pinned.len(), fixed.len());

    let bad = TetSoftBodyDesc {
        fixed: vec!["nope".into()],
        ..cantilever_desc()
    };
    let err = tet_soft_body(&mesh, &bad).unwrap_err().to_string();
    assert!(err.contains("nope") && err.contains("xmin"), "{err}");

    // The baker's other selectors pin the same particles: x ≤ 0, or a box around x = 0.
    let below = TetSoftBodyDesc {
        fixed: Vec::new(),
        fixed_below: vec![modal_bake::bake::FixedBelow {
            axis: 0,
            value: 0.0,
        }],
        ..cantilever_desc()
    };
    assert_eq!(tet_soft_body(&mesh, &below).unwrap().pinned, fixed);
    let boxed = TetSoftBodyDesc {
        fixed: Vec::new(),
        fixed_boxes: vec![[-1.0, -1.0, -1.0, 1e-9, 1.0, 1.0]],
        ..cantilever_desc()
    };
    assert_eq!(tet_soft_body(&mesh, &boxed).unwrap().pinned, fixed);
    let nothing = TetSoftBodyDesc {
        fixed_below: vec![modal_bake::bake::FixedBelow {
            axis: 1,
            value: -0.5,
        }],
        ..below
    };
    let err = tet_soft_body(&mesh, &nothing).unwrap_err().to_string();
    assert!(err.contains("fixes no node"), "{err}");
}

/// Pinned particles do not move, bit for bit, while the rest of the beam sags.
#[test]
fn pinned_particles_do_not_move() {
    let (world, h, start) = settle_cantilever(50, 20);
    let sb = &world.soft_bodies[h];
    let mesh = cantilever_mesh();
    for &n in &mesh.groups["xmin"] {
        let p = sb.particle_position(n);
        assert_eq!([p.x, p.y, p.z], start[n], "pinned node {n} moved");
    }
    let tip = mesh.groups["xmax"][0];
    assert!(
        sb.particle_position(tip).y < start[tip][1] - 1e-3,
        "the free end did not sag"
    );
}

/// Static tip deflection (m, downward positive) of the cantilever's P1 finite-element model
/// under gravity: `K u = M g` on the same mesh with the baker's assembly (lumped mass, the
/// clamped dofs removed), solved densely; the mean over the tip face's nodes.
fn p1_static_tip_deflection() -> f64 {
    p1_tip_deflection(true, &[])
}

/// The same model's static tip deflection (m, downward positive) under its own weight (when
/// `gravity`) and downward nodal forces `loads` (node, N).
fn p1_tip_deflection(gravity: bool, loads: &[(usize, f64)]) -> f64 {
    let mesh = cantilever_mesh();
    let mat = Material::new(1.0e7, 0.0, 100.0).unwrap();
    let fixed = mesh.groups["xmin"].clone();
    let (map, k, m) = assemble_clamped(&mesh, &mat, true, &fixed).unwrap();
    let n = map.n_free();
    let kd = k.to_dense();
    let md = m.to_dense();
    let mut f = faer::Mat::<f64>::zeros(n, 1);
    if gravity {
        for (i, &dof) in map.free_dofs().iter().enumerate() {
            if dof % 3 == 1 {
                f[(i, 0)] = -9.81 * md[(i, i)];
            }
        }
    }
    for &(node, force) in loads {
        f[(map.free_index(3 * node + 1).unwrap(), 0)] -= force;
    }
    let llt = kd.llt(faer::Side::Lower).unwrap();
    let u = llt.solve(&f);
    let tip = &mesh.groups["xmax"];
    -tip.iter()
        .map(|&node| u[(map.free_index(3 * node + 1).unwrap(), 0)])
        .sum::<f64>()
        / tip.len() as f64
}

/// A cantilever under its own weight sags by what linear elasticity predicts.
///
/// Timoshenko beam (ν = 0, shear factor 5/6): δ = qL⁴/(8EI) + qL²/(2κGA) with q = ρgA. The
/// P1 tetrahedra of a 2-element-thick beam are stiffer in bending than the beam (shear
/// locking), so the analytic value is checked against the P1 model's own static solution (the
/// discretization: 0.55 × the beam's
/// value on this mesh; asserted within 0.45…1 ×), and rapier's settled FEM body against that static solution
/// within 3 % (rapier solves the same linear elasticity, corotated, at strains of 1e-3 where
/// the rotation changes the sag by ~δ²/L² ≈ 1e-4; lumped masses as here; what remains is the
/// conjugate gradient's 1e-5 tolerance and the damped residual motion after 5 s). The conjugate
/// gradient runs to its tolerance here (cap 1000): at rapier's default cap of 20 iterations per
/// substep the settled sag is 12.6× the static one (a truncated solve is a softer body).
#[test]
fn cantilever_sags_as_linear_elasticity_predicts() {
    let (e, rho, g, l, b) = (1.0e7, 100.0, 9.81, 1.0, 0.1);
    let a = b * b;
    let i = b.powi(4) / 12.0;
    let q = rho * g * a;
    let kappa_g = 5.0 / 6.0 * e / 2.0;
    let analytic = q * l.powi(4) / (8.0 * e * i) + q * l * l / (2.0 * kappa_g * a);
    let p1 = p1_static_tip_deflection();
    assert!(
        p1 < analytic && p1 > 0.45 * analytic,
        "P1 static {p1} m vs Timoshenko {analytic} m"
    );

    let (world, h, start) = settle_cantilever(300, 1000);
    let sb = &world.soft_bodies[h];
    let mesh = cantilever_mesh();
    let tip = &mesh.groups["xmax"];
    let sag = tip
        .iter()
        .map(|&n| start[n][1] - sb.particle_position(n).y)
        .sum::<f64>()
        / tip.len() as f64;
    let err = (sag - p1).abs() / p1;
    assert!(
        err < 0.03,
        "rapier FEM sag {sag} m vs P1 static {p1} m ({:.1} %; Timoshenko {analytic} m)",
        100.0 * err
    );
}

/// The dinner scene with the table a soft body and the pot resting on the table (zero
/// velocity, its bottom on the top): nothing hits the table, so no plate or cup may lift beyond
/// the settling of the table under its own weight (it starts undeformed; at rapier's defaults
/// that settling is µm). The candlesticks are not checked: on their small bases the settling
/// top tilts them by ~0.7° at rapier's defaults (docs/benchmarks.md), a figure of the soft
/// table, not of a response.
#[test]
fn dinner_soft_table_at_rest_keeps_plates_down() {
    let root = dcr_scenes::repo_root();
    let mut desc = dcr_scenes::scene::SceneDesc::read(&root.join("scenes/dinner.json")).unwrap();
    let pot = desc.props.iter_mut().find(|p| p.name == "pot").unwrap();
    pot.linvel = [0.0; 3];
    // Cylinder half height 0.1 m on the top at y = 0.75 m.
    pot.pose.translation[1] = 0.75 + 0.1;
    let mut params = SoftSceneParams::new(root);
    params.seconds = Some(0.5);
    let r = run_soft_scene(&desc, &params).unwrap();
    for name in ["plates_max_lift", "teacups_max_lift"] {
        let lift = r.outcomes[name].0;
        assert!(
            lift < 0.05,
            "{name}: {lift} mm with nothing hitting the table"
        );
    }
}

/// The pot of the dinner scene started `k` steps into its free flight
/// (`with_projectiles_advanced`) is where rapier's own flight has it `k` steps after the
/// scene's start, with the same velocity, at every step until it lands (rigid world of
/// `build_world`, nothing else moves in flight), at 1 and at 4 substeps per step; the props at
/// rest are not moved; a spinning projectile (the roof's toolbox) is refused by name.
#[test]
fn advanced_projectiles_continue_the_original_flight() {
    use dcr_scenes::scene::{build_world, SceneDesc};
    let root = dcr_scenes::repo_root();
    let desc = SceneDesc::read(&root.join("scenes/dinner.json")).unwrap();
    let k = 10;
    let pot_after = |d: &SceneDesc, substeps: usize, steps: usize| {
        let mut b = build_world(d, &root).unwrap();
        b.world.integration_parameters.num_solver_iterations = substeps;
        for _ in 0..steps {
            b.world.step();
        }
        let i = b.bodies.iter().position(|x| x.name == "pot").unwrap();
        let rb = &b.world.bodies[b.bodies[i].handle];
        (rb.translation(), rb.linvel())
    };
    for substeps in [1, 4] {
        let adv = with_projectiles_advanced(&desc, k, substeps).unwrap();
        // The original pot lands after ~20 steps (0.4 m from 1 m/s, h = 0.01 s).
        for j in [0, 1, 4, 8] {
            let (x0, v0) = pot_after(&desc, substeps, k + j);
            let (x1, v1) = pot_after(&adv, substeps, j);
            assert!(
                (x0 - x1).length() < 1e-12 && (v0 - v1).length() < 1e-12,
                "{substeps} substeps, step {j}: original {x0:?} {v0:?}, advanced {x1:?} {v1:?}"
            );
        }
        for (a, b) in desc.props.iter().zip(&adv.props) {
            if a.name != "pot" {
                assert_eq!(a.pose.translation, b.pose.translation, "{} moved", a.name);
                assert_eq!(a.linvel, b.linvel);
            }
        }
    }
    let roof = SceneDesc::read(&root.join("scenes/roof.json")).unwrap();
    let err = with_projectiles_advanced(&roof, 1, 4)
        .unwrap_err()
        .to_string();
    assert!(err.contains("toolbox"), "{err}");
}

/// A 0.5 kg box resting on the cantilever's free end, its contact answered through rapier's
/// direct factorization (`max_dense_dofs` above the body's 189 dofs) and through the conjugate
/// gradient (`max_dense_dofs` 0), both run to tolerance: the two settle to the same tip sag
/// (within 1 %), and the sag the box adds is what the P1 static model gives for its weight
/// (within 2 %: where the box's contact points fall inside the element is the one modelling
/// choice), put on the top nodes of the last element's cross-section lines x = 0.95 m and
/// 1 m half each (the box's centre is midway), 1 : 2 : 1 across the width.
#[test]
fn box_on_cantilever_sags_it_as_p1_through_either_contact_solve() {
    let mesh = cantilever_mesh();
    let (bare_world, bare_h, start) = settle_cantilever(300, 1000);
    let tip = &mesh.groups["xmax"];
    let mean_sag = |world: &PhysicsWorld, h: SoftBodyHandle| {
        tip.iter()
            .map(|&n| start[n][1] - world.soft_bodies[h].particle_position(n).y)
            .sum::<f64>()
            / tip.len() as f64
    };
    let bare = mean_sag(&bare_world, bare_h);

    let (mass, g) = (0.5, 9.81);
    let loaded = |max_dense_dofs: usize| {
        let sb = tet_soft_body(&mesh, &cantilever_desc()).unwrap();
        let mut world = PhysicsWorld::new();
        let fem = &mut world.integration_parameters.soft_bodies.fem;
        fem.max_linear_iterations = 1000;
        fem.max_dense_dofs = max_dense_dofs;
        let h = world.insert_soft_body(sb.builder);
        // 2 cm × 2 cm × 8 cm over the middle of the last element's top (y = 0.1 m).
        world.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.975, 0.1 + 0.0102, 0.05)),
            ColliderBuilder::cuboid(0.01, 0.01, 0.04)
                .mass(mass)
                .friction(0.8),
        );
        for _ in 0..300 {
            world.step();
        }
        mean_sag(&world, h)
    };
    let direct = loaded(10_000);
    let cg = loaded(0);
    assert!(
        (direct - cg).abs() < 0.01 * direct,
        "tip sag with the box: direct {direct} m, CG {cg} m"
    );

    let weight = mass * g;
    let mut loads = Vec::new();
    for (n, p) in mesh.nodes.iter().enumerate() {
        let top = (p[1] - 0.1).abs() < 1e-9;
        let line = (p[0] - 0.95).abs() < 1e-9 || (p[0] - 1.0).abs() < 1e-9;
        if top && line {
            let across = if (p[2] - 0.05).abs() < 1e-9 {
                0.5
            } else {
                0.25
            };
            loads.push((n, 0.5 * across * weight));
        }
    }
    assert_eq!(loads.len(), 6);
    let added_p1 = p1_tip_deflection(false, &loads);
    for (name, sag) in [("direct", direct), ("CG", cg)] {
        let added = sag - bare;
        assert!(
            (added - added_p1).abs() < 0.02 * added_p1,
            "{name}: the box adds {added} m of tip sag, P1 static {added_p1} m"
        );
    }
}

/// Ensemble member m > 0 of the soft dinner scene starts the pot (the one body with an initial
/// velocity) exactly the perturbation distance away from member 0, across gravity (no vertical
/// component), each member in its own direction; every other body starts where member 0 has it.
#[test]
fn soft_ensemble_members_move_the_projectile_across_gravity_by_the_distance() {
    let root = dcr_scenes::repo_root();
    let desc = dcr_scenes::scene::SceneDesc::read(&root.join("scenes/dinner.json")).unwrap();
    let d = 1e-4;
    let start = |member: usize| {
        let mut p = SoftSceneParams::new(root.clone());
        p.seconds = Some(desc.h);
        p.perturbation = (member, d);
        let t = run_soft_scene(&desc, &p).unwrap().trajectory;
        (0..t.names.len())
            .map(|b| (t.names[b].clone(), t.pos(0, b)))
            .collect::<Vec<_>>()
    };
    let m0 = start(0);
    let mut dirs = Vec::new();
    for member in [1, 2] {
        let m = start(member);
        for ((n0, x0), (n, x)) in m0.iter().zip(&m) {
            assert_eq!(n0, n);
            let dx = [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]];
            if n == "pot" {
                let len = (dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]).sqrt();
                assert!(
                    (len - d).abs() < 1e-12,
                    "member {member}: pot moved {len} m"
                );
                // dinner's gravity is along −y.
                assert!(
                    dx[1].abs() < 1e-15,
                    "member {member}: vertical move {}",
                    dx[1]
                );
                dirs.push(dx);
            } else {
                assert_eq!(x0, x, "member {member}: {n} moved");
            }
        }
    }
    assert_eq!(dirs.len(), 2, "the dinner scene has a pot");
    let cos = (dirs[0][0] * dirs[1][0] + dirs[0][2] * dirs[1][2]) / (d * d);
    assert!(cos < 0.999, "members 1 and 2 move the pot the same way");
}

/// Before the pot lands (0.1 s of the dinner scene, the pot in flight until ~0.2 s) nothing
/// chaotic has happened: an ensemble row of three members gives every member the same
/// outcomes, bit for bit, and a standard deviation of exactly 0; the row says its members and
/// pools their steps.
#[test]
fn ensemble_members_agree_before_the_impact() {
    let root = dcr_scenes::repo_root();
    let desc = dcr_scenes::scene::SceneDesc::read(&root.join("scenes/dinner.json")).unwrap();
    let ens = EnsembleParams {
        members: 3,
        perturbation: 1e-4,
    };
    let r = run_side(&desc, &SideMethod::Off, root, Some(0.1), &ens, false).unwrap();
    assert_eq!(r.members, 3);
    assert_eq!(r.member_outcomes.len(), 3);
    assert!(!r.outcomes.is_empty());
    for m in &r.member_outcomes[1..] {
        assert_eq!(m, &r.member_outcomes[0]);
    }
    for (name, sd) in &r.spread {
        assert_eq!(
            *sd, 0.0,
            "{name}: standard deviation {sd} before the impact"
        );
    }
    for (name, (mean, _)) in &r.outcomes {
        assert_eq!(*mean, r.member_outcomes[0][name], "{name}");
    }
}

/// A rapier-FEM row of the sweep with one outcome whose mean alternates ±10 % around 10 mm
/// with each doubling, with `members` members of standard deviation `sd`.
fn synthetic_row(method: &SideMethod, members: usize, sd: f64) -> SideRow {
    let SideMethod::RapierFem { substeps, .. } = method else {
        panic!("the sweep runs rapier-fem rows")
    };
    let k = substeps.trailing_zeros() as i32;
    let v = 10.0 * (1.0 + 0.1 * f64::from((-1i32).pow(k as u32)));
    SideRow {
        scene: "synthetic".into(),
        method: method.clone(),
        steps: 1,
        step_ms_median: 1.0,
        step_ms_p99: 1.0,
        response_ms: None,
        peak_rss_mib: None,
        wall_s: 0.0,
        outcomes: BTreeMap::from([("lift".to_string(), (v, "mm".to_string()))]),
        spread: BTreeMap::from([("lift".to_string(), sd)]),
        members,
        perturbation: 1e-4,
        member_outcomes: Vec::new(),
        surface_peak_mm: None,
    }
}

/// The sweep's stopping rule: means that move by 2 mm (20 %) with each doubling stop the sweep
/// at its second row only when two standard errors of the difference cover the move (4
/// members of 3 mm: 4.2 mm), and reach the substep cap when they do not (4 members of 1 mm:
/// 1.4 mm) or when the rows are single runs (no noise estimate, whatever their spread field
/// says).
#[test]
fn sweep_converges_within_noise_only_when_the_noise_covers_the_change() {
    let params = SweepParams {
        first: 1,
        max_substeps: 16,
        budget_s: 1e9,
        ..SweepParams::default()
    };
    let sweep = |members: usize, sd: f64| {
        sweep_substeps(&params, |m| Ok(synthetic_row(m, members, sd))).unwrap()
    };
    let (rows, end) = sweep(4, 3.0);
    assert_eq!(rows.len(), 2);
    assert!(end.converged && end.within_noise, "{end:?}");
    assert_eq!(end.reason, "converged within noise");
    assert!((end.last_change - 2.0 / 11.0).abs() < 1e-12, "{end:?}");
    for (members, sd) in [(4, 1.0), (1, 3.0)] {
        let (rows, end) = sweep(members, sd);
        assert_eq!(rows.len(), 5, "{members} members of {sd} mm");
        assert!(!end.converged && !end.within_noise, "{end:?}");
        assert_eq!(end.reason, "substep cap");
        assert_eq!(end.last_substeps, 16);
    }
}
