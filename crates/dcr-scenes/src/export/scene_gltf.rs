//! [`write_scene_glb`]: runs of a scene as one animated binary glTF, side by side.
//!
//! Layout: one parent node per run ("side", e.g. `on` and `off`), offset along +x by the
//! scene's width plus a margin, the first side leftmost; under it one node per body named
//! `SIDE_BODY` (three.js reserves `/` in node names), its mesh in the body frame (elastic objects: the base's surface triangles;
//! every other body: its colliders' shapes placed at their offsets). Static bodies keep their
//! pose; every recorded (dynamic) body has a translation and a rotation keyframe per trajectory
//! row (t = row · h, linear interpolation; quaternion signs made continuous), all in one
//! animation named `run`. Coordinates are the simulation's (m, y-up) inside each side.
//!
//! `extras.dcr` of the document: `kind: "scene_run"`, `scene`, `h`, `rows`, and per side
//! `{label, node, dcr, offset, outcomes {name: [value, unit]}, events [{row, time, body, node,
//! model, point, impulse}]}` — every response impulse applied (trajectory row and time
//! t = row · h, receiving body, the elastic object whose response it is, point m and impulse
//! N·s in the simulation's world frame, i.e. the side's local frame).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context, Result};
use dcr_runtime::format::ModesFile;
use gltf::json;
use modal_bake::export::{extras_of, write_file_atomic, GltfBuilder};
use rapier3d_f64::math::Pose;
use serde_json::json as j;

use super::shape_mesh::{shape_triangles, ShapeMesh};
use crate::runner::{surface_base_path, RunReport, Trajectory};
use crate::scene::{build_world, BodyInfo, BuiltWorld, SceneDesc};

/// One run shown in the file.
#[derive(Clone, Copy, Debug)]
pub struct Side<'a> {
    /// Label, also the side's node name and the prefix of its body nodes (`on`, `off`).
    pub label: &'a str,
    /// The run.
    pub report: &'a RunReport,
}

/// The usual label of a run: `on` or `off`.
pub fn side_label(r: &RunReport) -> &'static str {
    if r.dcr {
        "on"
    } else {
        "off"
    }
}

/// What [`write_scene_glb`] wrote.
#[derive(Clone, Debug)]
pub struct SceneGlbInfo {
    /// File size (bytes).
    pub bytes: usize,
    /// Body nodes (all sides).
    pub body_nodes: usize,
    /// Keyframes per animated body.
    pub keyframes: usize,
    /// Response events recorded (all sides).
    pub events: usize,
}

const PALETTE: [[f32; 4]; 8] = [
    [0.80, 0.33, 0.25, 1.0],
    [0.93, 0.93, 0.90, 1.0],
    [0.35, 0.55, 0.80, 1.0],
    [0.85, 0.70, 0.30, 1.0],
    [0.45, 0.70, 0.45, 1.0],
    [0.60, 0.45, 0.70, 1.0],
    [0.50, 0.50, 0.52, 1.0],
    [0.30, 0.65, 0.65, 1.0],
];
const ELASTIC_COLOUR: [f32; 4] = [0.62, 0.47, 0.33, 1.0];

/// `plate_3` → `plate` (copies of a prop share one mesh).
fn family(name: &str) -> &str {
    match name.rsplit_once('_') {
        Some((head, tail)) if !tail.is_empty() && tail.bytes().all(|b| b.is_ascii_digit()) => head,
        _ => name,
    }
}

fn f32x3(p: [f64; 3]) -> [f32; 3] {
    [p[0] as f32, p[1] as f32, p[2] as f32]
}

