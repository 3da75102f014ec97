//! Dinner is served, in a headless Bevy app with bevy_rapier3d and [`DcrPlugin`]: a 5 kg pot
//! is dropped on a table laid with six plates (paper Fig. 1); the table entity carries the
//! modal base baked from `data/scenes/table.msh` (into `out/bases/table.modes` when missing or
//! stale), loaded through the `.modes` asset loader. The scene runs with the plugin and without
//! it, and prints one JSON object on stdout:
//!
//! ```text
//! {"lift_on_mm": 7.1, "lift_off_mm": 0.0, "events_on": 12, ...}
//! ```
//!
//! `lift_*_mm` is the largest rise of a plate's centre above its start (mm). Progress goes to
//! stderr. Run: `cargo run --release -p dcr-bevy --example dinner`; in a window (bevy's
//! renderer and bevy_rapier's debug lines): `cargo run --release -p dcr-bevy --features window
//! --example dinner -- --window`.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use bevy::asset::{AssetPlugin, LoadState};
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_rapier3d::prelude::*;
use dcr_bevy::dcr_rapier::f32::AdapterParams;
use dcr_bevy::dcr_rapier::{ResponseParams, WorldParams};
use dcr_bevy::{DcrElastic, DcrPlugin, DcrResponse, DcrSet, DcrStatus, ModesAsset};
use modal_bake::bake::{bake_file, is_up_to_date, BakeParams, MaterialSi, ModeRequest};

/// Rigid-body step and fixed-update period (s).
pub const H: f64 = 0.01;

/// The plates' starting positions (m, world; y up): around the middle of the table top.
pub const PLATES: [(f32, f32); 6] = [
    (-0.6, -0.25),
    (-0.6, 0.25),
    (0.6, -0.25),
    (0.6, 0.25),
    (-0.25, -0.3),
    (0.3, 0.3),
];

/// Height of the plates' centres at rest (m): table top at 0.75 m + the plate's half height.
pub const PLATE_Y: f32 = 0.758;

/// Mass of one plate (kg).
pub const PLATE_MASS: f32 = 0.5;

/// How a run is set up.
#[derive(Clone, Copy, Debug)]
pub struct DinnerOptions {
    /// Add [`DcrPlugin`] (the table is elastic) or not (plain bevy_rapier).
    pub response: bool,
    /// Give the plates a `Velocity` component (bevy_rapier then writes their velocity back
    /// every step and applies the component's changes before the next one).
    pub plate_velocity: bool,
    /// Fixed updates to run.
    pub steps: u32,
}

/// What one run measured.
#[derive(Clone, Debug, Default)]
pub struct DinnerOutcome {
    /// Largest rise of a plate's centre above its start (mm).
    pub lift_mm: f64,
    /// [`DcrResponse`] messages received (all bodies).
    pub events: u64,
    /// Of which on plates.
    pub plate_events: u64,
    /// Every [`DcrResponse`] message, in the order received.
    pub messages: Vec<DcrResponse>,
    /// The plugin's status at the end (`None` without the plugin).
    pub status: Option<DcrStatus>,
    /// Per event step and plate: the plate's linear velocity (m/s, world) just after rapier's
    /// step, its `Velocity` component after bevy_rapier's writeback, rapier's velocity after
    /// the writeback, and the sum of the step's response impulses on it (N·s, world).
    pub velocity_checks: Vec<VelocityCheck>,
}

/// One plate's velocities around one step with response impulses on it.
#[derive(Clone, Copy, Debug)]
pub struct VelocityCheck {
    /// Linear velocity after rapier's step, before the response (m/s, world).
    pub after_step: Vec3,
    /// The `Velocity` component after bevy_rapier's writeback (m/s, world; `None` without one).
    pub component: Option<Vec3>,
    /// rapier's linear velocity after the writeback (m/s, world).
    pub rapier: Vec3,
    /// Sum of the step's response impulses on the plate (N·s, world).
    pub impulse: Vec3,
}

/// Marks a plate.
#[derive(Component)]
pub struct Plate;

