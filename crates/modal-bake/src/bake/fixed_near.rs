//! [`FixedNear`]: a fixed-node selector given by geometry — every node within a distance of
//! a set of points and triangles (`--fixed-near FILE`), e.g. the vertices and faces of a
//! Blender vertex group. Unlike a box, it fixes exactly the region the points and triangles
//! cover, whatever its shape (two ears, a ring, a foot).
//!
//! The file is a Wavefront OBJ subset: `v x y z` (m, the mesh's frame) and `f i j k …`
//! (1-based or negative relative vertex indices, `i/t/n` forms accepted, polygons split into
//! fans); every other line (`#`, `o`, `g`, `vn`, …) is ignored. A file with vertices and no
//! faces is a point set.
//!
//! Selection ([`FixedNear::select`]): the distance from each node to the nearest triangle (an
//! exact point projection, parry's BVH) or point (a uniform grid of cell `distance`); nodes at
//! most `distance` away are fixed. On a second-order mesh, the mid-edge node of every edge
//! whose two corner nodes are fixed is fixed too (it lies on the chord between them, which a
//! curved region can put farther than `distance` from the triangles).

use std::collections::HashMap;

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::TriMesh;

use super::BakeError;

/// Default distance as a fraction of the mesh's bounding-box diagonal: 1/200, above the
/// distance between a remeshed or fTetWild boundary and the asset it came from (gmsh's
/// boundary nodes lie on the asset; fTetWild's within its envelope, 1/1000 by default).
pub const DEFAULT_DISTANCE_FRACTION: f64 = 1.0 / 200.0;

/// Every node within `distance` of `points` (and of the `triangles` over them) is fixed.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FixedNear {
    /// The points (m, mesh frame).
    pub points: Vec<[f64; 3]>,
    /// Triangles over `points` (0-based indices).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub triangles: Vec<[usize; 3]>,
    /// The distance (m); `None`: [`DEFAULT_DISTANCE_FRACTION`] of the mesh's bounding-box
    /// diagonal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distance: Option<f64>,
    /// Where the points came from (a file name), for messages; not part of the bake's
    /// parameters (moving the file does not change the base).
    #[serde(skip)]
    pub label: String,
}

fn vertex_index(token: &str, count: usize) -> Option<usize> {
    let first = token.split('/').next()?;
    let i: i64 = first.parse().ok()?;
    let n = i64::try_from(count).ok()?;
    let zero_based = if i > 0 { i - 1 } else { n + i };
    (0..n)
        .contains(&zero_based)
        .then(|| usize::try_from(zero_based).ok())
        .flatten()
}

