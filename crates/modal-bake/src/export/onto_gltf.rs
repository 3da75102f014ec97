//! [`write_modes_onto_gltf`]: a base's modes added to a glTF asset as morph targets, the asset
//! otherwise kept — its node hierarchy, materials, textures, UVs, normals, skins, cameras,
//! lights, extensions and animations — so an engine loads the artist's model as it was with the
//! modes on it.
//!
//! The asset is read as `mesh`/`bake` read it ([`read_gltf_scene`]): the placed triangle
//! primitives of the scene (or of `--object`), their vertices in the scene frame. Each vertex
//! takes the modes where [`map_modes_onto`] reads them (the closest point of the base's
//! surface) and each displacement `d` (m, scene frame) is written in the primitive's own frame,
//! `L⁻¹ d / s`, where L is the placing node's world matrix without its translation and s the
//! asset's unit in metres (`--units`): a morph target displaces the mesh's vertices before the
//! node transforms them.
//!
//! What changes in the document:
//! - every placed primitive gains one `POSITION` morph target per mode (`FLOAT VEC3` with
//!   `min`/`max`), after the targets it had; points and lines of the same mesh gain zero
//!   targets (an accessor without a buffer view), as glTF asks every primitive of a mesh to have
//!   the same targets; `mesh.weights` and a node's `weights` grow by zeros; `mesh.extras.
//!   targetNames` names them `mode N — F Hz` (a target it had without a name: `target K`);
//! - a mesh placed by several nodes, or by a node outside `--object`, is copied for each node
//!   of the selection that places it (each placement moves differently);
//! - one animation per mode (a 1 s sine of that target's weight on every node given targets)
//!   after the animations it had; those of them that animate the weights of a node given
//!   targets get zeros for the new targets in every keyframe;
//! - the buffers become the GLB's one binary chunk (each previous buffer at a 4-byte aligned
//!   offset, its buffer views moved with it), and images in files beside a `.gltf` are embedded
//!   (PNG, JPEG, WebP or KTX2, told by their first bytes), so the GLB stands alone;
//! - `extras.dcr` on the document: `kind: "modes_onto"`, `scale`, `diagonal_m`, `period_s`,
//!   `max_mapping_distance_m`, `fixed_vertices` and `placements` (`node`, `mesh`, `primitive`,
//!   `first_vertex`, `vertices`, `first_target`: where the asset's vertex list, in the order
//!   the reader appends it, lies in the document), and per mode the entry of
//!   [`write_modes_glb_onto`](super::write_modes_glb_onto) with its `animation`.
//!
//! The JSON is edited as JSON (`serde_json::Value`), not through `gltf-json`'s typed model,
//! which drops the members and extensions it does not model; the result is parsed and
//! validated as the reader validates an asset ([`validate_document`]) before it is written.

use std::path::Path;

use dcr_runtime::format::ModesFile;
use serde_json::{json, Map, Value};

use super::gltf_builder::glb_container;
use super::mode_onto::{check_onto_params, mode_amplitudes, onto_extras};
use super::{
    diagonal, map_modes_onto, write_file_atomic, ExportError, OntoInfo, OntoMapping, OntoParams,
};
use crate::mesh::surface::{
    gltf_component, read_beside, read_gltf_scene, validate_document, GltfPlacement,
};
use gltf::accessor::DataType;

/// `bufferView.target` of vertex attributes (`ARRAY_BUFFER`).
const ARRAY_BUFFER: u64 = 34962;

