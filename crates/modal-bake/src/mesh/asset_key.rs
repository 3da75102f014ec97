//! When meshing a surface asset again can be skipped: an [`AssetKey`] records what a mesh of
//! an asset depends on — the asset file's bytes, the surface the meshers read from them, this
//! build of the meshing chain ([`BUILD_HASH`]) and the meshers' versions — so that `check` and
//! `batch` find a base of an unchanged asset up to date without meshing it again (minutes on a
//! large asset), with the same answer meshing would give.
//!
//! Why that answer is the same: the meshers run on one thread with fixed seeds, so the same
//! surface, options (recorded beside the key: `selection`, `meshing`) and mesher versions give
//! the same mesh bytes (docs/artist-guide.md; fTetWild only where its fixed-sequence random
//! device is loaded — a mesh that is not reproducible gets no key). The surface is what
//! [`super::mesh_asset`] gives the meshers before scaling (the `--units` are compared apart):
//! the welded vertices and triangles of the asset's selected object, in order. So an asset
//! saved again with only a comment, a material, normals or texture coordinates changed is not
//! meshed again either; its bytes are compared first, and the surface is read only when they
//! differ. A glTF asset gets a key only when it is self-contained (a `.glb`'s own binary chunk
//! or `data:` URIs): buffers read from other files are not covered by the bytes.

use std::collections::BTreeMap;
use std::path::Path;

use sha2::{Digest, Sha256};

use super::{Backend, MeshParams, MeshReport};

/// A SHA-256 of the sources of this crate and the workspace crates it builds on, its
/// `Cargo.lock`, the compiler's version and the target (computed by `build.rs`): two builds
/// with the same hash mesh an asset alike.
pub const BUILD_HASH: &str = env!("MODAL_BAKE_BUILD_HASH");

/// What a mesh of a surface asset depends on besides the options
/// (`meta.bake_params.asset_key` of its base).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct AssetKey {
    /// `sha256:<hex>` of the asset file's bytes.
    pub sha256: String,
    /// The asset file's size (bytes).
    pub bytes: u64,
    /// `sha256:<hex>` of the surface the meshers read ([`surface_sha256`]); absent in bases
    /// written before it was recorded (then only the same bytes match).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<String>,
    /// The [`BUILD_HASH`] of the `modal-bake` that meshed it.
    pub build: String,
    /// The version of each mesher when it was meshed (`gmsh`, `ftetwild`; absent: not
    /// installed): both, since `auto` may run either and fall back to the other.
    pub meshers: BTreeMap<String, String>,
}

impl AssetKey {
    /// The key of the asset at `path` as it is now, meshed with `params` (whose `--gmsh` /
    /// `--ftetwild` choose the meshers asked for their versions); `None` for a glTF asset or a
    /// mesh `report` says is not reproducible, or a file that cannot be read.
    pub fn of(path: &Path, params: &MeshParams, report: &MeshReport) -> Option<AssetKey> {
        let ftetwild_ran = report.backend == Backend::Ftetwild;
        if ftetwild_ran && !report.reproducible {
            return None;
        }
        Self::now(path, params)
    }

    /// The key the asset at `path` would get now, with the meshers `params` would run; `None`
    /// for an unreadable file or a glTF asset that reads other files.
    fn now(path: &Path, params: &MeshParams) -> Option<AssetKey> {
        let bytes = read_keyable(path)?;
        Some(AssetKey {
            sha256: sha256(&bytes),
            bytes: bytes.len() as u64,
            surface: surface_sha256(path, params.object.as_deref()),
            build: BUILD_HASH.to_string(),
            meshers: meshers_now(params),
        })
    }

    /// Whether the asset at `path`, this build and the meshers `params` would run now are
    /// those of this key (the options are compared apart): the same build and meshers, and
    /// the same bytes or, failing that, the same recorded surface.
    pub fn matches_now(&self, path: &Path, params: &MeshParams) -> bool {
        // Cheap tests first: the build, then the bytes, before asking the meshers their
        // versions and, only when the bytes differ, reading the surface.
        if self.build != BUILD_HASH {
            return false;
        }
        let Some(bytes) = read_keyable(path) else {
            return false;
        };
        let same_bytes = bytes.len() as u64 == self.bytes && sha256(&bytes) == self.sha256;
        if !same_bytes && self.surface.is_none() {
            return false;
        }
        if meshers_now(params) != self.meshers {
            return false;
        }
        same_bytes || surface_sha256(path, params.object.as_deref()) == self.surface
    }
}

