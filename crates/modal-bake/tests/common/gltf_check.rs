//! Test helpers for written glTF files: the Khronos glTF-Validator on a file, and a minimal
//! GLB reader (document + float accessors) to check contents.
//!
//! The validator runs through `node viewer/test/validate.mjs` (npm `gltf-validator`, installed
//! by `npm ci` in `viewer/`, which `.ci/run` does). Without node or the package the check is
//! skipped with a message, except under CI (`CI` set), where it fails — unless `.ci/run` could
//! not install it (`DCR_NO_VALIDATOR` set).

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

use gltf::json;

pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs the Khronos glTF-Validator on `path` and panics on any error (warnings are printed).
pub fn validate_gltf(path: &Path) {
    let root = repo_root();
    let script = root.join("viewer/test/validate.mjs");
    let have = root.join("viewer/node_modules/gltf-validator").is_dir();
    let out = if have {
        Command::new("node").arg(&script).arg(path).output().ok()
    } else {
        None
    };
    let Some(out) = out else {
        let msg = format!(
            "glTF-Validator not available (run `npm ci` in viewer/); {} not validated",
            path.display()
        );
        if std::env::var_os("CI").is_some() && std::env::var_os("DCR_NO_VALIDATOR").is_none() {
            panic!("{msg}");
        }
        eprintln!("SKIPPED: {msg}");
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}");
    assert!(
        out.status.success(),
        "glTF-Validator reports errors for {}:\n{text}{}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A parsed GLB: the JSON document and the BIN chunk.
pub struct Glb {
    pub root: json::Root,
    pub bin: Vec<u8>,
}

impl Glb {
    pub fn read(path: &Path) -> Glb {
        let bytes = std::fs::read(path).unwrap();
        let glb = gltf::binary::Glb::from_slice(&bytes).expect("a GLB container");
        let root = json::Root::from_slice(&glb.json).expect("glTF JSON");
        Glb {
            root,
            bin: glb.bin.map(|b| b.into_owned()).unwrap_or_default(),
        }
    }

    /// Every float of a (tightly packed, f32) accessor, in order.
    pub fn floats(&self, acc: usize) -> Vec<f32> {
        let a = &self.root.accessors[acc];
        let v = &self.root.buffer_views[a.buffer_view.unwrap().value()];
        let comps = match a.type_.as_ref().unwrap() {
            json::accessor::Type::Scalar => 1,
            json::accessor::Type::Vec3 => 3,
            json::accessor::Type::Vec4 => 4,
            t => panic!("unexpected accessor type {t:?}"),
        };
        let start =
            v.byte_offset.map_or(0, |o| o.0 as usize) + a.byte_offset.map_or(0, |o| o.0 as usize);
        let n = a.count.0 as usize * comps;
        (0..n)
            .map(|i| {
                let b = &self.bin[start + 4 * i..start + 4 * i + 4];
                f32::from_le_bytes([b[0], b[1], b[2], b[3]])
            })
            .collect()
    }

    /// `extras` of the document as JSON.
    pub fn extras(&self) -> serde_json::Value {
        serde_json::from_str(self.root.extras.as_ref().expect("document extras").get()).unwrap()
    }
}