/// Writes `sides` (runs of `desc`, same step h) as one GLB at `path` (atomically). Bodies'
/// meshes come from a freshly built world of `desc` (`root`: repository root) and, for elastic
/// objects, from their bases in `bases_dir`.
///
/// # Errors
/// No side, sides of different scenes or steps, a run whose recorded bodies are not the
/// scene's, an unreadable base or mesh, a collider shape without a mesh, or I/O failures.
pub fn write_scene_glb(
    desc: &SceneDesc,
    root: &Path,
    bases_dir: &Path,
    sides: &[Side],
    path: &Path,
) -> Result<SceneGlbInfo> {
    let first = check_sides(desc, sides)?;
    let built = build_world(desc, root)?;
    let meshes = BodyMeshes::of(desc, &built, bases_dir)?;
    let mut g = GltfBuilder::new();
    let mesh_of = meshes.add_to(&mut g)?;
    let dx = side_spacing(&built, &meshes, &first.report.trajectory);

    let mut scene_nodes = Vec::new();
    let mut side_extras = Vec::new();
    let mut anim = Keyframes::default();
    let mut body_nodes = 0;
    let mut n_events = 0;
    let mut times_acc = BTreeMap::new();
    for (si, side) in sides.iter().enumerate() {
        let r = side.report;
        let traj = &r.trajectory;
        let offset = (si as f64 - 0.5 * (sides.len() - 1) as f64) * dx;
        let rows = traj.rows();
        if rows == 0 {
            bail!("run {:?} has no trajectory", side.label);
        }
        let input = *times_acc.entry(rows).or_insert_with(|| {
            let t: Vec<f32> = (0..rows).map(|k| (k as f64 * r.h) as f32).collect();
            g.scalars(&t, true)
        });
        let mut children = Vec::new();
        for (bi, b) in built.bodies.iter().enumerate() {
            let Some(&mesh) = mesh_of.get(&meshes.body_family[bi]) else {
                continue;
            };
            let col = traj.names.iter().position(|n| n == &b.name);
            if b.dynamic && col.is_none() {
                bail!("run {:?} did not record body {}", side.label, b.name);
            }
            let pose = *built.world.bodies[b.handle].position();
            let node = body_node(&mut g, side, b, mesh, col, &pose);
            children.push(node);
            body_nodes += 1;
            let Some(c) = col else { continue };
            anim.add_body(&mut g, traj, c, input, node)?;
        }
        let events = side_events(desc, side);
        n_events += events.len();
        side_extras.push(j!({
            "label": side.label,
            "node": side.label,
            "dcr": r.dcr,
            "offset": [offset, 0.0, 0.0],
            "outcomes": r.outcomes,
            "events": events,
        }));
        scene_nodes.push(g.root.push(json::Node {
            name: Some(side.label.to_string()),
            translation: Some([offset as f32, 0.0, 0.0]),
            children: Some(children),
            extras: extras_of(&j!({"side": side.label, "dcr": r.dcr})),
            ..Default::default()
        }));
    }
    if !anim.channels.is_empty() {
        g.root.push(json::Animation {
            extensions: None,
            extras: None,
            name: Some("run".into()),
            channels: anim.channels,
            samplers: anim.samplers,
        });
    }
    let scene = g.root.push(json::Scene {
        extensions: None,
        extras: None,
        name: Some(desc.name.clone()),
        nodes: scene_nodes,
    });
    g.root.scene = Some(scene);
    g.root.extras = extras_of(&j!({
        "dcr": {
            "kind": "scene_run",
            "scene": desc.name,
            "description": desc.description,
            "h": first.report.h,
            "rows": first.report.trajectory.rows(),
            "sides": side_extras,
        }
    }));
    let bytes = g.to_glb()?;
    write_file_atomic(path, &bytes)?;
    Ok(SceneGlbInfo {
        bytes: bytes.len(),
        body_nodes,
        keyframes: first.report.trajectory.rows(),
        events: n_events,
    })
}

/// The first of `sides` after checking that there is one and that every side is a run of
/// `desc` with the first side's step h.
fn check_sides<'s, 'a>(desc: &SceneDesc, sides: &'s [Side<'a>]) -> Result<&'s Side<'a>> {
    let Some(first) = sides.first() else {
        bail!("no run to export");
    };
    for s in sides {
        if s.report.scene != desc.name || s.report.h != first.report.h {
            bail!(
                "run {:?} is not a run of scene {} with h = {} s",
                s.label,
                desc.name,
                first.report.h
            );
        }
    }
    Ok(first)
}

/// One mesh per body family in the body frame (m), and each body's family.
struct BodyMeshes {
    /// Family name → (mesh, whether it is an elastic object's surface).
    families: BTreeMap<String, (ShapeMesh, bool)>,
    /// Family of each body of the built world, in body order.
    body_family: Vec<String>,
}

