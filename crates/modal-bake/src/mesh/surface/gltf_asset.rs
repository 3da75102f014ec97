//! glTF 2.0 surface assets (`.glb`, and `.gltf` with its buffers embedded as base64 data URIs
//! or in files beside it): every triangle primitive of every mesh its scene places, in the
//! scene's frame (metres and +Y up, as glTF defines them).
//!
//! The container (GLB chunks), the JSON document, its validation and the scene graph's node
//! transforms come from the `gltf` crate. The accessor reads are written here, with checked
//! arithmetic: `gltf` 1.4.1's reader computes an accessor's extent as
//! `offset + stride · (count − 1) + size` unchecked, which underflows for `count: 0` and wraps
//! for a hostile count, and a `.gltf`'s external buffers are read only through its `import`
//! feature (which also decodes every texture). Here every extent is checked against the buffer
//! it lies in before a byte is read, so allocation is bounded by the bytes the asset holds.
//!
//! What is read: the default scene (else the first; a file without scenes: every mesh, each
//! once, untransformed), each node's world transform (a mirroring one reverses the triangles'
//! winding back to outward), primitives of mode `TRIANGLES`, `TRIANGLE_STRIP` and
//! `TRIANGLE_FAN` with `POSITION` as `VEC3` `FLOAT` (or, with `KHR_mesh_quantization`, 8- or
//! 16-bit integers, normalized or not, as gltfpack writes by default) and optional
//! `u8`/`u16`/`u32` indices. Points and lines are ignored, as materials, textures, normals,
//! skins and morph targets are (a skinned mesh is read as its node places it, without its
//! joints). Refused with what to do: Draco or meshopt compression
//! (`KHR_draco_mesh_compression`, `EXT_meshopt_compression`), GPU instancing
//! (`EXT_mesh_gpu_instancing`), sparse positions,
//! nodes placed twice (glTF's nodes form trees), buffers behind a URL.

use std::borrow::Cow;
use std::path::Path;

use base64::Engine as _;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::{Soup3, SurfaceError};

/// Extensions that compress positions or indices; a file requiring one is refused (the other
/// required extensions concern materials, textures and lights, ignored, except
/// `KHR_mesh_quantization`, which is read).
const COMPRESSION_EXTENSIONS: [&str; 2] = ["KHR_draco_mesh_compression", "EXT_meshopt_compression"];

/// Copies of a mesh placed by per-instance attributes: refused when used.
const GPU_INSTANCING: &str = "EXT_mesh_gpu_instancing";

/// Integer positions (`KHR_mesh_quantization`): the node transform dequantizes them.
const QUANTIZATION: &str = "KHR_mesh_quantization";

fn err(name: &str, detail: impl ToString) -> SurfaceError {
    super::parse_err(name, "glTF", detail)
}

/// Reads a `.glb` or `.gltf` (`name` is its path: external buffers are found beside it).
/// Positions are the scene's world positions (m); triangles index them, each primitive's
/// vertices appended in file order.
///
/// `object`: only the node of that name (or the one node placing the mesh of that name) with
/// its children, where the scene places it; `None`: the whole scene.
pub(super) fn read_gltf(
    data: &[u8],
    name: &str,
    object: Option<&str>,
) -> Result<Soup3, SurfaceError> {
    let scene = read_gltf_scene(data, name, object)?;
    Ok((scene.positions, scene.triangles))
}