/// Test-side records, filled by [`record_before_response`] and [`record_after_writeback`].
#[derive(Resource, Default)]
struct Records {
    /// Each plate's rapier velocity right after the step (before the response).
    after_step: Vec<(Entity, Vec3)>,
    outcome: DinnerOutcome,
}

/// The repository root (`$DCR_ROOT`, else the workspace this example was built in).
pub fn repo_root() -> PathBuf {
    let root = std::env::var_os("DCR_ROOT")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."));
    root.canonicalize().unwrap_or(root)
}

/// The table's bake parameters (the paper's Table 2: E = 1.1 GPa, ν = 0.3, ρ = 770 kg/m³; 20
/// modes; feet fixed; Rayleigh α0 = 10 1/s, α1 = 1e-7 s), those of `scenes/dinner.json`.
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

/// The table's base `table.modes` in `bases_dir`, baked from `data/scenes/table.msh` unless an
/// up-to-date one is there. Returns whether it baked.
pub fn table_base(bases_dir: &Path) -> Result<bool, Box<dyn std::error::Error>> {
    let mesh = repo_root().join("data/scenes/table.msh");
    let out = bases_dir.join("table.modes");
    let params = table_params();
    std::fs::create_dir_all(bases_dir)?;
    if is_up_to_date(&mesh, &params, &out)? {
        return Ok(false);
    }
    eprintln!("[dinner] baking {} -> {}", mesh.display(), out.display());
    let t = Instant::now();
    bake_file(&mesh, &params, &out, &mut |_| {})?;
    eprintln!("[dinner] baked in {:.1} s", t.elapsed().as_secs_f64());
    Ok(true)
}

/// The plugin for the dinner table: world step [`H`], the adapter's defaults.
pub fn dinner_plugin() -> DcrPlugin {
    let world = WorldParams {
        h: H,
        ..WorldParams::default()
    };
    match DcrPlugin::new(world, AdapterParams::default()) {
        Ok(p) => p,
        Err(e) => unreachable!("the dinner's parameters are valid: {e}"),
    }
}

/// The table's response parameters: impacts from 0.5 N·s, contacts mapped within 0.1 m.
pub fn table_response() -> ResponseParams {
    ResponseParams {
        impact_threshold: 0.5,
        max_map_distance: 0.1,
        ..ResponseParams::default()
    }
}

/// A collider's contact material (friction, restitution 0.15 as in `scenes/dinner.json`).
fn material(friction: f32) -> (Friction, Restitution) {
    (
        Friction::coefficient(friction),
        Restitution::coefficient(0.15),
    )
}

/// Spawns the table (with `base` as its [`DcrElastic`] when given), the plates and the pot.
pub fn spawn_dinner(world: &mut World, base: Option<Handle<ModesAsset>>, plate_velocity: bool) {
    let mut table = world.spawn((RigidBody::Fixed, Transform::IDENTITY));
    if let Some(base) = base {
        let mut elastic = DcrElastic::new(base);
        elastic.response = table_response();
        table.insert(elastic);
    }
    // The table in the mesh's frame (y up): its top and four legs.
    table.with_children(|c| {
        c.spawn((
            Collider::cuboid(0.8, 0.02, 0.45),
            Transform::from_xyz(0.0, 0.73, 0.0),
            material(0.5),
        ));
        for (x, z) in [(-0.7, -0.35), (0.7, -0.35), (-0.7, 0.35), (0.7, 0.35)] {
            c.spawn((
                Collider::cuboid(0.03, 0.355, 0.03),
                Transform::from_xyz(x, 0.355, z),
                material(0.5),
            ));
        }
    });
    for (x, z) in PLATES {
        let mut plate = world.spawn((
            Plate,
            RigidBody::Dynamic,
            Transform::from_xyz(x, PLATE_Y, z),
            Collider::cylinder(0.008, 0.11),
            ColliderMassProperties::Mass(PLATE_MASS),
            material(0.6),
        ));
        if plate_velocity {
            plate.insert(Velocity::zero());
        }
    }
    // The pot, falling on the bare table between the plates.
    world.spawn((
        RigidBody::Dynamic,
        Transform::from_xyz(0.05, 1.25, 0.0),
        Velocity::linear(Vec3::new(0.0, -1.0, 0.0)),
        Ccd::enabled(),
        Collider::cylinder(0.1, 0.13),
        ColliderMassProperties::Mass(5.0),
        material(0.6),
    ));
}

