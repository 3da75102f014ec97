//! Fixed (clamped) nodes: restriction of K, M to the free dofs and expansion of modes back.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Mat, MatRef};

/// Why a set of fixed nodes was rejected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DofMapError {
    /// A fixed node index is not a node of the mesh.
    #[error("fixed node {node} out of range (mesh has {n_nodes} nodes)")]
    NodeOutOfRange {
        /// The offending 0-based node index.
        node: usize,
        /// Number of mesh nodes.
        n_nodes: usize,
    },
    /// The fixed-node list is not strictly ascending.
    #[error("fixed nodes must be sorted ascending without duplicates (at position {position})")]
    NotSorted {
        /// Position in the list where the order breaks.
        position: usize,
    },
}

/// Map between the full node-major dof vector (`3·node + axis`) and the free dofs left after
/// clamping a set of nodes (all three axes of each fixed node are removed).
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    n_full: usize,
    /// Full dof index of each free dof, ascending.
    free: Vec<usize>,
    /// Free index of each full dof, `usize::MAX` when fixed.
    full_to_free: Vec<usize>,
}

impl DofMap {
    /// The map for a mesh of `n_nodes` nodes with the strictly ascending `fixed_nodes` clamped.
    ///
    /// # Errors
    /// [`DofMapError`] if a node is out of range or the list is not strictly ascending.
    pub fn new(n_nodes: usize, fixed_nodes: &[usize]) -> Result<DofMap, DofMapError> {
        for (i, &v) in fixed_nodes.iter().enumerate() {
            if v >= n_nodes {
                return Err(DofMapError::NodeOutOfRange { node: v, n_nodes });
            }
            if i > 0 && fixed_nodes[i - 1] >= v {
                return Err(DofMapError::NotSorted { position: i });
            }
        }
        let n_full = 3 * n_nodes;
        let mut full_to_free = vec![usize::MAX; n_full];
        let mut free = Vec::with_capacity(n_full - 3 * fixed_nodes.len());
        let mut f = fixed_nodes.iter().peekable();
        for a in 0..n_nodes {
            if f.peek() == Some(&&a) {
                f.next();
                continue;
            }
            for k in 0..3 {
                full_to_free[3 * a + k] = free.len();
                free.push(3 * a + k);
            }
        }
        Ok(DofMap {
            n_full,
            free,
            full_to_free,
        })
    }

    /// Number of dofs of the full problem (3 per node).
    pub fn n_full(&self) -> usize {
        self.n_full
    }

    /// Number of free dofs.
    pub fn n_free(&self) -> usize {
        self.free.len()
    }

    /// Full dof index of each free dof (ascending).
    pub fn free_dofs(&self) -> &[usize] {
        &self.free
    }

    /// Free index of full dof `dof`, or `None` when it is fixed.
    pub fn free_index(&self, dof: usize) -> Option<usize> {
        self.full_to_free
            .get(dof)
            .copied()
            .filter(|&i| i != usize::MAX)
    }

    /// The submatrix of a full `3n × 3n` matrix on the free rows and columns (same units).
    ///
    /// # Panics
    /// If `a` is not `n_full × n_full`.
    pub fn restrict(&self, a: &SparseColMat<usize, f64>) -> SparseColMat<usize, f64> {
        assert_eq!((a.nrows(), a.ncols()), (self.n_full, self.n_full));
        let col_ptr_in = a.symbolic().col_ptr();
        let rows_in = a.symbolic().row_idx();
        let vals_in = a.val();
        let mut col_ptr = Vec::with_capacity(self.free.len() + 1);
        let mut rows = Vec::with_capacity(rows_in.len());
        let mut vals = Vec::with_capacity(rows_in.len());
        col_ptr.push(0);
        for &c in &self.free {
            for p in col_ptr_in[c]..col_ptr_in[c + 1] {
                let r = self.full_to_free[rows_in[p]];
                if r != usize::MAX {
                    rows.push(r);
                    vals.push(vals_in[p]);
                }
            }
            col_ptr.push(rows.len());
        }
        let n = self.free.len();
        SparseColMat::new(
            SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows),
            vals,
        )
    }

    /// Expands free-dof vectors (`n_free × m`, e.g. mode shapes) to full length with zeros at the
    /// fixed dofs.
    ///
    /// # Panics
    /// If `u.nrows() != n_free()`.
    pub fn expand(&self, u: MatRef<'_, f64>) -> Mat<f64> {
        assert_eq!(u.nrows(), self.free.len());
        let mut out = Mat::<f64>::zeros(self.n_full, u.ncols());
        for j in 0..u.ncols() {
            for (i, &d) in self.free.iter().enumerate() {
                out[(d, j)] = u[(i, j)];
            }
        }
        out
    }
}

/// Clamps `fixed_nodes` (strictly ascending node indices): returns the dof map and K, M
/// restricted to the free dofs.
///
/// # Errors
/// [`DofMapError`] if the node list is invalid for `k`'s size.
///
/// ```
/// use modal_bake::{fem::{assemble_mass, assemble_stiffness, reduce_fixed, Material}, mesh::TetMesh};
/// let mesh = TetMesh::structured_box([2, 1, 1], [2.0, 1.0, 1.0]);
/// let mat = Material::new(1e9, 0.3, 1000.0).unwrap();
/// let (k, m) = (assemble_stiffness(&mesh, &mat), assemble_mass(&mesh, &mat, false));
/// let (map, kf, mf) = reduce_fixed(&k, &m, &mesh.groups["xmin"]).unwrap();
/// assert_eq!(kf.nrows(), map.n_free());
/// assert_eq!(mf.nrows(), mesh.dofs() - 3 * mesh.groups["xmin"].len());
/// ```
#[allow(clippy::type_complexity)]
pub fn reduce_fixed(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    fixed_nodes: &[usize],
) -> Result<(DofMap, SparseColMat<usize, f64>, SparseColMat<usize, f64>), DofMapError> {
    let map = DofMap::new(k.nrows() / 3, fixed_nodes)?;
    let kf = map.restrict(k);
    let mf = map.restrict(m);
    Ok((map, kf, mf))
}
