//! [`QuadraticSurface`]: the mid-edge rows of a second-order (P2) base.
//!
//! A base baked from 10-node tetrahedra has a surface of 6-node triangles: the corners are the
//! base's `surface_vertices` (so the BVH, normals and heat geodesics work on the linear
//! triangles as for P1) and the mid-edge nodes are the surface edges listed here, with their
//! rows of U. The runtime interpolates a mode at barycentric (b₀, b₁, b₂) of triangle
//! (v₀, v₁, v₂) with the quadratic shape functions
//! `Σᵢ bᵢ(2bᵢ − 1) U(vᵢ) + 4 b₀b₁ U(e₀₁) + 4 b₁b₂ U(e₁₂) + 4 b₂b₀ U(e₂₀)`, which is the
//! finite-element field itself on straight-sided elements.
//!
//! Entries (version ≥ 2, all three present or none): `surface_edges` u32 (ne, 2),
//! `edge_to_volume` u32 (ne,), `edge_modes` f64 or f32 (ne, 3, m) in the precision of `modes`.

/// Entry names of the second-order surface (all present or all absent).
pub(crate) const QUADRATIC_ENTRIES: [&str; 3] = ["surface_edges", "edge_to_volume", "edge_modes"];

/// The first `.modes` version that can hold a second-order surface.
pub const QUADRATIC_FORMAT_VERSION: u32 = 2;

/// The mid-edge nodes of a second-order base's 6-node surface triangles and their mode rows.
#[derive(Clone, Debug, PartialEq)]
pub struct QuadraticSurface {
    /// Surface edges as surface-vertex pairs `[a, b]` with a < b, strictly ascending: exactly
    /// the edges of `ModesFile::surface_triangles` ([`QuadraticSurface::edges_of`]). Edge `e`
    /// carries the mid-edge node `e`.
    pub edges: Vec<[u32; 2]>,
    /// Volume-mesh node index of each mid-edge node, length ne.
    pub edge_to_volume: Vec<u32>,
    /// Mode rows at the mid-edge nodes, row-major (ne, 3, m): `modes[(e * 3 + axis) * m + j]`
    /// (m·kg^-1/2, object frame), laid out like `ModesFile::modes`.
    pub modes: Vec<f64>,
}

impl QuadraticSurface {
    /// The sorted, deduplicated edges (`[a, b]`, a < b) of a triangle list.
    ///
    /// ```
    /// use dcr_runtime::format::QuadraticSurface;
    /// let e = QuadraticSurface::edges_of(&[[0, 1, 2], [2, 1, 3]]);
    /// assert_eq!(e, vec![[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]);
    /// ```
    pub fn edges_of(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| sorted_pair(t[k], t[(k + 1) % 3])))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// Index of edge `{a, b}` (either order), `None` if it is not listed.
    pub fn edge_index(&self, a: u32, b: u32) -> Option<usize> {
        self.edges.binary_search(&sorted_pair(a, b)).ok()
    }

    /// For each triangle `[v₀, v₁, v₂]`, the indices of its edges (v₀,v₁), (v₁,v₂), (v₂,v₀).
    ///
    /// # Errors
    /// The first triangle with an edge that is not listed.
    pub fn triangle_edges(&self, triangles: &[[u32; 3]]) -> Result<Vec<[u32; 3]>, String> {
        triangles
            .iter()
            .enumerate()
            .map(|(t, tri)| {
                let mut out = [0u32; 3];
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    out[k] = self.edge_index(a, b).ok_or_else(|| {
                        format!("surface triangle {t}: edge ({a}, {b}) has no mid-edge node")
                    })? as u32;
                }
                Ok(out)
            })
            .collect()
    }

    /// Checks sizes, order, finiteness and that the edges are exactly the triangles' edges.
    pub(crate) fn check(&self, ns: usize, m: usize, triangles: &[[u32; 3]]) -> Result<(), String> {
        let ne = self.edges.len();
        if let Some(i) = self
            .edges
            .windows(2)
            .position(|w| w[0] >= w[1])
            .or_else(|| self.edges.iter().position(|e| e[0] >= e[1]))
        {
            return Err(format!(
                "surface_edges must be strictly ascending pairs [a, b] with a < b (at edge {i})"
            ));
        }
        if let Some(e) = self.edges.iter().find(|e| e[1] as usize >= ns) {
            return Err(format!("surface edge {e:?} names a vertex ≥ {ns}"));
        }
        if self.edges != Self::edges_of(triangles) {
            return Err(format!(
                "surface_edges ({ne}) are not exactly the edges of the surface triangles"
            ));
        }
        if self.edge_to_volume.len() != ne {
            return Err(format!(
                "edge_to_volume has {} entries for {ne} surface edges",
                self.edge_to_volume.len()
            ));
        }
        if self.modes.len() != ne * 3 * m {
            return Err(format!(
                "edge_modes hold {} values, expected ne×3×m = {ne}×3×{m}",
                self.modes.len()
            ));
        }
        if let Some(i) = self.modes.iter().position(|x| !x.is_finite()) {
            return Err(format!(
                "non-finite edge mode value at edge {}, axis {}, mode {}",
                i / (3 * m),
                (i / m) % 3,
                i % m
            ));
        }
        Ok(())
    }
}

fn sorted_pair(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}
