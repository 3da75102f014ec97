//! [`GltfBuilder`]: assembles a glTF 2.0 document (typed `gltf-json` model) and its one binary
//! buffer, and writes them as a `.glb` (the `gltf` crate's GLB container).
//!
//! Conventions the Khronos glTF-Validator checks and this builder guarantees: every buffer view
//! 4-byte aligned; vertex-attribute views tagged `ARRAY_BUFFER`, index views
//! `ELEMENT_ARRAY_BUFFER`, animation views untagged; `min`/`max` on every `POSITION` accessor
//! (morph targets included) and on every animation input; float data finite (callers pass
//! finite values; [`GltfBuilder::vec3`] refuses others).

use gltf::json::{
    self,
    accessor::{ComponentType, GenericComponentType, Type},
    buffer::Target,
    material::{EmissiveFactor, PbrBaseColorFactor, PbrMetallicRoughness, StrengthFactor},
    validation::{Checked, USize64},
    Index,
};
use serde_json::Value;

use super::ExportError;

/// `asset.generator` of every file this workspace writes.
pub const GLTF_GENERATOR: &str = concat!("dcr ", env!("CARGO_PKG_VERSION"));

/// A glTF document under construction plus its binary buffer (buffer 0 of the GLB).
pub struct GltfBuilder {
    /// The document; add nodes, meshes, scenes, animations directly.
    pub root: json::Root,
    bin: Vec<u8>,
}

impl Default for GltfBuilder {
    fn default() -> Self {
        Self::new()
    }
}

/// `extras` from a JSON value.
///
/// # Panics
/// Never for values built with `serde_json::json!` (always serialisable).
pub fn extras_of(v: &Value) -> json::Extras {
    Some(
        serde_json::value::RawValue::from_string(v.to_string())
            .expect("a serde_json value serialises"),
    )
}

impl GltfBuilder {
    /// An empty glTF 2.0 document (`asset.version` 2.0, [`GLTF_GENERATOR`]).
    pub fn new() -> GltfBuilder {
        let root = json::Root {
            asset: json::Asset {
                version: "2.0".into(),
                generator: Some(GLTF_GENERATOR.into()),
                ..Default::default()
            },
            ..Default::default()
        };
        GltfBuilder {
            root,
            bin: Vec::new(),
        }
    }

    fn push_view(&mut self, bytes: &[u8], target: Option<Target>) -> Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64(bytes.len() as u64),
            byte_offset: Some(USize64(offset as u64)),
            byte_stride: None,
            name: None,
            target: target.map(Checked::Valid),
            extensions: None,
            extras: None,
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn accessor(
        &mut self,
        bytes: &[u8],
        target: Option<Target>,
        count: usize,
        component: ComponentType,
        type_: Type,
        min: Option<Value>,
        max: Option<Value>,
    ) -> Index<json::Accessor> {
        let view = self.push_view(bytes, target);
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count as u64),
            component_type: Checked::Valid(GenericComponentType(component)),
            extensions: None,
            extras: None,
            type_: Checked::Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// A VEC3 float accessor with `min`/`max` (vertex positions, morph-target displacements
    /// when `vertex_attribute`; animation translations otherwise).
    ///
    /// # Errors
    /// [`ExportError::Invalid`] for an empty slice or a non-finite value.
    pub fn vec3(
        &mut self,
        data: &[[f32; 3]],
        vertex_attribute: bool,
    ) -> Result<Index<json::Accessor>, ExportError> {
        if data.is_empty() {
            return Err(ExportError::Invalid("empty VEC3 accessor".into()));
        }
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        let mut bytes = Vec::with_capacity(data.len() * 12);
        for p in data {
            for a in 0..3 {
                if !p[a].is_finite() {
                    return Err(ExportError::Invalid(format!(
                        "non-finite coordinate {} in a VEC3 accessor",
                        p[a]
                    )));
                }
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
                bytes.extend_from_slice(&p[a].to_le_bytes());
            }
        }
        let target = vertex_attribute.then_some(Target::ArrayBuffer);
        Ok(self.accessor(
            &bytes,
            target,
            data.len(),
            ComponentType::F32,
            Type::Vec3,
            Some(serde_json::json!(lo)),
            Some(serde_json::json!(hi)),
        ))
    }

    /// A VEC4 float accessor (rotation quaternions x y z w of an animation output).
    pub fn vec4(&mut self, data: &[[f32; 4]]) -> Index<json::Accessor> {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        self.accessor(
            &bytes,
            None,
            data.len(),
            ComponentType::F32,
            Type::Vec4,
            None,
            None,
        )
    }

    /// A SCALAR float accessor; with `bounds` it carries `min`/`max` (required for animation
    /// inputs: keyframe times, s).
    pub fn scalars(&mut self, data: &[f32], bounds: bool) -> Index<json::Accessor> {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let (min, max) = if bounds {
            let lo = data.iter().copied().fold(f32::INFINITY, f32::min);
            let hi = data.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            (Some(serde_json::json!([lo])), Some(serde_json::json!([hi])))
        } else {
            (None, None)
        };
        self.accessor(
            &bytes,
            None,
            data.len(),
            ComponentType::F32,
            Type::Scalar,
            min,
            max,
        )
    }