/// The names `--object` accepts that place something: the named nodes of the scene (depth
/// first, in the file's order) with a mesh in their subtree, then the placed meshes' names;
/// each once. Without scenes: the meshes' names.
pub(super) fn gltf_object_names(data: &[u8], name: &str) -> Result<Vec<String>, SurfaceError> {
    let Parsed { doc, .. } = document(data, name)?;
    let mut out: Vec<String> = Vec::new();
    let mut push = |n: Option<&str>| {
        if let Some(n) = n.filter(|n| !out.iter().any(|o| o == n)) {
            out.push(n.to_string());
        }
    };
    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        for mesh in doc.meshes() {
            push(mesh.name());
        }
        return Ok(out);
    };
    // Whether each node's subtree places a mesh (children before parents: post-order).
    let mut places = vec![false; doc.nodes().len()];
    let mut order = Vec::new();
    let mut seen = vec![false; doc.nodes().len()];
    let mut stack: Vec<gltf::Node> = scene.nodes().collect();
    stack.reverse();
    while let Some(node) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            continue;
        }
        order.push(node.clone());
        let at = stack.len();
        stack.extend(node.children());
        stack[at..].reverse();
    }
    for node in order.iter().rev() {
        places[node.index()] = node.mesh().is_some() || node.children().any(|c| places[c.index()]);
    }
    for node in &order {
        if places[node.index()] {
            push(node.name());
        }
    }
    for node in &order {
        push(node.mesh().and_then(|m| m.name()));
    }
    Ok(out)
}

/// One triangle primitive the scene places: which node places which mesh's primitive, its
/// world matrix, and the range of its vertices in [`GltfScene::positions`].
#[derive(Clone, Debug, PartialEq)]
pub struct GltfPlacement {
    /// The placing node (`None` in a document without scenes: the mesh as it is).
    pub node: Option<usize>,
    /// The mesh placed.
    pub mesh: usize,
    /// The primitive of the mesh.
    pub primitive: usize,
    /// The node's world matrix (column-major `m[column][row]`, the file's units).
    pub world: [[f64; 4]; 4],
    /// Index of the primitive's first vertex in [`GltfScene::positions`]; its `POSITION`
    /// accessor's vertices follow in order.
    pub first_vertex: usize,
    /// Number of vertices (the `POSITION` accessor's count).
    pub vertices: usize,
}

/// A glTF asset as read: the placed triangles (as `mesh` and `bake` read them), where each
/// came from, and the document's JSON and buffers (what a writer that keeps the asset starts
/// from).
#[derive(Clone, Debug)]
pub struct GltfScene<'d> {
    /// The JSON document as in the file (a GLB's JSON chunk).
    pub json: Cow<'d, [u8]>,
    /// Each buffer's bytes (exactly its `byteLength`).
    pub buffers: Vec<Cow<'d, [u8]>>,
    /// World positions of the placed primitives' vertices (the file's units).
    pub positions: Vec<[f64; 3]>,
    /// Outward triangles indexing `positions`.
    pub triangles: Vec<[usize; 3]>,
    /// The placed triangle primitives, in the order their vertices were appended.
    pub placements: Vec<GltfPlacement>,
}

