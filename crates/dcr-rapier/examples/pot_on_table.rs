//! Dinner is served, in a plain rapier3d (f32) app: a 5 kg pot is dropped on a table laid
//! with six plates; the table carries a modal base baked from `data/scenes/table.msh` (baked
//! into `out/bases/table.modes` if missing or stale). The scene runs twice, with the distant
//! collision response on and off, and prints one JSON object on stdout:
//!
//! ```text
//! {"backend": "rapier3d (f32)", "lift_on_mm": 7.1, "lift_off_mm": 0.0, "impacts": 4, ...}
//! ```
//!
//! `lift_*_mm` is the largest rise of a plate's centre above its start (mm). Progress goes to
//! stderr. Run: `cargo run --release -p dcr-rapier --example pot_on_table`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use dcr_rapier::f32::rapier::prelude::*;
use dcr_rapier::f32::{body_id, AdapterParams, ApplyMode, DcrRapier, StepGate};
use dcr_rapier::{ElasticObjectDesc, ModalModel, ResponseParams, WorldParams};
use modal_bake::bake::{bake_file, is_up_to_date, BakeParams, MaterialSi, ModeRequest};

/// Rigid-body step (s).
const H: f64 = 0.01;

/// What one run measured.
#[derive(Clone, Copy, Debug)]
pub struct RunOutcome {
    /// Largest rise of a plate's centre above its start (mm).
    pub lift_mm: f64,
    /// Impacts on the table.
    pub impacts: u32,
    /// Response impulses issued.
    pub events: u32,
}

/// The repository root (`$DCR_ROOT`, else the workspace this example was built in).
pub fn repo_root() -> PathBuf {
    let root = std::env::var_os("DCR_ROOT")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."));
    root.canonicalize().unwrap_or(root)
}

/// The table's bake parameters (the paper's Table 2: E = 1.1 GPa, ν = 0.3, ρ = 770 kg/m³; 20
/// modes; feet fixed; Rayleigh α0 = 10 1/s, α1 = 1e-7 s), the same as `scenes/dinner.json`.
fn table_params() -> BakeParams {
    BakeParams {
        material: MaterialSi {
            youngs: 1.1e9,
            poisson: 0.3,
            density: 770.0,
        },
        modes: ModeRequest::Count(20),
        fixed: vec!["feet".into()],
        rayleigh: [10.0, 1e-7],
        ..BakeParams::default()
    }
}

/// The table's base in `bases_dir`, baked from `data/scenes/table.msh` unless an up-to-date
/// one is there. Returns the path and whether it baked.
pub fn table_base(bases_dir: &Path) -> Result<(PathBuf, bool), Box<dyn std::error::Error>> {
    let mesh = repo_root().join("data/scenes/table.msh");
    let out = bases_dir.join("table.modes");
    let params = table_params();
    std::fs::create_dir_all(bases_dir)?;
    if is_up_to_date(&mesh, &params, &out)? {
        return Ok((out, false));
    }
    eprintln!(
        "[pot_on_table] baking {} -> {}",
        mesh.display(),
        out.display()
    );
    let t = std::time::Instant::now();
    bake_file(&mesh, &params, &out, &mut |_| {})?;
    eprintln!("[pot_on_table] baked in {:.1} s", t.elapsed().as_secs_f64());
    Ok((out, true))
}