/// Adds the lowest `params.modes` modes of `base` to the glTF asset at `asset` (`.glb` or
/// `.gltf`) as morph targets and writes it as a GLB at `path` (see the module doc for what
/// changes). `to_metres`: the asset's unit in m (`--units`); `object`: the named node or mesh
/// the base was baked from (`--object`), else the whole scene.
///
/// # Errors
/// [`ExportError::Invalid`] naming the asset for what its reader refuses, a singular node
/// transform, an image that is not PNG, JPEG, WebP or KTX2, `extras` that are not JSON
/// objects, a GLB over 4 GiB; as [`map_modes_onto`]; `Io` on read and write failures.
///
/// ```no_run
/// use modal_bake::export::{write_modes_onto_gltf, OntoParams};
/// let base = dcr_runtime::format::ModesFile::read("chair.modes".as_ref()).unwrap();
/// let p = OntoParams { modes: 8, ..Default::default() };
/// write_modes_onto_gltf(&base, "chair.glb".as_ref(), 1.0, None, &p, "chair_modes.glb".as_ref())
///     .unwrap();
/// ```
pub fn write_modes_onto_gltf(
    base: &ModesFile,
    asset: &Path,
    to_metres: f64,
    object: Option<&str>,
    params: &OntoParams,
    path: &Path,
) -> Result<OntoInfo, ExportError> {
    let data = std::fs::read(asset).map_err(|e| ExportError::Io {
        path: asset.to_path_buf(),
        source: e,
    })?;
    let name = asset.display().to_string();
    let (bytes, info) = onto_gltf_bytes(base, &data, &name, to_metres, object, params)?;
    write_file_atomic(path, &bytes)?;
    Ok(info)
}

/// The document being extended and its one binary buffer.
struct Doc {
    json: Value,
    bin: Vec<u8>,
}

impl Doc {
    /// The top-level array `key`, created empty when absent (push to it: glTF refuses an
    /// empty top-level array).
    fn array(&mut self, key: &str) -> &mut Vec<Value> {
        let root = self
            .json
            .as_object_mut()
            .expect("a glTF document is an object");
        let v = root.entry(key).or_insert_with(|| json!([]));
        if !v.is_array() {
            *v = json!([]);
        }
        v.as_array_mut().expect("an array")
    }

    /// The length of the top-level array `key` (0 when absent).
    fn len(&self, key: &str) -> usize {
        self.json
            .get(key)
            .and_then(Value::as_array)
            .map_or(0, Vec::len)
    }

    /// Appends `v` to the top-level array `key`; its index.
    fn push(&mut self, key: &str, v: Value) -> usize {
        let a = self.array(key);
        a.push(v);
        a.len() - 1
    }

    /// Appends `bytes` to the binary buffer at a 4-byte aligned offset; the new view's index.
    fn view(&mut self, bytes: &[u8], target: Option<u64>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() });
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.push("bufferViews", v)
    }

    /// A `FLOAT` accessor of `data` (`VEC3` when `vec3`, else `SCALAR`) with its `min`/`max`.
    fn floats(&mut self, data: &[f32], vec3: bool, target: Option<u64>) -> usize {
        let width = if vec3 { 3 } else { 1 };
        let mut lo = vec![f32::INFINITY; width];
        let mut hi = vec![f32::NEG_INFINITY; width];
        for e in data.chunks_exact(width) {
            for k in 0..width {
                lo[k] = lo[k].min(e[k]);
                hi[k] = hi[k].max(e[k]);
            }
        }
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        self.push(
            "accessors",
            json!({
                "bufferView": view,
                "componentType": 5126,
                "count": data.len() / width,
                "type": if vec3 { "VEC3" } else { "SCALAR" },
                "min": lo,
                "max": hi,
            }),
        )
    }
}

/// `v.extras` as an object (created when absent); `what` names `v` in the error.
fn extras_of<'v>(
    v: &'v mut Value,
    what: &str,
    name: &str,
) -> Result<&'v mut Map<String, Value>, ExportError> {
    let e = v
        .as_object_mut()
        .ok_or_else(|| ExportError::Invalid(format!("{name}: {what} is not a JSON object")))?
        .entry("extras")
        .or_insert_with(|| json!({}));
    e.as_object_mut().ok_or_else(|| {
        ExportError::Invalid(format!(
            "{name}: the extras of {what} are not a JSON object; dcr adds its members there \
             (make them an object)"
        ))
    })
}