/// Reads a `.glb` or `.gltf` as [`read_surface`](super::read_surface) does, keeping the
/// document, its buffers and each primitive's placement.
///
/// # Errors
/// [`SurfaceError`] naming the file: what the glTF reader refuses (compression, GPU
/// instancing, sparse or out-of-range accessors, URL buffers, nodes placed twice, …).
pub fn read_gltf_scene<'d>(
    data: &'d [u8],
    name: &str,
    object: Option<&str>,
) -> Result<GltfScene<'d>, SurfaceError> {
    let Parsed {
        doc,
        json,
        bin,
        quantized,
    } = document(data, name)?;
    let buffers = load_buffers(&doc, bin, name)?;
    let budget = data.len() + buffers.iter().map(|b| b.len()).sum::<usize>();
    let mut out = Collect {
        name,
        quantized,
        buffers: &buffers,
        positions: Vec::new(),
        triangles: Vec::new(),
        placements: Vec::new(),
        budget,
    };
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    // Whether a node is the selected object: its name, or its mesh's.
    let selected = |node: &gltf::Node| {
        object.is_some_and(|o| {
            node.name() == Some(o) || node.mesh().is_some_and(|m| m.name() == Some(o))
        })
    };
    let mut matches = 0;
    match scene {
        Some(scene) => {
            let mut placed = vec![false; doc.nodes().len()];
            // Depth-first over the scene's trees in the file's order (pushed reversed, popped
            // first to last), each node with its world matrix and whether it is (inside) the
            // object read.
            let mut stack: Vec<(gltf::Node, [[f64; 4]; 4], bool)> = scene
                .nodes()
                .map(|n| (n, IDENTITY, object.is_none()))
                .collect();
            stack.reverse();
            while let Some((node, parent, inside)) = stack.pop() {
                if std::mem::replace(&mut placed[node.index()], true) {
                    return Err(err(
                        name,
                        format!(
                            "node {} is placed twice in scene {} (glTF nodes form trees: each \
                             has at most one parent)",
                            node.index(),
                            scene.index()
                        ),
                    ));
                }
                let world = mul(
                    &parent,
                    &node.transform().matrix().map(|c| c.map(f64::from)),
                );
                let this = selected(&node);
                matches += usize::from(this);
                let inside = inside || this;
                if let (Some(mesh), true) = (node.mesh(), inside) {
                    out.mesh(&mesh, Some(node.index()), &world)?;
                }
                let at = stack.len();
                stack.extend(node.children().map(|c| (c, world, inside)));
                stack[at..].reverse();
            }
        }
        None => {
            for mesh in doc.meshes() {
                if object.is_none_or(|o| mesh.name() == Some(o)) {
                    matches += 1;
                    out.mesh(&mesh, None, &IDENTITY)?;
                }
            }
        }
    }
    if let Some(o) = object {
        if matches != 1 {
            let nodes: Vec<&str> = doc.nodes().filter_map(|n| n.name()).collect();
            let detail = if matches == 0 {
                let mut names = nodes.clone();
                names.extend(doc.meshes().filter_map(|m| m.name()));
                format!(
                    "no node or mesh named `{o}` in the scene; {}",
                    super::list_names(&names)
                )
            } else {
                format!(
                    "{matches} nodes are named `{o}` or place a mesh of that name; name one node \
                     ({})",
                    super::list_names(&nodes)
                )
            };
            return Err(SurfaceError::Object {
                file: name.to_string(),
                detail,
            });
        }
    }
    let (positions, triangles, placements) = (out.positions, out.triangles, out.placements);
    Ok(GltfScene {
        json,
        buffers,
        positions,
        triangles,
        placements,
    })
}

/// A `.glb` or `.gltf` parsed and validated.
struct Parsed<'d> {
    doc: gltf::Document,
    /// The JSON document's bytes.
    json: Cow<'d, [u8]>,
    /// The GLB's binary chunk.
    bin: Option<Cow<'d, [u8]>>,
    /// The file uses `KHR_mesh_quantization`.
    quantized: bool,
}

