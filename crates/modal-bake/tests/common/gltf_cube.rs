//! A unit cube as glTF 2.0 (binary and embedded), shared by the glTF reader's tests and the
//! readers' fuzzer.
#![allow(dead_code)]

use serde_json::{json, Value};

#[path = "unit_cube.rs"]
mod unit_cube;
pub use unit_cube::{CUBE_Q as Q, CUBE_V as V};

/// The cube's triangles as glTF `u16` indices.
pub fn cube_triangles() -> Vec<u16> {
    unit_cube::cube_tris()
        .into_iter()
        .flatten()
        .map(|i| i as u16)
        .collect()
}

/// Positions (8 × 12 bytes) then u16 indices; the accessors and views of a one-mesh document.
pub fn cube_document(indices: &[u16], mode: u32, buffer: Value) -> (Value, Vec<u8>) {
    let mut bin: Vec<u8> = V
        .iter()
        .flatten()
        .flat_map(|&x| (x as f32).to_le_bytes())
        .collect();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut buffer = buffer;
    buffer["byteLength"] = json!(bin.len());
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": mode}]}],
        "buffers": [buffer],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 96},
            {"buffer": 0, "byteOffset": 96, "byteLength": 2 * indices.len()}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0]},
            {"bufferView": 1, "componentType": 5123, "count": indices.len(), "type": "SCALAR"}
        ]
    });
    (doc, bin)
}

/// A binary glTF: 12-byte header, the JSON chunk (space-padded), the BIN chunk (zero-padded).
pub fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(doc).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(j);
    out.extend((b.len() as u32).to_le_bytes());
    out.extend(0x004E_4942u32.to_le_bytes());
    out.extend(b);
    out
}

pub fn cube_glb() -> Vec<u8> {
    let (doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    glb(&doc, &bin)
}

/// The cube as a `.gltf` whose buffer is a base64 data URI.
pub fn cube_gltf_embedded() -> Vec<u8> {
    use base64::Engine as _;
    let (mut doc, bin) = cube_document(&cube_triangles(), 4, json!({}));
    doc["buffers"][0]["uri"] = json!(format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    ));
    serde_json::to_vec_pretty(&doc).unwrap()
}