/// The media type of an image from its first bytes.
fn image_mime(b: &[u8]) -> Option<&'static str> {
    if b.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("image/png")
    } else if b.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Some("image/jpeg")
    } else if b.len() >= 12 && &b[..4] == b"RIFF" && &b[8..12] == b"WEBP" {
        Some("image/webp")
    } else if b.starts_with(b"\xABKTX 20\xBB\r\n\x1A\n") {
        Some("image/ktx2")
    } else {
        None
    }
}

/// The inverse of the upper 3 × 3 of a column-major world matrix (`m[column][row]`), as rows.
fn linear_inverse(m: &[[f64; 4]; 4]) -> Option<[[f64; 3]; 3]> {
    let a = |r: usize, c: usize| m[c][r];
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)
    };
    let det = a(0, 0) * cof(0, 0) + a(0, 1) * cof(0, 1) + a(0, 2) * cof(0, 2);
    let scale = (0..3)
        .flat_map(|r| (0..3).map(move |c| (r, c)))
        .map(|(r, c)| a(r, c).abs())
        .fold(0.0, f64::max);
    if !(det.abs() > 1e-12 * scale.powi(3)) {
        return None;
    }
    // inverse[r][c] = cofactor(c, r) / det.
    Some(std::array::from_fn(|r| {
        std::array::from_fn(|c| cof(c, r) / det)
    }))
}

fn onto_gltf_bytes(
    base: &ModesFile,
    data: &[u8],
    name: &str,
    to_metres: f64,
    object: Option<&str>,
    params: &OntoParams,
) -> Result<(Vec<u8>, OntoInfo), ExportError> {
    check_onto_params(params)?;
    if !(to_metres.is_finite() && to_metres > 0.0) {
        return Err(ExportError::Invalid(format!(
            "the asset's unit must be a positive length in m, got {to_metres}"
        )));
    }
    let invalid = |e: crate::mesh::surface::SurfaceError| ExportError::Invalid(e.to_string());
    let scene = read_gltf_scene(data, name, object).map_err(invalid)?;
    if scene.triangles.is_empty() {
        return Err(ExportError::Invalid(format!(
            "{name}: the scene places no triangles"
        )));
    }
    let positions: Vec<[f64; 3]> = scene
        .positions
        .iter()
        .map(|p| p.map(|x| x * to_metres))
        .collect();
    if let Some(v) = positions
        .iter()
        .position(|p| !p.iter().all(|x| x.is_finite()))
    {
        return Err(ExportError::Invalid(format!(
            "{name}: vertex {v} has a non-finite coordinate"
        )));
    }
    let n = params.modes;
    let named = |e: ExportError| match e {
        ExportError::Invalid(e) => ExportError::Invalid(format!("{name}: {e}")),
        e => e,
    };
    let map = map_modes_onto(base, &positions, n).map_err(named)?;
    let diag = diagonal(&positions);
    let amplitudes = mode_amplitudes(base, &map, diag, params.scale).map_err(named)?;

    let json: Value = serde_json::from_slice(&scene.json)
        .map_err(|e| ExportError::Invalid(format!("{name}: JSON: {e}")))?;
    let mut doc = Doc::one_buffer(json, &scene.buffers);
    embed_images(&mut doc, name)?;
    let owners = own_meshes(&mut doc, &scene.placements);
    let modes = Modes {
        map: &map,
        amplitudes: &amplitudes,
        to_metres,
    };
    let mut placements_info = Vec::new();
    // (node, first new target, targets in all) of each node given targets.
    let mut animated: Vec<(usize, usize, usize)> = Vec::new();
    for (node, mesh, prims) in &owners {
        let first = add_targets(&mut doc, *mesh, prims, &modes, name)?;
        if let Some(node) = *node {
            if let Some(w) = doc.array("nodes")[node]
                .get_mut("weights")
                .and_then(Value::as_array_mut)
            {
                w.extend(std::iter::repeat_n(json!(0.0), n));
            }
            animated.push((node, first, first + n));
        }
        for p in prims {
            placements_info.push(json!({
                "node": p.node,
                "mesh": mesh,
                "primitive": p.primitive,
                "first_vertex": p.first_vertex,
                "vertices": p.vertices,
                "first_target": first,
            }));
        }
    }
    let nv = positions.len();

    pad_weight_animations(&mut doc, &animated, n, name)?;

    let modes_info = add_mode_animations(&mut doc, &animated, amplitudes, params);

    let (max_d, worst) = map.max_distance();
    let extras = extras_of(&mut doc.json, "the document", name)?;
    extras.insert(
        "dcr".into(),
        onto_extras(base, params, diag, &map, modes_info, Some(placements_info)),
    );
    while !doc.bin.len().is_multiple_of(4) {
        doc.bin.push(0);
    }
    doc.json["buffers"] = json!([{ "byteLength": doc.bin.len() }]);
    let bytes = glb(&doc, name)?;
    let info = OntoInfo {
        vertices: nv,
        triangles: scene.triangles.len(),
        primitives: scene.placements.len(),
        max_distance_m: max_d,
        max_distance_vertex: worst,
        diagonal_m: diag,
    };
    Ok((bytes, info))
}