/// Each plate's rapier velocity right after the step, before the response is applied.
fn record_before_response(
    plates: Query<(Entity, &RapierRigidBodyHandle), With<Plate>>,
    context: ReadRapierContext,
    mut records: ResMut<Records>,
) {
    let Ok(ctx) = context.single() else { return };
    records.after_step.clear();
    for (e, h) in &plates {
        if let Some(rb) = ctx.rigidbody_set.bodies.get(h.0) {
            records.after_step.push((e, rb.linvel()));
        }
    }
}

/// After bevy_rapier's writeback: the plates' lift, the step's messages and, for each plate
/// that received impulses, its velocities.
#[allow(clippy::type_complexity)]
fn record_after_writeback(
    plates: Query<
        (
            Entity,
            &Transform,
            Option<&Velocity>,
            &RapierRigidBodyHandle,
        ),
        With<Plate>,
    >,
    context: ReadRapierContext,
    mut messages: MessageReader<DcrResponse>,
    mut records: ResMut<Records>,
) {
    let Ok(ctx) = context.single() else { return };
    let records = &mut *records;
    let events: Vec<DcrResponse> = messages.read().copied().collect();
    records.outcome.events += events.len() as u64;
    records.outcome.messages.extend(events.iter().copied());
    for (e, transform, velocity, h) in &plates {
        let lift = f64::from(transform.translation.y - PLATE_Y) * 1e3;
        records.outcome.lift_mm = records.outcome.lift_mm.max(lift);
        let mine: Vec<&DcrResponse> = events.iter().filter(|m| m.body == e).collect();
        if mine.is_empty() {
            continue;
        }
        records.outcome.plate_events += mine.len() as u64;
        let impulse = mine.iter().map(|m| m.impulse).sum::<Vec3>();
        let after_step = records
            .after_step
            .iter()
            .find(|(p, _)| *p == e)
            .map_or(Vec3::NAN, |&(_, v)| v);
        let rapier = ctx
            .rigidbody_set
            .bodies
            .get(h.0)
            .map_or(Vec3::NAN, |rb| rb.linvel());
        records.outcome.velocity_checks.push(VelocityCheck {
            after_step,
            component: velocity.map(|v| v.linear),
            rapier,
            impulse,
        });
    }
}

/// A headless app: bevy's minimal plugins, assets from `assets_dir`, bevy_rapier in
/// `FixedUpdate` with one step of [`H`] per update, and [`DcrPlugin`] when `response`.
pub fn headless_app(assets_dir: &Path, response: bool) -> App {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        TransformPlugin,
        AssetPlugin {
            file_path: assets_dir.display().to_string(),
            ..AssetPlugin::default()
        },
        RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule(),
    ));
    if response {
        app.add_plugins(dinner_plugin());
    } else {
        // The same rapier stepping as the plugin sets up.
        app.insert_resource(TimestepMode::Fixed {
            dt: H as f32,
            substeps: 1,
        })
        .insert_resource(Time::<Fixed>::from_seconds(H))
        .add_message::<DcrResponse>();
    }
    // Each update advances time by one fixed step: one rapier step per update.
    app.insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    app
}

/// Updates `app` until `handle` has loaded (the physics world is still empty).
///
/// # Errors
/// The asset failed to load, or did not load within 60 s.
pub fn wait_for_base(app: &mut App, handle: &Handle<ModesAsset>) -> Result<(), String> {
    let start = Instant::now();
    loop {
        app.update();
        match app.world().resource::<AssetServer>().load_state(handle) {
            LoadState::Loaded => return Ok(()),
            LoadState::Failed(e) => return Err(format!("the table's base did not load: {e}")),
            _ if start.elapsed() > Duration::from_secs(60) => {
                return Err("the table's base did not load within 60 s".into())
            }
            _ => std::thread::sleep(Duration::from_millis(1)),
        }
    }
}

