//! [`run_scene`]: one headless run of a scene, response on or off.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use dcr_rapier::f64::{body_handle, AdapterParams, ApplyMode, DcrRapier, StepGate};
use dcr_rapier::{ElasticHandle, ElasticObjectDesc, WorldParams};
use dcr_runtime::format::ModesFile;
use dcr_runtime::response::{
    AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind, ServedBy, TableFallback,
    TablePolicy,
};
use dcr_runtime::{Launch, Method, ModalModel, ResponseParams};
use ndarray::{Array1, Array2};
use ndarray_npy::NpzWriter;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::RigidBodyHandle;
use serde::Serialize;

use crate::runner::bases::{ensure_base, ensure_transfer_base};
use crate::runner::outcomes::{measure_outcome, unit_of};
use crate::runner::Trajectory;
use crate::scene::{
    build_world, BuiltWorld, DriverDesc, ElasticDesc, MethodDesc, SceneDesc, TransferDesc,
};

/// Which response method a run uses.
#[derive(Clone, Debug, PartialEq)]
pub enum MethodChoice {
    /// Each elastic object's own `method` from the scene file.
    Scene,
    /// Modal for every object.
    Modal,
    /// Spatial attenuation for every object (the object's `attenuation` settings, or its
    /// `method` if that is attenuation, or C = 1, β = 1, heat distances).
    Attenuation,
    /// Spatial attenuation with this β (the object's other settings kept).
    AttenuationBeta(f64),
    /// The bake-time peak-transfer table for every object (its `method` if that is
    /// `transfer`, else its `transfer` settings; an object with neither is refused).
    Transfer,
}

/// Settings of one run.
#[derive(Clone, Debug)]
pub struct RunParams {
    /// Simulated time (s); None: the scene's `seconds`.
    pub seconds: Option<f64>,
    /// Response on?
    pub dcr: bool,
    /// Method.
    pub method: MethodChoice,
    /// Scale on every elastic object's response Δv, replacing the objects' own `gain`
    /// (`None`: each object's `gain`).
    pub gain: Option<f64>,
    /// Repository root (mesh paths are relative to it).
    pub root: PathBuf,
    /// Where bases are baked/read.
    pub bases_dir: PathBuf,
    /// Output directory (None: write nothing).
    pub out_dir: Option<PathBuf>,
    /// Progress lines on stderr.
    pub progress: bool,
    /// How the responses reach the bodies (when `dcr` is on). Default after the step.
    pub apply: ApplyMode,
    /// Energy bound η ∈ [0, 1] of the world ([`WorldParams::energy_eta`]); `None`: no bound.
    pub energy_eta: Option<f64>,
    /// The lateral kick (paper §5.4) on every elastic object.
    pub lateral_kick: bool,
    /// How every elastic object's resting contacts are launched ([`Launch`]; not
    /// [`Launch::PeakOverStep`] turns the objects' carry-over on). Default the paper's rule.
    pub launch: Launch,
    /// rapier's contact recycling on the elastic objects' colliders
    /// ([`AdapterParams::contact_recycling`]; always off in the solver path).
    pub contact_recycling: bool,
    /// On which steps the contacts are read ([`AdapterParams::gate`]). Default
    /// [`StepGate::ImpactSteps`].
    pub gate: StepGate,
    /// Ensemble member and placement distance (m): the launched bodies start moved as
    /// [`crate::scene::BuiltWorld::perturb_placement`] says. Default `(0, 0.0)`: the scene as written.
    pub perturbation: (usize, f64),
    /// The work a missing or stale base may take to bake (the mesh's modes, a table's mode set
    /// and the table itself, each estimated before it starts); over it the run is refused with
    /// the estimate. `None`: no limit. Default `modal_bake::bake::Budget::default()` (5
    /// minutes, 2 GB), as `modal-bake bake`.
    pub bake_budget: Option<modal_bake::bake::Budget>,
}

impl RunParams {
    /// Settings for a run of the scene at `root` with the response on or off, bases in
    /// `out/bases`, nothing written, no progress, the world's default energy bound, responses
    /// applied after the step, no lateral kick.
    pub fn new(root: PathBuf, dcr: bool) -> RunParams {
        RunParams {
            seconds: None,
            dcr,
            method: MethodChoice::Scene,
            gain: None,
            bases_dir: root.join("out").join("bases"),
            root,
            out_dir: None,
            progress: false,
            apply: ApplyMode::AfterStep,
            energy_eta: WorldParams::default().energy_eta,
            lateral_kick: false,
            launch: Launch::PeakOverStep,
            contact_recycling: true,
            gate: StepGate::ImpactSteps,
            perturbation: (0, 0.0),
            bake_budget: Some(modal_bake::bake::Budget::default()),
        }
    }
}

