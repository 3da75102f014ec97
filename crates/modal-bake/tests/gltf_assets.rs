//! glTF 2.0 surface assets: a `.glb`, a `.gltf` with a base64 data URI and one with a buffer
//! file beside it read as the same cube, placed by the scene's node transforms (a mirroring
//! node keeps the surface outward); strips and fans are triangulated with one winding; and
//! quantized positions are dequantized by their node; hostile documents (extents past their buffers, counts that overflow, indices out of range,
//! nodes placed twice, instancing past the file's size, compressed geometry) are refused with
//! the file named.

use std::path::Path;

use modal_bake::mesh::surface::{read_surface, read_surface_bytes, read_surface_unwelded};
use serde_json::{json, Value};

#[path = "common/gltf_cube.rs"]
mod gltf_cube;
use gltf_cube::{cube_document, cube_glb, cube_triangles, glb, Q, V};

#[path = "common/gmsh_gate.rs"]
mod gmsh_gate;
use gmsh_gate::have_gmsh;

/// Signed volume of a triangle soup (m³): positive when the triangles face outward.
fn signed_volume(p: &[[f64; 3]], t: &[[usize; 3]]) -> f64 {
    t.iter()
        .map(|&[a, b, c]| {
            let (a, b, c) = (p[a], p[b], p[c]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

#[test]
fn a_glb_cube_reads_closed_with_its_eight_corners() {
    let mut s = read_surface_bytes(&cube_glb(), "cube.glb").unwrap();
    s.check_closed("cube.glb").unwrap();
    let (p, t) = read_surface_unwelded(&cube_glb(), "cube.glb").unwrap();
    assert_eq!(p.len(), 8);
    assert_eq!(t.len(), 12);
    assert!((signed_volume(&p, &t) - 1.0).abs() < 1e-12);
}

// An accessor without a buffer view is zeros in glTF 2.0 (gltf-json 1.4.1's validation calls
// it missing data): a morph target written so does not stop the read.
#[test]
fn a_morph_target_of_zeros_without_a_buffer_view_is_read_past() {
    let (mut doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"componentType": 5126, "count": 8,
        "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [0.0, 0.0, 0.0]}));
    doc["meshes"][0]["primitives"][0]["targets"] = json!([{"POSITION": 2}]);
    let (p, t) = read_surface_unwelded(&glb(&doc, &bin), "zeros.glb").unwrap();
    assert_eq!((p.len(), t.len()), (8, 12));
    assert!((signed_volume(&p, &t) - 1.0).abs() < 1e-12);
}

// The scene's transforms place the mesh: a parent translation, a child mirrored in x and
// scaled. A mirroring placement turns the triangles inside out unless their winding is
// reversed: the volume stays positive and the surface closed and oriented.
#[test]
fn node_transforms_place_the_mesh_and_a_mirror_keeps_it_outward() {
    let (mut doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    doc["scenes"] = json!([{"nodes": [0]}]);
    doc["nodes"] = json!([
        {"translation": [1.0, 2.0, 3.0], "children": [1]},
        {"mesh": 0, "scale": [-2.0, 2.0, 2.0]}
    ]);
    let bytes = glb(&doc, &bin);
    let (p, t) = read_surface_unwelded(&bytes, "placed.glb").unwrap();
    for (q, v) in p.iter().zip(V) {
        let want = [1.0 - 2.0 * v[0], 2.0 + 2.0 * v[1], 3.0 + 2.0 * v[2]];
        assert_eq!(*q, want);
    }
    assert!(
        (signed_volume(&p, &t) - 8.0).abs() < 1e-9,
        "{}",
        signed_volume(&p, &t)
    );
    read_surface_bytes(&bytes, "placed.glb")
        .unwrap()
        .check_closed("placed.glb")
        .unwrap();
    // A matrix with the same mirror: the same positions.
    doc["nodes"][1] = json!({"mesh": 0, "matrix": [
        -2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0]});
    let (q, u) = read_surface_unwelded(&glb(&doc, &bin), "matrix.glb").unwrap();
    assert_eq!((p, t), (q, u));
}

// One cube through three containers: GLB, `.gltf` with the buffer as a base64 data URI, and
// `.gltf` with the buffer in a file beside it whose name needs a URI escape.
#[test]
fn glb_data_uri_and_buffer_file_read_the_same_cube() {
    let want = read_surface_unwelded(&cube_glb(), "cube.glb").unwrap();
    let text = gltf_cube::cube_gltf_embedded();
    assert_eq!(read_surface_unwelded(&text, "cube.gltf").unwrap(), want);
    let (doc, bin) = cube_document(&cube_triangles(), 4, json!({}));

    let dir = tempfile::tempdir().unwrap();
    let mut beside = doc;
    beside["buffers"][0]["uri"] = json!("cube%20data.bin");
    std::fs::write(dir.path().join("cube data.bin"), &bin).unwrap();
    let path = dir.path().join("cube.gltf");
    std::fs::write(&path, serde_json::to_vec(&beside).unwrap()).unwrap();
    let mut s = read_surface(&path).unwrap();
    s.check_closed("cube.gltf").unwrap();
    assert_eq!(
        read_surface_unwelded(&std::fs::read(&path).unwrap(), &path.display().to_string()).unwrap(),
        want
    );

    // The buffer file shorter than its byteLength: refused, naming both files.
    std::fs::write(dir.path().join("cube data.bin"), &bin[..50]).unwrap();
    let e = read_surface(&path).unwrap_err().to_string();
    assert!(
        e.starts_with(&path.display().to_string())
            && e.contains("cube data.bin")
            && e.contains("50 bytes"),
        "{e}"
    );
}

// Strips and fans: each face of the cube as a 4-vertex strip or fan in its own primitive. The
// strip's odd triangles are reversed, so every triangle keeps the quad's outward winding.
#[test]
fn strips_and_fans_triangulate_with_one_winding() {
    for (mode, order) in [(5u32, [0usize, 1, 3, 2]), (6, [0, 1, 2, 3])] {
        let idx: Vec<u16> = Q.iter().flat_map(|q| order.map(|k| q[k] as u16)).collect();
        let (mut doc, bin) = cube_document(&idx, mode, json!({}));
        doc["bufferViews"] = json!([{"buffer": 0, "byteLength": 96},
            {"buffer": 0, "byteOffset": 96, "byteLength": 48}]);
        doc["accessors"][1]["count"] = json!(4);
        // Six primitives, each reading its 4 indices from the one view.
        let mut accessors = vec![doc["accessors"][0].clone()];
        let mut prims = Vec::new();
        for f in 0..6 {
            accessors.push(
                json!({"bufferView": 1, "byteOffset": 8 * f, "componentType": 5123,
                "count": 4, "type": "SCALAR"}),
            );
            prims.push(json!({"attributes": {"POSITION": 0}, "indices": f + 1, "mode": mode}));
        }
        doc["accessors"] = json!(accessors);
        doc["meshes"] = json!([{"primitives": prims}]);
        let bytes = glb(&doc, &bin);
        let (p, t) = read_surface_unwelded(&bytes, "faces.glb").unwrap();
        assert_eq!(t.len(), 12, "mode {mode}");
        assert!((signed_volume(&p, &t) - 1.0).abs() < 1e-12, "mode {mode}");
        read_surface_bytes(&bytes, "faces.glb")
            .unwrap()
            .check_closed("faces.glb")
            .unwrap();
    }
}

// KHR_mesh_quantization as gltfpack writes it: normalized 16-bit positions (stride 8, as
// vertex attributes are 4-byte aligned) dequantized by the node's scale and offset. The same
// cube; without the extension declared, integer positions are refused.
#[test]
fn quantized_positions_are_dequantized_by_the_node() {
    let (mut doc, mut bin) = cube_document(&cube_triangles(), 4, json!({}));
    let idx = bin[96..].to_vec();
    bin.clear();
    for v in V {
        for x in v {
            bin.extend(((x * 65535.0) as u16).to_le_bytes());
        }
        bin.extend([0, 0]);
    }
    bin.extend(&idx);
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    doc["bufferViews"] = json!([
        {"buffer": 0, "byteLength": 64, "byteStride": 8},
        {"buffer": 0, "byteOffset": 64, "byteLength": 72}
    ]);
    doc["accessors"][0] = json!({"bufferView": 0, "componentType": 5123, "normalized": true,
        "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [65535, 65535, 65535]});
    doc["nodes"][0]["scale"] = json!([0.5, 0.5, 0.5]);
    doc["nodes"][0]["translation"] = json!([-0.25, 0.0, 0.0]);
    doc["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    let (p, t) = read_surface_unwelded(&glb(&doc, &bin), "quantized.glb").unwrap();
    for (q, v) in p.iter().zip(V) {
        let want = [0.5 * v[0] - 0.25, 0.5 * v[1], 0.5 * v[2]];
        assert_eq!(*q, want);
    }
    assert!((signed_volume(&p, &t) - 0.125).abs() < 1e-12);
    let o = doc.as_object_mut().unwrap();
    o.remove("extensionsUsed");
    o.remove("extensionsRequired");
    let e = read_surface_bytes(&glb(&doc, &bin), "plain.glb")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("integer positions need KHR_mesh_quantization"),
        "{e}"
    );
}

// A document without scenes: every mesh once, where it is defined.
#[test]
fn a_document_without_scenes_reads_every_mesh() {
    let (mut doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    let o = doc.as_object_mut().unwrap();
    o.remove("scene");
    o.remove("scenes");
    o.remove("nodes");
    let (p, t) = read_surface_unwelded(&glb(&doc, &bin), "bare.glb").unwrap();
    assert_eq!((p.len(), t.len()), (8, 12));
}

/// A change to the cube's glTF document.
type Edit = Box<dyn FnOnce(&mut Value)>;

/// The error of reading the cube GLB after `edit` changed its document.
fn refusal(edit: impl FnOnce(&mut Value), name: &str) -> String {
    let (mut doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    edit(&mut doc);
    match read_surface_bytes(&glb(&doc, &bin), name) {
        Ok(_) => panic!("{name}: read"),
        Err(e) => e.to_string(),
    }
}

// Hostile or unsupported documents: refused with the file named and what is wrong, never a
// panic or an allocation beyond what the file holds.
#[test]
fn hostile_documents_are_refused_with_the_file_and_the_reason() {
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "count0.glb",
            Box::new(|d| d["accessors"][0]["count"] = json!(0)),
            "count 0",
        ),
        (
            "huge.glb",
            Box::new(|d| d["accessors"][1]["count"] = json!(1u64 << 61)),
            "spans 4611686018427387904 bytes of buffer view 1, which has 72",
        ),
        (
            "overflow.glb",
            Box::new(|d| d["accessors"][1]["count"] = json!(1u64 << 63)),
            "count 9223372036854775808 and stride 2",
        ),
        (
            "past.glb",
            Box::new(|d| d["accessors"][0]["byteOffset"] = json!(4)),
            "spans 100 bytes",
        ),
        (
            "view.glb",
            Box::new(|d| d["bufferViews"][1]["byteOffset"] = json!(1000)),
            "lies outside buffer 0",
        ),
        (
            "index.glb",
            Box::new(|d| d["accessors"][0]["count"] = json!(7)),
            "but POSITION has 7 vertices",
        ),
        (
            "twice.glb",
            Box::new(|d| {
                d["nodes"] = json!([{"children": [1]}, {"mesh": 0}]);
                d["scenes"] = json!([{"nodes": [0, 1]}]);
            }),
            "node 1 is placed twice",
        ),
        (
            "draco.glb",
            Box::new(|d| d["extensionsRequired"] = json!(["KHR_draco_mesh_compression"])),
            "without compression",
        ),
        (
            "instancing.glb",
            Box::new(|d| d["extensionsUsed"] = json!(["EXT_mesh_gpu_instancing"])),
            "without GPU instancing",
        ),
        (
            "sparse.glb",
            Box::new(|d| {
                d["accessors"][0]["sparse"] = json!({"count": 1,
                    "indices": {"bufferView": 1, "componentType": 5123},
                    "values": {"bufferView": 0}});
            }),
            "is sparse",
        ),
        (
            "url.glb",
            Box::new(|d| d["buffers"][0]["uri"] = json!("https://example.com/cube.bin")),
            "download it beside the asset",
        ),
        (
            // glTF allows an accessor without a view (zeros), but not as positions.
            "zeros.glb",
            Box::new(|d| {
                d["accessors"][0]
                    .as_object_mut()
                    .unwrap()
                    .remove("bufferView");
            }),
            "accessor 0 has no bufferView",
        ),
        (
            "vec2.glb",
            Box::new(|d| d["accessors"][0]["type"] = json!("VEC2")),
            "not VEC3 FLOAT",
        ),
        (
            "third.glb",
            Box::new(|d| {
                d["accessors"][1]["count"] = json!(35);
            }),
            "35 vertex indices, not a whole number of triangles",
        ),
        (
            "long.glb",
            Box::new(|d| d["buffers"][0]["byteLength"] = json!(10_000)),
            "byteLength is 10000",
        ),
        (
            "instanced.glb",
            Box::new(|d| {
                let n = 20_000;
                let roots: Vec<usize> = (0..n).collect();
                d["nodes"] = json!(vec![json!({"mesh": 0}); n]);
                d["scenes"] = json!([{"nodes": roots}]);
            }),
            "a mesh instanced by many nodes",
        ),
        (
            "noscene.glb",
            Box::new(|d| d["scene"] = json!(3)),
            "invalid glTF",
        ),
    ];
    for (name, edit, want) in cases {
        let e = refusal(edit, name);
        assert!(
            e.starts_with(name) && e.contains(want),
            "{name}: `{e}` (wanted `{want}`)"
        );
    }
    // Not a glTF at all, and a GLB cut short.
    let e = read_surface_bytes(b"{\"asset\": ", "cut.gltf")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("cut.gltf: invalid glTF file"), "{e}");
    let bytes = cube_glb();
    let e = read_surface_bytes(&bytes[..bytes.len() - 10], "short.glb")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("short.glb: invalid glTF file: GLB"), "{e}");
    assert!(Path::new("x.GLB").extension().is_some());
    assert!(modal_bake::mesh::surface::is_surface_asset(Path::new(
        "x.GLB"
    )));
}

fn modal_bake(args: &[&std::ffi::OsStr]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_modal-bake"))
        .args(args)
        .output()
        .unwrap()
}

// The CLI on a GLB: `bake` meshes it as it meshes the same cube written as OBJ (the same
// frequencies, bit for bit), `export --onto` puts the modes on the GLB's own 8 vertices, and a
// broken GLB is named once in the error line.
#[test]
fn the_cli_bakes_a_glb_as_the_same_obj_and_exports_onto_it() {
    if !have_gmsh("the_cli_bakes_a_glb_as_the_same_obj_and_exports_onto_it") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (mut doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    // A scale exact in f32 and f64: the two files hold the same positions bit for bit (gmsh's
    // meshing of a cube's cospherical corners follows the last bit).
    doc["nodes"][0]["scale"] = json!([0.25, 0.25, 0.25]);
    let glb_path = dir.path().join("cube.glb");
    std::fs::write(&glb_path, glb(&doc, &bin)).unwrap();
    let mut obj = String::new();
    for v in V {
        obj += &format!("v {} {} {}\n", 0.25 * v[0], 0.25 * v[1], 0.25 * v[2]);
    }
    for q in Q {
        obj += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    let obj_path = dir.path().join("cube.obj");
    std::fs::write(&obj_path, obj).unwrap();
    let mut freqs = Vec::new();
    for asset in [&glb_path, &obj_path] {
        let base = asset.with_extension("modes");
        let o = modal_bake(&[
            "bake".as_ref(),
            asset.as_os_str(),
            "-o".as_ref(),
            base.as_os_str(),
            "--material=steel".as_ref(),
            "--order=1".as_ref(),
            "--modes=4".as_ref(),
            "--size=0.05".as_ref(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let info = modal_bake(&["info".as_ref(), "--json".as_ref(), base.as_os_str()]);
        let v: Value = serde_json::from_slice(&info.stdout).unwrap();
        freqs.push(v["frequencies_hz"].clone());
    }
    assert_eq!(freqs[0], freqs[1]);
    assert_eq!(freqs[0].as_array().unwrap().len(), 4);
    // A self-contained GLB is checked without meshing it again; a .gltf whose buffer is
    // another file gets no key (the key would not cover that file), so it is meshed again.
    let beside = dir.path().join("beside.gltf");
    let mut doc_beside = doc.clone();
    doc_beside["buffers"][0]["uri"] = json!("beside.bin");
    std::fs::write(dir.path().join("beside.bin"), &bin).unwrap();
    std::fs::write(&beside, serde_json::to_vec(&doc_beside).unwrap()).unwrap();
    let options = ["--material=steel", "--order=1", "--modes=4", "--size=0.05"];
    // (cube.modes is the OBJ's now: both files are named cube.)
    let glb_base = dir.path().join("glb.modes");
    for (asset, base) in [
        (&glb_path, &glb_base),
        (&beside, &beside.with_extension("modes")),
    ] {
        let mut a: Vec<&std::ffi::OsStr> = vec![
            "bake".as_ref(),
            asset.as_os_str(),
            "-o".as_ref(),
            base.as_os_str(),
        ];
        a.extend(options.iter().map(std::ffi::OsStr::new));
        let o = modal_bake(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    for (asset, base, meshed_again) in [
        (&glb_path, glb_base.clone(), false),
        (&beside, beside.with_extension("modes"), true),
    ] {
        let mut a: Vec<&std::ffi::OsStr> = vec![
            "check".as_ref(),
            asset.as_os_str(),
            base.as_os_str(),
            "--json".as_ref(),
        ];
        a.extend(options.iter().map(std::ffi::OsStr::new));
        let v: Value = serde_json::from_slice(&modal_bake(&a).stdout).unwrap();
        assert_eq!(
            (&v["up_to_date"], &v["meshed_again"]),
            (&json!(true), &json!(meshed_again)),
            "{}: {v}",
            asset.display()
        );
    }
    let out = dir.path().join("modes.glb");
    let o = modal_bake(&[
        "export".as_ref(),
        glb_path.with_extension("modes").as_os_str(),
        "--gltf".as_ref(),
        out.as_os_str(),
        "--onto".as_ref(),
        glb_path.as_os_str(),
    ]);
    let text = String::from_utf8_lossy(&o.stderr).to_string() + &String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("morph targets on 8 vertices"),
        "{text}"
    );

    let bad = dir.path().join("bad.glb");
    std::fs::write(&bad, &glb(&doc, &bin)[..100]).unwrap();
    let o = modal_bake(&[
        "mesh".as_ref(),
        bad.as_os_str(),
        "-o".as_ref(),
        dir.path().join("bad.msh").as_os_str(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    let named = bad.display().to_string();
    assert!(!o.status.success() && e.matches(&named).count() == 1, "{e}");
    assert!(e.contains("invalid glTF file: GLB"), "{e}");
}

// `--object`: one node of the scene (its name, or the name of the mesh it places) with its
// children, where the scene places it; a name the file lacks is refused with the names it has,
// and a mesh name placed by two nodes asks for a node name.
#[test]
fn one_named_object_is_read_where_the_scene_places_it() {
    use modal_bake::mesh::surface::read_surface_unwelded_object;
    let (mut doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    doc["meshes"][0]["name"] = json!("box");
    doc["scenes"] = json!([{"nodes": [0, 1]}]);
    doc["nodes"] = json!([
        {"name": "A", "mesh": 0},
        {"name": "B", "translation": [5.0, 0.0, 0.0], "children": [2]},
        {"name": "B-child", "mesh": 0, "translation": [0.0, 1.0, 0.0]}
    ]);
    let bytes = glb(&doc, &bin);
    let read = |o: &str| read_surface_unwelded_object(&bytes, "two.glb", Some(o));
    let (p, t) = read("B").unwrap();
    assert_eq!((p.len(), t.len()), (8, 12));
    for (q, v) in p.iter().zip(V) {
        assert_eq!(*q, [5.0 + v[0], 1.0 + v[1], v[2]]);
    }
    let (p, _) = read("A").unwrap();
    assert_eq!(p[6], [1.0, 1.0, 1.0]);
    let e = read("C").unwrap_err().to_string();
    assert!(
        e.starts_with("two.glb: no node or mesh named `C`")
            && e.contains("`A`, `B`, `B-child`, `box`"),
        "{e}"
    );
    let e = read("box").unwrap_err().to_string();
    assert!(
        e.contains("2 nodes are named `box` or place a mesh of that name"),
        "{e}"
    );
    // The whole scene without --object: both copies, in the file's node order (A, then B's).
    let (p, _) = read_surface_unwelded(&bytes, "two.glb").unwrap();
    assert_eq!(p.len(), 16);
    assert_eq!((p[6], p[14]), ([1.0, 1.0, 1.0], [6.0, 2.0, 1.0]));
}

// OBJ objects and groups by name (`o`/`g`); STL and PLY name no objects.
#[test]
fn obj_objects_are_selected_by_name_and_stl_has_none() {
    use modal_bake::export::AssetMesh;
    use modal_bake::mesh::surface::read_surface_unwelded_object;
    let mut obj = String::new();
    for (name, dx) in [("left", 0.0), ("right", 3.0)] {
        obj += &format!("o {name}\n");
        for v in V {
            obj += &format!("v {} {} {}\n", v[0] + dx, v[1], v[2]);
        }
    }
    for (name, base) in [("left", 1), ("right", 9)] {
        obj += &format!("g {name}\n");
        for q in Q {
            obj += &format!(
                "f {} {} {} {}\n",
                q[0] + base,
                q[1] + base,
                q[2] + base,
                q[3] + base
            );
        }
    }
    // Faces grouped after every vertex: `g` names the faces' groups.
    let (p, t) = read_surface_unwelded_object(obj.as_bytes(), "two.obj", Some("right")).unwrap();
    assert_eq!(t.len(), 12);
    let used: std::collections::BTreeSet<usize> = t.iter().flatten().copied().collect();
    assert!(used.iter().all(|&v| p[v][0] >= 3.0), "{:?}", used);
    let e = read_surface_unwelded_object(obj.as_bytes(), "two.obj", Some("middle"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("two.obj: no object or group named `middle`"),
        "{e}"
    );
    // `export --onto --object`: the object's vertices, in file order.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two.obj");
    std::fs::write(&path, &obj).unwrap();
    let a = AssetMesh::read(&path, 1.0, Some("right")).unwrap();
    let want: Vec<[f64; 3]> = V.iter().map(|v| [v[0] + 3.0, v[1], v[2]]).collect();
    assert_eq!((a.positions, a.triangles.len()), (want, 12));
    let e = read_surface_unwelded_object(b"solid x\nendsolid x\n", "x.stl", Some("x"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("STL and PLY files name no objects"), "{e}");
}

// `mesh --dry-run` (no mesher runs: no gmsh needed): the inspection, the objects `--object`
// accepts (named nodes with a mesh below them, then mesh names; an empty group node is not
// one), the mesher auto would choose and the estimate; nothing is written; over the budget it
// exits 1 with the refusal, as the real run would.
#[test]
fn a_dry_run_lists_the_objects_and_the_mesher_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (mut doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    doc["meshes"][0]["name"] = json!("box");
    doc["scenes"] = json!([{"nodes": [0, 1, 3]}]);
    doc["nodes"] = json!([
        {"name": "A", "mesh": 0},
        {"name": "B", "translation": [5.0, 0.0, 0.0], "children": [2]},
        {"name": "B-child", "mesh": 0, "translation": [0.0, 1.0, 0.0]},
        {"name": "empty"}
    ]);
    let asset = dir.path().join("two.glb");
    std::fs::write(&asset, glb(&doc, &bin)).unwrap();
    let out = dir.path().join("two.msh");
    let run = |extra: &[&str]| {
        let mut args: Vec<&std::ffi::OsStr> = vec!["mesh".as_ref(), asset.as_os_str()];
        args.extend(extra.iter().map(|s| std::ffi::OsStr::new(*s)));
        modal_bake(&args)
    };
    let o = run(&["--dry-run"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{text}{err}");
    assert!(
        text.contains("objects (--object NAME meshes one; this run: the whole file): `A`, `B`, `B-child`, `box`"),
        "{text}"
    );
    // Two separate cubes: not one solid, so fTetWild, naming --object.
    assert!(
        text.contains("backend: fTetWild") && text.contains("2 shells"),
        "{text}"
    );
    assert!(
        err.contains("size estimate for") && text.contains("`mesh` would run (the estimate"),
        "{text}{err}"
    );
    let o = run(&["--dry-run", "--object", "B", "-o", out.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{text}");
    assert!(
        text.contains("this run: `B`") && text.contains("backend: gmsh"),
        "{text}"
    );
    assert!(!out.exists(), "a dry run wrote {}", out.display());
    let o = run(&["--dry-run", "--object", "B", "--size", "0.001"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("refused before meshing or baking"), "{err}");
    let o = run(&["--dry-run", "--object", "C"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("no node or mesh named `C`"),
        "{err}"
    );
    let o = run(&["--dry-run", "--json"]);
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["dry_run"], true);
    assert_eq!(v["backend"], "ftetwild");
    assert_eq!(v["objects"], json!(["A", "B", "B-child", "box"]));
    assert!(v["estimate"]["tets"].as_f64().unwrap() > 0.0);
    // gmsh forced on the two separate cubes: the reason says why, and the run fails as the
    // real one would.
    let o = run(&["--dry-run", "--json", "--mesher", "gmsh"]);
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(!o.status.success());
    assert!(
        v["backend"].is_null() && v["reason"].as_str().unwrap().contains("2 shells"),
        "{v}"
    );
}

// The OBJ objects `--object` accepts: `o`/`g` names with faces, in the file's order; STL none.
#[test]
fn obj_object_names_are_the_named_groups_with_faces() {
    use modal_bake::mesh::surface::object_names;
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("parts.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\no lid\nf 1 2 3\ng empty\no pot body\nf 1 3 4\nf 1 2 4\no lid\nf 2 3 4\n",
    )
    .unwrap();
    assert_eq!(object_names(&obj).unwrap(), ["lid", "pot body"]);
    let stl = dir.path().join("x.stl");
    std::fs::write(&stl, b"solid x\nendsolid x\n").unwrap();
    assert!(object_names(&stl).unwrap().is_empty());
    let e = object_names(&dir.path().join("x.fbx"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.fbx"), "{e}");
}