impl BodyMeshes {
    /// The meshes of `built`'s bodies: an elastic object's base surface (from `bases_dir`),
    /// every other body's collider shapes placed at their offsets (copies of a prop share one
    /// family).
    fn of(desc: &SceneDesc, built: &BuiltWorld, bases_dir: &Path) -> Result<Self> {
        let mut families: BTreeMap<String, (ShapeMesh, bool)> = BTreeMap::new();
        let mut body_family = Vec::with_capacity(built.bodies.len());
        let mut colliders: Vec<_> = built.collider_body.iter().map(|(&c, &b)| (c, b)).collect();
        colliders.sort_by_key(|(c, _)| c.into_raw_parts());
        for (bi, b) in built.bodies.iter().enumerate() {
            let key = match b.elastic {
                Some(_) => b.name.clone(),
                None => family(&b.name).to_string(),
            };
            body_family.push(key.clone());
            if families.contains_key(&key) {
                continue;
            }
            let mesh = match b.elastic {
                Some(ei) => {
                    let e = &desc.elastic[ei];
                    let bp = surface_base_path(bases_dir, e);
                    let base = ModesFile::read(&bp)
                        .with_context(|| format!("reading base {}", bp.display()))?;
                    ShapeMesh {
                        positions: base.surface_vertices.clone(),
                        triangles: base.surface_triangles.clone(),
                    }
                }
                None => {
                    let mut m = ShapeMesh::default();
                    for &(ch, owner) in &colliders {
                        if owner != bi {
                            continue;
                        }
                        let c = &built.world.colliders[ch];
                        let part = shape_triangles(c.shape())
                            .with_context(|| format!("body {}", b.name))?;
                        let offset = c.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
                        m.append(&part, &offset);
                    }
                    m
                }
            };
            families.insert(key, (mesh, b.elastic.is_some()));
        }
        Ok(Self {
            families,
            body_family,
        })
    }

    /// Adds every non-empty family mesh with its material to `g` (elastic objects in
    /// [`ELASTIC_COLOUR`], the rest from [`PALETTE`]); returns family name → glTF mesh.
    fn add_to(&self, g: &mut GltfBuilder) -> Result<BTreeMap<String, json::Index<json::Mesh>>> {
        let mut mesh_of = BTreeMap::new();
        for (k, (key, (mesh, elastic))) in self.families.iter().enumerate() {
            if mesh.triangles.is_empty() {
                continue;
            }
            let colour = if *elastic {
                ELASTIC_COLOUR
            } else {
                PALETTE[k % PALETTE.len()]
            };
            let mat = g.material(key, colour, 0.7, true);
            let pos: Vec<[f32; 3]> = mesh.positions.iter().map(|&p| f32x3(p)).collect();
            let idx = g.triangle_mesh(key, &pos, &mesh.triangles, mat, &[])?;
            mesh_of.insert(key.clone(), idx);
        }
        Ok(mesh_of)
    }
}

/// Distance (m) between the sides along x: 1.15 × the scene's x extent (static meshes at
/// their poses, the dynamic bodies' paths in `traj0`) plus 0.3 m.
fn side_spacing(built: &BuiltWorld, meshes: &BodyMeshes, traj0: &Trajectory) -> f64 {
    let (mut x0, mut x1) = (f64::INFINITY, f64::NEG_INFINITY);
    for (bi, b) in built.bodies.iter().enumerate() {
        let pose = *built.world.bodies[b.handle].position();
        if let Some((m, _)) = meshes.families.get(&meshes.body_family[bi]) {
            for p in &m.positions {
                let q = pose.transform_point(rapier3d_f64::math::Vector::new(p[0], p[1], p[2]));
                x0 = x0.min(q.x);
                x1 = x1.max(q.x);
            }
        }
    }
    for k in 0..traj0.rows() {
        for b in 0..traj0.names.len() {
            let x = traj0.pos(k, b)[0];
            x0 = x0.min(x);
            x1 = x1.max(x);
        }
    }
    let width = if x1 > x0 { x1 - x0 } else { 1.0 };
    1.15 * width + 0.3
}

