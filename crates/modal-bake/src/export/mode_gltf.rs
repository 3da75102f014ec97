//! [`write_modes_glb`]: a base's surface as binary glTF 2.0 with one morph target and one
//! animation per mode.

use std::path::Path;

use dcr_runtime::format::ModesFile;
use gltf::json::{self, animation::Property, validation::Checked, Index};

use super::gltf_builder::extras_of;
use super::{diagonal, mode_label, write_file_atomic, ExportError, ExportSurface, GltfBuilder};

/// Settings of [`write_modes_glb`].
#[derive(Clone, Debug)]
pub struct ModeGltfParams {
    /// Number of the lowest modes exported (1..=m).
    pub modes: usize,
    /// Visual amplitude: at morph weight 1 a mode's largest vertex displacement is `scale` ×
    /// the surface's bounding-box diagonal (dimensionless). Default 0.05.
    pub scale: f64,
    /// Period of every mode's animation (s; a visual period, not the mode's own). Default 1.
    pub period_s: f64,
    /// Keyframes per period (linear interpolation of a sine). Default 24.
    pub keyframes: usize,
}

impl Default for ModeGltfParams {
    fn default() -> Self {
        ModeGltfParams {
            modes: 8,
            scale: 0.05,
            period_s: 1.0,
            keyframes: 24,
        }
    }
}

/// Writes the surface of `base` as a GLB with the lowest `params.modes` mode shapes as morph
/// targets of its one mesh, and one animation per mode (`mode_01_12.3Hz`, ...) that drives
/// that target's weight through one sine period (w = sin 2πt/period, the other weights 0).
///
/// Geometry: positions in m, object frame (y-up for the scene meshes), outward triangles.
/// Morph target j is a_j U_j (m), U_j the mode's surface rows (m·kg^-½) and a_j (kg^½·m) the
/// modal coordinate at weight 1, chosen so that the largest vertex displacement is
/// `scale × diagonal`. `extras.dcr` on the document records `kind: "modes"`, `scale`,
/// `diagonal_m`, `period_s`, `fixed_vertices` (the vertices whose volume node the bake held
/// fixed, ascending) and per mode `{mode, label, name, frequency_hz, eigenvalue,
/// modal_coordinate, max_displacement_m}` (`name` = [`super::mode_title`], `modal_coordinate`
/// = a_j), so the physical shape is recoverable: displacement = weight × target.
///
/// Written atomically (temporary file + rename).
///
/// # Errors
/// [`ExportError::Invalid`] for a mode count out of range, a non-positive or non-finite
/// scale/period, fewer than 4 keyframes, or a zero mode; `Io` on write failures.
///
/// ```no_run
/// use modal_bake::export::{write_modes_glb, ModeGltfParams};
/// let base = dcr_runtime::format::ModesFile::read("table.modes".as_ref()).unwrap();
/// write_modes_glb(&base, &ModeGltfParams { modes: 8, ..Default::default() }, "table.glb".as_ref()).unwrap();
/// ```
pub fn write_modes_glb(
    base: &ModesFile,
    params: &ModeGltfParams,
    path: &Path,
) -> Result<(), ExportError> {
    let bytes = modes_glb_bytes(base, params)?;
    write_file_atomic(path, &bytes)
}