impl Doc {
    /// The document with its buffers end to end in one (each at a 4-byte aligned offset) and
    /// every buffer view moved with its buffer.
    fn one_buffer(mut json: Value, buffers: &[std::borrow::Cow<'_, [u8]>]) -> Doc {
        let mut bin = Vec::new();
        let mut offsets = Vec::with_capacity(buffers.len());
        for b in buffers {
            while !bin.len().is_multiple_of(4) {
                bin.push(0);
            }
            offsets.push(bin.len());
            bin.extend_from_slice(b);
        }
        if let Some(views) = json.get_mut("bufferViews").and_then(Value::as_array_mut) {
            for v in views {
                let b = v["buffer"].as_u64().unwrap_or(0) as usize;
                let off = v["byteOffset"].as_u64().unwrap_or(0) as usize;
                v["buffer"] = json!(0);
                v["byteOffset"] = json!(off + offsets.get(b).copied().unwrap_or(0));
            }
        }
        Doc { json, bin }
    }
}

/// Each node of the selection placing a mesh, the mesh that will carry its targets and the
/// placements of its primitives. A mesh placed by more than one node is copied for each such
/// node of the selection (each placement moves its own way).
fn own_meshes<'p>(
    doc: &mut Doc,
    placements: &'p [GltfPlacement],
) -> Vec<(Option<usize>, usize, Vec<&'p GltfPlacement>)> {
    let mut users = vec![0usize; doc.len("meshes")];
    let nodes = doc.json.get("nodes").and_then(Value::as_array);
    for node in nodes.into_iter().flatten() {
        if let Some(u) = node
            .get("mesh")
            .and_then(Value::as_u64)
            .and_then(|m| users.get_mut(m as usize))
        {
            *u += 1;
        }
    }
    let mut owners: Vec<(Option<usize>, usize, Vec<&GltfPlacement>)> = Vec::new();
    for p in placements {
        match owners
            .iter_mut()
            .find(|o| o.0 == p.node && o.2[0].mesh == p.mesh)
        {
            Some(o) => o.2.push(p),
            None => owners.push((p.node, p.mesh, vec![p])),
        }
    }
    for (node, mesh, _) in &mut owners {
        if let (Some(node), true) = (*node, users[*mesh] > 1) {
            let copy = doc.array("meshes")[*mesh].clone();
            let m = doc.push("meshes", copy);
            doc.array("nodes")[node]["mesh"] = json!(m);
            *mesh = m;
        }
    }
    owners
}

/// The modes read at the asset's vertices and their amplitudes.
struct Modes<'a> {
    map: &'a OntoMapping,
    /// `(a_j, name, extras entry)` per mode ([`mode_amplitudes`]).
    amplitudes: &'a [(f64, String, Value)],
    /// The asset's unit (m).
    to_metres: f64,
}

