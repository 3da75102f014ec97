//! Checks on a [`TetMesh`] before assembly: orientation, degenerate tetrahedra and group
//! look-up (connectivity: the `pieces` module).

use super::mesh_error::{Location, MeshError, MeshErrorKind};
use super::tet_mesh::{signed_volume, tet_faces, TetMesh};

/// Default relative volume tolerance for [`TetMesh::orient_tets`]: a tetrahedron whose
/// |volume| is below this fraction of the mean tetrahedron volume is degenerate.
pub const DEFAULT_DEGENERATE_REL_TOL: f64 = 1e-10;

/// Default relative tolerance of [`TetMesh::check_straight`]: a mid-edge node farther than this
/// fraction of its edge's length from the midpoint makes the element curved. gmsh's ASCII
/// output (`%.16g`) moves a midpoint by far less.
pub const DEFAULT_STRAIGHT_REL_TOL: f64 = 1e-6;

/// The floor of [`TetMesh::check_straight`]'s tolerance, as a fraction of the mesh's
/// bounding-box diagonal: a mid-edge node this close to its midpoint is the rounding of the
/// file's coordinates, not a curve (Netgen writes six decimals: 8.7e-7 m at most in metres,
/// below this floor on objects over 9 cm across). The assembly never reads mid-edge positions
/// (its elements are affine in their corners), so a node within the floor moves the surface
/// the base stores by at most this much.
pub const STRAIGHT_DIAGONAL_TOL: f64 = 1e-5;

impl TetMesh {
    /// Makes every tetrahedron positively oriented ([`signed_volume`] > 0) by swapping its
    /// last two nodes where the volume is negative; returns how many were flipped.
    ///
    /// `rel_tol` (dimensionless, [`DEFAULT_DEGENERATE_REL_TOL`] is a good default) sets the
    /// degeneracy threshold `rel_tol × mean |volume|` (m³). The mesh is left unchanged on error.
    ///
    /// # Errors
    /// [`MeshErrorKind::DegenerateTet`] for the first tetrahedron whose |volume| is below the
    /// threshold or NaN, located at its element id ([`TetMesh::tet_ids`]).
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// let mut m = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]);
    /// m.tets[0].swap(0, 1);
    /// assert_eq!(m.orient_tets(1e-10).unwrap(), 1);
    /// ```
    pub fn orient_tets(&mut self, rel_tol: f64) -> Result<usize, MeshError> {
        let volumes: Vec<f64> = self
            .tets
            .iter()
            .map(|t| {
                signed_volume(
                    self.nodes[t[0]],
                    self.nodes[t[1]],
                    self.nodes[t[2]],
                    self.nodes[t[3]],
                )
            })
            .collect();
        if volumes.is_empty() {
            return Ok(0);
        }
        let degenerate = |i: usize, volume: f64, threshold: f64| {
            let element = self.tet_ids.get(i).copied().unwrap_or(i as u64 + 1);
            MeshError::new(
                "",
                Location::Element(element),
                MeshErrorKind::DegenerateTet {
                    element,
                    volume,
                    threshold,
                },
            )
        };
        // Non-finite volumes first: they would poison the mean.
        if let Some(i) = volumes.iter().position(|v| !v.is_finite()) {
            return Err(degenerate(i, volumes[i], f64::NAN));
        }
        let mean = volumes.iter().map(|v| v.abs()).sum::<f64>() / volumes.len() as f64;
        let threshold = rel_tol * mean;
        if let Some(i) = volumes
            .iter()
            .position(|&v| v == 0.0 || v.abs() < threshold)
        {
            return Err(degenerate(i, volumes[i], threshold));
        }
        let mut flipped = 0;
        for (i, (t, &v)) in self.tets.iter_mut().zip(&volumes).enumerate() {
            if v < 0.0 {
                t.swap(2, 3);
                // Corners 2 ↔ 3 move the edges (1,2) ↔ (1,3) and (0,2) ↔ (0,3) of
                // TET10_EDGES; (0,1) and (2,3) stay.
                if let Some(e) = self.mid_edges.get_mut(i) {
                    e.swap(1, 5);
                    e.swap(2, 3);
                }
                flipped += 1;
            }
        }
        Ok(flipped)
    }

