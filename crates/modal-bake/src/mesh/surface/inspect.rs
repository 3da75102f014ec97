//! Surface inspection: every defect that keeps a triangle surface from bounding a solid, counted
//! and located, so the meshing backend can be chosen before any work
//! ([`crate::mesh::mesher`]).
//!
//! Topology (one sort of the 3·T half-edges, union–find over corners): open edges (one
//! triangle), non-manifold edges (three or more), edges two triangles run in the same direction
//! (inconsistent orientation), non-manifold vertices (the triangles around a vertex form more
//! than one fan, joined across edges of exactly two triangles; vertices of a non-manifold edge
//! are reported with the edge, not again), shells (components joined across shared edges) and
//! degenerate triangles (a repeated vertex or zero area).
//!
//! Self-intersections: candidate pairs from a traversal of a bounding-volume hierarchy of the
//! triangles' boxes against itself (parry's `Bvh`), pairs on two sides of a plane rejected in
//! floating point with a wide margin, the rest tested exactly with Shewchuk's adaptive `orient3d` (the
//! `robust` crate): two triangles with no common vertex intersect when an edge of one meets
//! the other (closed triangles: touching counts); two sharing one vertex intersect beyond it
//! when the edge opposite the shared vertex of one meets the other. Pairs sharing an edge and
//! coplanar pairs are not tested (a fold of two coplanar triangles over their common edge, or
//! overlapping coplanar triangles, is not reported).
//!
//! Every defect carries a position (m, the asset's frame): an edge's midpoint, the vertex, a
//! point of the intersection. Counts are exact; the first [`MAX_EXAMPLES`] of each kind are kept
//! in a deterministic order (sorted edges, vertex index, triangle pairs).

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};
use robust::{orient3d, Coord3D};

use super::SurfaceMesh;
use dcr_runtime::math::{cross, sub};

/// How many defects of each kind are kept with their positions.
pub const MAX_EXAMPLES: usize = 8;

/// What is wrong at one place of a surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DefectKind {
    /// A triangle with a repeated vertex or zero area.
    DegenerateTriangle,
    /// An edge of one triangle only: the surface has a hole or a gap.
    OpenEdge,
    /// An edge of three or more triangles.
    NonManifoldEdge,
    /// A vertex where separate fans of triangles meet (two solids touching at a point).
    NonManifoldVertex,
    /// An edge two triangles run in the same direction: their normals disagree.
    InconsistentOrientation,
    /// Two triangles crossing or touching away from shared vertices.
    SelfIntersection,
}

impl DefectKind {
    /// A short description (`"open edge"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            DefectKind::DegenerateTriangle => "degenerate triangle",
            DefectKind::OpenEdge => "open edge",
            DefectKind::NonManifoldEdge => "non-manifold edge",
            DefectKind::NonManifoldVertex => "non-manifold vertex",
            DefectKind::InconsistentOrientation => "inconsistently oriented edge",
            DefectKind::SelfIntersection => "self-intersection",
        }
    }
}

/// One defect and where it is.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Defect {
    /// What is wrong.
    pub kind: DefectKind,
    /// Where (m, the asset's frame): an edge's midpoint, the vertex, or a point of the
    /// intersection.
    pub at: [f64; 3],
}

impl std::fmt::Display for Defect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} at ({:.6}, {:.6}, {:.6}) m",
            self.kind.name(),
            self.at[0],
            self.at[1],
            self.at[2]
        )
    }
}

/// What [`inspect_surface`] found: exact counts per kind and located examples.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SurfaceInspection {
    /// Vertices (after welding).
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Axis-aligned bounding box, min then max corner (m).
    pub bbox: [[f64; 3]; 2],
    /// Triangles with a repeated vertex or zero area.
    pub degenerate_triangles: usize,
    /// Edges of exactly one triangle.
    pub open_edges: usize,
    /// Edges of three or more triangles.
    pub non_manifold_edges: usize,
    /// Vertices (not on a non-manifold edge) whose triangles form more than one fan.
    pub non_manifold_vertices: usize,
    /// Edges of two triangles that run them in the same direction.
    pub inconsistent_edges: usize,
    /// Pairs of triangles that intersect (see the module docs for the pairs tested).
    pub self_intersections: usize,
    /// Connected components across shared edges.
    pub shells: usize,
    /// Up to [`MAX_EXAMPLES`] defects of each kind, kinds in [`DefectKind`] order.
    pub examples: Vec<Defect>,
}