/// Adds body `b`'s node `SIDE_BODY` with `mesh`, posed at its first trajectory row (column
/// `col`) or, unrecorded, at its built `pose`.
fn body_node(
    g: &mut GltfBuilder,
    side: &Side,
    b: &BodyInfo,
    mesh: json::Index<json::Mesh>,
    col: Option<usize>,
    pose: &Pose,
) -> json::Index<json::Node> {
    let traj = &side.report.trajectory;
    let (t0, q0) = match col {
        Some(c) => (traj.pos(0, c), traj.rot(0, c)),
        None => (
            [pose.translation.x, pose.translation.y, pose.translation.z],
            [
                pose.rotation.x,
                pose.rotation.y,
                pose.rotation.z,
                pose.rotation.w,
            ],
        ),
    };
    let name = format!("{}_{}", side.label, b.name);
    g.root.push(json::Node {
        mesh: Some(mesh),
        name: Some(name),
        translation: Some(f32x3(t0)),
        rotation: Some(json::scene::UnitQuaternion([
            q0[0] as f32,
            q0[1] as f32,
            q0[2] as f32,
            q0[3] as f32,
        ])),
        extras: extras_of(&j!({
            "body": b.name, "dynamic": b.dynamic, "elastic": b.elastic.is_some()
        })),
        ..Default::default()
    })
}

/// Samplers and channels of the `run` animation.
#[derive(Default)]
struct Keyframes {
    /// Animation samplers (linear), two per animated body.
    samplers: Vec<json::animation::Sampler>,
    /// Translation and rotation channels, one per sampler.
    channels: Vec<json::animation::Channel>,
}

impl Keyframes {
    /// Animates `node` along column `c` of `traj`: a translation and a rotation keyframe per
    /// row at times `input` (quaternions normalised, signs made continuous).
    fn add_body(
        &mut self,
        g: &mut GltfBuilder,
        traj: &Trajectory,
        c: usize,
        input: json::Index<json::Accessor>,
        node: json::Index<json::Node>,
    ) -> Result<()> {
        let rows = traj.rows();
        let tr: Vec<[f32; 3]> = (0..rows).map(|k| f32x3(traj.pos(k, c))).collect();
        let mut prev = [0.0f64, 0.0, 0.0, 1.0];
        let rot: Vec<[f32; 4]> = (0..rows)
            .map(|k| {
                let mut q = traj.rot(k, c);
                let d: f64 = (0..4).map(|i| q[i] * prev[i]).sum();
                if d < 0.0 {
                    q = q.map(|x| -x);
                }
                prev = q;
                let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
                [
                    (q[0] / n) as f32,
                    (q[1] / n) as f32,
                    (q[2] / n) as f32,
                    (q[3] / n) as f32,
                ]
            })
            .collect();
        let out_t = g.vec3(&tr, false)?;
        let out_r = g.vec4(&rot);
        for (out, prop) in [
            (out_t, json::animation::Property::Translation),
            (out_r, json::animation::Property::Rotation),
        ] {
            self.samplers.push(json::animation::Sampler {
                extensions: None,
                extras: None,
                input,
                interpolation: json::validation::Checked::Valid(
                    json::animation::Interpolation::Linear,
                ),
                output: out,
            });
            self.channels.push(json::animation::Channel {
                sampler: json::Index::new(self.samplers.len() as u32 - 1),
                target: json::animation::Target {
                    extensions: None,
                    extras: None,
                    node,
                    path: json::validation::Checked::Valid(prop),
                },
                extensions: None,
                extras: None,
            });
        }
        Ok(())
    }
}

/// `extras` entries of `side`'s response events: row, time t = row · h (s), receiving body
/// and its node, the elastic object, point (m) and impulse (N·s) in the simulation's frame.
fn side_events(desc: &SceneDesc, side: &Side) -> Vec<serde_json::Value> {
    let r = side.report;
    r.events
        .iter()
        .map(|e| {
            let body = r.bodies_all.get(e.body).cloned().unwrap_or_default();
            j!({
                "row": e.row,
                "time": e.row as f64 * r.h,
                "body": body,
                "node": format!("{}_{}", side.label, body),
                "model": desc.elastic.get(e.model).map(|m| m.name.as_str()),
                "point": e.point,
                "impulse": e.impulse,
            })
        })
        .collect()
}