/// The asset's bytes when it can have a key: `None` for an unreadable file or a glTF asset
/// that reads other files.
fn read_keyable(path: &Path) -> Option<Vec<u8>> {
    let bytes = std::fs::read(path).ok()?;
    (!is_gltf(path) || self_contained_gltf(&bytes)).then_some(bytes)
}

/// `sha256:<hex>` of the surface the meshers read from the asset at `path` (its `object`, or
/// all of it), in the file's units: the welded vertex count, each vertex's coordinates as f64
/// bits (little-endian), the triangle count and each triangle's vertex indices as u64, in the
/// order [`super::surface::read_surface_object`] gives them. `None` when it cannot be read.
pub fn surface_sha256(path: &Path, object: Option<&str>) -> Option<String> {
    let s = super::surface::read_surface_object(path, object).ok()?;
    let mut h = Sha256::new();
    h.update((s.vertices.len() as u64).to_le_bytes());
    for v in &s.vertices {
        for x in v {
            h.update(x.to_bits().to_le_bytes());
        }
    }
    h.update((s.triangles.len() as u64).to_le_bytes());
    for t in &s.triangles {
        for &i in t {
            h.update((i as u64).to_le_bytes());
        }
    }
    Some(format!("sha256:{:x}", h.finalize()))
}

/// The versions of the meshers `params` would run now (`gmsh`, `ftetwild`; absent: not
/// installed).
fn meshers_now(params: &MeshParams) -> BTreeMap<String, String> {
    let mut meshers = BTreeMap::new();
    if let Ok(v) = super::gmsh::gmsh_version(params.gmsh.as_deref()) {
        meshers.insert("gmsh".to_string(), v);
    }
    let ftetwild = match params.ftetwild.as_deref() {
        // A FloatTetwild_bin names no version: its bytes identify it.
        Some(p) => std::fs::read(p)
            .ok()
            .map(|b| format!("FloatTetwild_bin {}", sha256(&b))),
        None => super::ftetwild::ftetwild_version(None).ok(),
    };
    if let Some(v) = ftetwild {
        meshers.insert("ftetwild".to_string(), v);
    }
    meshers
}

fn sha256(bytes: &[u8]) -> String {
    format!("sha256:{:x}", Sha256::digest(bytes))
}

/// Whether a glTF document (`.glb` or `.gltf` bytes) holds all its buffers: each buffer is
/// the `.glb`'s binary chunk (no `uri`) or a `data:` URI. Anything unreadable is not.
fn self_contained_gltf(bytes: &[u8]) -> bool {
    let json = if bytes.starts_with(b"glTF") {
        // Header (12 bytes), then the first chunk: length, type `JSON`, content.
        let word = |at: usize| {
            bytes
                .get(at..at + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        };
        match (word(12), bytes.get(16..20)) {
            (Some(len), Some(b"JSON")) => match bytes.get(20..20usize.saturating_add(len)) {
                Some(j) => j,
                None => return false,
            },
            _ => return false,
        }
    } else {
        bytes
    };
    let Ok(doc) = serde_json::from_slice::<serde_json::Value>(json) else {
        return false;
    };
    match doc.get("buffers") {
        None => true,
        Some(serde_json::Value::Array(buffers)) => buffers.iter().all(|b| match b.get("uri") {
            None => true,
            Some(u) => u.as_str().is_some_and(|u| u.starts_with("data:")),
        }),
        Some(_) => false,
    }
}

fn is_gltf(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

#[cfg(test)]
mod tests {
    use super::self_contained_gltf;

    fn glb(json: &str) -> Vec<u8> {
        let mut j = json.as_bytes().to_vec();
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((20 + j.len()) as u32).to_le_bytes());
        out.extend((j.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(j);
        out
    }

    #[test]
    fn only_gltf_that_holds_its_buffers_is_self_contained() {
        assert!(self_contained_gltf(&glb(
            r#"{"buffers": [{"byteLength": 8}]}"#
        )));
        assert!(self_contained_gltf(
            br#"{"buffers": [{"uri": "data:application/octet-stream;base64,AAAA"}]}"#
        ));
        assert!(!self_contained_gltf(&glb(
            r#"{"buffers": [{"uri": "mesh.bin"}]}"#
        )));
        assert!(!self_contained_gltf(
            br#"{"buffers": [{"byteLength": 8}, {"uri": "b.bin"}]}"#
        ));
        // Truncated or malformed: not.
        assert!(!self_contained_gltf(
            &glb(r#"{"buffers": [{"byteLength": 8}]}"#)[..22]
        ));
        assert!(!self_contained_gltf(b"glTF"));
        assert!(!self_contained_gltf(br#"{"buffers": 3}"#));
    }
}