impl SurfaceInspection {
    /// Whether the surface bounds one solid as it is: no defect of any kind and one shell
    /// (what gmsh needs).
    pub fn is_solid(&self) -> bool {
        self.degenerate_triangles == 0
            && self.open_edges == 0
            && self.non_manifold_edges == 0
            && self.non_manifold_vertices == 0
            && self.inconsistent_edges == 0
            && self.self_intersections == 0
            && self.shells == 1
    }

    /// The first located defect (in [`DefectKind`] order), if any.
    pub fn first_defect(&self) -> Option<&Defect> {
        self.examples.first()
    }

    /// The defects as a list (`"64 open edges, 1 non-manifold vertex, 2 shells"`), or
    /// `"closed, manifold, consistently oriented, no self-intersection, one shell"`.
    pub fn summary(&self) -> String {
        let plural = |n: usize, one: &str, many: &str| {
            if n == 1 {
                format!("1 {one}")
            } else {
                format!("{n} {many}")
            }
        };
        let mut parts = Vec::new();
        for (n, one, many) in [
            (
                self.degenerate_triangles,
                "degenerate triangle",
                "degenerate triangles",
            ),
            (self.open_edges, "open edge", "open edges"),
            (
                self.non_manifold_edges,
                "non-manifold edge",
                "non-manifold edges",
            ),
            (
                self.non_manifold_vertices,
                "non-manifold vertex",
                "non-manifold vertices",
            ),
            (
                self.inconsistent_edges,
                "inconsistently oriented edge",
                "inconsistently oriented edges",
            ),
            (
                self.self_intersections,
                "self-intersecting triangle pair",
                "self-intersecting triangle pairs",
            ),
        ] {
            if n > 0 {
                parts.push(plural(n, one, many));
            }
        }
        if self.shells != 1 {
            parts.push(plural(self.shells, "shell", "shells"));
        }
        if parts.is_empty() {
            "closed, manifold, consistently oriented, no self-intersection, one shell".into()
        } else {
            parts.join(", ")
        }
    }
}

fn find(parent: &mut [usize], mut v: usize) -> usize {
    while parent[v] != v {
        parent[v] = parent[parent[v]];
        v = parent[v];
    }
    v
}

fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb)] = ra.min(rb);
    }
}

fn mid(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        0.5 * (a[0] + b[0]),
        0.5 * (a[1] + b[1]),
        0.5 * (a[2] + b[2]),
    ]
}

