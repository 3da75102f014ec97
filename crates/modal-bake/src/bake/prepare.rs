//! A mesh made ready for baking: tetrahedra oriented and checked, connectivity checked, the
//! fixed-node set selected (groups, half-spaces, boxes, nodes near given points) and the geometry hashed.

use super::{geometry_hash, unit_hint, BakeError, BakeParams};
use crate::mesh::{MeshError, TetMesh, DEFAULT_DEGENERATE_REL_TOL, DEFAULT_STRAIGHT_REL_TOL};

/// A mesh prepared for baking: oriented, checked, with its fixed-node set and hash.
pub(super) struct Prepared {
    pub(super) mesh: TetMesh,
    pub(super) fixed: Vec<usize>,
    /// What each selector fixed: (description, nodes), in the order groups, below, boxes.
    pub(super) fixed_by: Vec<(String, usize)>,
    /// Second-order meshes: each edge (sorted corner pair) with its mid-edge node, sorted.
    pub(super) mid_table: Vec<([usize; 2], usize)>,
    pub(super) reoriented: usize,
    pub(super) hash: String,
}

/// The nodes (sorted) each fixed-node selector of `params` picks, with a description per
/// selector (`group bottom`, `below y=0.01`, `box [..]`, `near FILE (..)`).
///
/// # Errors
/// An unknown group, or a selector that picks no node (it names the mesh's extent).
fn select_fixed(
    mesh: &TetMesh,
    mid_table: &[([usize; 2], usize)],
    params: &BakeParams,
    file: &str,
) -> Result<Vec<(String, Vec<usize>)>, BakeError> {
    let name_file = |mut e: MeshError| {
        if e.file.is_empty() {
            e.file = file.to_string();
        }
        e
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &mesh.nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = || {
        format!(
            "the mesh spans x {:.6}…{:.6}, y {:.6}…{:.6}, z {:.6}…{:.6} m{}",
            lo[0],
            hi[0],
            lo[1],
            hi[1],
            lo[2],
            hi[2],
            scale_note(mesh)
        )
    };
    let mut out = Vec::new();
    for name in &params.fixed {
        let nodes = mesh.group_nodes(name).map_err(name_file)?.to_vec();
        if nodes.is_empty() {
            return Err(BakeError::Params(format!(
                "{file}: parameter `fixed`: group {name} fixes no node (the group has no node on the tetrahedra)"
            )));
        }
        out.push((format!("group {name}"), nodes));
    }
    for b in &params.fixed_below {
        let nodes: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&v| mesh.nodes[v][b.axis] <= b.value)
            .collect();
        if nodes.is_empty() {
            return Err(BakeError::Params(format!(
                "{file}: parameter `fixed_below` ({b}) fixes no node ({})",
                extent()
            )));
        }
        out.push((format!("below {b}"), nodes));
    }
    for bx in &params.fixed_boxes {
        let nodes: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&v| (0..3).all(|k| (bx[k]..=bx[k + 3]).contains(&mesh.nodes[v][k])))
            .collect();
        if nodes.is_empty() {
            return Err(BakeError::Params(format!(
                "{file}: parameter `fixed_boxes` ({}) fixes no node ({})",
                bx.map(|x| x.to_string()).join(","),
                extent()
            )));
        }
        out.push((
            format!("box {}", bx.map(|x| x.to_string()).join(",")),
            nodes,
        ));
    }
    let diagonal = mesh.extent();
    for near in &params.fixed_near {
        let nodes = near.select(&mesh.nodes, mid_table, diagonal);
        let what = format!(
            "near {} ({} points, {} triangles, within {:.4e} m)",
            if near.label.is_empty() {
                "the given points"
            } else {
                &near.label
            },
            near.points.len(),
            near.triangles.len(),
            near.distance_for(diagonal)
        );
        if nodes.is_empty() {
            return Err(BakeError::Params(format!(
                "{file}: parameter `fixed_near` ({what}) fixes no node ({}); check that the points are in the mesh's frame and unit (m), or give a larger distance",
                extent()
            )));
        }
        out.push((what, nodes));
    }
    Ok(out)
}

