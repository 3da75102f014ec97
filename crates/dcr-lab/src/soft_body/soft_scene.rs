//! A scene run with its elastic objects as rapier FEM soft bodies instead of rigid bodies with a
//! distant response: the same world as `dcr-scenes run` (bodies, poses, masses, materials,
//! contacts), the same trajectory recording and outcome figures.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use dcr_scenes::runner::{measure_outcome, unit_of, Trajectory};
use dcr_scenes::scene::{build_world, pose_from_desc, BodyKind, SceneDesc};
use rapier3d_f64::prelude::*;
use serde::Serialize;

use super::tet_soft_body::{tet_soft_body_from_file, TetSoftBodyDesc};

/// Settings of a soft-body run. Defaults: rapier's own (`IntegrationParameters` and
/// `SoftFemParameters` defaults), the scene's length, a 0.1 mm contact skin.
#[derive(Clone, Debug)]
pub struct SoftSceneParams {
    /// Repository root (mesh paths are relative to it).
    pub root: PathBuf,
    /// Simulated time (s); `None`: the scene's `seconds`.
    pub seconds: Option<f64>,
    /// Solver substeps per step (`IntegrationParameters::num_solver_iterations`; each substep
    /// is one implicit-Euler elastic step of length h/substeps). Default rapier's (4).
    pub substeps: usize,
    /// Extra substeps rapier may add while a soft body is hit fast
    /// (`SoftBodiesSettings::max_extra_substeps`). Default rapier's (4).
    pub max_extra_substeps: usize,
    /// Cap on the conjugate-gradient iterations of each substep's elastic solve
    /// (`SoftFemParameters::max_linear_iterations`). Default rapier's (20).
    pub cg_iterations: usize,
    /// Relative residual at which that conjugate gradient stops. Default rapier's (1e-5).
    pub cg_tolerance: f64,
    /// Bodies up to this many degrees of freedom get a direct factorization for their contact
    /// responses (`SoftFemParameters::max_dense_dofs`). Default rapier's (600).
    pub max_dense_dofs: usize,
    /// Contact skin of the soft surfaces (m). Default 1e-4.
    pub particle_radius: f64,
    /// Ensemble member and distance (m): member m > 0 starts the projectiles (bodies with a
    /// non-zero initial velocity) `distance` away across gravity, in the direction
    /// `dcr_scenes::scene::BuiltWorld::perturb_placement` gives that member. Default `(0, 0.0)`:
    /// the scene as written.
    pub perturbation: (usize, f64),
    /// Progress lines on stderr every 5 s.
    pub progress: bool,
}

impl SoftSceneParams {
    /// rapier's defaults for the scene at `root`.
    pub fn new(root: PathBuf) -> SoftSceneParams {
        let ip = IntegrationParameters::default();
        let fem = SoftFemParameters::default();
        SoftSceneParams {
            root,
            seconds: None,
            substeps: ip.num_solver_iterations,
            max_extra_substeps: ip.soft_bodies.max_extra_substeps,
            cg_iterations: fem.max_linear_iterations,
            cg_tolerance: fem.linear_tolerance,
            max_dense_dofs: fem.max_dense_dofs,
            particle_radius: TetSoftBodyDesc::default().particle_radius,
            perturbation: (0, 0.0),
            progress: false,
        }
    }
}

/// One soft elastic object of a run.
#[derive(Clone, Debug, Serialize)]
pub struct SoftObjectInfo {
    /// The elastic object's name.
    pub name: String,
    /// Particles (the mesh's corner nodes) and tetrahedra.
    pub particles: usize,
    /// Tetrahedra.
    pub cells: usize,
    /// Pinned particles.
    pub pinned: usize,
    /// Mass (kg).
    pub mass: f64,
    /// The elastic damping ratio given to rapier, and the per-cell β (s) it gives: smallest,
    /// median, largest.
    pub damping_ratio: f64,
    /// β range (s).
    pub beta_range: [f64; 3],
}