/// Runs the dinner scene headless; the base is `table.modes` in `bases_dir`.
///
/// # Errors
/// The base did not load.
pub fn run(bases_dir: &Path, opts: DinnerOptions) -> Result<DinnerOutcome, String> {
    let mut app = headless_app(bases_dir, opts.response);
    app.init_resource::<Records>().add_systems(
        FixedUpdate,
        (
            record_before_response
                .after(PhysicsSet::StepSimulation)
                .before(DcrSet::AfterStep),
            record_after_writeback.after(PhysicsSet::Writeback),
        ),
    );
    let base = if opts.response {
        let handle = app
            .world()
            .resource::<AssetServer>()
            .load::<ModesAsset>("table.modes");
        wait_for_base(&mut app, &handle)?;
        Some(handle)
    } else {
        None
    };
    spawn_dinner(app.world_mut(), base, opts.plate_velocity);
    for _ in 0..opts.steps {
        app.update();
    }
    let mut outcome = std::mem::take(&mut app.world_mut().resource_mut::<Records>().outcome);
    outcome.status = app.world().get_resource::<DcrStatus>().cloned();
    Ok(outcome)
}

#[cfg(feature = "window")]
fn run_window(bases_dir: &Path) {
    let mut app = App::new();
    app.add_plugins((
        DefaultPlugins.set(AssetPlugin {
            file_path: bases_dir.display().to_string(),
            ..AssetPlugin::default()
        }),
        RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule(),
        RapierDebugRenderPlugin::default(),
        dinner_plugin(),
    ));
    app.add_systems(
        Startup,
        |mut commands: Commands, assets: Res<AssetServer>| {
            commands.spawn((
                Camera3d::default(),
                Transform::from_xyz(1.6, 1.7, 2.2).looking_at(Vec3::new(0.0, 0.7, 0.0), Vec3::Y),
            ));
            commands.spawn((
                DirectionalLight::default(),
                Transform::from_xyz(2.0, 4.0, 1.0).looking_at(Vec3::ZERO, Vec3::Y),
            ));
            let base = assets.load::<ModesAsset>("table.modes");
            commands.queue(move |world: &mut World| spawn_dinner(world, Some(base), false));
        },
    );
    app.add_systems(Update, |mut messages: MessageReader<DcrResponse>| {
        for m in messages.read() {
            eprintln!(
                "[dinner] response on {}: {:.4} N·s up, Δv {:.3} m/s",
                m.body, m.impulse.y, m.delta_v
            );
        }
    });
    app.run();
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bases = repo_root().join("out/bases");
    let baked = table_base(&bases)?;
    if std::env::args().any(|a| a == "--window") {
        #[cfg(feature = "window")]
        {
            run_window(&bases);
            return Ok(());
        }
        #[cfg(not(feature = "window"))]
        return Err(
            "--window needs the `window` feature: cargo run --release -p dcr-bevy \
                    --features window --example dinner -- --window"
                .into(),
        );
    }
    let steps = 150;
    eprintln!("[dinner] with DcrPlugin");
    let on = run(
        &bases,
        DinnerOptions {
            response: true,
            plate_velocity: false,
            steps,
        },
    )?;
    eprintln!("[dinner] without");
    let off = run(
        &bases,
        DinnerOptions {
            response: false,
            plate_velocity: false,
            steps,
        },
    )?;
    let status = on.status.unwrap_or_default();
    let json = serde_json::json!({
        "engine": "bevy_rapier3d 0.37 (rapier3d 0.36, f32)",
        "h_s": H,
        "steps": steps,
        "lift_on_mm": on.lift_mm,
        "lift_off_mm": off.lift_mm,
        "events_on": on.events,
        "plate_events_on": on.plate_events,
        "dcr_steps": status.steps,
        "refused_steps": status.refused_steps,
        "base": bases.join("table.modes").display().to_string(),
        "baked": baked,
    });
    println!("{json}");
    Ok(())
}
