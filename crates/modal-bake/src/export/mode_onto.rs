//! [`write_modes_glb_onto`]: a base's mode shapes as morph targets on the artist's own mesh.
//!
//! The base's surface is the tetrahedral mesh's boundary (gmsh remeshes the asset), so its
//! vertices are not the asset's. Each asset vertex p is mapped to the closest point of the
//! base's surface triangles (parry's BVH, [`ModalModel::project`]) and a mode is read there
//! with the finite-element interpolation of the base: barycentric weights on a first-order
//! base, the six quadratic shape functions ([`quadratic_triangle_weights`]) on a
//! second-order one. The morph target of mode j at vertex p is `a_j Σᵢ Nᵢ U_j(nodeᵢ)` (m).
//!
//! The asset is read with its own vertex list, in file order, none merged or dropped, so the
//! glTF mesh has the asset's vertex count and index order (what Blender shape keys and engine
//! morph targets index by). OBJ is read here (`v` and `f` records) rather than with `tobj`,
//! which renumbers each object's vertices in first-use order and drops unused ones; STL and
//! PLY come from [`read_surface_unwelded`].

use std::path::Path;

use dcr_runtime::format::ModesFile;
use dcr_runtime::model::quadratic_triangle_weights;
use dcr_runtime::ModalModel;

use super::gltf_builder::extras_of;
use super::mode_gltf::morph_scene;
use super::{diagonal, write_file_atomic, ExportError, GltfBuilder};
use crate::mesh::surface::read_surface_unwelded_object;

/// A surface asset's own vertices and triangles (positions in m after unit scaling).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AssetMesh {
    /// Vertex positions in file order (m, the asset's frame).
    pub positions: Vec<[f64; 3]>,
    /// Triangles (polygons fan-triangulated), 0-based indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

impl AssetMesh {
    /// Reads an OBJ, STL, PLY or glTF asset keeping its vertex list and order, and multiplies its
    /// coordinates by `to_metres` (the factor `modal-bake mesh --units` applies). `object`: only
    /// that named object ([`read_surface_object`](crate::mesh::surface::read_surface_object)),
    /// for an OBJ the vertices its faces use, in file order.
    ///
    /// # Errors
    /// [`ExportError::Invalid`] naming the file (and line for OBJ): unreadable, unknown
    /// extension, parse errors, indices out of range, non-finite coordinates, no triangles.
    pub fn read(
        path: &Path,
        to_metres: f64,
        object: Option<&str>,
    ) -> Result<AssetMesh, ExportError> {
        let name = path.display().to_string();
        let data = std::fs::read(path).map_err(|e| ExportError::Io {
            path: path.to_path_buf(),
            source: e,
        })?;
        let is_obj = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        let (mut positions, triangles) = if is_obj {
            let a = read_obj_ordered(&data, &name, object)?;
            (a.positions, a.triangles)
        } else {
            let (p, t) = read_surface_unwelded_object(&data, &name, object)
                .map_err(|e| ExportError::Invalid(e.to_string()))?;
            (p, t.into_iter().map(|t| t.map(|i| i as u32)).collect())
        };
        if let Some(v) = positions
            .iter()
            .position(|p| !p.iter().all(|x| x.is_finite()))
        {
            return Err(ExportError::Invalid(format!(
                "{name}: vertex {v} has a non-finite coordinate"
            )));
        }
        if to_metres != 1.0 {
            for p in &mut positions {
                *p = p.map(|x| x * to_metres);
            }
        }
        Ok(AssetMesh {
            positions,
            triangles,
        })
    }
}

