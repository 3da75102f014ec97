//! `modal-bake export --gltf OUT --onto ASSET.gltf|.glb`: the modes are added to the asset
//! itself. Its morph targets, written in each primitive's own frame, move the placed vertices
//! as the modes move the base (through a mirroring, non-uniformly scaling node and a unit
//! other than metres); what the asset had is kept (its node tree, material and texture, its
//! own morph target and animations, a second buffer's data), its animation of the weights
//! gains zeros for the new targets, a mesh shared with a node outside `--object` is copied,
//! points and lines get zero targets, and the GLB stands alone and passes the Khronos
//! glTF-Validator.

mod common;

use std::path::Path;
use std::process::Command;

use base64::Engine as _;
use common::gltf_check::{repo_root, validate_gltf};
use dcr_runtime::format::ModesFile;
use serde_json::{json, Value};

/// A 1 × 1 PNG.
const PNG: &str = "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNkYPhfDwAChwGA60e6kgAAAABJRU5ErkJggg==";

/// The placing node's world matrix, column-major (`m[column][row]`): the parent's rotation by
/// 90° about z and translation (1, 2, 3) m (in mm here), times the child's scale (1, −2, 0.5).
const PARENT: [[f64; 4]; 4] = [
    [0.0, 1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [1000.0, 2000.0, 3000.0, 1.0],
];
const SCALE: [f64; 3] = [1.0, -2.0, 0.5];

/// World (mm) of a point in the child's frame.
fn world(p: [f64; 3]) -> [f64; 3] {
    let s = [p[0] * SCALE[0], p[1] * SCALE[1], p[2] * SCALE[2]];
    std::array::from_fn(|r| (0..3).map(|c| PARENT[c][r] * s[c]).sum::<f64>() + PARENT[3][r])
}

/// A world displacement (mm) of a displacement in the child's frame.
fn world_dir(d: [f32; 3]) -> [f64; 3] {
    let s = [
        d[0] as f64 * SCALE[0],
        d[1] as f64 * SCALE[1],
        d[2] as f64 * SCALE[2],
    ];
    std::array::from_fn(|r| (0..3).map(|c| PARENT[c][r] * s[c]).sum::<f64>())
}

/// The child-frame point whose world position is `w` (mm).
fn local(w: [f64; 3]) -> [f64; 3] {
    let t = [w[0] - 1000.0, w[1] - 2000.0, w[2] - 3000.0];
    // Rotation by −90° about z, then the scale undone.
    let r = [t[1], -t[0], t[2]];
    std::array::from_fn(|k| r[k] / SCALE[k])
}

fn le_f32(data: &[f32]) -> Vec<u8> {
    data.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Every float of a tightly packed f32 accessor of the written GLB (zeros without a view).
fn floats(doc: &Value, bin: &[u8], acc: usize) -> Vec<f32> {
    let a = &doc["accessors"][acc];
    let comps = match a["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        t => panic!("{t}"),
    };
    let n = a["count"].as_u64().unwrap() as usize * comps;
    let Some(view) = a["bufferView"].as_u64() else {
        return vec![0.0; n];
    };
    let v = &doc["bufferViews"][view as usize];
    assert_eq!(v["buffer"], 0);
    let start = v["byteOffset"].as_u64().unwrap_or(0) as usize
        + a["byteOffset"].as_u64().unwrap_or(0) as usize;
    (0..n)
        .map(|i| f32::from_le_bytes(bin[start + 4 * i..start + 4 * i + 4].try_into().unwrap()))
        .collect()
}

/// The beam base's surface as a `.gltf` in mm (`beam.bin` and `tex.png` beside it): node 0
/// (`rig`, the parent) holds node 1 (`beam`, the child, placing mesh 0) and node 2 (`other`,
/// placing mesh 0 as well, 5 m away); mesh 0 has the beam's triangles (textured, with one morph
/// target `smile` and weights [0.5]) and a two-vertex LINES primitive; `sway` moves `other`
/// and `blink` moves `beam`'s weight on a cubic spline, their data in a second buffer given as a data URI.
fn write_asset(dir: &Path, base: &ModesFile) -> (Value, Vec<[f64; 3]>) {
    let nv = base.surface_vertices.len();
    let positions: Vec<[f64; 3]> = base
        .surface_vertices
        .iter()
        .map(|p| local(p.map(|x| 1000.0 * x)))
        .collect();
    let pos: Vec<f32> = positions.iter().flat_map(|p| p.map(|x| x as f32)).collect();
    let uv: Vec<f32> = (0..2 * nv).map(|i| (i % 7) as f32 / 7.0).collect();
    // Mirrored placement (det < 0): the local triangles are written reversed, as an exporter
    // of the mirrored object would.
    let idx: Vec<u32> = base
        .surface_triangles
        .iter()
        .flat_map(|t| [t[0], t[2], t[1]])
        .collect();
    let line: [f32; 6] = [0.0, 0.0, 0.0, 10.0, 0.0, 0.0];
    let mut bin = le_f32(&pos);
    let uv_at = bin.len();
    bin.extend(le_f32(&uv));
    let idx_at = bin.len();
    bin.extend(idx.iter().flat_map(|i| i.to_le_bytes()));
    let line_at = bin.len();
    bin.extend(le_f32(&line));
    std::fs::write(dir.join("beam.bin"), &bin).unwrap();
    std::fs::write(
        dir.join("tex.png"),
        base64::engine::general_purpose::STANDARD
            .decode(PNG)
            .unwrap(),
    )
    .unwrap();
    // Times, `other`'s translations, `beam`'s weights.
    // (a cubic spline: in-tangent, value, out-tangent per keyframe).
    let anim = le_f32(&[
        0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 0.5, 1.0, -0.5,
    ]);
    let (lo, hi) = (0..3).fold(([f32::MAX; 3], [f32::MIN; 3]), |(mut lo, mut hi), k| {
        for p in pos.chunks(3) {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
        (lo, hi)
    });
    let doc = json!({
        "asset": {"version": "2.0", "generator": "a test exporter"},
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "rig", "matrix": PARENT.iter().flatten().collect::<Vec<_>>(), "children": [1]},
            {"name": "beam", "mesh": 0, "scale": SCALE},
            {"name": "other", "mesh": 0, "translation": [5000.0, 0.0, 0.0]}
        ],
        "meshes": [{"name": "beam-mesh", "weights": [0.5], "extras": {"targetNames": ["smile"]},
            "primitives": [
                {"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0,
                 "targets": [{"POSITION": 4}]},
                {"attributes": {"POSITION": 3}, "mode": 1, "targets": [{"POSITION": 5}]}
            ]}],
        "materials": [{"name": "wood", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "tex.png"}],
        "animations": [{"name": "sway",
            "samplers": [{"input": 6, "output": 7}],
            "channels": [{"sampler": 0, "target": {"node": 2, "path": "translation"}}]},
            {"name": "blink", "samplers": [{"input": 6, "output": 8, "interpolation": "CUBICSPLINE"}],
             "channels": [{"sampler": 0, "target": {"node": 1, "path": "weights"}}]}],
        "buffers": [
            {"uri": "beam.bin", "byteLength": bin.len()},
            {"uri": format!("data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&anim)), "byteLength": anim.len()}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12 * nv, "target": 34962},
            {"buffer": 0, "byteOffset": uv_at, "byteLength": 8 * nv, "target": 34962},
            {"buffer": 0, "byteOffset": idx_at, "byteLength": 4 * idx.len(), "target": 34963},
            {"buffer": 0, "byteOffset": line_at, "byteLength": 24, "target": 34962},
            {"buffer": 1, "byteOffset": 0, "byteLength": 8},
            {"buffer": 1, "byteOffset": 8, "byteLength": 24},
            {"buffer": 1, "byteOffset": 32, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": nv, "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5125, "count": idx.len(), "type": "SCALAR"},
            {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [10.0, 0.0, 0.0]},
            {"componentType": 5126, "count": nv, "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [0.0, 0.0, 0.0]},
            {"componentType": 5126, "count": 2, "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [0.0, 0.0, 0.0]},
            {"bufferView": 4, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0.0], "max": [1.0]},
            {"bufferView": 5, "componentType": 5126, "count": 2, "type": "VEC3"},
            {"bufferView": 6, "componentType": 5126, "count": 6, "type": "SCALAR"}
        ]
    });
    std::fs::write(
        dir.join("beam.gltf"),
        serde_json::to_vec_pretty(&doc).unwrap(),
    )
    .unwrap();
    (doc, positions)
}

/// The beam (`data/meshes/beam.msh`, steel, free-free) baked with `modes` modes into `dir`.
fn bake_beam(dir: &Path, modes: usize) -> (std::path::PathBuf, ModesFile) {
    let path = dir.join("beam.modes");
    let o = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .arg("bake")
        .arg(repo_root().join("data/meshes/beam.msh"))
        .args(["-o".as_ref(), path.as_os_str()])
        .args(["--modes", &modes.to_string(), "--material", "steel"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let base = ModesFile::read(&path).unwrap();
    (path, base)
}

#[test]
fn targets_in_each_primitives_frame_move_the_placed_vertices_as_the_modes_and_the_asset_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let (asset_dir, out_dir) = (dir.path().join("asset"), dir.path().join("out"));
    std::fs::create_dir_all(&asset_dir).unwrap();
    std::fs::create_dir_all(&out_dir).unwrap();
    let (base_path, base) = bake_beam(dir.path(), 4);
    let exe = env!("CARGO_BIN_EXE_modal-bake");
    let (m, nv) = (base.num_modes(), base.surface_vertices.len());
    let (input, local_positions) = write_asset(&asset_dir, &base);
    for (p, w) in local_positions.iter().zip(&base.surface_vertices) {
        let back = world(*p);
        assert!(
            (0..3).all(|k| (back[k] - 1000.0 * w[k]).abs() < 1e-9),
            "{back:?} {w:?}"
        );
    }
    let out = out_dir.join("beam_modes.glb");
    let o = Command::new(exe)
        .arg("export")
        .arg(&base_path)
        .args(["--gltf".as_ref(), out.as_os_str()])
        .args(["--onto".as_ref(), asset_dir.join("beam.gltf").as_os_str()])
        .args(["--object", "beam", "--units", "mm"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(&format!("morph targets on {nv} vertices")) && !err.contains("warning"),
        "{err}"
    );
    // The GLB stands alone: nothing beside it.
    std::fs::remove_dir_all(&asset_dir).unwrap();
    validate_gltf(&out);

    let bytes = std::fs::read(&out).unwrap();
    let glb = gltf::binary::Glb::from_slice(&bytes).unwrap();
    let doc: Value = serde_json::from_slice(&glb.json).unwrap();
    let bin = glb.bin.unwrap().into_owned();
    let dcr = &doc["extras"]["dcr"];
    assert_eq!(dcr["kind"], "modes_onto");

    // One buffer, the GLB's; the image embedded; the kept data intact.
    assert_eq!(doc["buffers"].as_array().unwrap().len(), 1);
    assert!(doc["buffers"][0].get("uri").is_none());
    let image = &doc["images"][0];
    assert!(image.get("uri").is_none() && image["mimeType"] == "image/png");
    let v = &doc["bufferViews"][image["bufferView"].as_u64().unwrap() as usize];
    let at = v["byteOffset"].as_u64().unwrap() as usize;
    assert_eq!(
        bin[at..at + v["byteLength"].as_u64().unwrap() as usize],
        base64::engine::general_purpose::STANDARD
            .decode(PNG)
            .unwrap()[..]
    );
    assert_eq!(floats(&doc, &bin, 7), [0.0, 0.0, 0.0, 0.0, 0.25, 0.0]);
    assert_eq!(
        floats(&doc, &bin, 1)[..4],
        [0.0, 1.0 / 7.0, 2.0 / 7.0, 3.0 / 7.0]
    );
    assert_eq!(doc["nodes"][0]["name"], "rig");
    assert_eq!(doc["nodes"][0]["children"], json!([1]));
    assert_eq!(doc["materials"], input["materials"]);
    assert_eq!(doc["asset"]["generator"], "a test exporter");

    // `other` keeps mesh 0 as it was; `beam` has a copy with the modes after `smile`.
    assert_eq!(doc["nodes"][2]["mesh"], 0);
    assert_eq!(doc["meshes"][0], input["meshes"][0]);
    let mesh_index = doc["nodes"][1]["mesh"].as_u64().unwrap() as usize;
    assert_eq!(mesh_index, 1);
    let mesh = &doc["meshes"][mesh_index];
    let names = mesh["extras"]["targetNames"].as_array().unwrap();
    assert_eq!(names.len(), 1 + m);
    assert_eq!(names[0], "smile");
    let freqs = base.frequencies_hz();
    for j in 0..m {
        assert_eq!(
            names[1 + j],
            modal_bake::export::mode_title(j, freqs[j]).as_str()
        );
    }
    assert_eq!(mesh["weights"].as_array().unwrap().len(), 1 + m);
    assert_eq!(mesh["weights"][0], 0.5);
    // Lines: zero targets with the primitive's vertex count.
    let lines = &mesh["primitives"][1]["targets"];
    assert_eq!(lines.as_array().unwrap().len(), 1 + m);
    for t in &lines.as_array().unwrap()[1..] {
        let a = &doc["accessors"][t["POSITION"].as_u64().unwrap() as usize];
        assert!(a.get("bufferView").is_none() && a["count"] == 2);
    }
    assert_eq!(
        dcr["placements"],
        json!([{"node": 1, "mesh": 1, "primitive": 0, "first_vertex": 0, "vertices": nv, "first_target": 1}])
    );

    // The physics: world(target) is a_j U_j at each vertex (the asset's vertices are the
    // base's surface vertices, in mm, placed through the mirroring node).
    let targets = mesh["primitives"][0]["targets"].as_array().unwrap();
    let diag_m = dcr["diagonal_m"].as_f64().unwrap();
    for j in 0..m {
        let a = dcr["modes"][j]["modal_coordinate"].as_f64().unwrap();
        let t = floats(
            &doc,
            &bin,
            targets[1 + j]["POSITION"].as_u64().unwrap() as usize,
        );
        assert_eq!(t.len(), 3 * nv);
        let mut largest: f64 = 0.0;
        for v in 0..nv {
            let d = world_dir([t[3 * v], t[3 * v + 1], t[3 * v + 2]]);
            let norm = (0..3).map(|c| (d[c] / 1000.0).powi(2)).sum::<f64>().sqrt();
            largest = largest.max(norm);
            for c in 0..3 {
                let want = a * base.modes[(v * 3 + c) * m + j];
                assert!(
                    (d[c] / 1000.0 - want).abs() <= 1e-5 * diag_m,
                    "mode {j} vertex {v} axis {c}: {} m vs {want} m",
                    d[c] / 1000.0
                );
            }
        }
        // The largest displacement is scale × diagonal (0.05 by default).
        assert!((largest / diag_m - 0.05).abs() < 1e-5, "{largest}");
        // Its animation: the mode's weight a sine on `beam`, the other weights zero.
        let anim = &doc["animations"][dcr["modes"][j]["animation"].as_u64().unwrap() as usize];
        assert_eq!(anim["name"], names[1 + j]);
        assert_eq!(
            anim["channels"][0]["target"],
            json!({"node": 1, "path": "weights"})
        );
        let w = floats(
            &doc,
            &bin,
            anim["samplers"][0]["output"].as_u64().unwrap() as usize,
        );
        let k = w.len() / (1 + m);
        for i in 0..k {
            for t in 0..1 + m {
                let want = if t == 1 + j {
                    // `libm`'s sin, as the exporter's: the C library's differs by platform.
                    libm::sin(std::f64::consts::TAU * i as f64 / (k - 1) as f64) as f32
                } else {
                    0.0
                };
                assert_eq!(w[i * (1 + m) + t], want);
            }
        }
    }
    assert_eq!(doc["animations"][0]["name"], "sway");
    assert_eq!(doc["animations"].as_array().unwrap().len(), 2 + m);
    // `blink` animated beam's one weight on a cubic spline: now each of its six values
    // (in-tangent, value, out-tangent per keyframe) followed by m zeros.
    let blink = &doc["animations"][1];
    assert_eq!(blink["samplers"][0]["interpolation"], "CUBICSPLINE");
    let w = floats(
        &doc,
        &bin,
        blink["samplers"][0]["output"].as_u64().unwrap() as usize,
    );
    let want: Vec<f32> = [0.0f32, 0.0, 0.0, 0.5, 1.0, -0.5]
        .iter()
        .flat_map(|&x| std::iter::once(x).chain(std::iter::repeat_n(0.0, m)))
        .collect();
    assert_eq!(w, want);
}

/// What cannot be written is refused naming the asset and the cause, and nothing is written: an
/// image beside the asset that is not an image, a missing image file, a node scaling its mesh
/// to nothing, and document `extras` that are not an object.
#[test]
fn assets_that_cannot_carry_the_targets_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let (base_path, base) = bake_beam(dir.path(), 2);
    let exe = env!("CARGO_BIN_EXE_modal-bake");
    let (doc, _) = write_asset(dir.path(), &base);
    type Case = (&'static str, fn(&mut Value), &'static str);
    let cases: [Case; 4] = [
        (
            "text.gltf",
            |d| d["images"][0]["uri"] = json!("beam.gltf"),
            "image 0 (beam.gltf) is not a PNG, JPEG, WebP or KTX2 image",
        ),
        (
            "gone.gltf",
            |d| d["images"][0]["uri"] = json!("gone%20away.png"),
            "gone away.png",
        ),
        (
            "flat.gltf",
            |d| d["nodes"][1]["scale"] = json!([1.0, 0.0, 1.0]),
            "node 1 places its mesh with a singular transform",
        ),
        (
            "extras.gltf",
            |d| d["extras"] = json!([1, 2]),
            "the extras of the document are not a JSON object",
        ),
    ];
    for (file, edit, want) in cases {
        let mut d = doc.clone();
        edit(&mut d);
        let asset = dir.path().join(file);
        std::fs::write(&asset, serde_json::to_vec(&d).unwrap()).unwrap();
        let out = dir.path().join("out.glb");
        let o = Command::new(exe)
            .arg("export")
            .arg(&base_path)
            .args(["--gltf".as_ref(), out.as_os_str()])
            .args(["--onto".as_ref(), asset.as_os_str()])
            .args(["--object", "beam", "--units", "mm"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{file}: {err}");
        assert!(err.contains(want) && err.contains(file), "{file}: {err}");
        assert!(!out.exists(), "{file}: an output was left behind");
    }
}

/// Every leaf of a JSON value: its path (object keys and array indices).
fn leaves(v: &Value, path: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                path.push(json!(k));
                leaves(x, path, out);
                path.pop();
            }
        }
        Value::Array(a) if !a.is_empty() => {
            for (i, x) in a.iter().enumerate() {
                path.push(json!(i));
                leaves(x, path, out);
                path.pop();
            }
        }
        _ => out.push(path.clone()),
    }
}

fn at<'v>(v: &'v mut Value, path: &[Value]) -> &'v mut Value {
    path.iter().fold(v, |v, k| match k {
        Value::String(k) => &mut v[k.as_str()],
        k => &mut v[k.as_u64().unwrap() as usize],
    })
}

/// Structure-aware mutation of the test asset's document (indices, counts, offsets, types and
/// members changed or removed; `DCR_FUZZ_ITERS`, default 300): the export never panics, and a
/// refusal names the asset.
#[test]
fn mutated_assets_never_panic_the_export() {
    let dir = tempfile::tempdir().unwrap();
    let (_, base) = bake_beam(dir.path(), 2);
    let (doc, _) = write_asset(dir.path(), &base);
    let mut paths = Vec::new();
    leaves(&doc, &mut Vec::new(), &mut paths);
    let iters: usize = std::env::var("DCR_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300);
    let mut rng = dcr_runtime::testing::SplitMix64(
        std::env::var("DCR_FUZZ_SEED")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(7),
    );
    let asset = dir.path().join("mutant.gltf");
    let out = dir.path().join("mutant.glb");
    let params = modal_bake::export::OntoParams {
        modes: 2,
        ..Default::default()
    };
    let (mut written, mut refused) = (0, 0);
    for i in 0..iters {
        let mut d = doc.clone();
        let mut what = Vec::new();
        for _ in 0..1 + rng.below(3) {
            let path = &paths[rng.below(paths.len())];
            let leaf = at(&mut d, path);
            let new = match rng.below(8) {
                0 => json!(0),
                1 => json!(-1),
                2 => json!(u32::MAX),
                3 => json!(1e300),
                4 => json!(leaf.as_u64().unwrap_or(0) + 1),
                5 => json!("x"),
                6 => Value::Null,
                _ => json!([]),
            };
            what.push(format!("{path:?} = {new}"));
            *leaf = new;
        }
        std::fs::write(&asset, serde_json::to_vec(&d).unwrap()).unwrap();
        let object = if rng.below(2) == 0 {
            Some("beam")
        } else {
            None
        };
        let r = std::panic::catch_unwind(|| {
            modal_bake::export::write_modes_onto_gltf(&base, &asset, 1e-3, object, &params, &out)
        });
        match r {
            Err(_) => panic!("mutation {i} panicked: {}", what.join(", ")),
            Ok(Ok(_)) => written += 1,
            Ok(Err(e)) => {
                refused += 1;
                let e = e.to_string();
                assert!(
                    e.contains("mutant.gltf"),
                    "mutation {i} ({}): the error does not name the asset: {e}",
                    what.join(", ")
                );
            }
        }
    }
    eprintln!("{iters} mutated assets: {written} written, {refused} refused");
    assert!(
        written > 0 && refused > 0,
        "{written} written, {refused} refused"
    );
}

/// A document without scenes (every mesh read once, as it is): the mesh gains the targets, no
/// node or animation is invented (glTF refuses empty top-level arrays), and the file passes
/// the Khronos glTF-Validator.
#[test]
fn a_document_without_scenes_gains_targets_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let (base_path, base) = bake_beam(dir.path(), 2);
    let (mut doc, _) = write_asset(dir.path(), &base);
    for k in ["scene", "scenes", "nodes", "animations"] {
        doc.as_object_mut().unwrap().remove(k);
    }
    // Unplaced, the mesh lies away from the base (the export warns of the distance and
    // writes): only the document's structure is checked here.
    let asset = dir.path().join("noscene.gltf");
    std::fs::write(&asset, serde_json::to_vec(&doc).unwrap()).unwrap();
    let out = dir.path().join("noscene.glb");
    let o = Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .arg("export")
        .arg(&base_path)
        .args(["--gltf".as_ref(), out.as_os_str()])
        .args(["--onto".as_ref(), asset.as_os_str()])
        .args(["--units", "mm"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    validate_gltf(&out);
    let bytes = std::fs::read(&out).unwrap();
    let glb = gltf::binary::Glb::from_slice(&bytes).unwrap();
    let d: Value = serde_json::from_slice(&glb.json).unwrap();
    assert!(d.get("nodes").is_none() && d.get("animations").is_none());
    assert_eq!(d["meshes"].as_array().unwrap().len(), 1);
    for prim in d["meshes"][0]["primitives"].as_array().unwrap() {
        assert_eq!(prim["targets"].as_array().unwrap().len(), 1 + 2);
    }
    assert!(d["extras"]["dcr"]["modes"][0].get("animation").is_none());
}