/// What a soft-body run measured.
#[derive(Clone, Debug, Serialize)]
pub struct SoftRunReport {
    /// Scene name.
    pub scene: String,
    /// Steps and step h (s).
    pub steps: usize,
    /// h (s).
    pub h: f64,
    /// Settings: substeps per step.
    pub substeps: usize,
    /// Extra substeps allowed on fast hits.
    pub max_extra_substeps: usize,
    /// CG cap per substep.
    pub cg_iterations: usize,
    /// CG tolerance.
    pub cg_tolerance: f64,
    /// Direct-factorization limit (dofs).
    pub max_dense_dofs: usize,
    /// Contact skin (m).
    pub particle_radius: f64,
    /// The soft objects.
    pub objects: Vec<SoftObjectInfo>,
    /// Outcome figures: name → (value, unit), as `dcr-scenes run` measures them.
    pub outcomes: BTreeMap<String, (f64, String)>,
    /// Per body whose name an outcome matches: the largest displacement (mm) of the soft
    /// surface particle nearest to its start position, over the run.
    pub surface_peak_mm: BTreeMap<String, f64>,
    /// Wall time of each `PhysicsWorld::step` (ms).
    #[serde(skip)]
    pub step_ms: Vec<f64>,
    /// The recorded trajectory (props), for the outcome code and hashes.
    #[serde(skip)]
    pub trajectory: Trajectory,
    /// `sha256:` of the trajectory.
    pub trajectory_hash: String,
}