/// OBJ `v` records in file order and `f` records fan-triangulated (`i`, `i/t`, `i//n`,
/// `i/t/n`; negative indices count back from the last vertex read).
fn read_obj_ordered(
    data: &[u8],
    name: &str,
    object: Option<&str>,
) -> Result<AssetMesh, ExportError> {
    let bad = |line: usize, what: String| ExportError::Invalid(format!("{name}:{line}: {what}"));
    let text = std::str::from_utf8(data)
        .map_err(|e| ExportError::Invalid(format!("{name}: not a text OBJ file: {e}")))?;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut triangles = Vec::new();
    // The current `o`/`g` name, and the names seen (for the error when `object` is not there).
    let mut current = String::new();
    let mut names: Vec<String> = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let mut tok = raw.split_whitespace();
        match tok.next() {
            Some("o" | "g") => {
                current = tok.collect::<Vec<_>>().join(" ");
                if !names.contains(&current) {
                    names.push(current.clone());
                }
            }
            Some("f") if object.is_some_and(|o| o != current) => {}
            Some("v") => {
                let mut p = [0.0; 3];
                for (a, x) in p.iter_mut().enumerate() {
                    let t = tok.next().ok_or_else(|| {
                        bad(line, format!("`v` record has {a} coordinates, needs 3"))
                    })?;
                    *x = t
                        .parse()
                        .map_err(|_| bad(line, format!("`{t}` is not a number")))?;
                }
                positions.push(p);
            }
            Some("f") => {
                let mut face = Vec::new();
                for t in tok {
                    let first = t.split('/').next().unwrap_or("");
                    let i: i64 = first
                        .parse()
                        .map_err(|_| bad(line, format!("face corner `{t}` is not an index")))?;
                    let n = positions.len() as i64;
                    let idx = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || idx < 0 || idx >= n {
                        return Err(bad(
                            line,
                            format!(
                                "face names vertex {i}, but {n} vertices are defined before it"
                            ),
                        ));
                    }
                    face.push(idx as u32);
                }
                if face.len() < 3 {
                    return Err(bad(
                        line,
                        format!("face has {} corners, needs 3", face.len()),
                    ));
                }
                for c in 1..face.len() - 1 {
                    triangles.push([face[0], face[c], face[c + 1]]);
                }
            }
            _ => {}
        }
    }
    if let Some(o) = object {
        if !names.iter().any(|n| n == o) {
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            return Err(ExportError::Invalid(format!(
                "{name}: no object or group named `{o}`; {}",
                crate::mesh::surface::list_names(&names)
            )));
        }
        // The vertices the object's faces use, in file order.
        let mut keep = vec![u32::MAX; positions.len()];
        for t in &triangles {
            for &v in t {
                keep[v as usize] = 0;
            }
        }
        let mut kept = Vec::new();
        for (v, k) in keep.iter_mut().enumerate() {
            if *k == 0 {
                *k = kept.len() as u32;
                kept.push(positions[v]);
            }
        }
        positions = kept;
        for t in &mut triangles {
            *t = t.map(|v| keep[v as usize]);
        }
    }
    if triangles.is_empty() {
        return Err(ExportError::Invalid(format!(
            "{name}: the file holds no faces"
        )));
    }
    Ok(AssetMesh {
        positions,
        triangles,
    })
}

/// Mode shapes read at an asset's vertices.
#[derive(Clone, Debug)]
pub struct OntoMapping {
    /// Number of modes mapped (the lowest n).
    pub modes: usize,
    /// Displacements (nv, 3, n) row-major: `u[(v * 3 + axis) * n + j]` (m·kg^-½ per unit
    /// modal coordinate, the base's frame).
    pub u: Vec<f64>,
    /// Distance from each asset vertex to its closest point on the base's surface (m).
    pub distance: Vec<f64>,
    /// Whether every node interpolated at the vertex (weight ≠ 0) was held fixed by the bake.
    pub fixed: Vec<bool>,
}

impl OntoMapping {
    /// Largest mapping distance (m) and the vertex where it occurs.
    pub fn max_distance(&self) -> (f64, usize) {
        self.distance.iter().enumerate().fold(
            (0.0, 0),
            |(d, i), (k, &x)| if x > d { (x, k) } else { (d, i) },
        )
    }
}