/// Appends one `POSITION` target per mode to every primitive of `mesh` (`prims`: its placed
/// triangle primitives; the others get zeros), the names to `extras.targetNames` and zeros to
/// `weights`. Returns the number of targets the mesh had.
fn add_targets(
    doc: &mut Doc,
    mesh: usize,
    prims: &[&GltfPlacement],
    modes: &Modes,
    name: &str,
) -> Result<usize, ExportError> {
    let (map, n) = (modes.map, modes.amplitudes.len());
    let inverse = linear_inverse(&prims[0].world).ok_or_else(|| {
        let at = match prims[0].node {
            Some(k) => format!("node {k}"),
            None => format!("mesh {}", prims[0].mesh),
        };
        ExportError::Invalid(format!(
            "{name}: {at} places its mesh with a singular transform (a zero scale); morph \
             targets cannot be written in its frame"
        ))
    })?;
    let count = doc.array("meshes")[mesh]["primitives"]
        .as_array()
        .map_or(0, Vec::len);
    let first = doc.array("meshes")[mesh]["primitives"][0]["targets"]
        .as_array()
        .map_or(0, Vec::len);
    for k in 0..count {
        let placed = prims.iter().find(|p| p.primitive == k);
        let mut targets = Vec::with_capacity(n);
        for (j, (a, _, _)) in modes.amplitudes.iter().enumerate() {
            let accessor = match placed {
                // L⁻¹ d / s: the scene-frame displacement (m) in the mesh's frame and unit.
                Some(p) => {
                    let mut d = Vec::with_capacity(3 * p.vertices);
                    for v in p.first_vertex..p.first_vertex + p.vertices {
                        let w: [f64; 3] = std::array::from_fn(|x| {
                            a * map.u[(v * 3 + x) * n + j] / modes.to_metres
                        });
                        for row in &inverse {
                            d.push((row[0] * w[0] + row[1] * w[1] + row[2] * w[2]) as f32);
                        }
                    }
                    doc.floats(&d, true, Some(ARRAY_BUFFER))
                }
                // Points or lines: zeros (no buffer view), as many as its vertices.
                None => {
                    let prim = &doc.array("meshes")[mesh]["primitives"][k];
                    let pos = prim["attributes"]["POSITION"].as_u64();
                    let vertices = pos
                        .and_then(|i| doc.array("accessors").get(i as usize)?["count"].as_u64())
                        .ok_or_else(|| {
                            ExportError::Invalid(format!(
                                "{name}: mesh {mesh} primitive {k} has no POSITION; every \
                                 primitive of a mesh given morph targets needs one"
                            ))
                        })?;
                    doc.push(
                        "accessors",
                        json!({ "componentType": 5126, "count": vertices, "type": "VEC3",
                                "min": [0.0, 0.0, 0.0], "max": [0.0, 0.0, 0.0] }),
                    )
                }
            };
            targets.push(json!({ "POSITION": accessor }));
        }
        let prim = &mut doc.array("meshes")[mesh]["primitives"][k];
        let t = prim
            .as_object_mut()
            .ok_or_else(|| {
                ExportError::Invalid(format!(
                    "{name}: mesh {mesh} primitive {k} is not an object"
                ))
            })?
            .entry("targets")
            .or_insert_with(|| json!([]));
        if let Some(t) = t.as_array_mut() {
            t.extend(targets);
        }
    }
    let mesh_json = &mut doc.array("meshes")[mesh];
    if let Some(w) = mesh_json.get_mut("weights").and_then(Value::as_array_mut) {
        w.extend(std::iter::repeat_n(json!(0.0), n));
    }
    let extras = extras_of(mesh_json, &format!("mesh {mesh}"), name)?;
    let mut names: Vec<Value> = extras
        .get("targetNames")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    names.truncate(first);
    while names.len() < first {
        names.push(json!(format!("target {}", names.len())));
    }
    names.extend(modes.amplitudes.iter().map(|(_, t, _)| json!(t)));
    extras.insert("targetNames".into(), Value::Array(names));
    Ok(first)
}