/// Inspects `surface` for every defect kind (see the module docs); the surface is not changed.
/// Cost: a sort of the half-edges and a BVH query per triangle, O(T log T).
///
/// ```
/// use modal_bake::mesh::surface::{inspect_surface, SurfaceMesh};
/// let open = SurfaceMesh {
///     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]],
/// };
/// let found = inspect_surface(&open);
/// assert_eq!(found.open_edges, 3);
/// assert!(!found.is_solid());
/// ```
pub fn inspect_surface(surface: &SurfaceMesh) -> SurfaceInspection {
    let x = &surface.vertices;
    let tris = &surface.triangles;
    let mut out = SurfaceInspection {
        vertices: x.len(),
        triangles: tris.len(),
        bbox: surface.bounding_box(),
        ..Default::default()
    };
    let mut examples: Vec<Defect> = Vec::new();
    let push = |examples: &mut Vec<Defect>, n: &mut usize, kind, at| {
        *n += 1;
        if *n <= MAX_EXAMPLES {
            examples.push(Defect { kind, at });
        }
    };
    let degenerate: Vec<bool> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| x[v]);
            t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || cross(sub(b, a), sub(c, a)) == [0.0; 3]
        })
        .collect();
    for (t, &d) in degenerate.iter().enumerate() {
        if d {
            push(
                &mut examples,
                &mut out.degenerate_triangles,
                DefectKind::DegenerateTriangle,
                x[tris[t][0]],
            );
        }
    }

    // Half-edges keyed by their sorted vertex pair: (key, forward?, triangle).
    let mut half: Vec<([usize; 2], bool, usize)> = Vec::with_capacity(3 * tris.len());
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if a != b {
                half.push(([a.min(b), a.max(b)], a < b, t));
            }
        }
    }
    half.sort_unstable();
    let corner = |t: usize, v: usize| 3 * t + tris[t].iter().position(|&w| w == v).unwrap_or(0);
    let mut fans: Vec<usize> = (0..3 * tris.len()).collect();
    let mut shells: Vec<usize> = (0..tris.len()).collect();
    let mut on_bad_edge = vec![false; x.len()];
    let mut i = 0;
    while i < half.len() {
        let mut j = i + 1;
        while j < half.len() && half[j].0 == half[i].0 {
            j += 1;
        }
        let [a, b] = half[i].0;
        let at = mid(x[a], x[b]);
        for k in i + 1..j {
            union(&mut shells, half[i].2, half[k].2);
        }
        match j - i {
            1 => push(&mut examples, &mut out.open_edges, DefectKind::OpenEdge, at),
            2 => {
                if half[i].1 == half[i + 1].1 {
                    push(
                        &mut examples,
                        &mut out.inconsistent_edges,
                        DefectKind::InconsistentOrientation,
                        at,
                    );
                }
                let (t1, t2) = (half[i].2, half[i + 1].2);
                for v in [a, b] {
                    union(&mut fans, corner(t1, v), corner(t2, v));
                }
            }
            _ => {
                push(
                    &mut examples,
                    &mut out.non_manifold_edges,
                    DefectKind::NonManifoldEdge,
                    at,
                );
                on_bad_edge[a] = true;
                on_bad_edge[b] = true;
            }
        }
        i = j;
    }
    // Fans per vertex: distinct corner classes.
    let mut classes: Vec<(usize, usize)> = (0..3 * tris.len())
        .map(|c| (tris[c / 3][c % 3], find(&mut fans, c)))
        .collect();
    classes.sort_unstable();
    classes.dedup();
    let mut k = 0;
    while k < classes.len() {
        let v = classes[k].0;
        let mut e = k + 1;
        while e < classes.len() && classes[e].0 == v {
            e += 1;
        }
        if e - k > 1 && !on_bad_edge[v] {
            push(
                &mut examples,
                &mut out.non_manifold_vertices,
                DefectKind::NonManifoldVertex,
                x[v],
            );
        }
        k = e;
    }
    out.shells = (0..tris.len())
        .filter(|&t| find(&mut shells, t) == t)
        .count();

    // Self-intersections over a BVH of the (non-degenerate) triangles' boxes.
    let boxes: Vec<Aabb> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| x[v]);
            let lo = Vector::new(
                a[0].min(b[0]).min(c[0]),
                a[1].min(b[1]).min(c[1]),
                a[2].min(b[2]).min(c[2]),
            );
            let hi = Vector::new(
                a[0].max(b[0]).max(c[0]),
                a[1].max(b[1]).max(c[1]),
                a[2].max(b[2]).max(c[2]),
            );
            Aabb::new(lo, hi)
        })
        .collect();
    if tris.len() > 1 {
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes);
        // Plane of each triangle (unnormalised normal) for a floating-point rejection before
        // the exact tests.
        let planes: Vec<([f64; 3], f64)> = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| x[v]);
                let (u, w) = (sub(b, a), sub(c, a));
                (
                    cross(u, w),
                    (dcr_runtime::math::norm2(u) * dcr_runtime::math::norm2(w)).sqrt(),
                )
            })
            .collect();
        let mut hits: Vec<(usize, usize, [f64; 3])> = Vec::new();
        let mut workspace = BvhWorkspace::default();
        bvh.traverse_bvtt_single_tree::<false>(&mut workspace, &mut |a, b| {
            let (t, u) = (a.min(b) as usize, a.max(b) as usize);
            if t == u || degenerate[t] || degenerate[u] {
                return;
            }
            if separated(x, tris[t], planes[t], tris[u])
                || separated(x, tris[u], planes[u], tris[t])
            {
                return;
            }
            if let Some(p) = triangles_intersect(x, tris[t], tris[u]) {
                hits.push((t, u, p));
            }
        });
        hits.sort_unstable_by_key(|h| (h.0, h.1));
        for (_, _, p) in hits {
            push(
                &mut examples,
                &mut out.self_intersections,
                DefectKind::SelfIntersection,
                p,
            );
        }
    }
    examples.sort_by_key(|d| d.kind);
    out.examples = examples;
    out
}

/// Whether the triangle `other` meets the plane of `tri` (normal `n = (b−a)×(c−a)`, `scale`
/// = |b−a|·|c−a|) at most in vertices it shares with `tri`: its other vertices strictly on one
/// side, decided in floating point with a margin (1e-9 relative) far above the rounding error of
/// `n` and of the products; `false` leaves the decision to the exact tests.
fn separated(
    x: &[[f64; 3]],
    tri: [usize; 3],
    (n, scale): ([f64; 3], f64),
    other: [usize; 3],
) -> bool {
    let p = x[tri[0]];
    let mut pos = 0;
    let mut neg = 0;
    let mut free = 0;
    for v in other {
        if tri.contains(&v) {
            continue;
        }
        free += 1;
        let d = sub(x[v], p);
        let s = dcr_runtime::math::dot(n, d);
        let margin = 1e-9 * scale * dcr_runtime::math::norm2(d).sqrt();
        if s > margin {
            pos += 1;
        } else if s < -margin {
            neg += 1;
        }
    }
    free > 0 && (pos == free || neg == free)
}

fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

fn orient(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// Where the closed segment `p q` meets the closed triangle `a b c` (a non-coplanar meeting),
/// exactly decided; the point is computed in floating point.
fn segment_meets_triangle(p: [f64; 3], q: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> Option<[f64; 3]> {
    let op = orient(a, b, c, p);
    let oq = orient(a, b, c, q);
    if (op > 0.0 && oq > 0.0) || (op < 0.0 && oq < 0.0) || (op == 0.0 && oq == 0.0) {
        return None;
    }
    let s = [orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)];
    let all_nonneg = s.iter().all(|&v| v >= 0.0);
    let all_nonpos = s.iter().all(|&v| v <= 0.0);
    if !(all_nonneg || all_nonpos) {
        return None;
    }
    let w = op / (op - oq);
    Some([
        p[0] + w * (q[0] - p[0]),
        p[1] + w * (q[1] - p[1]),
        p[2] + w * (q[2] - p[2]),
    ])
}

/// Whether triangles `s` and `t` (vertex indices into `x`) intersect as described in the
/// module docs; a point of the intersection when they do.
fn triangles_intersect(x: &[[f64; 3]], s: [usize; 3], t: [usize; 3]) -> Option<[f64; 3]> {
    let shared_count = s.iter().filter(|v| t.contains(v)).count();
    let ps = s.map(|v| x[v]);
    let pt = t.map(|v| x[v]);
    match shared_count {
        0 => {
            // Quick rejection: one triangle strictly on one side of the other's plane.
            let side = |tri: [[f64; 3]; 3], pts: [[f64; 3]; 3]| {
                let o = pts.map(|p| orient(tri[0], tri[1], tri[2], p));
                o.iter().all(|&v| v > 0.0) || o.iter().all(|&v| v < 0.0)
            };
            if side(ps, pt) || side(pt, ps) {
                return None;
            }
            for k in 0..3 {
                if let Some(p) = segment_meets_triangle(ps[k], ps[(k + 1) % 3], pt) {
                    return Some(p);
                }
                if let Some(p) = segment_meets_triangle(pt[k], pt[(k + 1) % 3], ps) {
                    return Some(p);
                }
            }
            None
        }
        1 => {
            let v = s.iter().copied().find(|v| t.contains(v)).unwrap_or(s[0]);
            let opposite = |tri: [usize; 3]| {
                let k = tri.iter().position(|&w| w == v).unwrap_or(0);
                (x[tri[(k + 1) % 3]], x[tri[(k + 2) % 3]])
            };
            let (a1, a2) = opposite(s);
            let (b1, b2) = opposite(t);
            segment_meets_triangle(a1, a2, pt).or_else(|| segment_meets_triangle(b1, b2, ps))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(offset: [f64; 3], base: usize) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
        let mut v = Vec::new();
        for k in 0..8 {
            v.push([
                offset[0] + (k & 1) as f64,
                offset[1] + ((k >> 1) & 1) as f64,
                offset[2] + ((k >> 2) & 1) as f64,
            ]);
        }
        let q = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let mut t = Vec::new();
        for f in q {
            t.push([base + f[0], base + f[1], base + f[2]]);
            t.push([base + f[0], base + f[2], base + f[3]]);
        }
        (v, t)
    }

    #[test]
    fn closed_cube_is_solid() {
        let (vertices, triangles) = cube([0.0; 3], 0);
        let s = SurfaceMesh {
            vertices,
            triangles,
        };
        let found = inspect_surface(&s);
        assert!(found.is_solid(), "{}", found.summary());
        assert!(s.signed_volume() > 0.0);
    }

    #[test]
    fn crossing_triangles_found() {
        let s = SurfaceMesh {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 2.0, 0.0],
                [0.5, 0.5, -1.0],
                [0.5, 0.5, 1.0],
                [3.0, 3.0, 0.5],
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        let found = inspect_surface(&s);
        assert_eq!(found.self_intersections, 1);
        let d = found
            .examples
            .iter()
            .find(|d| d.kind == DefectKind::SelfIntersection)
            .unwrap();
        assert!(d.at[2].abs() < 1e-12);
    }
}