/// Parses and validates a `.glb` or `.gltf`; refused when it needs what is not read
/// (compression, GPU instancing).
fn document<'d>(data: &'d [u8], name: &str) -> Result<Parsed<'d>, SurfaceError> {
    let (json, bin): (Cow<[u8]>, Option<Cow<[u8]>>) = if data.starts_with(b"glTF") {
        let glb = gltf::Glb::from_slice(data).map_err(|e| err(name, format!("GLB: {e}")))?;
        (glb.json, glb.bin)
    } else {
        (Cow::Borrowed(data), None)
    };
    let mut root: gltf::json::Root =
        gltf::json::deserialize::from_slice(&json).map_err(|e| err(name, e))?;
    if let Some(ext) = root
        .extensions_required
        .iter()
        .find(|e| COMPRESSION_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(err(
            name,
            format!(
                "the file requires {ext} (compressed geometry), which is not read; export it \
                 without compression (Blender: File → Export → glTF 2.0, Data → Compression \
                 off; gltfpack: without -c/-cc) or as OBJ/STL/PLY"
            ),
        ));
    }
    // Copies placed by per-instance attributes: read without them, the solid would be one copy.
    if root.extensions_used.iter().any(|e| e == GPU_INSTANCING) {
        return Err(err(
            name,
            format!(
                "the file uses {GPU_INSTANCING} (copies of a mesh placed by per-instance \
                 attributes), which is not read; export the one object without GPU instancing"
            ),
        ));
    }
    let quantized = root.extensions_used.iter().any(|e| e == QUANTIZATION);
    // Material, texture and light extensions do not change the geometry.
    root.extensions_required.clear();
    // gltf-json 1.4.1's validation indexes the accessor a POSITION names before checking it
    // (a panic on a hostile index): checked here first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let pos = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(a) = prim.attributes.get(&pos) {
                if a.value() >= root.accessors.len() {
                    return Err(err(
                        name,
                        format!(
                            "mesh {m} primitive {p}: POSITION names accessor {}, but the file has {}",
                            a.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    validate_document(&root).map_err(|e| err(name, e))?;
    let doc = gltf::Document::from_json_without_validation(root);
    Ok(Parsed {
        doc,
        json,
        bin,
        quantized,
    })
}

/// Validates a glTF document as `gltf::Document::from_json` does (indices in range, required
/// members present, enumerations known), except for one finding: `gltf-json` 1.4.1 reports an
/// accessor without a buffer view and without sparse values as missing data, where glTF 2.0
/// defines its elements as zeros (a morph target that leaves a primitive in place is written
/// so). Such an accessor is refused only where it is read (`POSITION`, indices).
///
/// # Errors
/// The findings, `invalid glTF: PATH: WHAT; …`.
pub fn validate_document(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::{Error, Validate};
    let mut findings = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path();
        let zeros = matches!(error, Error::Missing)
            && path.as_str().starts_with("accessors[")
            && path.as_str().ends_with("].bufferView")
            && path.as_str().matches('.').count() == 1;
        if !zeros {
            findings.push(format!("{path}: {error}"));
        }
    });
    if findings.is_empty() {
        Ok(())
    } else {
        Err(format!("invalid glTF: {}", findings.join("; ")))
    }
}

const IDENTITY: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// `a · b` of column-major 4 × 4 matrices (`m[column][row]`, glTF's layout).
fn mul(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut c = [[0.0; 4]; 4];
    for (j, col) in c.iter_mut().enumerate() {
        for (i, x) in col.iter_mut().enumerate() {
            *x = (0..4).map(|k| a[k][i] * b[j][k]).sum();
        }
    }
    c
}

/// Each buffer's bytes (exactly its `byteLength`): the GLB's BIN chunk, a base64 data URI, or
/// a file beside the asset.
fn load_buffers<'a>(
    doc: &gltf::Document,
    bin: Option<Cow<'a, [u8]>>,
    name: &str,
) -> Result<Vec<Cow<'a, [u8]>>, SurfaceError> {
    let mut out = Vec::with_capacity(doc.buffers().len());
    for buffer in doc.buffers() {
        let (i, need) = (buffer.index(), buffer.length());
        let short = |what: &str, have: usize| {
            err(
                name,
                format!("buffer {i}: {what} holds {have} bytes, but byteLength is {need}"),
            )
        };
        let bytes: Cow<[u8]> = match buffer.source() {
            gltf::buffer::Source::Bin => {
                let Some(bin) = &bin else {
                    return Err(err(
                        name,
                        format!("buffer {i} is the GLB's binary chunk, which the file lacks"),
                    ));
                };
                if bin.len() < need {
                    return Err(short("the BIN chunk", bin.len()));
                }
                match bin {
                    Cow::Borrowed(b) => Cow::Borrowed(&b[..need]),
                    Cow::Owned(b) => Cow::Owned(b[..need].to_vec()),
                }
            }
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let Some((_, payload)) = uri.split_once(";base64,") else {
                    return Err(err(
                        name,
                        format!("buffer {i}: a data URI that is not base64"),
                    ));
                };
                let b = base64::engine::general_purpose::STANDARD
                    .decode(payload)
                    .map_err(|e| err(name, format!("buffer {i}: base64: {e}")))?;
                if b.len() < need {
                    return Err(short("its data URI", b.len()));
                }
                let mut b = b;
                b.truncate(need);
                Cow::Owned(b)
            }
            gltf::buffer::Source::Uri(uri) => Cow::Owned(external_buffer(uri, need, i, name)?),
        };
        out.push(bytes);
    }
    Ok(out)
}