fn modes_glb_bytes(base: &ModesFile, params: &ModeGltfParams) -> Result<Vec<u8>, ExportError> {
    let m = base.num_modes();
    let n = params.modes;
    if n == 0 || n > m {
        return Err(ExportError::Invalid(format!(
            "cannot export {n} modes from a base with {m}"
        )));
    }
    if !(params.scale > 0.0 && params.scale <= super::MAX_SCALE) {
        return Err(ExportError::Invalid(format!(
            "parameter `scale` (--scale) must be in (0, {}] (the largest displacement as a \
             fraction of the bounding-box diagonal), got {}",
            super::MAX_SCALE,
            params.scale
        )));
    }
    if !(params.period_s.is_finite() && params.period_s > 0.0) || params.keyframes < 4 {
        return Err(ExportError::Invalid(
            "animation period must be positive with at least 4 keyframes".into(),
        ));
    }
    let surf = ExportSurface::of(base);
    let ns = surf.len();
    let freqs = base.frequencies_hz();
    let diag = diagonal(&surf.positions);
    let positions: Vec<[f32; 3]> = surf
        .positions
        .iter()
        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
        .collect();
    let mut targets = Vec::with_capacity(n);
    let mut info = Vec::with_capacity(n);
    for j in 0..n {
        let peak = surf.mode_max_norm(j);
        if !(peak > 0.0) {
            return Err(ExportError::Invalid(format!(
                "mode {} is zero on the surface",
                j + 1
            )));
        }
        let a = params.scale * diag / peak;
        let d: Vec<[f32; 3]> = (0..ns)
            .map(|v| {
                let u = surf.mode_vec(v, j);
                [(a * u[0]) as f32, (a * u[1]) as f32, (a * u[2]) as f32]
            })
            .collect();
        let label = mode_label(j, freqs[j]);
        info.push(serde_json::json!({
            "mode": j + 1,
            "label": label,
            "name": super::mode_title(j, freqs[j]),
            "frequency_hz": freqs[j],
            "eigenvalue": base.eigenvalues[j],
            "modal_coordinate": a,
            "max_displacement_m": params.scale * diag,
        }));
        targets.push((label, d));
    }

    let mut b = GltfBuilder::new();
    morph_scene(
        &mut b,
        "surface",
        &positions,
        &surf.triangles,
        false,
        &targets,
        (params.period_s, params.keyframes),
    )?;
    let fixed: std::collections::BTreeSet<u32> = base.fixed_nodes.iter().copied().collect();
    let fixed_vertices: Vec<usize> = (0..ns)
        .filter(|&v| fixed.contains(&surf.volume_node[v]))
        .collect();
    b.root.extras = extras_of(&serde_json::json!({
        "dcr": {
            "kind": "modes",
            "scale": params.scale,
            "diagonal_m": diag,
            "period_s": params.period_s,
            "fixed_vertices": fixed_vertices,
            "source_hash": base.meta.source_hash,
            "modes": info,
        }
    }));
    b.to_glb()
}

/// Adds to `b` one mesh `name` (`positions` in m, `triangles`, a neutral material, one-sided
/// unless `double_sided`) with `targets` as its morph targets (POSITION deltas, m), one node and
/// scene holding it, and per target one animation (the last argument: its period in s and its
/// keyframes) that drives its weight through one sine period (w = sin 2πt/period, the other
/// weights 0) by linear keyframes. Shared by the base-surface and the `--onto` exports.
///
/// # Errors
/// [`ExportError`] from the builder (non-finite positions or deltas).
pub(super) fn morph_scene(
    b: &mut GltfBuilder,
    name: &str,
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    double_sided: bool,
    targets: &[(String, Vec<[f32; 3]>)],
    (period_s, keyframes): (f64, usize),
) -> Result<(), ExportError> {
    let n = targets.len();
    let material = b.material(name, [0.75, 0.72, 0.68, 1.0], 0.6, double_sided);
    let mesh = b.triangle_mesh(name, positions, triangles, material, targets)?;
    let node = b.root.push(json::Node {
        mesh: Some(mesh),
        name: Some(name.into()),
        weights: Some(vec![0.0; n]),
        ..Default::default()
    });
    let scene = b.root.push(json::Scene {
        extensions: None,
        extras: None,
        name: Some("modes".into()),
        nodes: vec![node],
    });
    b.root.scene = Some(scene);

    // One shared time input; one weights output per mode.
    let k = keyframes;
    let times: Vec<f32> = (0..=k)
        .map(|i| (period_s * i as f64 / k as f64) as f32)
        .collect();
    let input = b.scalars(&times, true);
    for (j, (label, _)) in targets.iter().enumerate() {
        let mut w = vec![0.0f32; (k + 1) * n];
        for i in 0..=k {
            w[i * n + j] = super::loop_weight(i, k);
        }
        let output = b.scalars(&w, false);
        b.root.push(json::Animation {
            extensions: None,
            extras: None,
            name: Some(label.clone()),
            samplers: vec![json::animation::Sampler {
                extensions: None,
                extras: None,
                input,
                interpolation: Checked::Valid(json::animation::Interpolation::Linear),
                output,
            }],
            channels: vec![json::animation::Channel {
                sampler: Index::new(0),
                target: json::animation::Target {
                    extensions: None,
                    extras: None,
                    node,
                    path: Checked::Valid(Property::MorphTargetWeights),
                },
                extensions: None,
                extras: None,
            }],
        });
    }
    Ok(())
}