    /// Checks that every second-order tetrahedron is straight-sided: each mid-edge node lies at
    /// its edge's midpoint within `rel_tol` × the edge length, or within
    /// [`STRAIGHT_DIAGONAL_TOL`] × the mesh's bounding-box diagonal (the coordinates' rounding)
    /// (a curved, non-affine element would need an isoparametric map, which the assembly does
    /// not implement). A linear mesh always passes.
    ///
    /// # Errors
    /// [`MeshErrorKind::CurvedTet`] for the first element whose mid-edge node is off the
    /// midpoint, located at its element id.
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// let mut m = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]).to_quadratic();
    /// assert!(m.check_straight(1e-8).is_ok());
    /// let v = m.mid_edges[0][0];
    /// m.nodes[v][2] += 0.01;
    /// assert!(m.check_straight(1e-8).unwrap_err().to_string().contains("curved"));
    /// ```
    pub fn check_straight(&self, rel_tol: f64) -> Result<(), MeshError> {
        if self.mid_edges.is_empty() {
            return Ok(());
        }
        let floor = STRAIGHT_DIAGONAL_TOL * self.extent();
        for (t, e) in self.mid_edges.iter().enumerate() {
            let c = &self.tets[t];
            for (k, &[a, b]) in super::tet_mesh::TET10_EDGES.iter().enumerate() {
                let (x, y, m) = (self.nodes[c[a]], self.nodes[c[b]], self.nodes[e[k]]);
                let mid = [0, 1, 2].map(|i| 0.5 * (x[i] + y[i]));
                let len =
                    super::tet_mesh::dot(super::tet_mesh::sub(y, x), super::tet_mesh::sub(y, x))
                        .sqrt();
                let off = super::tet_mesh::sub(m, mid);
                let off = super::tet_mesh::dot(off, off).sqrt();
                if !(off <= (rel_tol * len).max(floor)) {
                    let element = self.tet_ids.get(t).copied().unwrap_or(t as u64 + 1);
                    return Err(MeshError::new(
                        "",
                        Location::Element(element),
                        MeshErrorKind::CurvedTet {
                            element,
                            offset: off,
                            edge_length: len,
                        },
                    ));
                }
            }
        }
        Ok(())
    }

    /// Moves every mid-edge node of a second-order mesh to its edge's midpoint, making every
    /// element straight-sided (affine) and the boundary faceted at the corner nodes; returns
    /// the largest distance a node moved (m) and that distance over its edge's length. A node
    /// shared by several tetrahedra is moved once (conforming meshes name it for one edge). A
    /// linear mesh is left as it is: `(0, 0)`.
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// let mut m = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]).to_quadratic();
    /// let v = m.mid_edges[0][0];
    /// m.nodes[v][2] += 0.01;
    /// let (moved, _) = m.straighten();
    /// assert!((moved - 0.01).abs() < 1e-15);
    /// assert!(m.check_straight(1e-12).is_ok());
    /// ```
    pub fn straighten(&mut self) -> (f64, f64) {
        let mut worst = (0.0, 0.0);
        for (t, e) in self.mid_edges.iter().enumerate() {
            let c = self.tets[t];
            for (k, &[a, b]) in super::tet_mesh::TET10_EDGES.iter().enumerate() {
                let (x, y) = (self.nodes[c[a]], self.nodes[c[b]]);
                let mid = [0, 1, 2].map(|i| 0.5 * (x[i] + y[i]));
                let off = super::tet_mesh::sub(self.nodes[e[k]], mid);
                let off = super::tet_mesh::dot(off, off).sqrt();
                if off > worst.0 {
                    let d = super::tet_mesh::sub(y, x);
                    worst = (off, off / super::tet_mesh::dot(d, d).sqrt());
                }
                self.nodes[e[k]] = mid;
            }
        }
        worst
    }

