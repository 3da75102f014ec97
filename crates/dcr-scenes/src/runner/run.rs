//! [`run_scene`]: one headless run of a scene, response on or off.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::adapter::engine::{
    AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind, DistantResponse, Method,
    ModalModel, ResponseParams,
};
use anyhow::{bail, Context, Result};
use dcr_runtime::format::ModesFile;
use ndarray::{Array1, Array2};
use ndarray_npy::NpzWriter;
use rapier3d_f64::math::Vector;
use serde::Serialize;

use crate::adapter::{AdapterParams, DcrAdapter, ModelStats, ResponseEvent};
use crate::runner::bases::ensure_base;
use crate::runner::outcomes::{measure_outcome, unit_of};
use crate::runner::Trajectory;
use crate::scene::{build_world, ElasticDesc, MethodDesc, SceneDesc};

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
    /// Repository root (mesh paths are relative to it).
    pub root: PathBuf,
    /// Where bases are baked/read.
    pub bases_dir: PathBuf,
    /// Output directory (None: write nothing).
    pub out_dir: Option<PathBuf>,
    /// Progress lines on stderr.
    pub progress: bool,
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
    /// Method used (`modal`, `attenuation C=.. beta=..`).
    pub method: String,
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
    /// The run's trajectory (not serialised; written as NPZ).
    #[serde(skip)]
    pub trajectory: Trajectory,
    /// Response impulses applied, with `body` an index into `bodies_all` (not serialised;
    /// exported with `--gltf`).
    #[serde(skip)]
    pub events: Vec<ResponseEvent>,
    /// Names of every body of the built world (events' `body` indexes this).
    #[serde(skip)]
    pub bodies_all: Vec<String>,
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