/// What one elastic object saw and did over a run (from the world's per-step counters).
#[derive(Clone, Debug, Default, Serialize)]
pub struct ModelStats {
    /// Model (elastic object) name.
    pub name: String,
    /// Wall time (µs) of the object's response call on each step it ran (the world's
    /// `ObjectStepInfo::response_time_ns`).
    #[serde(skip)]
    pub query_us: Vec<f64>,
    /// Resting contacts at each of those steps.
    #[serde(skip)]
    pub query_resting: Vec<usize>,
    /// Impacts over the run.
    pub impacts: usize,
    /// Impacts that came from another model's responses (a dynamic elastic object).
    pub chained_impacts: usize,
    /// Impulse events issued (applied, replayed or only measured by the run's mode).
    pub responses_applied: usize,
    /// Largest Δv of an event (m/s, after gain, Gauss–Seidel and energy bound).
    pub max_delta_v: f64,
    /// Kinetic energy the responses gave the receiving bodies (J, the world's account; 0 in an
    /// off run, which applies nothing).
    pub injected_ke: f64,
    /// Energy the object's impacts dissipated (J, the world's estimate).
    pub dissipated: f64,
    /// Kinetic energy chained impulses gave the object's body (J).
    pub received: f64,
    /// Steps on which the energy bound scaled the object's responses down.
    pub energy_limited_steps: usize,
    /// Resting contacts (summed over the queries) whose response came from the transfer
    /// table.
    pub contacts_by_table: usize,
    /// Resting contacts (summed over the queries) a transfer response served with its modal
    /// base instead (outside the table's region; reasons in `table_fallback_steps`).
    pub contacts_table_fallback: usize,
    /// Queries on which the table did not serve (some) contacts, by reason
    /// (`impact_outside_region`, `contacts_outside_region`, `forces`, `unavailable`).
    pub table_fallback_steps: BTreeMap<String, usize>,
    /// Impulse events computed from the transfer table (`ServedBy::TransferTable`).
    pub events_by_table: usize,
}

/// One response impulse of a run (what a viewer marks).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ResponseEvent {
    /// Trajectory row at whose time the impulse acts: after the step it is applied right after
    /// step `row − 1`'s solve, at t = row · h (s); in the solver path it is replayed during step
    /// `row − 1` (one step after the step that issued it) and acts at its end.
    pub row: usize,
    /// Elastic object (index in the scene's `elastic`) whose response it is.
    pub model: usize,
    /// Receiving body (index into `BuiltWorld::bodies`, names in `RunReport::bodies_all`).
    pub body: usize,
    /// Point of application (m, world frame).
    pub point: [f64; 3],
    /// Impulse (N·s, world frame).
    pub impulse: [f64; 3],
    /// Velocity change at the point along the object's normal (m/s; the world's
    /// `ImpulseEvent::delta_v`).
    pub delta_v: f64,
    /// Whether the transfer table computed it (`ServedBy::TransferTable`); else the modal base
    /// or the attenuation law did.
    pub by_table: bool,
}

/// What the responses gave one receiving body over a run (every response impulse issued to it,
/// applied or, in an off run, only measured).
#[derive(Clone, Debug, Default, Serialize)]
pub struct BodyReceived {
    /// Impulse events.
    pub events: usize,
    /// Largest Δv of an event at its contact along the normal (m/s, after gain, Gauss–Seidel and
    /// energy bound).
    pub max_delta_v: f64,
    /// Largest impulse magnitude of an event (N·s).
    pub max_impulse: f64,
}

/// One elastic object's figures from a run (a Table 1 row).
#[derive(Clone, Debug, Serialize)]
pub struct ModelReport {
    /// Model name.
    pub model: String,
    /// Surface vertices and triangles of the base.
    pub surface_vertices: usize,
    /// Surface triangles.
    pub surface_triangles: usize,
    /// Modes in the base.
    pub modes: usize,
    /// Method used (`modal`, `attenuation C=.. beta=..`, `transfer order .. ..`).
    pub method: String,
    /// File name of the base the run read (`NAME.modes`, or `NAME.transfer.modes` for the
    /// transfer method).
    pub base: String,
    /// Scale on the response Δv the run used (the object's `gain` or the run's override).
    pub gain: f64,
    /// IIR sub-step T (s); None when off.
    pub iir_t: Option<f64>,
    /// IIR samples per rigid step h/T.
    pub samples_per_step: Option<usize>,
    /// Largest number of resting (distant) contacts at a query.
    pub distant_contacts: usize,
    /// Number of response queries (steps with ≥ 1 impact).
    pub queries: usize,
    /// Median and 99th percentile query time (µs).
    pub query_us_median: Option<f64>,
    /// 99th percentile (µs).
    pub query_us_p99: Option<f64>,
    /// The adapter's raw counters.
    pub stats: ModelStats,
}