/// One animation per mode, named as the mode, after the asset's own: that target's weight a
/// sine over `params.period_s` (`params.keyframes` linear segments) on every node of
/// `animated` (`(node, first new target, targets in all)`), the other weights zero. Returns the
/// modes' `extras.dcr.modes` entries with their `animation`.
fn add_mode_animations(
    doc: &mut Doc,
    animated: &[(usize, usize, usize)],
    amplitudes: Vec<(f64, String, Value)>,
    params: &OntoParams,
) -> Vec<Value> {
    let k = params.keyframes;
    let times: Vec<f32> = (0..=k)
        .map(|i| (params.period_s * i as f64 / k as f64) as f32)
        .collect();
    let input = (!animated.is_empty()).then(|| doc.floats(&times, false, None));
    let mut modes_info = Vec::with_capacity(amplitudes.len());
    for (j, (_, title, mut info)) in amplitudes.into_iter().enumerate() {
        if let Some(input) = input {
            let mut samplers = Vec::new();
            let mut channels = Vec::new();
            for &(node, first, total) in animated {
                let mut w = vec![0.0f32; (k + 1) * total];
                for i in 0..=k {
                    w[i * total + first + j] = super::loop_weight(i, k);
                }
                let output = doc.floats(&w, false, None);
                channels.push(json!({ "sampler": samplers.len(),
                                      "target": { "node": node, "path": "weights" } }));
                samplers
                    .push(json!({ "input": input, "output": output, "interpolation": "LINEAR" }));
            }
            let anim = doc.push(
                "animations",
                json!({ "name": title, "samplers": samplers, "channels": channels }),
            );
            info["animation"] = json!(anim);
        }
        modes_info.push(info);
    }
    modes_info
}

/// The asset's own animations of the morph weights of a node given targets: each keyframe's
/// `first` weights (three groups of them for cubic splines) followed by `n` zeros, written as
/// a new `FLOAT` output (a sampler shared with another channel is copied first).
fn pad_weight_animations(
    doc: &mut Doc,
    animated: &[(usize, usize, usize)],
    n: usize,
    name: &str,
) -> Result<(), ExportError> {
    let count = doc.len("animations");
    for a in 0..count {
        let channels = doc.array("animations")[a]["channels"]
            .as_array()
            .cloned()
            .unwrap_or_default();
        for (c, channel) in channels.iter().enumerate() {
            let node = channel["target"]["node"].as_u64().map(|k| k as usize);
            let Some(&(_, first, _)) = animated.iter().find(|x| Some(x.0) == node) else {
                continue;
            };
            if channel["target"]["path"] != "weights" {
                continue;
            }
            let at = format!("animation {a} channel {c}");
            let sampler = channel["sampler"].as_u64().unwrap_or(0) as usize;
            let shared = channels
                .iter()
                .filter(|x| x["sampler"].as_u64() == Some(sampler as u64))
                .count()
                > 1;
            let old = doc.array("animations")[a]["samplers"][sampler].clone();
            let output = old["output"].as_u64().unwrap_or(0) as usize;
            let values = read_weights(doc, output).map_err(|e| {
                ExportError::Invalid(format!("{name}: {at}: the weights (accessor {output}) {e}"))
            })?;
            if first == 0 || !values.len().is_multiple_of(first) {
                return Err(ExportError::Invalid(format!(
                    "{name}: {at} animates {} weights, not a multiple of the mesh's {first}                      morph targets",
                    values.len()
                )));
            }
            let padded: Vec<f32> = values
                .chunks(first)
                .flat_map(|w| w.iter().copied().chain(std::iter::repeat_n(0.0, n)))
                .collect();
            let acc = doc.floats(&padded, false, None);
            let anim = &mut doc.array("animations")[a];
            if shared {
                let mut copy = old;
                copy["output"] = json!(acc);
                let samplers = anim["samplers"].as_array_mut().expect("validated samplers");
                samplers.push(copy);
                anim["channels"][c]["sampler"] = json!(samplers.len() - 1);
            } else {
                anim["samplers"][sampler]["output"] = json!(acc);
            }
        }
    }
    Ok(())
}

