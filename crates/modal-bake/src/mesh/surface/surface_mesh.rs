//! [`SurfaceMesh`]: an indexed triangle surface and its closed / manifold / orientation check.

use super::SurfaceError;

/// An indexed triangle surface (positions in m after unit scaling, object frame).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Vertex positions (m).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as 0-based vertex indices, counter-clockwise seen from outside once
    /// [`SurfaceMesh::check_closed`] has run.
    pub triangles: Vec<[usize; 3]>,
}

/// What [`SurfaceMesh::check_closed`] found on a valid surface.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SurfaceInfo {
    /// Distinct vertices after welding.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Enclosed volume (m³), positive.
    pub volume_m3: f64,
    /// Axis-aligned bounding box: min then max corner (m).
    pub bbox: [[f64; 3]; 2],
    /// Whether every triangle was reversed to point outward (the file's were inward).
    pub flipped: bool,
}

use dcr_runtime::math::{cross, sub};

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

impl SurfaceMesh {
    /// A surface from positions (m) and triangles, with bit-identical positions merged into one
    /// vertex and unreferenced vertices dropped (vertices keep their first-use order).
    pub fn welded(positions: Vec<[f64; 3]>, triangles: Vec<[usize; 3]>) -> SurfaceMesh {
        let mut order: Vec<usize> = (0..positions.len()).collect();
        let key = |p: &[f64; 3]| p.map(|x| (x + 0.0).to_bits()); // −0.0 welds with 0.0
        order.sort_unstable_by_key(|&i| (key(&positions[i]), i));
        let mut rep: Vec<usize> = (0..positions.len()).collect();
        for w in order.windows(2) {
            if key(&positions[w[0]]) == key(&positions[w[1]]) {
                rep[w[1]] = rep[w[0]];
            }
        }
        let mut index = vec![usize::MAX; positions.len()];
        let mut vertices = Vec::new();
        let triangles = triangles
            .iter()
            .map(|t| {
                t.map(|v| {
                    let r = rep[v];
                    if index[r] == usize::MAX {
                        index[r] = vertices.len();
                        vertices.push(positions[r]);
                    }
                    index[r]
                })
            })
            .collect();
        SurfaceMesh {
            vertices,
            triangles,
        }
    }

    /// Multiplies every position by `factor` (unit conversion to metres).
    pub fn scale(&mut self, factor: f64) {
        for p in &mut self.vertices {
            *p = p.map(|x| x * factor);
        }
    }

    /// Axis-aligned bounding box (min corner, max corner), m.
    pub fn bounding_box(&self) -> [[f64; 3]; 2] {
        let mut b = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
        for p in &self.vertices {
            for k in 0..3 {
                b[0][k] = b[0][k].min(p[k]);
                b[1][k] = b[1][k].max(p[k]);
            }
        }
        b
    }