/// Runs the scene for 1.5 s with the response on or off (`model`: the table's base).
pub fn run(model: &Arc<ModalModel>, on: bool) -> Result<RunOutcome, Box<dyn std::error::Error>> {
    let mut world = PhysicsWorld::default();
    world.integration_parameters.dt = H as f32;
    // The table: a static body in the mesh's frame (y up), its top and four legs as boxes.
    let table = world.insert_body(RigidBodyBuilder::fixed());
    let top = ColliderBuilder::cuboid(0.8, 0.02, 0.45).translation(Vector::new(0.0, 0.73, 0.0));
    world.insert_collider(top.friction(0.5).restitution(0.15), Some(table));
    for (x, z) in [(-0.7, -0.35), (0.7, -0.35), (-0.7, 0.35), (0.7, 0.35)] {
        let leg = ColliderBuilder::cuboid(0.03, 0.355, 0.03).translation(Vector::new(x, 0.355, z));
        world.insert_collider(leg.friction(0.5).restitution(0.15), Some(table));
    }
    // Six plates around the middle, and the pot falling on the bare table between them.
    let mut plates = Vec::new();
    for (x, z) in [
        (-0.6, -0.25),
        (-0.6, 0.25),
        (0.6, -0.25),
        (0.6, 0.25),
        (-0.25, -0.3),
        (0.3, 0.3),
    ] {
        let b =
            world.insert_body(RigidBodyBuilder::dynamic().translation(Vector::new(x, 0.758, z)));
        let plate = ColliderBuilder::cylinder(0.008, 0.11).mass(0.5);
        world.insert_collider(plate.friction(0.6).restitution(0.15), Some(b));
        plates.push(b);
    }
    let pot = RigidBodyBuilder::dynamic()
        .translation(Vector::new(0.05, 1.25, 0.0))
        .linvel(Vector::new(0.0, -1.0, 0.0))
        .ccd_enabled(true);
    let pot = world.insert_body(pot);
    let pot_shape = ColliderBuilder::cylinder(0.1, 0.13).mass(5.0);
    world.insert_collider(pot_shape.friction(0.6).restitution(0.15), Some(pot));

    // The response: the table as a static elastic object (object frame = the table body's).
    let apply = if on {
        ApplyMode::AfterStep
    } else {
        ApplyMode::MeasureOnly
    };
    let mut dcr = DcrRapier::new(
        WorldParams {
            h: H,
            ..WorldParams::default()
        },
        AdapterParams {
            apply,
            gate: StepGate::ImpactSteps,
            ..AdapterParams::default()
        },
    )?;
    let mut desc = ElasticObjectDesc::new(model.clone(), 0);
    desc.response = ResponseParams {
        impact_threshold: 0.5,
        max_map_distance: 0.1,
        ..ResponseParams::default()
    };
    let handle = dcr.add_object(&world.bodies, &mut world.colliders, table, desc)?;

    let y0: Vec<f64> = plates
        .iter()
        .map(|&p| f64::from(world.bodies[p].translation().y))
        .collect();
    let plate_ids: Vec<u64> = plates.iter().map(|&p| body_id(p)).collect();
    let mut out = RunOutcome {
        lift_mm: 0.0,
        impacts: 0,
        events: 0,
    };
    for _ in 0..150 {
        let events = dcr.step(&mut world);
        out.events += events
            .iter()
            .filter(|e| plate_ids.contains(&e.body))
            .count() as u32;
        for (i, &p) in plates.iter().enumerate() {
            let lift = (f64::from(world.bodies[p].translation().y) - y0[i]) * 1e3;
            out.lift_mm = out.lift_mm.max(lift);
        }
    }
    out.impacts = dcr.world().object_totals(handle).impacts as u32;
    Ok(out)
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bases = repo_root().join("out/bases");
    let (path, baked) = table_base(&bases)?;
    let model = ModalModel::load(&path)?;
    eprintln!("[pot_on_table] response on");
    let on = run(&model, true)?;
    eprintln!("[pot_on_table] response off");
    let off = run(&model, false)?;
    println!(
        "{{\"backend\": \"rapier3d (f32)\", \"lift_on_mm\": {:.4}, \"lift_off_mm\": {:.4}, \
         \"impacts_on\": {}, \"impacts_off\": {}, \"plate_events_on\": {}, \"base\": {:?}, \
         \"baked\": {}}}",
        on.lift_mm,
        off.lift_mm,
        on.impacts,
        off.impacts,
        on.events,
        path.display().to_string(),
        baked
    );
    Ok(())
}