/// The file a relative `uri` names beside the asset `name` (URI escapes decoded); a URL
/// (`scheme://`) is refused naming `what` refers to it.
fn beside(uri: &str, what: &str, name: &str) -> Result<std::path::PathBuf, SurfaceError> {
    if uri.contains("://") {
        return Err(err(
            name,
            format!(
                "{what} is at {uri}; download it beside the asset and name it by a relative path"
            ),
        ));
    }
    Ok(Path::new(name)
        .parent()
        .unwrap_or(Path::new(""))
        .join(percent_decode(uri)))
}

/// The first `need` bytes of the file a relative `uri` names beside the asset `name`.
fn external_buffer(uri: &str, need: usize, i: usize, name: &str) -> Result<Vec<u8>, SurfaceError> {
    read_beside(uri, Some(need), &format!("buffer {i}"), name)
}

/// The bytes of the file a relative `uri` names beside the asset `name` (a buffer's or an
/// image's, `what` in errors): the first `need`, or all of it. Only regular files are read.
///
/// # Errors
/// A URL, a missing or irregular file, or one shorter than `need`, naming the file.
pub fn read_beside(
    uri: &str,
    need: Option<usize>,
    what: &str,
    name: &str,
) -> Result<Vec<u8>, SurfaceError> {
    use std::io::Read;
    let path = beside(uri, what, name)?;
    let cannot = |detail: String| err(name, format!("{what} ({}): {detail}", path.display()));
    let (f, len) =
        dcr_runtime::format::open_regular_file(&path).map_err(|e| cannot(e.to_string()))?;
    let need = match need {
        Some(need) if len < need as u64 => {
            return Err(cannot(format!(
                "the file holds {len} bytes, but byteLength is {need}"
            )))
        }
        Some(need) => need,
        None => usize::try_from(len).map_err(|_| cannot(format!("{len} bytes")))?,
    };
    let mut b = Vec::with_capacity(need);
    f.take(need as u64)
        .read_to_end(&mut b)
        .map_err(|e| cannot(e.to_string()))?;
    if b.len() < need {
        return Err(cannot(format!("read {} of {need} bytes", b.len())));
    }
    Ok(b)
}

/// `%20` → ` ` (URI escapes in a relative buffer path); anything else as written.
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut k = 0;
    while k < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[k] == b'%' && k + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[k + 1]), hex(b[k + 2])) {
                out.push((h * 16 + l) as u8);
                k += 3;
                continue;
            }
        }
        out.push(b[k]);
        k += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Gathers the placed primitives' world positions and triangles.
struct Collect<'a, 'b> {
    name: &'a str,
    /// The file uses `KHR_mesh_quantization`: positions may be 8- or 16-bit integers.
    quantized: bool,
    buffers: &'a [Cow<'b, [u8]>],
    positions: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    placements: Vec<GltfPlacement>,
    /// Bytes the asset holds (file and buffers): the positions and triangles gathered over every
    /// placement may not outnumber them.
    budget: usize,
}