    /// Triangle indices (u16 when every index fits, else u32), `ELEMENT_ARRAY_BUFFER`.
    pub fn indices(&mut self, tris: &[[u32; 3]]) -> Index<json::Accessor> {
        let small = tris.iter().flatten().all(|&i| i < u16::MAX as u32);
        let (bytes, ct): (Vec<u8>, _) = if small {
            (
                tris.iter()
                    .flatten()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect(),
                ComponentType::U16,
            )
        } else {
            (
                tris.iter()
                    .flatten()
                    .flat_map(|&i| i.to_le_bytes())
                    .collect(),
                ComponentType::U32,
            )
        };
        self.accessor(
            &bytes,
            Some(Target::ElementArrayBuffer),
            tris.len() * 3,
            ct,
            Type::Scalar,
            None,
            None,
        )
    }

    /// A metallic-roughness material (linear RGBA base colour, metallic 0).
    pub fn material(
        &mut self,
        name: &str,
        rgba: [f32; 4],
        roughness: f32,
        double_sided: bool,
    ) -> Index<json::Material> {
        self.root.push(json::Material {
            name: Some(name.into()),
            pbr_metallic_roughness: PbrMetallicRoughness {
                base_color_factor: PbrBaseColorFactor(rgba),
                metallic_factor: StrengthFactor(0.0),
                roughness_factor: StrengthFactor(roughness),
                ..Default::default()
            },
            emissive_factor: EmissiveFactor([0.0; 3]),
            double_sided,
            ..Default::default()
        })
    }

    /// A one-primitive triangle mesh from positions (m) and triangles, with optional morph
    /// targets (per-vertex displacements, m) named in `extras.targetNames` (the name list
    /// three.js and Blender read).
    ///
    /// # Errors
    /// As [`GltfBuilder::vec3`].
    pub fn triangle_mesh(
        &mut self,
        name: &str,
        positions: &[[f32; 3]],
        tris: &[[u32; 3]],
        material: Index<json::Material>,
        targets: &[(String, Vec<[f32; 3]>)],
    ) -> Result<Index<json::Mesh>, ExportError> {
        let pos = self.vec3(positions, true)?;
        let idx = self.indices(tris);
        let mut morphs = Vec::with_capacity(targets.len());
        for (_, d) in targets {
            morphs.push(json::mesh::MorphTarget {
                positions: Some(self.vec3(d, true)?),
                normals: None,
                tangents: None,
            });
        }
        let mut attributes = std::collections::BTreeMap::new();
        attributes.insert(Checked::Valid(json::mesh::Semantic::Positions), pos);
        let (weights, extras) = if targets.is_empty() {
            (None, None)
        } else {
            let names: Vec<&str> = targets.iter().map(|(n, _)| n.as_str()).collect();
            (
                Some(vec![0.0; targets.len()]),
                extras_of(&serde_json::json!({ "targetNames": names })),
            )
        };
        Ok(self.root.push(json::Mesh {
            extensions: None,
            extras,
            name: Some(name.into()),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: None,
                indices: Some(idx),
                material: Some(material),
                mode: Checked::Valid(json::mesh::Mode::Triangles),
                targets: (!morphs.is_empty()).then_some(morphs),
            }],
            weights,
        }))
    }

    /// Serialises to a GLB byte vector (JSON chunk + one BIN chunk).
    ///
    /// # Errors
    /// [`ExportError::Invalid`] if the document does not serialise or exceeds 4 GiB.
    pub fn to_glb(mut self) -> Result<Vec<u8>, ExportError> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        if !self.bin.is_empty() {
            self.root.buffers = vec![json::Buffer {
                byte_length: USize64(self.bin.len() as u64),
                name: None,
                uri: None,
                extensions: None,
                extras: None,
            }];
        }
        let json = self
            .root
            .to_vec()
            .map_err(|e| ExportError::Invalid(format!("glTF JSON: {e}")))?;
        glb_container(json, &self.bin).map_err(|e| ExportError::Invalid(format!("glTF {e}")))
    }
}

/// The GLB container of a JSON document and its binary buffer (none when empty).
///
/// # Errors
/// The text of the refusal when the two exceed the 4 GiB a GLB can hold, or the container
/// does not serialise.
pub(super) fn glb_container(json: Vec<u8>, bin: &[u8]) -> Result<Vec<u8>, String> {
    if json.len() + bin.len() > u32::MAX as usize - 64 {
        return Err("larger than 4 GiB, the most a GLB holds".into());
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: json.into(),
        bin: (!bin.is_empty()).then(|| bin.into()),
    };
    glb.to_vec().map_err(|e| format!("GLB: {e}"))
}