/// Maps the lowest `modes` modes of `base` to the points `positions` (m, the base's frame):
/// closest point on the surface triangles, then the base's finite-element interpolation there.
///
/// # Errors
/// [`ExportError::Invalid`] when the base is not a valid surface model or a point is not
/// finite.
pub fn map_modes_onto(
    base: &ModesFile,
    positions: &[[f64; 3]],
    modes: usize,
) -> Result<OntoMapping, ExportError> {
    let m = base.num_modes();
    if modes == 0 || modes > m {
        return Err(ExportError::Invalid(format!(
            "cannot map {modes} modes from a base with {m}"
        )));
    }
    let model = ModalModel::from_base(base.clone())
        .map_err(|e| ExportError::Invalid(format!("the base's surface: {e}")))?;
    let tri_edges = match &base.quadratic {
        Some(q) => q
            .triangle_edges(&base.surface_triangles)
            .map_err(ExportError::Invalid)?,
        None => Vec::new(),
    };
    let reach = 1e3 * (model.bounding_box_diagonal() + diagonal(positions)) + 1.0;
    let n = modes;
    let mut u = vec![0.0; positions.len() * 3 * n];
    let mut distance = Vec::with_capacity(positions.len());
    let fixed_nodes: std::collections::BTreeSet<u32> = base.fixed_nodes.iter().copied().collect();
    let mut fixed = Vec::with_capacity(positions.len());
    for (v, &p) in positions.iter().enumerate() {
        let sp = model.project(p, reach).ok_or_else(|| {
            ExportError::Invalid(format!(
                "asset vertex {v} at ({:.6}, {:.6}, {:.6}) m has no closest point on the base's surface",
                p[0], p[1], p[2]
            ))
        })?;
        distance.push(sp.distance);
        let corners = model.triangle(sp.triangle);
        let mut add = |rows: &[f64], node: usize, w: f64| {
            for axis in 0..3 {
                let row = &rows[(node * 3 + axis) * m..(node * 3 + axis) * m + n];
                let out = &mut u[(v * 3 + axis) * n..(v * 3 + axis + 1) * n];
                for (o, x) in out.iter_mut().zip(row) {
                    *o += w * x;
                }
            }
        };
        let mut all_fixed = true;
        let mut held = |volume_node: u32, w: f64| {
            if w != 0.0 && !fixed_nodes.contains(&volume_node) {
                all_fixed = false;
            }
        };
        match &base.quadratic {
            None => {
                for (i, c) in corners.into_iter().enumerate() {
                    add(&base.modes, c, sp.bary[i]);
                    held(base.surface_to_volume[c], sp.bary[i]);
                }
            }
            Some(q) => {
                let w = quadratic_triangle_weights(sp.bary);
                for (i, c) in corners.into_iter().enumerate() {
                    add(&base.modes, c, w[i]);
                    held(base.surface_to_volume[c], w[i]);
                }
                for (k, e) in tri_edges[sp.triangle as usize].into_iter().enumerate() {
                    add(&q.modes, e as usize, w[3 + k]);
                    held(q.edge_to_volume[e as usize], w[3 + k]);
                }
            }
        }
        fixed.push(all_fixed && !fixed_nodes.is_empty());
    }
    Ok(OntoMapping {
        modes,
        u,
        distance,
        fixed,
    })
}

/// A mode's display name, `mode N — F Hz` (1-based N; F with one decimal, three significant
/// digits below 1 Hz): the morph-target and shape-key name.
///
/// ```
/// assert_eq!(modal_bake::export::mode_title(0, 12.34), "mode 1 — 12.3 Hz");
/// ```
pub fn mode_title(j: usize, hz: f64) -> String {
    if hz >= 1.0 {
        format!("mode {} — {:.1} Hz", j + 1, hz)
    } else {
        format!("mode {} — {} Hz", j + 1, super::format_sig(hz, 3))
    }
}

/// Settings of [`write_modes_glb_onto`].
#[derive(Clone, Debug)]
pub struct OntoParams {
    /// Number of the lowest modes exported (1..=m).
    pub modes: usize,
    /// Visual amplitude: at morph weight 1 a mode's largest displacement over the asset's
    /// vertices is `scale` × the asset's bounding-box diagonal (dimensionless). Default 0.05.
    pub scale: f64,
    /// Period of every mode's preview animation (s, visual). Default 1.
    pub period_s: f64,
    /// Keyframes per period. Default 24.
    pub keyframes: usize,
}