impl Collect<'_, '_> {
    fn mesh(
        &mut self,
        mesh: &gltf::Mesh,
        node: Option<usize>,
        world: &[[f64; 4]; 4],
    ) -> Result<(), SurfaceError> {
        let name = self.name;
        // Upper 3 × 3 determinant: a mirroring placement turns the winding inside out.
        let m = world;
        let det = m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
            - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
            + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
        for prim in mesh.primitives() {
            let at = format!("mesh {} primitive {}", mesh.index(), prim.index());
            if !matches!(
                prim.mode(),
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                continue;
            }
            let Some(pos) = prim.get(&gltf::Semantic::Positions) else {
                return Err(err(name, format!("{at} has no POSITION attribute")));
            };
            let ty = pos.data_type();
            let integer = matches!(
                ty,
                DataType::I8 | DataType::U8 | DataType::I16 | DataType::U16
            );
            if pos.dimensions() != Dimensions::Vec3
                || !(ty == DataType::F32 || (integer && self.quantized))
            {
                let allowed = if self.quantized {
                    "VEC3 FLOAT, BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT"
                } else {
                    "VEC3 FLOAT (integer positions need KHR_mesh_quantization in extensionsUsed)"
                };
                return Err(err(
                    name,
                    format!(
                        "{at}: POSITION (accessor {}) is {:?} {:?}, not {allowed}",
                        pos.index(),
                        pos.dimensions(),
                        ty
                    ),
                ));
            }
            let normalized = pos.normalized();
            let raw = Self::accessor(self.buffers, name, &pos, &at)?;
            let count = pos.count();
            let indices: Vec<usize> = match prim.indices() {
                Some(acc) => {
                    if acc.dimensions() != Dimensions::Scalar {
                        return Err(err(
                            name,
                            format!("{at}: indices (accessor {}) are not SCALAR", acc.index()),
                        ));
                    }
                    let width = match acc.data_type() {
                        DataType::U8 => 1,
                        DataType::U16 => 2,
                        DataType::U32 => 4,
                        t => {
                            return Err(err(
                                name,
                                format!(
                                "{at}: indices (accessor {}) are {t:?}, not an unsigned integer",
                                acc.index()
                            ),
                            ))
                        }
                    };
                    let elems = Self::accessor(self.buffers, name, &acc, &at)?;
                    let mut v = Vec::with_capacity(acc.count());
                    for e in elems {
                        let i = match width {
                            1 => e[0] as usize,
                            2 => u16::from_le_bytes([e[0], e[1]]) as usize,
                            _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]) as usize,
                        };
                        if i >= count {
                            return Err(err(
                                name,
                                format!(
                                    "{at}: index {} is {i}, but POSITION has {count} vertices",
                                    v.len()
                                ),
                            ));
                        }
                        v.push(i);
                    }
                    v
                }
                None => (0..count).collect(),
            };
            if prim.mode() == Mode::Triangles && !indices.len().is_multiple_of(3) {
                return Err(err(
                    name,
                    format!(
                        "{at}: {} vertex indices, not a whole number of triangles",
                        indices.len()
                    ),
                ));
            }
            let tris = triangles_of(prim.mode(), &indices);
            let added = count + tris.len();
            let total = self.positions.len() + self.triangles.len() + added;
            if total > self.budget.max(1 << 16) {
                return Err(err(
                    name,
                    format!(
                        "{at}: the scene places its meshes into {total} vertices and triangles, \
                         more than the {} bytes the asset holds (a mesh instanced by many nodes); \
                         export the one object to mesh",
                        self.budget
                    ),
                ));
            }
            let base = self.positions.len();
            self.placements.push(GltfPlacement {
                node,
                mesh: mesh.index(),
                primitive: prim.index(),
                world: *world,
                first_vertex: base,
                vertices: count,
            });
            for e in raw {
                let p: [f64; 3] = std::array::from_fn(|k| gltf_component(e, k, ty, normalized));
                self.positions.push(std::array::from_fn(|r| {
                    m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]
                }));
            }
            self.triangles.extend(tris.into_iter().map(|[a, b, c]| {
                if det < 0.0 {
                    [base + a, base + c, base + b]
                } else {
                    [base + a, base + b, base + c]
                }
            }));
        }
        Ok(())
    }

    /// The accessor's elements as byte slices, every extent checked against its buffer view
    /// and buffer. An accessor without a view (all zeros) or with sparse values is refused.
    fn accessor<'s>(
        buffers: &'s [Cow<'_, [u8]>],
        name: &str,
        acc: &gltf::Accessor,
        at: &str,
    ) -> Result<impl Iterator<Item = &'s [u8]> + 's, SurfaceError> {
        let what = || format!("{at}: accessor {}", acc.index());
        if acc.sparse().is_some() {
            return Err(err(
                name,
                format!("{} is sparse, which is not read; apply the mesh's morph targets and shape keys, or export without them", what()),
            ));
        }
        let Some(view) = acc.view() else {
            return Err(err(name, format!("{} has no bufferView", what())));
        };
        let size = acc.size();
        let stride = view.stride().unwrap_or(size);
        let count = acc.count();
        let extent = count
            .checked_sub(1)
            .and_then(|c| c.checked_mul(stride))
            .and_then(|x| x.checked_add(size))
            .and_then(|x| x.checked_add(acc.offset()));
        let Some(extent) = extent.filter(|_| stride >= size) else {
            return Err(err(
                name,
                format!(
                    "{} has count {count} and stride {stride} for {size}-byte elements",
                    what()
                ),
            ));
        };
        if extent > view.length() {
            return Err(err(
                name,
                format!(
                    "{} spans {extent} bytes of buffer view {}, which has {}",
                    what(),
                    view.index(),
                    view.length()
                ),
            ));
        }
        let buffer = &buffers[view.buffer().index()];
        let start = view.offset();
        let Some(bytes) = start
            .checked_add(view.length())
            .and_then(|end| buffer.get(start..end))
        else {
            return Err(err(
                name,
                format!(
                    "buffer view {} (bytes {start}..+{}) lies outside buffer {} ({} bytes)",
                    view.index(),
                    view.length(),
                    view.buffer().index(),
                    buffer.len()
                ),
            ));
        };
        let bytes = &bytes[acc.offset()..extent];
        Ok((0..count).map(move |k| &bytes[k * stride..k * stride + size]))
    }
}