/// Everything a run measured.
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    /// Scene name.
    pub scene: String,
    /// Response on?
    pub dcr: bool,
    /// Simulated seconds and steps.
    pub seconds: f64,
    /// Steps.
    pub steps: usize,
    /// Rigid step h (s).
    pub h: f64,
    /// Recorded bodies.
    pub bodies: Vec<String>,
    /// Hash of the trajectory (determinism).
    pub trajectory_hash: String,
    /// Outcome figures: name → (value, unit).
    pub outcomes: BTreeMap<String, (f64, String)>,
    /// Per elastic object.
    pub models: Vec<ModelReport>,
    /// Wall time in `PhysicsWorld::step` (ms, total).
    pub rapier_ms: f64,
    /// Wall time in the adapter (ms, total: classification, queries, impulses).
    pub adapter_ms: f64,
    /// adapter_ms / rapier_ms.
    pub dcr_share_of_step: f64,
    /// Kinetic energy injected by responses (J, all models).
    pub injected_ke: f64,
    /// Energy dissipated by impacts (J, estimate, all models).
    pub dissipated: f64,
    /// The energy bound η of the run (`None`: unbounded).
    pub energy_eta: Option<f64>,
    /// How responses were applied (`after_step`, `in_solver`; `none` when off).
    pub apply: String,
    /// Whether the lateral kick was on.
    pub lateral_kick: bool,
    /// The launch rule (`peak_over_step`, the paper's; `sustained_peak`).
    pub launch: String,
    /// Whether rapier's contact recycling was on for the elastic objects' colliders.
    pub contact_recycling: bool,
    /// On which steps the contacts were read (`every_step`, `impact_steps`).
    pub gate: String,
    /// Steps on which the contacts were read and the world stepped.
    pub world_steps: usize,
    /// Per receiving body (by name): what the responses gave it.
    pub received: BTreeMap<String, BodyReceived>,
    /// In-solver path: collider pairs whose replay rapier's hook never saw (applied after the
    /// step instead).
    pub replay_missed: usize,
    /// The run's trajectory (not serialised; written as NPZ).
    #[serde(skip)]
    pub trajectory: Trajectory,
    /// Every response impulse issued, in order, with `body` an index into `bodies_all` (not
    /// serialised; exported with `--gltf`).
    #[serde(skip)]
    pub events: Vec<ResponseEvent>,
    /// Names of every body of the built world (events' `body` indexes this).
    #[serde(skip)]
    pub bodies_all: Vec<String>,
    /// Per step: wall time of rapier's step and of the adapter (µs), whether the world was
    /// stepped, and the contact reports it was given (not serialised; `timings.npz`).
    #[serde(skip)]
    pub step_times: Vec<StepTime>,
    /// Launched bodies (the scene's projectiles: dynamic, with a non-zero initial velocity,
    /// starting more than 1 mm from the object) that hit an elastic object within
    /// the world's settle window — its first `settle_steps` steps (3 by default), whose
    /// contacts are the initial resting set and never impacts — so that the hit had no
    /// response: one line per body and object, with the step and the fix. Also printed on
    /// stderr. Empty: none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// A launched body starting within this distance (m) of an elastic object rests on it (a
/// vehicle on the ground), and its contacts in the settle window are not reported.
const SETTLE_GAP_M: f64 = 1e-3;

/// Watches the world's settle window for the scene's projectiles (see
/// [`RunReport::warnings`]).
struct SettleWatch {
    /// The window: steps 0 … `steps` − 1.
    steps: usize,
    /// Launched bodies: (handle, name).
    launched: Vec<(RigidBodyHandle, String)>,
    /// Elastic bodies: (handle, object name).
    elastic: Vec<(RigidBodyHandle, String)>,
    /// Pairs (launched, object) that start resting on each other (closer than
    /// [`SETTLE_GAP_M`]).
    resting: Vec<(usize, usize)>,
    /// What was seen: (launched, object, step, the pair's impulse in N·s).
    hits: Vec<(usize, usize, usize, f64)>,
}

impl SettleWatch {
    fn new(desc: &SceneDesc, built: &BuiltWorld, settle_steps: u64) -> SettleWatch {
        let launched: Vec<(RigidBodyHandle, String)> = built
            .bodies
            .iter()
            .filter(|b| b.dynamic && built.world.bodies[b.handle].linvel().length() > 0.0)
            .map(|b| (b.handle, b.name.clone()))
            .collect();
        let elastic: Vec<(RigidBodyHandle, String)> = built
            .elastic_body
            .iter()
            .zip(&desc.elastic)
            .map(|(&i, e)| (built.bodies[i].handle, e.name.clone()))
            .collect();
        let mut resting = Vec::new();
        for (l, (a, _)) in launched.iter().enumerate() {
            for (e, (b, _)) in elastic.iter().enumerate() {
                if gap(built, *a, *b) <= SETTLE_GAP_M {
                    resting.push((l, e));
                }
            }
        }
        SettleWatch {
            steps: settle_steps as usize,
            launched,
            elastic,
            resting,
            hits: Vec::new(),
        }
    }

    /// Records the contacts of step `k` between a launched body and an elastic object that
    /// carried an impulse (touching, not only predicted).
    fn look(&mut self, built: &BuiltWorld, k: usize) {
        if k >= self.steps || self.launched.is_empty() {
            return;
        }
        let world = &built.world;
        for pair in world.narrow_phase.contact_pairs() {
            let body = |c| world.colliders.get(c).and_then(|c| c.parent());
            let (Some(b1), Some(b2)) = (body(pair.collider1), body(pair.collider2)) else {
                continue;
            };
            let impulse: f64 = pair
                .solver_manifolds()
                .iter()
                .flat_map(|m| m.points.iter())
                .map(|p| p.data.impulse)
                .sum();
            if !(impulse > 0.0) {
                continue;
            }
            for (a, b) in [(b1, b2), (b2, b1)] {
                let l = self.launched.iter().position(|(h, _)| *h == a);
                let e = self.elastic.iter().position(|(h, _)| *h == b);
                if let (Some(l), Some(e)) = (l, e) {
                    if !self.resting.contains(&(l, e))
                        && !self.hits.iter().any(|h| h.0 == l && h.1 == e)
                    {
                        self.hits.push((l, e, k, impulse));
                    }
                }
            }
        }
    }