impl Default for OntoParams {
    fn default() -> Self {
        OntoParams {
            modes: 8,
            scale: 0.05,
            period_s: 1.0,
            keyframes: 24,
        }
    }
}

/// What [`write_modes_glb_onto`] did.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OntoInfo {
    /// Vertices of the asset given targets (= of the glTF mesh written for OBJ, STL, PLY).
    pub vertices: usize,
    /// Triangles of the glTF mesh.
    pub triangles: usize,
    /// Primitives given the targets (1 for OBJ, STL and PLY assets: one new mesh).
    pub primitives: usize,
    /// Largest distance from an asset vertex to the base's surface (m).
    pub max_distance_m: f64,
    /// Index of the vertex with the largest distance.
    pub max_distance_vertex: usize,
    /// The asset's bounding-box diagonal (m).
    pub diagonal_m: f64,
}

/// Writes the asset's mesh as a GLB with the lowest `params.modes` modes of `base` as morph
/// targets on its own vertices ([`map_modes_onto`]), one preview animation per mode
/// (w = sin 2πt/period), target names `mode N — F Hz` in `mesh.extras.targetNames`, and
/// `extras.dcr` on the document: `kind: "modes_onto"`, `scale`, `diagonal_m`, `period_s`,
/// `max_mapping_distance_m`, `fixed_vertices` (asset vertices interpolated only from fixed
/// nodes) and per mode `{mode, name, frequency_hz, eigenvalue,
/// modal_coordinate, max_displacement_m}` (displacement = weight × target, m).
///
/// Positions in m in the asset's frame (the base's), triangles as the asset's polygons.
///
/// # Errors
/// As [`map_modes_onto`]; [`ExportError::Invalid`] for a non-positive scale or period, fewer
/// than 4 keyframes, or a mode that is zero at every asset vertex; `Io` on write failures.
///
/// ```no_run
/// use modal_bake::export::{write_modes_glb_onto, AssetMesh, OntoParams};
/// let base = dcr_runtime::format::ModesFile::read("cube.modes".as_ref()).unwrap();
/// let asset = AssetMesh::read("cube.obj".as_ref(), 1.0, None).unwrap();
/// write_modes_glb_onto(&base, &asset, &OntoParams::default(), "cube.glb".as_ref()).unwrap();
/// ```
pub fn write_modes_glb_onto(
    base: &ModesFile,
    asset: &AssetMesh,
    params: &OntoParams,
    path: &Path,
) -> Result<OntoInfo, ExportError> {
    let (bytes, info) = onto_glb_bytes(base, asset, params)?;
    write_file_atomic(path, &bytes)?;
    Ok(info)
}

/// Refuses a non-positive scale or period and fewer than 4 keyframes.
pub(super) fn check_onto_params(params: &OntoParams) -> Result<(), ExportError> {
    if !(params.scale.is_finite() && params.scale > 0.0) {
        return Err(ExportError::Invalid(format!(
            "parameter `scale` must be positive, got {}",
            params.scale
        )));
    }
    if !(params.period_s.is_finite() && params.period_s > 0.0) || params.keyframes < 4 {
        return Err(ExportError::Invalid(
            "animation period must be positive with at least 4 keyframes".into(),
        ));
    }
    Ok(())
}

