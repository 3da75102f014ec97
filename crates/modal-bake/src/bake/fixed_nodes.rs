//! The fixed-node selectors of an elastic object — physical groups, half-spaces, boxes and
//! nodes near given points — checked and resolved to a mesh's nodes. One definition serves the
//! bake ([`BakeParams`](super::BakeParams)), the full-order reference
//! ([`SystemParams`](crate::full_order::SystemParams)) and every tool that pins a scene's
//! object, so a selector fixes the same nodes wherever it is given.

use super::{unit_hint, BakeError, FixedBelow, FixedNear};
use crate::mesh::{MeshError, TetMesh};

/// The fixed-node selectors of one object, borrowed; the fixed set is their union. All
/// coordinates are in the mesh's frame (m). Every selector empty: free-free.
#[derive(Clone, Copy, Debug, Default)]
pub struct FixedSelectors<'a> {
    /// Names of physical groups whose nodes are fixed.
    pub groups: &'a [String],
    /// Half-spaces: every node whose coordinate `axis` is ≤ `value` (m).
    pub below: &'a [FixedBelow],
    /// Axis-aligned boxes `[x0, y0, z0, x1, y1, z1]` (m, bounds included).
    pub boxes: &'a [[f64; 6]],
    /// Nodes within a distance of given points and triangles (m).
    pub near: &'a [FixedNear],
}

/// A resolved fixed-node set.
#[derive(Clone, Debug, PartialEq)]
pub struct FixedNodes {
    /// The fixed nodes: sorted, without repeats (empty: free-free).
    pub nodes: Vec<usize>,
    /// What each selector fixed: (description, node count), in the order groups, half-spaces,
    /// boxes, near.
    pub by: Vec<(String, usize)>,
}

impl FixedSelectors<'_> {
    /// Whether no selector is given (the object is free-free).
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
            && self.below.is_empty()
            && self.boxes.is_empty()
            && self.near.is_empty()
    }

    /// Checks the selectors before any mesh work: axes 0–2 and finite values, boxes with each
    /// minimum ≤ its maximum, `near` sets with points, finite coordinates, triangles indexing
    /// the points and a positive distance.
    ///
    /// # Errors
    /// [`BakeError::Params`] naming the parameter and the value.
    pub fn check(&self) -> Result<(), BakeError> {
        for b in self.below {
            if b.axis > 2 || !b.value.is_finite() {
                return Err(BakeError::Params(format!(
                    "parameter `fixed_below` needs an axis 0, 1 or 2 (x, y, z) and a finite value in m, got axis {} value {}",
                    b.axis, b.value
                )));
            }
        }
        for b in self.boxes {
            if !b.iter().all(|x| x.is_finite()) || (0..3).any(|k| b[k] > b[k + 3]) {
                return Err(BakeError::Params(format!(
                    "parameter `fixed_boxes` = {b:?}: expected finite [x0, y0, z0, x1, y1, z1] (m) with each minimum ≤ its maximum"
                )));
            }
        }
        for f in self.near {
            let n = f.points.len();
            if n == 0
                || !f.points.iter().flatten().all(|x| x.is_finite())
                || f.triangles.iter().flatten().any(|&i| i >= n)
                || f.distance.is_some_and(|d| !(d.is_finite() && d > 0.0))
            {
                return Err(BakeError::Params(format!(
                    "parameter `fixed_near` ({}): expected at least one point, finite coordinates (m), triangles indexing the points and a positive distance (m), got {n} points, {} triangles, distance {:?}",
                    f.label,
                    f.triangles.len(),
                    f.distance
                )));
            }
        }
        Ok(())
    }

    /// The fixed nodes of `mesh` (read from `file`, named in errors): [`check`](Self::check),
    /// then the union of every selector's nodes.
    ///
    /// # Errors
    /// An invalid selector, an unknown group, a selector that fixes no node (the message gives
    /// the mesh's extent), fixed nodes that are collinear (rotations about their line stay free:
    /// K is singular) or that are every node of the mesh.
    pub fn resolve(&self, mesh: &TetMesh, file: &str) -> Result<FixedNodes, BakeError> {
        let mid_table = if self.near.is_empty() {
            Vec::new()
        } else {
            mesh.edge_mid_nodes().map_err(|mut e| {
                if e.file.is_empty() {
                    e.file = file.to_string();
                }
                BakeError::Mesh(e)
            })?
        };
        self.resolve_with(mesh, &mid_table, file)
    }

    /// [`resolve`](Self::resolve) with the mesh's mid-edge table (each edge, as a sorted
    /// corner pair, with its mid-edge node, sorted; empty for a linear mesh) already built.
    pub(crate) fn resolve_with(
        &self,
        mesh: &TetMesh,
        mid_table: &[([usize; 2], usize)],
        file: &str,
    ) -> Result<FixedNodes, BakeError> {
        self.check()?;
        let selected = select_each(mesh, mid_table, self, file)?;
        let by: Vec<(String, usize)> = selected
            .iter()
            .map(|(what, nodes)| (what.clone(), nodes.len()))
            .collect();
        let mut fixed: Vec<usize> = selected.into_iter().flat_map(|(_, n)| n).collect();
        fixed.sort_unstable();
        fixed.dedup();
        if !fixed.is_empty() && !spans_a_plane(mesh, &fixed) {
            return Err(BakeError::Params(format!(
                "{file}: the fixed nodes ({} of them: {}) are collinear, so rotations about their line stay free \
                 (a mechanism, K is singular); fix a patch of at least three non-collinear nodes{}",
                fixed.len(),
                by.iter().map(|(w, _)| w.as_str()).collect::<Vec<_>>().join(", "),
                scale_note(mesh)
            )));
        }
        if !fixed.is_empty() && fixed.len() == mesh.nodes.len() {
            return Err(BakeError::Params(format!(
                "{file}: the fixed-node selectors fix every node; nothing can vibrate{}",
                scale_note(mesh)
            )));
        }
        Ok(FixedNodes { nodes: fixed, by })
    }
}

/// The nodes (sorted) each selector of `sel` picks, with a description per selector
/// (`group bottom`, `below y=0.01`, `box [..]`, `near FILE (..)`).
///
/// # Errors
/// An unknown group, or a selector that picks no node (it names the mesh's extent).
fn select_each(
    mesh: &TetMesh,
    mid_table: &[([usize; 2], usize)],
    sel: &FixedSelectors<'_>,
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
    for name in sel.groups {
        let nodes = mesh.group_nodes(name).map_err(name_file)?.to_vec();
        if nodes.is_empty() {
            return Err(BakeError::Params(format!(
                "{file}: parameter `fixed`: group {name} fixes no node (the group has no node on the tetrahedra)"
            )));
        }
        out.push((format!("group {name}"), nodes));
    }
    for b in sel.below {
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
    for bx in sel.boxes {
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
    for near in sel.near {
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