    /// One warning per launched body and object it hit in the window.
    fn warnings(&self, h: f64) -> Vec<String> {
        self.hits
            .iter()
            .map(|&(l, e, k, impulse)| {
                format!(
                    "{} hit elastic object {} in step {} (t = {:.3} s, impulse {impulse:.3e} N·s), \
                     inside the world's settle window (its first {} steps, whose contacts are the \
                     initial resting set and never impacts): that hit has no distant response; \
                     start {} farther from the object so that it arrives after t = {:.3} s",
                    self.launched[l].1,
                    self.elastic[e].1,
                    k + 1,
                    (k + 1) as f64 * h,
                    self.steps,
                    self.launched[l].1,
                    self.steps as f64 * h
                )
            })
            .collect()
    }
}

/// The smallest distance (m) between the colliders of bodies `a` and `b` at their current
/// poses (0 when they overlap; infinite when no pair of their shapes has a distance query).
fn gap(built: &BuiltWorld, a: RigidBodyHandle, b: RigidBodyHandle) -> f64 {
    let bodies = &built.world.bodies;
    let colliders = &built.world.colliders;
    let mut best = f64::INFINITY;
    for &ca in bodies[a].colliders() {
        for &cb in bodies[b].colliders() {
            let (ca, cb) = (&colliders[ca], &colliders[cb]);
            if let Ok(d) = rapier3d_f64::parry::query::distance(
                ca.position(),
                ca.shape(),
                cb.position(),
                cb.shape(),
            ) {
                best = best.min(d.distance);
            }
        }
    }
    best
}

/// One step's timing (see [`RunReport::step_times`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct StepTime {
    /// rapier's `step` (µs).
    pub rapier_us: f64,
    /// The adapter's `before_step` + `after_step` (µs).
    pub adapter_us: f64,
    /// Whether the contacts were read in full and the world stepped.
    pub world_stepped: bool,
    /// Contact reports given to the world (0 on quiet steps).
    pub reports: u32,
}

fn percentile(v: &[f64], p: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    let i = ((p / 100.0) * (s.len() - 1) as f64).round() as usize;
    Some(s[i.min(s.len() - 1)])
}

/// The settings of the transfer method for object `e` under `choice` (`None`: another
/// method).
///
/// # Errors
/// `choice` is [`MethodChoice::Transfer`] and the object has no transfer settings (the message
/// names the object and says what to add).
fn transfer_of<'a>(e: &'a ElasticDesc, choice: &MethodChoice) -> Result<Option<&'a TransferDesc>> {
    let own = match &e.method {
        MethodDesc::Transfer(t) => Some(t),
        _ => None,
    };
    Ok(match choice {
        MethodChoice::Scene => own,
        MethodChoice::Transfer => match own.or(e.transfer.as_ref()) {
            Some(t) => Some(t),
            None => bail!(
                "elastic object {}: `--method transfer` needs its transfer-table settings: add \
                 `\"transfer\": {{\"up\": [0, 1, 0]}}` (region options: up, boxes, modes, \
                 order; docs/scenes.md) to the object in the scene file",
                e.name
            ),
        },
        MethodChoice::Modal | MethodChoice::Attenuation | MethodChoice::AttenuationBeta(_) => None,
    })
}

fn attenuation_of(e: &ElasticDesc, choice: &MethodChoice) -> Option<(f64, f64, String, String)> {
    let from = |m: &MethodDesc| match m {
        MethodDesc::Attenuation {
            c,
            beta,
            distance,
            amplitude,
        } => Some((*c, *beta, distance.clone(), amplitude.clone())),
        MethodDesc::Modal | MethodDesc::Transfer(_) => None,
    };
    let own = from(&e.method).or_else(|| e.attenuation.as_ref().and_then(from));
    match choice {
        MethodChoice::Scene => from(&e.method),
        MethodChoice::Modal | MethodChoice::Transfer => None,
        MethodChoice::Attenuation => {
            Some(own.unwrap_or((1.0, 1.0, "heat".into(), "per_vertex".into())))
        }
        MethodChoice::AttenuationBeta(b) => {
            let (c, _, d, a) = own.unwrap_or((1.0, 1.0, "heat".into(), "per_vertex".into()));
            Some((c, *b, d, a))
        }
    }
}

/// Surface-vertex indices of the base whose volume node is in mesh group `group`.
fn group_surface_vertices(
    root: &Path,
    e: &ElasticDesc,
    base: &ModesFile,
    group: &str,
) -> Result<Vec<u32>> {
    let mesh = modal_bake::mesh::read_mesh(&root.join(&e.mesh))?;
    let Some(nodes) = mesh.groups.get(group) else {
        bail!("elastic object {}: mesh has no group {group:?}", e.name);
    };
    let set: std::collections::BTreeSet<u32> = nodes.iter().map(|&n| n as u32).collect();
    Ok((0..base.surface_to_volume.len() as u32)
        .filter(|&i| set.contains(&base.surface_to_volume[i as usize]))
        .collect())
}