    /// Signed enclosed volume (m³), Σ a·(b×c)/6: positive when the triangles face outward.
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices[v]);
                let n = cross(b, c);
                (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / 6.0
            })
            .sum()
    }

    /// Checks that the surface bounds a solid: no degenerate triangle, every edge shared by
    /// exactly two triangles running it in opposite directions (closed, manifold, consistently
    /// oriented), one fan of triangles around every vertex, one connected shell. Orients the
    /// triangles outward (reversing all of them when the enclosed volume is negative).
    ///
    /// Defects are reported at the first one in vertex-index order, with positions (m).
    ///
    /// # Errors
    /// The first defect as a [`SurfaceError`] naming `file`.
    ///
    /// ```
    /// use modal_bake::mesh::surface::SurfaceMesh;
    /// let tet = |tris: Vec<[usize; 3]>| SurfaceMesh {
    ///     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ///     triangles: tris,
    /// };
    /// let mut closed = tet(vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
    /// assert!((closed.check_closed("t.stl").unwrap().volume_m3 - 1.0 / 6.0).abs() < 1e-15);
    /// let err = tet(vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]]).check_closed("t.stl").unwrap_err();
    /// assert!(err.to_string().contains("open edge"));
    /// ```
    pub fn check_closed(&mut self, file: &str) -> Result<SurfaceInfo, SurfaceError> {
        let file_s = || file.to_string();
        if self.triangles.is_empty() {
            return Err(SurfaceError::Empty { file: file_s() });
        }
        let x = &self.vertices;
        for (t, tri) in self.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|v| x[v]);
            let n = cross(sub(b, a), sub(c, a));
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || n == [0.0; 3] {
                return Err(SurfaceError::Degenerate {
                    file: file_s(),
                    triangle: t,
                    at: a,
                });
            }
        }
        // Half-edges keyed by their sorted vertex pair: (key, forward?, triangle).
        let mut half: Vec<([usize; 2], bool, usize)> = Vec::with_capacity(3 * self.triangles.len());
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                half.push(([a.min(b), a.max(b)], a < b, t));
            }
        }
        half.sort_unstable();
        let open_edges = {
            let mut n = 0;
            let mut i = 0;
            while i < half.len() {
                let j = (i..half.len())
                    .find(|&j| half[j].0 != half[i].0)
                    .unwrap_or(half.len());
                if j - i == 1 {
                    n += 1;
                }
                i = j;
            }
            n
        };
        // Corners (triangle, local vertex) joined across shared edges: one class per fan.
        let corner = |t: usize, v: usize, tris: &[[usize; 3]]| {
            3 * t + tris[t].iter().position(|&w| w == v).unwrap_or(0)
        };
        let mut fans: Vec<usize> = (0..3 * self.triangles.len()).collect();
        let mut shells: Vec<usize> = (0..self.triangles.len()).collect();
        let mut i = 0;
        while i < half.len() {
            let j = (i..half.len())
                .find(|&j| half[j].0 != half[i].0)
                .unwrap_or(half.len());
            let [a, b] = half[i].0;
            let (pa, pb) = (x[a], x[b]);
            match j - i {
                1 => {
                    return Err(SurfaceError::OpenEdge {
                        file: file_s(),
                        a: pa,
                        b: pb,
                        open_edges,
                    })
                }
                2 => {
                    if half[i].1 == half[i + 1].1 {
                        return Err(SurfaceError::Orientation {
                            file: file_s(),
                            a: pa,
                            b: pb,
                        });
                    }
                    let (t1, t2) = (half[i].2, half[i + 1].2);
                    union(&mut shells, t1, t2);
                    for v in [a, b] {
                        let (c1, c2) = (
                            corner(t1, v, &self.triangles),
                            corner(t2, v, &self.triangles),
                        );
                        union(&mut fans, c1, c2);
                    }
                }
                n => {
                    return Err(SurfaceError::NonManifoldEdge {
                        file: file_s(),
                        a: pa,
                        b: pb,
                        triangles: n,
                    })
                }
            }
            i = j;
        }
        // Fans per vertex: distinct corner classes.
        let mut classes: Vec<(usize, usize)> = (0..3 * self.triangles.len())
            .map(|c| (self.triangles[c / 3][c % 3], find(&mut fans, c)))
            .collect();
        classes.sort_unstable();
        classes.dedup();
        if let Some(w) = classes.windows(2).find(|w| w[0].0 == w[1].0) {
            let v = w[0].0;
            let n = classes.iter().filter(|c| c.0 == v).count();
            return Err(SurfaceError::NonManifoldVertex {
                file: file_s(),
                at: x[v],
                fans: n,
            });
        }
        let nshells = (0..self.triangles.len())
            .filter(|&t| find(&mut shells, t) == t)
            .count();
        if nshells != 1 {
            return Err(SurfaceError::Shells {
                file: file_s(),
                shells: nshells,
            });
        }
        let mut volume = self.signed_volume();
        let flipped = volume < 0.0;
        if flipped {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
            volume = -volume;
        }
        Ok(SurfaceInfo {
            vertices: self.vertices.len(),
            triangles: self.triangles.len(),
            volume_m3: volume,
            bbox: self.bounding_box(),
            flipped,
        })
    }
}