/// Component `k` of a little-endian element of type `ty` (`F32`, or 8-/16-bit integers); a
/// normalized integer as glTF maps it to [-1, 1] or [0, 1] (signed: `max(c / MAX, -1)`).
pub fn gltf_component(e: &[u8], k: usize, ty: DataType, normalized: bool) -> f64 {
    let (c, max) = match ty {
        DataType::I8 => (f64::from(e[k] as i8), 127.0),
        DataType::U8 => (f64::from(e[k]), 255.0),
        DataType::I16 => (
            f64::from(i16::from_le_bytes([e[2 * k], e[2 * k + 1]])),
            32767.0,
        ),
        DataType::U16 => (
            f64::from(u16::from_le_bytes([e[2 * k], e[2 * k + 1]])),
            65535.0,
        ),
        _ => {
            let b = [e[4 * k], e[4 * k + 1], e[4 * k + 2], e[4 * k + 3]];
            return f64::from(f32::from_le_bytes(b));
        }
    };
    if normalized {
        (c / max).max(-1.0)
    } else {
        c
    }
}

/// Triangles of a primitive from its vertex sequence: a list, a strip (every other triangle
/// reversed to keep one winding) or a fan. Degenerate strip triangles (repeated indices, used to
/// join strips) are dropped.
fn triangles_of(mode: Mode, idx: &[usize]) -> Vec<[usize; 3]> {
    match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        Mode::TriangleStrip => (2..idx.len())
            .map(|k| {
                if k % 2 == 0 {
                    [idx[k - 2], idx[k - 1], idx[k]]
                } else {
                    [idx[k - 1], idx[k - 2], idx[k]]
                }
            })
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect(),
        Mode::TriangleFan => (2..idx.len())
            .map(|k| [idx[0], idx[k - 1], idx[k]])
            .collect(),
        _ => Vec::new(),
    }
}