/// Runs `desc` with every elastic object a rapier FEM soft body (see
/// [`tet_soft_body()`](fn@super::tet_soft_body)): the world `dcr_scenes::scene::build_world` builds, the rigid
/// bodies of the elastic objects (and their proxy colliders) replaced by their tetrahedral
/// meshes, pinned at their fixed nodes (`fixed`, `fixed_below`, `fixed_boxes`), with the scene's material and Rayleigh damping;
/// the projectiles moved as `params.perturbation` says.
///
/// # Errors
/// A dynamic elastic object (only static ones, pinned in place, are supported), a scene with
/// scripted drivers, or a mesh the soft-body builder refuses.
pub fn run_soft_scene(desc: &SceneDesc, params: &SoftSceneParams) -> Result<SoftRunReport> {
    if !desc.drivers.is_empty() {
        bail!(
            "scene {}: scripted drivers are not supported by the soft-body run (scenes without \
             drivers: dinner, roof, scaffold, rockfall)",
            desc.name
        );
    }
    if params.substeps == 0 {
        bail!("substeps must be at least 1");
    }
    let seconds = params.seconds.unwrap_or(desc.seconds);
    let steps = (seconds / desc.h).round() as usize;
    let mut built = build_world(desc, &params.root)?;
    built.perturb_placement(params.perturbation.0, params.perturbation.1);
    {
        let ip = &mut built.world.integration_parameters;
        ip.num_solver_iterations = params.substeps;
        ip.soft_bodies.max_extra_substeps = params.max_extra_substeps;
        ip.soft_bodies.fem.max_linear_iterations = params.cg_iterations;
        ip.soft_bodies.fem.linear_tolerance = params.cg_tolerance;
        ip.soft_bodies.fem.max_dense_dofs = params.max_dense_dofs;
    }

    let mut objects = Vec::new();
    let mut soft = Vec::new();
    for (i, e) in desc.elastic.iter().enumerate() {
        if let BodyKind::Dynamic { .. } = e.body {
            bail!(
                "scene {}: elastic object {} is dynamic; the soft-body run pins objects in place \
                 (static objects only)",
                desc.name,
                e.name
            );
        }
        let body = built.bodies[built.elastic_body[i]].handle;
        built.world.remove_body(body);
        let sb_desc = TetSoftBodyDesc {
            youngs: e.material.youngs,
            poisson: e.material.poisson,
            density: e.material.density,
            rayleigh: e.rayleigh,
            fixed: e.fixed.clone(),
            fixed_below: e.fixed_below(),
            fixed_boxes: e.fixed_boxes.clone(),
            pose: pose_from_desc(&e.pose),
            particle_radius: params.particle_radius,
            friction: e.friction,
            restitution: desc.restitution,
        };
        let sb = tet_soft_body_from_file(&params.root.join(&e.mesh), &sb_desc)
            .with_context(|| format!("elastic object {}", e.name))?;
        objects.push(SoftObjectInfo {
            name: e.name.clone(),
            particles: sb.particle_node.len(),
            cells: sb.builder.cells.len(),
            pinned: sb.pinned.len(),
            mass: sb.mass,
            damping_ratio: sb.damping_ratio,
            beta_range: sb.beta_range,
        });
        soft.push(built.world.insert_soft_body(sb.builder));
    }

    // Recording: the dynamic bodies, as `dcr-scenes run` records them.
    let rec: Vec<usize> = (0..built.bodies.len())
        .filter(|&i| built.bodies[i].dynamic && built.bodies[i].elastic.is_none())
        .collect();
    let mut traj = Trajectory {
        names: rec.iter().map(|&i| built.bodies[i].name.clone()).collect(),
        ..Default::default()
    };
    let record = |world: &PhysicsWorld, traj: &mut Trajectory, t: f64| {
        traj.time.push(t);
        for &i in &rec {
            let p = world.bodies[built.bodies[i].handle].position();
            traj.positions
                .extend([p.translation.x, p.translation.y, p.translation.z]);
            traj.rotations
                .extend([p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w]);
        }
    };

    // The soft surface particle under each body an outcome names.
    let watched: Vec<(String, usize, usize, rapier3d_f64::math::Vector)> = rec
        .iter()
        .filter(|&&i| {
            desc.outcomes
                .iter()
                .any(|o| dcr_scenes::scene::name_matches(&o.bodies, &built.bodies[i].name))
        })
        .filter_map(|&i| {
            let c = built.world.bodies[built.bodies[i].handle].translation();
            soft.iter()
                .enumerate()
                .flat_map(|(s, &h)| {
                    built.world.soft_bodies[h]
                        .particle_positions()
                        .enumerate()
                        .map(move |(p, x)| (s, p, x))
                        .collect::<Vec<_>>()
                })
                .min_by(|a, b| (a.2 - c).length().total_cmp(&(b.2 - c).length()))
                .map(|(s, p, x)| (built.bodies[i].name.clone(), s, p, x))
        })
        .collect();
    let mut surface_peak_mm: BTreeMap<String, f64> =
        watched.iter().map(|w| (w.0.clone(), 0.0)).collect();

    record(&built.world, &mut traj, 0.0);
    let mut step_ms = Vec::with_capacity(steps);
    let wall = Instant::now();
    let mut last_progress = Instant::now();
    for k in 0..steps {
        let t0 = Instant::now();
        built.world.step();
        step_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        record(&built.world, &mut traj, (k + 1) as f64 * desc.h);
        for (name, s, p, x0) in &watched {
            let x = built.world.soft_bodies[soft[*s]].particle_position(*p);
            let d = (x - *x0).length() * 1e3;
            let e = surface_peak_mm.entry(name.clone()).or_default();
            *e = e.max(d);
        }
        if params.progress && last_progress.elapsed().as_secs_f64() > 5.0 {
            last_progress = Instant::now();
            eprintln!(
                "[dcr-lab] {} soft ({} substeps, member {}) step {}/{} ({:.1} s wall)",
                desc.name,
                params.substeps,
                params.perturbation.0,
                k + 1,
                steps,
                wall.elapsed().as_secs_f64()
            );
        }
    }
    for h in &soft {
        let sb = &built.world.soft_bodies[*h];
        if sb.particle_positions().any(|p| !p.is_finite()) {
            bail!(
                "scene {}: the soft body blew up (non-finite particle positions); more substeps \
                 or CG iterations may hold it",
                desc.name
            );
        }
    }
    let mut outcomes = BTreeMap::new();
    for o in &desc.outcomes {
        if let Some(v) = measure_outcome(o, &traj) {
            outcomes.insert(o.name.clone(), (v, unit_of(&o.kind).to_string()));
        }
    }
    Ok(SoftRunReport {
        scene: desc.name.clone(),
        steps,
        h: desc.h,
        substeps: params.substeps,
        max_extra_substeps: params.max_extra_substeps,
        cg_iterations: params.cg_iterations,
        cg_tolerance: params.cg_tolerance,
        max_dense_dofs: params.max_dense_dofs,
        particle_radius: params.particle_radius,
        objects,
        outcomes,
        surface_peak_mm,
        step_ms,
        trajectory_hash: traj.hash(),
        trajectory: traj,
    })
}