    /// Second-order meshes: every edge (sorted corner pair) with its mid-edge node, sorted by
    /// edge. Empty for a linear mesh.
    ///
    /// # Errors
    /// [`MeshErrorKind::NonConforming`] when tetrahedra sharing an edge name different mid-edge
    /// nodes for it, a mid-edge node sits on two edges, or a node is both a corner and a
    /// mid-edge node; located at the element.
    pub fn edge_mid_nodes(&self) -> Result<Vec<([usize; 2], usize)>, MeshError> {
        let err = |t: usize, detail: String| {
            let element = self.tet_ids.get(t).copied().unwrap_or(t as u64 + 1);
            MeshError::new(
                "",
                Location::Element(element),
                MeshErrorKind::NonConforming { element, detail },
            )
        };
        let mut corner = vec![false; self.nodes.len()];
        for t in &self.tets {
            for &v in t {
                corner[v] = true;
            }
        }
        let mut all: Vec<([usize; 2], usize, usize)> = Vec::with_capacity(6 * self.mid_edges.len());
        for (t, e) in self.mid_edges.iter().enumerate() {
            let c = &self.tets[t];
            for (k, &[a, b]) in super::tet_mesh::TET10_EDGES.iter().enumerate() {
                if corner[e[k]] {
                    return Err(err(
                        t,
                        format!("node {} is a corner of one tetrahedron and a mid-edge node of this one", e[k]),
                    ));
                }
                all.push(([c[a].min(c[b]), c[a].max(c[b])], e[k], t));
            }
        }
        all.sort_unstable();
        let mut out: Vec<([usize; 2], usize)> = Vec::with_capacity(all.len() / 4);
        for w in &all {
            match out.last() {
                Some(&(edge, mid)) if edge == w.0 => {
                    if mid != w.1 {
                        return Err(err(
                            w.2,
                            format!(
                                "edge of nodes {:?} has two mid-edge nodes, {mid} and {}",
                                edge, w.1
                            ),
                        ));
                    }
                }
                _ => out.push((w.0, w.1)),
            }
        }
        let mut mids: Vec<(usize, usize)> = out.iter().enumerate().map(|(i, e)| (e.1, i)).collect();
        mids.sort_unstable();
        if let Some(w) = mids.windows(2).find(|w| w[0].0 == w[1].0) {
            let t = all.iter().find(|x| x.0 == out[w[1].1].0).map_or(0, |x| x.2);
            return Err(err(
                t,
                format!(
                    "mid-edge node {} sits on two edges, {:?} and {:?}",
                    w[0].0, out[w[0].1].0, out[w[1].1].0
                ),
            ));
        }
        Ok(out)
    }

    /// [`TetMesh::edge_mid_nodes`] as a check: a conforming second-order mesh (or any linear
    /// one) passes.
    ///
    /// # Errors
    /// As [`TetMesh::edge_mid_nodes`].
    pub fn check_conforming(&self) -> Result<(), MeshError> {
        self.edge_mid_nodes().map(|_| ())
    }

    /// Checks node positions are within the range the bake and the runtime work in: every
    /// coordinate within ±[`dcr_runtime::format::MAX_COORDINATE_M`] (1e6 m) and a bounding-box
    /// diagonal of at least [`dcr_runtime::format::MIN_EXTENT_M`] (1e-6 m). Outside, volumes,
    /// stiffness and eigenvalues over- or underflow and the failure would surface as a
    /// numerical one far from its cause.
    ///
    /// # Errors
    /// [`MeshErrorKind::CoordinateOutOfRange`] at the first node outside (1-based, canonical
    /// order), [`MeshErrorKind::TooSmall`].
    pub fn check_extent(&self) -> Result<(), MeshError> {
        use dcr_runtime::format::{MAX_COORDINATE_M, MIN_EXTENT_M};
        for (i, p) in self.nodes.iter().enumerate() {
            if let Some(&value) = p.iter().find(|x| !(x.abs() <= MAX_COORDINATE_M)) {
                return Err(MeshError::new(
                    "",
                    Location::Node(i as u64 + 1),
                    MeshErrorKind::CoordinateOutOfRange {
                        value,
                        max: MAX_COORDINATE_M,
                    },
                ));
            }
        }
        let extent = self.extent();
        if !(extent >= MIN_EXTENT_M) && !self.nodes.is_empty() {
            return Err(MeshError::new(
                "",
                Location::None,
                MeshErrorKind::TooSmall {
                    extent,
                    min: MIN_EXTENT_M,
                },
            ));
        }
        Ok(())
    }