/// The response method of elastic object `e` (modal, the attenuation law or the transfer
/// table the scene or `params.method` names) and its name for the report. `base` is the base
/// the run reads (with a table for the transfer method).
///
/// # Errors
/// An unknown distance kind, or an amplitude group the mesh does not have.
fn elastic_method(
    e: &ElasticDesc,
    params: &RunParams,
    base: &ModesFile,
) -> Result<(Method, String)> {
    if transfer_of(e, &params.method)?.is_some() {
        let name = match &base.transfer {
            Some(t) => format!(
                "transfer order {} points {} modes {} samples {}",
                t.order,
                t.num_points(),
                t.modes,
                t.samples
            ),
            None => "transfer".to_string(),
        };
        return Ok((Method::Transfer, name));
    }
    let att = attenuation_of(e, &params.method);
    let method = match &att {
        None => Method::Modal,
        Some((c, beta, distance, amplitude)) => {
            let distance = match distance.as_str() {
                "euclidean" => DistanceKind::Euclidean,
                "heat" => DistanceKind::Heat,
                "heat_table" => DistanceKind::HeatTable,
                other => bail!(
                    "elastic object {}: distance {other:?} (expected heat, heat_table or euclidean)",
                    e.name
                ),
            };
            let amplitude = match amplitude.as_str() {
                "per_vertex" => AmplitudeKind::PerVertex,
                "mean" => AmplitudeKind::Mean,
                group => {
                    AmplitudeKind::MeanOver(group_surface_vertices(&params.root, e, base, group)?)
                }
            };
            Method::Attenuation(AttenuationParams {
                law: AttenuationLaw::Simplified { c: *c, beta: *beta },
                distance,
                amplitude,
                ..AttenuationParams::default()
            })
        }
    };
    let method_name = match &att {
        None => "modal".to_string(),
        Some((c, b, d, a)) => format!("attenuation C={c} beta={b} {d} {a}"),
    };
    Ok((method, method_name))
}

/// Applies the impulses of the `drivers` (body index, description) due at time `t` (s).
fn apply_drivers(drivers: &[(usize, DriverDesc)], built: &mut BuiltWorld, t: f64) {
    for (b, d) in drivers {
        apply_driver(d, &mut built.world.bodies[built.bodies[*b].handle], t);
    }
}

/// Applies driver `d`'s impulse to `rb` when one is due at time `t` (s): it fires at
/// `start + n·period` within [start, stop], its impulse (N·s, world frame) turned about
/// `rotate_axis` at `hz` when given, at a body-frame point or the centre of mass.
pub fn apply_driver(d: &DriverDesc, rb: &mut rapier3d_f64::dynamics::RigidBody, t: f64) {
    if t + 1e-9 < d.start || t > d.stop {
        return;
    }
    let phase = (t - d.start) / d.period;
    if (phase - phase.round()).abs() > 1e-6 {
        return;
    }
    let mut j = Vector::new(d.impulse[0], d.impulse[1], d.impulse[2]);
    if let Some(ax) = d.rotate_axis {
        let axis = Vector::new(ax[0], ax[1], ax[2]).normalize();
        let q = rapier3d_f64::math::Rotation::from_axis_angle(
            axis,
            std::f64::consts::TAU * d.hz * (t - d.start),
        );
        j = q * j;
    }
    match d.point {
        Some(p) => {
            let wp = rb.position().transform_point(Vector::new(p[0], p[1], p[2]));
            rb.apply_impulse_at_point(j, wp, true);
        }
        None => rb.apply_impulse(j, true),
    }
}

/// The files a run writes into its output folder.
pub const RUN_OUTPUTS: [&str; 3] = ["trajectory.npz", "timings.npz", "summary.json"];