/// Each mapped mode's modal coordinate `a_j` (kg^½·m) that makes its largest displacement over
/// the asset's vertices `scale × diag` (m), its display name, and its entry of
/// `extras.dcr.modes`.
///
/// # Errors
/// [`ExportError::Invalid`] for a mode that is zero at every asset vertex.
pub(super) fn mode_amplitudes(
    base: &ModesFile,
    map: &OntoMapping,
    diag: f64,
    scale: f64,
) -> Result<Vec<(f64, String, serde_json::Value)>, ExportError> {
    let n = map.modes;
    let nv = map.distance.len();
    let freqs = base.frequencies_hz();
    (0..n)
        .map(|j| {
            let peak = (0..nv)
                .map(|v| {
                    (0..3)
                        .map(|a| map.u[(v * 3 + a) * n + j].powi(2))
                        .sum::<f64>()
                        .sqrt()
                })
                .fold(0.0, f64::max);
            if !(peak > 0.0) {
                return Err(ExportError::Invalid(format!(
                    "mode {} is zero at every asset vertex",
                    j + 1
                )));
            }
            let a = scale * diag / peak;
            let name = mode_title(j, freqs[j]);
            let info = serde_json::json!({
                "mode": j + 1,
                "name": name,
                "frequency_hz": freqs[j],
                "eigenvalue": base.eigenvalues[j],
                "modal_coordinate": a,
                "max_displacement_m": scale * diag,
            });
            Ok((a, name, info))
        })
        .collect()
}

/// `extras.dcr` of an `--onto` GLB: `kind: "modes_onto"`, `scale`, `diagonal_m` (m),
/// `period_s` (s), `max_mapping_distance_m` (m), `fixed_vertices`, `source_hash`, the glTF
/// asset's `placements` when given, and `modes`.
pub(super) fn onto_extras(
    base: &ModesFile,
    params: &OntoParams,
    diag: f64,
    map: &OntoMapping,
    modes: Vec<serde_json::Value>,
    placements: Option<Vec<serde_json::Value>>,
) -> serde_json::Value {
    let (max_d, _) = map.max_distance();
    let mut dcr = serde_json::json!({
        "kind": "modes_onto",
        "scale": params.scale,
        "diagonal_m": diag,
        "period_s": params.period_s,
        "max_mapping_distance_m": max_d,
        "fixed_vertices": (0..map.distance.len()).filter(|&v| map.fixed[v]).collect::<Vec<_>>(),
        "source_hash": base.meta.source_hash,
        "modes": modes,
    });
    if let Some(p) = placements {
        dcr["placements"] = serde_json::Value::Array(p);
    }
    dcr
}

fn onto_glb_bytes(
    base: &ModesFile,
    asset: &AssetMesh,
    params: &OntoParams,
) -> Result<(Vec<u8>, OntoInfo), ExportError> {
    check_onto_params(params)?;
    let nv = asset.positions.len();
    if let Some(t) = asset
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= nv))
    {
        return Err(ExportError::Invalid(format!(
            "asset triangle {t:?} names a vertex beyond its {nv} vertices"
        )));
    }
    let n = params.modes;
    let map = map_modes_onto(base, &asset.positions, n)?;
    let diag = diagonal(&asset.positions);
    let positions: Vec<[f32; 3]> = asset
        .positions
        .iter()
        .map(|p| p.map(|x| x as f32))
        .collect();
    let mut targets = Vec::with_capacity(n);
    let mut modes_info = Vec::with_capacity(n);
    for (j, (a, name, info)) in mode_amplitudes(base, &map, diag, params.scale)?
        .into_iter()
        .enumerate()
    {
        let d: Vec<[f32; 3]> = (0..nv)
            .map(|v| std::array::from_fn(|x| (a * map.u[(v * 3 + x) * n + j]) as f32))
            .collect();
        modes_info.push(info);
        targets.push((name, d));
    }
    let (max_d, worst) = map.max_distance();

    let mut b = GltfBuilder::new();
    morph_scene(
        &mut b,
        "asset",
        &positions,
        &asset.triangles,
        true,
        &targets,
        (params.period_s, params.keyframes),
    )?;
    b.root.extras = extras_of(&serde_json::json!({
        "dcr": onto_extras(base, params, diag, &map, modes_info, None),
    }));
    let info = OntoInfo {
        vertices: nv,
        triangles: asset.triangles.len(),
        primitives: 1,
        max_distance_m: max_d,
        max_distance_vertex: worst,
        diagonal_m: diag,
    };
    Ok((b.to_glb()?, info))
}