    /// Bounding-box diagonal of the nodes (m); 0 for an empty mesh.
    pub fn extent(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.nodes {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if self.nodes.is_empty() {
            return 0.0;
        }
        (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
    }

    /// Checks that no two tetrahedra overlap across a face: in a conforming mesh every
    /// interior face is shared by exactly two tetrahedra, one on each side, so with every
    /// tetrahedron positively oriented (call [`TetMesh::orient_tets`] first) no oriented face
    /// occurs twice. A face occurring twice with one orientation means two tetrahedra on the
    /// same side of it (an overlap, a tetrahedron listed twice, or a face shared by three).
    /// One sort of the 4 faces per tetrahedron.
    ///
    /// # Errors
    /// [`MeshErrorKind::OverlappingTets`] naming both element ids ([`TetMesh::tet_ids`]),
    /// located at the larger.
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// let mut m = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]);
    /// m.check_overlaps().unwrap();
    /// let first = m.tets[0];
    /// m.tets.push(first);
    /// m.tet_ids.push(7);
    /// assert!(m.check_overlaps().is_err());
    /// ```
    pub fn check_overlaps(&self) -> Result<(), MeshError> {
        // Key: sorted node triple and the orientation's parity against it.
        let parity = |f: [usize; 3]| ((f[0] > f[1]) ^ (f[0] > f[2]) ^ (f[1] > f[2])) as u64;
        let pair = if self.nodes.len() <= 1 << 21 && self.tets.len() < 1 << 30 {
            let mut faces: Vec<(u64, u32)> = Vec::with_capacity(4 * self.tets.len());
            for (t, &tet) in self.tets.iter().enumerate() {
                for f in tet_faces(tet) {
                    let mut k = f;
                    k.sort_unstable();
                    let key = (parity(f) << 63)
                        | ((k[0] as u64) << 42)
                        | ((k[1] as u64) << 21)
                        | k[2] as u64;
                    faces.push((key, t as u32));
                }
            }
            faces.sort_unstable();
            faces
                .windows(2)
                .find(|w| w[0].0 == w[1].0)
                .map(|w| (w[0].1 as usize, w[1].1 as usize))
        } else {
            let mut faces: Vec<([usize; 3], u64, usize)> = Vec::with_capacity(4 * self.tets.len());
            for (t, &tet) in self.tets.iter().enumerate() {
                for f in tet_faces(tet) {
                    let mut k = f;
                    k.sort_unstable();
                    faces.push((k, parity(f), t));
                }
            }
            faces.sort_unstable();
            faces
                .windows(2)
                .find(|w| (w[0].0, w[0].1) == (w[1].0, w[1].1))
                .map(|w| (w[0].2, w[1].2))
        };
        let Some((a, b)) = pair else {
            return Ok(());
        };
        let id = |i: usize| self.tet_ids.get(i).copied().unwrap_or(i as u64 + 1);
        let (first, second) = (id(a).min(id(b)), id(a).max(id(b)));
        Err(MeshError::new(
            "",
            Location::Element(second),
            MeshErrorKind::OverlappingTets { first, second },
        ))
    }

    /// The sorted 0-based node indices of group `name`.
    ///
    /// # Errors
    /// [`MeshErrorKind::UnknownGroup`] listing the available group names.
    ///
    /// ```
    /// use modal_bake::mesh::TetMesh;
    /// let m = TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]);
    /// assert_eq!(m.group_nodes("zmin").unwrap().len(), 4);
    /// assert!(m.group_nodes("clamp").unwrap_err().to_string().contains("xmax"));
    /// ```
    pub fn group_nodes(&self, name: &str) -> Result<&[usize], MeshError> {
        self.groups.get(name).map(Vec::as_slice).ok_or_else(|| {
            MeshError::new(
                "",
                Location::None,
                MeshErrorKind::UnknownGroup {
                    name: name.to_string(),
                    available: self.groups.keys().cloned().collect(),
                },
            )
        })
    }
}