pub(super) fn prepare(
    mut mesh: TetMesh,
    params: &BakeParams,
    file: &str,
) -> Result<Prepared, BakeError> {
    let name_file = |mut e: MeshError| {
        if e.file.is_empty() {
            e.file = file.to_string();
        }
        e
    };
    if mesh.tets.is_empty() {
        return Err(BakeError::Params(format!(
            "{file}: the mesh has no tetrahedra"
        )));
    }
    mesh.check_extent().map_err(name_file)?;
    let reoriented = mesh
        .orient_tets(DEFAULT_DEGENERATE_REL_TOL)
        .map_err(name_file)?;
    mesh.check_straight(DEFAULT_STRAIGHT_REL_TOL)
        .map_err(name_file)?;
    let mid_table = mesh.edge_mid_nodes().map_err(name_file)?;
    mesh.check_overlaps().map_err(name_file)?;
    let pieces = mesh.connected_components();
    if pieces != 1 {
        return Err(BakeError::Disconnected {
            file: file.to_string(),
            pieces,
        });
    }
    let selected = select_fixed(&mesh, &mid_table, params, file)?;
    let fixed_by: Vec<(String, usize)> = selected
        .iter()
        .map(|(what, nodes)| (what.clone(), nodes.len()))
        .collect();
    let mut fixed: Vec<usize> = selected.into_iter().flat_map(|(_, n)| n).collect();
    fixed.sort_unstable();
    fixed.dedup();
    if !fixed.is_empty() && !spans_a_plane(&mesh, &fixed) {
        return Err(BakeError::Params(format!(
            "{file}: the fixed nodes ({} of them: {}) are collinear, so rotations about their line stay free \
             (a mechanism, K is singular); fix a patch of at least three non-collinear nodes{}",
            fixed.len(),
            fixed_by.iter().map(|(w, _)| w.as_str()).collect::<Vec<_>>().join(", "),
            scale_note(&mesh)
        )));
    }
    if !fixed.is_empty() && fixed.len() == mesh.nodes.len() {
        return Err(BakeError::Params(format!(
            "{file}: the fixed-node selectors fix every node; nothing can vibrate{}",
            scale_note(&mesh)
        )));
    }
    let hash = geometry_hash(&mesh, &fixed);
    Ok(Prepared {
        mesh,
        fixed,
        fixed_by,
        mid_table,
        reoriented,
        hash,
    })
}

/// `"; note: <unit hint>"` when the mesh's size is implausible ([`unit_hint`]), else empty: a
/// selector that fixes nothing, one node, a line or everything is often a length-unit mistake.
fn scale_note(mesh: &TetMesh) -> String {
    unit_hint(mesh.extent()).map_or_else(String::new, |h| format!("; note: {h}"))
}

/// Whether the nodes `set` contain three non-collinear points (relative tolerance 1e-9 of the
/// set's extent): only then do they suppress every rigid-body motion.
fn spans_a_plane(mesh: &TetMesh, set: &[usize]) -> bool {
    let p0 = mesh.nodes[set[0]];
    let dist2 = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>();
    let Some(&far) = set
        .iter()
        .max_by(|&&a, &&b| dist2(p0, mesh.nodes[a]).total_cmp(&dist2(p0, mesh.nodes[b])))
    else {
        return false;
    };
    let p1 = mesh.nodes[far];
    let l2 = dist2(p0, p1);
    if !(l2 > 0.0) {
        return false;
    }
    // Area of (p0, p1, p) relative to |p0 p1|²: twice the triangle area = |(p1−p0)×(p−p0)|.
    let e = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
    set.iter().any(|&v| {
        let p = mesh.nodes[v];
        let d = [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]];
        let c = [
            e[1] * d[2] - e[2] * d[1],
            e[2] * d[0] - e[0] * d[2],
            e[0] * d[1] - e[1] * d[0],
        ];
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() > 1e-9 * l2
    })
}
