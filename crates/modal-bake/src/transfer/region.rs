//! Region selection: which surface vertices the transfer table covers.

use dcr_runtime::ModalModel;

/// An axis-aligned box (m, object frame): `[xmin, ymin, zmin, xmax, ymax, zmax]`.
pub type RegionBox = [f64; 6];

/// Surface vertices (ascending indices) in the union of `boxes` (all vertices when empty) whose
/// outward area-weighted vertex normal n satisfies `n·û ≥ min_cos` for `up = Some(û)` (any
/// direction, normalised here; `None`: no normal filter).
pub fn select_region(
    model: &ModalModel,
    boxes: &[RegionBox],
    up: Option<[f64; 3]>,
    min_cos: f64,
) -> Vec<u32> {
    let x = &model.base().surface_vertices;
    let normals = model.vertex_normals();
    let up = up.map(|u| {
        let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        u.map(|c| c / l)
    });
    (0..x.len())
        .filter(|&v| {
            let p = x[v];
            let in_box = boxes.is_empty()
                || boxes
                    .iter()
                    .any(|b| (0..3).all(|k| p[k] >= b[k] && p[k] <= b[k + 3]));
            let facing = match up {
                None => true,
                Some(u) => {
                    let n = normals[v];
                    n[0] * u[0] + n[1] * u[1] + n[2] * u[2] >= min_cos
                }
            };
            in_box && facing
        })
        .map(|v| v as u32)
        .collect()
}