/// Writes `trajectory.npz`, `timings.npz` (per-step rapier and adapter µs, whether the world
/// stepped, each object's query µs and resting contacts) and `summary.json` into `dir`.
///
/// # Errors
/// I/O failures.
fn write_outputs(
    dir: &Path,
    report: &RunReport,
    rapier_us: &[f64],
    adapter_us: &[f64],
) -> Result<()> {
    // Everything is encoded before the first file is written.
    let trajectory = report.trajectory.to_npz()?;
    let mut npz = NpzWriter::new(std::io::Cursor::new(Vec::new()));
    npz.add_array("rapier_us", &Array1::from(rapier_us.to_vec()))?;
    npz.add_array("adapter_us", &Array1::from(adapter_us.to_vec()))?;
    npz.add_array(
        "world_stepped",
        &Array1::from(
            report
                .step_times
                .iter()
                .map(|t| u8::from(t.world_stepped))
                .collect::<Vec<u8>>(),
        ),
    )?;
    for m in &report.models {
        let q = &m.stats.query_us;
        let arr = Array2::from_shape_vec(
            (q.len(), 2),
            q.iter()
                .zip(&m.stats.query_resting)
                .flat_map(|(a, b)| [*a, *b as f64])
                .collect(),
        )?;
        npz.add_array(format!("query_us_resting_{}", m.model), &arr)?;
    }
    let timings = npz.finish()?.into_inner();
    let json = serde_json::to_string_pretty(&report)? + "\n";
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    for (name, bytes) in
        RUN_OUTPUTS
            .into_iter()
            .zip([&trajectory[..], &timings[..], json.as_bytes()])
    {
        let path = dir.join(name);
        dcr_files::write_atomic(&path, bytes)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// Runs `desc` headless and, if `params.out_dir` is set, writes `trajectory.npz`,
/// `timings.npz` and `summary.json` there.
///
/// # Errors
/// Bake, load, mesh or I/O failures.
pub fn run_scene(desc: &SceneDesc, params: &RunParams) -> Result<RunReport> {
    desc.validate()
        .map_err(|e| anyhow::anyhow!("scene {}: {e}", desc.name))?;
    let steps = desc
        .run_steps(params.seconds)
        .map_err(|e| anyhow::anyhow!("scene {}: {e}", desc.name))?;
    let seconds = params.seconds.unwrap_or(desc.seconds);
    let mut built = build_world(desc, &params.root)?;
    built.perturb_placement(params.perturbation.0, params.perturbation.1);
    // Off runs measure only (impacts, what the responses would have been) and apply nothing.
    let apply = if params.dcr {
        params.apply
    } else {
        ApplyMode::MeasureOnly
    };
    let mut dcr = new_adapter(desc, params, apply)?;
    // The support compensation of after-step impulses reads rapier's gravity.
    dcr.set_gravity(built.world.gravity);
    let objects = add_elastic_objects(desc, params, &mut built, &mut dcr)?;
    let drivers = resolve_drivers(desc, &built)?;
    let mut rec = RunRecord::new(desc, &built, steps);
    let mut settle = SettleWatch::new(desc, &built, dcr.world().params().classify.settle_steps);
    let wall = Instant::now();
    let mut last_progress = Instant::now();
    for k in 0..steps {
        apply_drivers(&drivers, &mut built, k as f64 * desc.h);
        rec.step(&mut built, &mut dcr);
        rec.count_world_step(&dcr, &objects, apply);
        rec.collect_events(&dcr, &objects, &built, apply, k);
        rec.record_poses(&built, (k + 1) as f64 * desc.h);
        settle.look(&built, k);
        if params.progress && last_progress.elapsed().as_secs_f64() > 5.0 {
            last_progress = Instant::now();
            eprintln!(
                "[dcr-scenes] {} ({}) step {}/{} ({:.1} s wall)",
                desc.name,
                if params.dcr { "on" } else { "off" },
                k + 1,
                steps,
                wall.elapsed().as_secs_f64()
            );
        }
    }
    let (mut report, rapier_us, adapter_us) =
        rec.into_report(desc, params, (seconds, steps, apply), &built, objects);
    report.warnings = settle.warnings(desc.h);
    for w in &report.warnings {
        eprintln!("[dcr-scenes] warning: scene {}: {w}", desc.name);
    }
    if let Some(dir) = &params.out_dir {
        write_outputs(dir, &report, &rapier_us, &adapter_us)?;
    }
    Ok(report)
}

/// The rapier adapter of a run: the scene's step, the run's energy bound, apply mode,
/// contact recycling and gate.
fn new_adapter(desc: &SceneDesc, params: &RunParams, apply: ApplyMode) -> Result<DcrRapier> {
    DcrRapier::new(
        WorldParams {
            h: desc.h,
            energy_eta: params.energy_eta,
            ..WorldParams::default()
        },
        AdapterParams {
            apply,
            contact_recycling: params.contact_recycling,
            gate: params.gate,
        },
    )
    .map_err(|err| anyhow::anyhow!("scene {}: {err}", desc.name))
}

/// One elastic object of a run: its handle and what the report says of it.
struct RunObject {
    handle: ElasticHandle,
    /// The base's file name.
    base: String,
    gain: f64,
    surface_vertices: usize,
    surface_triangles: usize,
    modes: usize,
    method: String,
    /// IIR sub-step T (s) and samples per step, for runs with the response on.
    iir_t: Option<f64>,
    samples_per_step: Option<usize>,
}

/// Bakes (if missing) and loads each elastic object's base and adds the object to the
/// adapter, with the run's method, gain and lateral kick.
fn add_elastic_objects(
    desc: &SceneDesc,
    params: &RunParams,
    built: &mut BuiltWorld,
    dcr: &mut DcrRapier,
) -> Result<Vec<RunObject>> {
    let mut objects = Vec::new();
    for (i, e) in desc.elastic.iter().enumerate() {
        let transfer = transfer_of(e, &params.method)?;
        let (path, _) = match transfer {
            Some(t) => ensure_transfer_base(
                &params.root,
                &params.bases_dir,
                e,
                t,
                desc.h,
                params.bake_budget,
            )?,
            None => ensure_base(&params.root, &params.bases_dir, e, params.bake_budget)?,
        };
        let base =
            ModesFile::read(&path).with_context(|| format!("reading base {}", path.display()))?;
        let (method, method_name) = elastic_method(e, params, &base)?;
        let model = ModalModel::load(&path)
            .map_err(|err| anyhow::anyhow!("loading {}: {err}", path.display()))?;
        let mut object = ElasticObjectDesc::new(model, 0);
        object.response = ResponseParams {
            h: desc.h,
            impact_threshold: e.impact_threshold,
            max_map_distance: 0.1,
            method,
            lateral_kick: params.lateral_kick,
            // A launch other than the paper's reads the carried-over filters.
            carry_over: params.launch != Launch::PeakOverStep,
            launch: params.launch,
            // The table was baked for this scene: a table that does not apply is an error,
            // not a silent modal run.
            table_policy: TablePolicy::Refuse,
            ..ResponseParams::default()
        };
        let gain = params.gain.unwrap_or(e.gain);
        object.gain = gain;
        let body = built.bodies[built.elastic_body[i]].handle;
        let handle = dcr
            .add_object(
                &built.world.bodies,
                &mut built.world.colliders,
                body,
                object,
            )
            .map_err(|err| anyhow::anyhow!("elastic object {}: {err}", e.name))?;
        let response = dcr.world().response(handle);
        objects.push(RunObject {
            handle,
            base: path
                .file_name()
                .map_or(String::new(), |f| f.to_string_lossy().into_owned()),
            gain,
            surface_vertices: base.num_surface_vertices(),
            surface_triangles: base.surface_triangles.len(),
            modes: base.num_modes(),
            method: method_name,
            iir_t: params.dcr.then(|| response.substep()),
            samples_per_step: params.dcr.then(|| response.samples_per_step()),
        });
    }
    Ok(objects)
}

/// The scene's drivers with the index of the body each one moves.
fn resolve_drivers(desc: &SceneDesc, built: &BuiltWorld) -> Result<Vec<(usize, DriverDesc)>> {
    desc.drivers
        .iter()
        .map(|d| {
            let b = built
                .body_index(&d.body)
                .with_context(|| format!("driver: no body {}", d.body))?;
            Ok((b, d.clone()))
        })
        .collect()
}

/// What a run records step by step: timings, the world's counters per object, the events
/// and what each body received, and the dynamic bodies' poses.
struct RunRecord {
    stats: Vec<ModelStats>,
    /// Receiving body id → index into `built.bodies` (events name bodies by rapier handle).
    body_index: BTreeMap<u64, usize>,
    /// The recorded (dynamic) bodies, indices into `built.bodies`.
    recorded: Vec<usize>,
    traj: Trajectory,
    rapier_us: Vec<f64>,
    adapter_us: Vec<f64>,
    step_times: Vec<StepTime>,
    events: Vec<ResponseEvent>,
    world_steps: usize,
    replay_missed: usize,
    received: BTreeMap<String, BodyReceived>,
}

impl RunRecord {
    /// An empty record for `steps` steps of `desc`, with the poses at t = 0.
    fn new(desc: &SceneDesc, built: &BuiltWorld, steps: usize) -> RunRecord {
        let recorded: Vec<usize> = (0..built.bodies.len())
            .filter(|&i| built.bodies[i].dynamic)
            .collect();
        let mut rec = RunRecord {
            stats: desc
                .elastic
                .iter()
                .map(|e| ModelStats {
                    name: e.name.clone(),
                    ..Default::default()
                })
                .collect(),
            body_index: built
                .bodies
                .iter()
                .enumerate()
                .map(|(i, b)| (dcr_rapier::f64::body_id(b.handle), i))
                .collect(),
            traj: Trajectory {
                names: recorded
                    .iter()
                    .map(|&i| built.bodies[i].name.clone())
                    .collect(),
                ..Default::default()
            },
            recorded,
            rapier_us: Vec::with_capacity(steps),
            adapter_us: Vec::with_capacity(steps),
            step_times: Vec::with_capacity(steps),
            events: Vec::new(),
            world_steps: 0,
            replay_missed: 0,
            received: BTreeMap::new(),
        };
        rec.record_poses(built, 0.0);
        rec
    }

    /// Appends the recorded bodies' poses at time `t` (s) to the trajectory.
    fn record_poses(&mut self, built: &BuiltWorld, t: f64) {
        self.traj.time.push(t);
        for &i in &self.recorded {
            let p = built.world.bodies[built.bodies[i].handle].position();
            self.traj
                .positions
                .extend([p.translation.x, p.translation.y, p.translation.z]);
            self.traj
                .rotations
                .extend([p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w]);
        }
    }

    /// One step: the adapter's `before_step`, rapier's step and the adapter's `after_step`,
    /// each timed (µs).
    fn step(&mut self, built: &mut BuiltWorld, dcr: &mut DcrRapier) {
        let ta = Instant::now();
        dcr.before_step(&mut built.world.bodies);
        let before_us = ta.elapsed().as_secs_f64() * 1e6;
        let ts = Instant::now();
        built.world.step_with_events(dcr.hooks(), &());
        self.rapier_us.push(ts.elapsed().as_secs_f64() * 1e6);
        let ta = Instant::now();
        dcr.after_step(
            &mut built.world.bodies,
            &built.world.colliders,
            &built.world.narrow_phase,
        );
        let us = before_us + ta.elapsed().as_secs_f64() * 1e6;
        self.adapter_us.push(us);
        self.world_steps += usize::from(dcr.step_info().world_stepped);
        self.replay_missed += dcr.step_info().replay_missed as usize;
        self.step_times.push(StepTime {
            rapier_us: *self.rapier_us.last().unwrap_or(&0.0),
            adapter_us: us,
            world_stepped: dcr.step_info().world_stepped,
            reports: dcr.step_info().reports,
        });
    }

    /// Adds the world's per-object counters of the step to `stats`. The world's counters
    /// describe its last `step`: read only when it stepped.
    fn count_world_step(&mut self, dcr: &DcrRapier, objects: &[RunObject], apply: ApplyMode) {
        if !dcr.step_info().world_stepped {
            return;
        }
        for (s, o) in self.stats.iter_mut().zip(objects) {
            let info = dcr.world().object_info(o.handle);
            s.impacts += info.impacts as usize;
            s.chained_impacts += info.chained_impacts as usize;
            s.responses_applied += info.events as usize;
            // An off run applies nothing: the world's account is what would have been injected.
            if apply != ApplyMode::MeasureOnly {
                s.injected_ke = info.energy.total_injected;
            }
            s.dissipated = info.energy.total_dissipated;
            s.received = info.energy.total_received;
            s.energy_limited_steps += usize::from(info.energy.scale < 1.0);
            s.contacts_by_table += info.response.contacts_by_table as usize;
            s.contacts_table_fallback += info.response.contacts_table_fallback as usize;
            if let Some(reason) = info.response.table_fallback {
                let reason = match reason {
                    TableFallback::Unavailable => "unavailable",
                    TableFallback::Forces => "forces",
                    TableFallback::ImpactOutsideRegion => "impact_outside_region",
                    TableFallback::ContactsOutsideRegion => "contacts_outside_region",
                };
                *s.table_fallback_steps
                    .entry(reason.to_string())
                    .or_default() += 1;
            }
            if info.queried {
                s.query_us.push(info.response_time_ns as f64 / 1e3);
                s.query_resting.push(info.resting as usize);
            }
        }
    }

    /// Accounts step `k`'s impulse events per object and per receiving body, and keeps them
    /// (runs that apply them) for the exports.
    fn collect_events(
        &mut self,
        dcr: &DcrRapier,
        objects: &[RunObject],
        built: &BuiltWorld,
        apply: ApplyMode,
        k: usize,
    ) {
        for e in dcr.events() {
            let i = objects
                .iter()
                .position(|o| o.handle == e.object)
                .unwrap_or_default();
            let s = &mut self.stats[i];
            s.max_delta_v = s.max_delta_v.max(e.delta_v);
            s.events_by_table += usize::from(e.served_by == ServedBy::TransferTable);
            if let Some(&body) = self.body_index.get(&e.body) {
                let r = self
                    .received
                    .entry(built.bodies[body].name.clone())
                    .or_default();
                r.events += 1;
                r.max_delta_v = r.max_delta_v.max(e.delta_v);
                let j = e.impulse;
                r.max_impulse = r
                    .max_impulse
                    .max((j[0] * j[0] + j[1] * j[1] + j[2] * j[2]).sqrt());
            }
            // Off runs apply nothing: no events to show.
            if apply == ApplyMode::MeasureOnly {
                continue;
            }
            if let Some(&body) = self.body_index.get(&e.body) {
                self.events.push(ResponseEvent {
                    row: k + if apply == ApplyMode::InSolver { 2 } else { 1 },
                    model: i,
                    body,
                    point: e.point,
                    impulse: e.impulse,
                    delta_v: e.delta_v,
                    by_table: e.served_by == ServedBy::TransferTable,
                });
            } else {
                debug_assert!(false, "event for unknown body {:?}", body_handle(e.body));
            }
        }
    }

    /// The run's report (per-object summaries, outcomes, totals and shares), with the
    /// per-step rapier and adapter times (µs) for `timings.npz`.
    fn into_report(
        self,
        desc: &SceneDesc,
        params: &RunParams,
        (seconds, steps, apply): (f64, usize, ApplyMode),
        built: &BuiltWorld,
        objects: Vec<RunObject>,
    ) -> (RunReport, Vec<f64>, Vec<f64>) {
        let models: Vec<ModelReport> = self
            .stats
            .into_iter()
            .zip(objects)
            .map(|(s, o)| ModelReport {
                model: s.name.clone(),
                base: o.base,
                gain: o.gain,
                surface_vertices: o.surface_vertices,
                surface_triangles: o.surface_triangles,
                modes: o.modes,
                method: o.method,
                iir_t: o.iir_t,
                samples_per_step: o.samples_per_step,
                distant_contacts: s.query_resting.iter().copied().max().unwrap_or(0),
                queries: s.query_us.len(),
                query_us_median: percentile(&s.query_us, 50.0),
                query_us_p99: percentile(&s.query_us, 99.0),
                stats: s,
            })
            .collect();
        let traj = self.traj;
        let mut outcomes = BTreeMap::new();
        for o in &desc.outcomes {
            if let Some(v) = measure_outcome(o, &traj) {
                outcomes.insert(o.name.clone(), (v, unit_of(&o.kind).to_string()));
            }
        }
        let rapier_ms = self.rapier_us.iter().sum::<f64>() / 1e3;
        let adapter_ms = self.adapter_us.iter().sum::<f64>() / 1e3;
        let report = RunReport {
            scene: desc.name.clone(),
            dcr: params.dcr,
            seconds,
            steps,
            h: desc.h,
            bodies: traj.names.clone(),
            trajectory_hash: traj.hash(),
            outcomes,
            injected_ke: models.iter().map(|m| m.stats.injected_ke).sum(),
            dissipated: models.iter().map(|m| m.stats.dissipated).sum(),
            models,
            rapier_ms,
            adapter_ms,
            dcr_share_of_step: if rapier_ms > 0.0 {
                adapter_ms / rapier_ms
            } else {
                0.0
            },
            energy_eta: params.energy_eta,
            apply: match apply {
                ApplyMode::AfterStep => "after_step",
                ApplyMode::InSolver => "in_solver",
                _ => "none",
            }
            .to_string(),
            lateral_kick: params.lateral_kick,
            launch: match params.launch {
                Launch::PeakOverStep => "peak_over_step",
                Launch::SustainedPeak => "sustained_peak",
            }
            .to_string(),
            contact_recycling: params.contact_recycling && apply != ApplyMode::InSolver,
            gate: match params.gate {
                StepGate::EveryStep => "every_step",
                _ => "impact_steps",
            }
            .to_string(),
            world_steps: self.world_steps,
            received: self.received,
            replay_missed: self.replay_missed,
            trajectory: traj,
            events: self.events,
            bodies_all: built.bodies.iter().map(|b| b.name.clone()).collect(),
            step_times: self.step_times,
            warnings: Vec::new(),
        };
        (report, self.rapier_us, self.adapter_us)
    }
}