impl FixedNear {
    /// Parses the OBJ subset of the module doc; `name` names the file in errors.
    ///
    /// # Errors
    /// A malformed `v` or `f` line (with its line number and how to fix it), a non-finite
    /// coordinate, a face index out of range, or a file without vertices.
    ///
    /// ```
    /// use modal_bake::bake::FixedNear;
    /// let f = FixedNear::parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "ears.obj").unwrap();
    /// assert_eq!((f.points.len(), f.triangles), (3, vec![[0, 1, 2]]));
    /// ```
    pub fn parse(text: &str, name: &str) -> Result<FixedNear, BakeError> {
        let bad = |line: usize, what: String| {
            BakeError::Params(format!(
                "{name}:{line}: --fixed-near: {what}; the file is an OBJ of `v x y z` lines (m) and optional `f i j k` faces (1-based vertex numbers)"
            ))
        };
        let mut points = Vec::new();
        let mut faces: Vec<(usize, Vec<&str>)> = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let mut it = line.split_whitespace();
            match it.next() {
                Some("v") => {
                    let xyz: Vec<f64> = it
                        .by_ref()
                        .take(3)
                        .map(str::parse)
                        .collect::<Result<_, _>>()
                        .map_err(|e| {
                            bad(k + 1, format!("a vertex coordinate is not a number ({e})"))
                        })?;
                    if xyz.len() != 3 || !xyz.iter().all(|x| x.is_finite()) {
                        return Err(bad(k + 1, "a vertex needs three finite coordinates".into()));
                    }
                    points.push([xyz[0], xyz[1], xyz[2]]);
                }
                Some("f") => faces.push((k + 1, it.collect())),
                _ => {}
            }
        }
        if points.is_empty() {
            return Err(BakeError::Params(format!(
                "{name}: --fixed-near: the file has no `v x y z` vertex lines, so it selects nothing"
            )));
        }
        let mut triangles = Vec::new();
        for (line, tokens) in faces {
            let idx: Vec<usize> = tokens
                .iter()
                .map(|t| vertex_index(t, points.len()))
                .collect::<Option<_>>()
                .ok_or_else(|| {
                    bad(
                        line,
                        format!(
                            "a face vertex is not a vertex number within 1…{}",
                            points.len()
                        ),
                    )
                })?;
            if idx.len() < 3 {
                return Err(bad(line, "a face needs at least three vertices".into()));
            }
            for j in 1..idx.len() - 1 {
                triangles.push([idx[0], idx[j], idx[j + 1]]);
            }
        }
        Ok(FixedNear {
            points,
            triangles,
            distance: None,
            label: name.to_string(),
        })
    }

    /// Reads and parses the file at `path` ([`FixedNear::parse`]); only a regular file is
    /// opened, and no more than its size is read.
    ///
    /// # Errors
    /// The file cannot be opened or is not UTF-8 text, or [`FixedNear::parse`]'s errors.
    pub fn read(path: &std::path::Path) -> Result<FixedNear, BakeError> {
        use dcr_runtime::format::{open_regular_file, OpenError};
        use std::io::Read;
        let name = path.display().to_string();
        let (file, len) = open_regular_file(path).map_err(|e| {
            BakeError::Params(format!(
                "{name}: --fixed-near: {}",
                match e {
                    OpenError::NotRegular(what) => format!("not a regular file ({what})"),
                    OpenError::Io(e) => e.to_string(),
                }
            ))
        })?;
        let mut text = String::new();
        file.take(len)
            .read_to_string(&mut text)
            .map_err(|e| BakeError::Params(format!("{name}: --fixed-near: {e}")))?;
        FixedNear::parse(&text, &name)
    }

    /// The distance used on a mesh whose bounding-box diagonal is `diagonal` (m).
    pub fn distance_for(&self, diagonal: f64) -> f64 {
        self.distance
            .unwrap_or(DEFAULT_DISTANCE_FRACTION * diagonal)
    }

    /// The nodes (ascending) within the distance of the points or triangles, plus (second
    /// order) the mid-edge node of each edge `mid_table` lists whose corners are both in.
    /// `diagonal` is the mesh's bounding-box diagonal (m) for the default distance.
    pub fn select(
        &self,
        nodes: &[[f64; 3]],
        mid_table: &[([usize; 2], usize)],
        diagonal: f64,
    ) -> Vec<usize> {
        let d = self.distance_for(diagonal);
        let d2 = d * d;
        // Points: a uniform grid of cell d, each node looks in its 27 neighbouring cells.
        let cell = |p: [f64; 3]| p.map(|x| (x / d).floor() as i64);
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (i, p) in self.points.iter().enumerate() {
            grid.entry(cell(*p)).or_default().push(i);
        }
        let near_point = |p: [f64; 3]| {
            let c = cell(p);
            (-1..=1).any(|dx| {
                (-1..=1).any(|dy| {
                    (-1..=1).any(|dz| {
                        grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz])
                            .is_some_and(|ids| {
                                ids.iter().any(|&i| {
                                    let q = self.points[i];
                                    (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>() <= d2
                                })
                            })
                    })
                })
            })
        };
        let tris = (!self.triangles.is_empty())
            .then(|| {
                let v = self
                    .points
                    .iter()
                    .map(|p| Vector::new(p[0], p[1], p[2]))
                    .collect();
                let t = self.triangles.iter().map(|t| t.map(|i| i as u32)).collect();
                TriMesh::new(v, t).ok()
            })
            .flatten();
        let mut fixed: Vec<bool> = nodes
            .iter()
            .map(|p| {
                near_point(*p)
                    || tris.as_ref().is_some_and(|tm| {
                        let q = Vector::new(p[0], p[1], p[2]);
                        let proj = tm.project_local_point(q, false);
                        (proj.point - q).length() <= d
                    })
            })
            .collect();
        for &([a, b], m) in mid_table {
            if fixed[a] && fixed[b] {
                fixed[m] = true;
            }
        }
        (0..nodes.len()).filter(|&v| fixed[v]).collect()
    }
}