/// The values of an animation output accessor of morph weights: `FLOAT`, or normalized
/// 8- or 16-bit integers, tightly packed in the binary buffer.
fn read_weights(doc: &mut Doc, acc: usize) -> Result<Vec<f32>, String> {
    let a = doc
        .array("accessors")
        .get(acc)
        .cloned()
        .ok_or("do not exist")?;
    if a.get("sparse").is_some() {
        return Err("are sparse, which is not read".into());
    }
    let count = a["count"].as_u64().ok_or("have no count")? as usize;
    let ty = a["componentType"].as_u64().unwrap_or(0);
    let width = match ty {
        5126 => 4,
        5120 | 5121 => 1,
        5122 | 5123 => 2,
        _ => return Err("are not FLOAT or a normalized integer".into()),
    };
    let Some(view) = a["bufferView"].as_u64() else {
        return Ok(vec![0.0; count]);
    };
    let v = &doc.array("bufferViews")[view as usize];
    let start = v["byteOffset"].as_u64().unwrap_or(0) as usize
        + a["byteOffset"].as_u64().unwrap_or(0) as usize;
    let bytes = count
        .checked_mul(width)
        .and_then(|len| doc.bin.get(start..start.checked_add(len)?))
        .ok_or("lie outside the buffer")?;
    let ty = match ty {
        5120 => DataType::I8,
        5121 => DataType::U8,
        5122 => DataType::I16,
        5123 => DataType::U16,
        _ => DataType::F32,
    };
    Ok(bytes
        .chunks_exact(width)
        .map(|e| gltf_component(e, 0, ty, true) as f32)
        .collect())
}

/// Images in files beside the asset move into the binary buffer (data URIs stay as they are).
fn embed_images(doc: &mut Doc, name: &str) -> Result<(), ExportError> {
    let count = doc.len("images");
    for i in 0..count {
        let Some(uri) = doc.array("images")[i]["uri"].as_str().map(str::to_owned) else {
            continue;
        };
        if uri.starts_with("data:") {
            continue;
        }
        let what = format!("image {i}");
        let bytes = read_beside(&uri, None, &what, name)
            .map_err(|e| ExportError::Invalid(e.to_string()))?;
        let mime = image_mime(&bytes).ok_or_else(|| {
            ExportError::Invalid(format!(
                "{name}: {what} ({uri}) is not a PNG, JPEG, WebP or KTX2 image; a GLB embeds \
                 its images"
            ))
        })?;
        let view = doc.view(&bytes, None);
        let image = doc.array("images")[i]
            .as_object_mut()
            .ok_or_else(|| ExportError::Invalid(format!("{name}: {what} is not an object")))?;
        image.remove("uri");
        image.insert("bufferView".into(), json!(view));
        image.insert("mimeType".into(), json!(mime));
    }
    Ok(())
}

/// The GLB container of `doc`, its JSON parsed and validated ([`validate_document`]) first.
fn glb(doc: &Doc, name: &str) -> Result<Vec<u8>, ExportError> {
    let json = serde_json::to_vec(&doc.json)
        .map_err(|e| ExportError::Invalid(format!("glTF JSON: {e}")))?;
    gltf::json::deserialize::from_slice::<gltf::json::Root>(&json)
        .map_err(|e| e.to_string())
        .and_then(|root| validate_document(&root))
        .map_err(|e| {
            ExportError::Invalid(format!(
                "{name}: the asset with the morph targets does not validate as glTF ({e}); \
                 please report this with the asset"
            ))
        })?;
    glb_container(json, &doc.bin).map_err(|e| {
        ExportError::Invalid(format!(
            "{name} with the morph targets: {e}; export fewer modes (--modes)"
        ))
    })
}