fn attenuation_of(e: &ElasticDesc, choice: &MethodChoice) -> Option<(f64, f64, String, String)> {
    let from = |m: &MethodDesc| match m {
        MethodDesc::Attenuation {
            c,
            beta,
            distance,
            amplitude,
        } => Some((*c, *beta, distance.clone(), amplitude.clone())),
        MethodDesc::Modal => None,
    };
    let own = from(&e.method).or_else(|| e.attenuation.as_ref().and_then(from));
    match choice {
        MethodChoice::Scene => from(&e.method),
        MethodChoice::Modal => None,
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

/// Runs `desc` headless and, if `params.out_dir` is set, writes `trajectory.npz`,
/// `timings.npz` and `summary.json` there.
///
/// # Errors
/// Bake, load, mesh or I/O failures.
pub fn run_scene(desc: &SceneDesc, params: &RunParams) -> Result<RunReport> {
    let seconds = params.seconds.unwrap_or(desc.seconds);
    let steps = (seconds / desc.h).round() as usize;
    let mut built = build_world(desc, &params.root)?;

    // Bases and responses.
    let mut responses = Vec::new();
    let mut infos = Vec::new();
    for e in &desc.elastic {
        let (path, _) = ensure_base(&params.root, &params.bases_dir, e)?;
        let base =
            ModesFile::read(&path).with_context(|| format!("reading base {}", path.display()))?;
        let att = attenuation_of(e, &params.method);
        let method = match &att {
            None => Method::Modal,
            Some((c, beta, distance, amplitude)) => {
                let distance = match distance.as_str() {
                    "euclidean" => DistanceKind::Euclidean,
                    _ => DistanceKind::Heat,
                };
                let amplitude = match amplitude.as_str() {
                    "per_vertex" => AmplitudeKind::PerVertex,
                    "mean" => AmplitudeKind::Mean,
                    group => AmplitudeKind::MeanOver(group_surface_vertices(
                        &params.root,
                        e,
                        &base,
                        group,
                    )?),
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
        let response = if params.dcr {
            let model = ModalModel::load(&path)
                .map_err(|err| anyhow::anyhow!("loading {}: {err}", path.display()))?;
            let rp = ResponseParams {
                h: desc.h,
                impact_threshold: e.impact_threshold,
                max_map_distance: 0.1,
                method,
                ..ResponseParams::default()
            };
            Some(
                DistantResponse::new(model, rp)
                    .map_err(|err| anyhow::anyhow!("response of {}: {err}", e.name))?,
            )
        } else {
            None
        };
        let (t, sps) = match &response {
            Some(r) => (Some(r.substep()), Some(r.samples_per_step())),
            None => (None, None),
        };
        infos.push((
            base.num_surface_vertices(),
            base.surface_triangles.len(),
            base.num_modes(),
            method_name,
            t,
            sps,
        ));
        responses.push(response);
    }
    let thresholds: Vec<f64> = desc.elastic.iter().map(|e| e.impact_threshold).collect();
    let gains: Vec<f64> = desc.elastic.iter().map(|e| e.gain).collect();
    let names: Vec<String> = desc.elastic.iter().map(|e| e.name.clone()).collect();
    let mut adapter = DcrAdapter::new(
        &built,
        responses,
        &thresholds,
        &gains,
        &names,
        AdapterParams {
            enabled: params.dcr,
            restitution: desc.restitution,
            ..AdapterParams::default()
        },
    );

    // Drivers.
    let mut drivers = Vec::new();
    for d in &desc.drivers {
        let b = built
            .body_index(&d.body)
            .with_context(|| format!("driver: no body {}", d.body))?;
        drivers.push((b, d.clone()));
    }

    // Recording.
    let rec: Vec<usize> = (0..built.bodies.len())
        .filter(|&i| built.bodies[i].dynamic)
        .collect();
    let mut traj = Trajectory {
        names: rec.iter().map(|&i| built.bodies[i].name.clone()).collect(),
        ..Default::default()
    };
    let record = |built: &crate::scene::BuiltWorld, traj: &mut Trajectory, t: f64| {
        traj.time.push(t);
        for &i in &rec {
            let p = built.world.bodies[built.bodies[i].handle].position();
            traj.positions
                .extend([p.translation.x, p.translation.y, p.translation.z]);
            traj.rotations
                .extend([p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w]);
        }
    };
    record(&built, &mut traj, 0.0);

    let mut rapier_us = Vec::with_capacity(steps);
    let mut adapter_us = Vec::with_capacity(steps);
    let wall = Instant::now();
    let mut last_progress = Instant::now();
    for k in 0..steps {
        let t = k as f64 * desc.h;
        for (b, d) in &drivers {
            if t + 1e-9 < d.start || t > d.stop {
                continue;
            }
            let phase = (t - d.start) / d.period;
            if (phase - phase.round()).abs() > 1e-6 {
                continue;
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
            let rb = &mut built.world.bodies[built.bodies[*b].handle];
            match d.point {
                Some(p) => {
                    let wp = rb.position().transform_point(Vector::new(p[0], p[1], p[2]));
                    rb.apply_impulse_at_point(j, wp, true);
                }
                None => rb.apply_impulse(j, true),
            }
        }
        adapter.before_step(&built);
        let ts = Instant::now();
        built.world.step();
        rapier_us.push(ts.elapsed().as_secs_f64() * 1e6);
        let st = adapter.after_step(&mut built);
        adapter_us.push(st.adapter_us);
        record(&built, &mut traj, (k + 1) as f64 * desc.h);
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

    let stats = adapter.stats();
    let models: Vec<ModelReport> = stats
        .into_iter()
        .zip(infos)
        .map(|(s, (sv, st, modes, method, t, sps))| ModelReport {
            model: s.name.clone(),
            surface_vertices: sv,
            surface_triangles: st,
            modes,
            method,
            iir_t: t,
            samples_per_step: sps,
            distant_contacts: s.query_resting.iter().copied().max().unwrap_or(0),
            queries: s.query_us.len(),
            query_us_median: percentile(&s.query_us, 50.0),
            query_us_p99: percentile(&s.query_us, 99.0),
            stats: s,
        })
        .collect();
    let mut outcomes = BTreeMap::new();
    for o in &desc.outcomes {
        if let Some(v) = measure_outcome(o, &traj) {
            outcomes.insert(o.name.clone(), (v, unit_of(&o.kind).to_string()));
        }
    }
    let rapier_ms = rapier_us.iter().sum::<f64>() / 1e3;
    let adapter_ms = adapter_us.iter().sum::<f64>() / 1e3;
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
        trajectory: traj,
        events: adapter.events().to_vec(),
        bodies_all: built.bodies.iter().map(|b| b.name.clone()).collect(),
    };

    if let Some(dir) = &params.out_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        report.trajectory.write_npz(&dir.join("trajectory.npz"))?;
        let f = std::fs::File::create(dir.join("timings.npz"))?;
        let mut npz = NpzWriter::new(f);
        npz.add_array("rapier_us", &Array1::from(rapier_us.clone()))?;
        npz.add_array("adapter_us", &Array1::from(adapter_us.clone()))?;
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
        npz.finish()?;
        let json = serde_json::to_string_pretty(&report)?;
        std::fs::write(dir.join("summary.json"), json + "\n")?;
    }
    Ok(report)
}
