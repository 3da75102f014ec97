//! Fill-reducing orderings of the node graph of a FEM matrix: approximate minimum degree
//! (faer's AMD) and nested dissection (METIS).
//!
//! Why METIS next to faer's AMD: faer 0.24 offers only AMD (and custom orderings). AMD is
//! local and on 3-D meshes leaves a factor close to a banded one; nested dissection orders two
//! halves of the mesh before the nodes that separate them, so the fill of each half stays
//! inside it. METIS's multilevel vertex separators (`METIS_NodeND`) are much smaller than
//! breadth-first level sets (factor entries of the bake bench's stout 100 × 18 × 18-cell,
//! 108k-dof beam: AMD 123.6M, level sets 97.2M, METIS 83.5M; see the tests for a block). The
//! safe `metis` crate does not wrap `METIS_NodeND`; [`crate::ordering::nested_dissection`]
//! holds the one FFI call, shared with the surface ordering of the heat geodesic
//! ([`crate::ordering::plan_surface_order`]). Deterministic: METIS reseeds its random generator (fixed seed) on every
//! call, but that generator is process-global C state, so calls are serialised by one lock
//! there (two bakes ordering at once on two threads would otherwise interleave one stream).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
};
use faer::sparse::SymbolicSparseColMat;
use faer::Side;

/// AMD ordering of a symmetric graph (`fwd[k]`: the vertex placed at position k). `None` if
/// faer's AMD fails (out of memory).
pub(crate) fn amd_order(g: &SymbolicSparseColMat<usize>) -> Option<Vec<usize>> {
    let nn = g.nrows();
    let mut fwd = vec![0usize; nn];
    let mut inv = vec![0usize; nn];
    let mut mem = MemBuffer::try_new(amd::order_scratch::<usize>(nn, g.row_idx().len())).ok()?;
    amd::order(
        &mut fwd,
        &mut inv,
        g.as_ref(),
        amd::Control::default(),
        MemStack::new(&mut mem),
    )
    .ok()?;
    Some(fwd)
}

/// The inverse of the permutation `fwd` (`inv[fwd[k]] = k`).
pub(crate) fn inverse(fwd: &[usize]) -> Vec<usize> {
    let mut inv = vec![0usize; fwd.len()];
    for (k, &v) in fwd.iter().enumerate() {
        inv[v] = k;
    }
    inv
}

/// Entries of the supernodal Cholesky factor of a matrix with the symmetric pattern `g` under
/// the ordering `fwd` (symbolic analysis only); `usize::MAX` if the analysis fails.
pub(crate) fn factor_entries(g: &SymbolicSparseColMat<usize>, fwd: &[usize]) -> usize {
    let inv = inverse(fwd);
    factorize_symbolic_cholesky(
        g.as_ref(),
        Side::Lower,
        SymmetricOrdering::Custom(PermRef::new_checked(fwd, &inv, g.nrows())),
        CholeskySymbolicParams::default(),
    )
    .map_or(usize::MAX, |s| s.len_val())
}

/// METIS nested-dissection ordering (`METIS_NodeND`, default options) of a symmetric graph
/// given by its adjacency lists (column pointers and row indices, both triangles; self loops
/// allowed and ignored). `fwd[k]`: the vertex placed at position k. `None` when the graph does
/// not fit METIS's 32-bit indices or METIS fails (out of memory): callers fall back to AMD.
/// The one METIS call site is [`crate::ordering::nested_dissection`] (it serialises calls:
/// METIS uses the C library's global `rand` state, in the program `ordering::c_rand`'s).
pub(crate) fn metis_nested_dissection(g: &SymbolicSparseColMat<usize>) -> Option<Vec<usize>> {
    crate::ordering::nested_dissection(g.col_ptr(), g.row_idx())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TetMesh;

    /// Node graph (both triangles, self loops) of a structured tet box with `cells`.
    fn box_graph(cells: [usize; 3]) -> SymbolicSparseColMat<usize> {
        let mesh = TetMesh::structured_box(cells, [1.0, 1.0, 1.0]);
        let n = mesh.nodes.len();
        let mut adj = vec![Vec::new(); n];
        for t in &mesh.tets {
            for &a in t {
                adj[a].extend_from_slice(t);
            }
        }
        let mut ptr = vec![0];
        let mut idx = Vec::new();
        for mut l in adj {
            l.sort_unstable();
            l.dedup();
            idx.extend(l);
            ptr.push(idx.len());
        }
        SymbolicSparseColMat::new_checked(n, n, ptr, None, idx)
    }

    fn assert_permutation(p: &[usize], n: usize) {
        let mut seen = vec![false; n];
        for &v in p {
            assert!(!seen[v], "{v} twice");
            seen[v] = true;
        }
        assert!(seen.iter().all(|&s| s), "not all vertices ordered");
    }

    #[test]
    fn nested_dissection_is_a_deterministic_permutation() {
        for cells in [[1, 1, 1], [24, 6, 6], [10, 10, 10]] {
            let g = box_graph(cells);
            let nd = metis_nested_dissection(&g).unwrap();
            assert_permutation(&nd, g.nrows());
            assert_eq!(nd, metis_nested_dissection(&g).unwrap());
        }
    }

    /// Nested dissection fills much less than AMD on a block (measured at 16³ cells: see the
    /// assertion's message) and about as much on a short beam (24 × 6 × 6 cells: 61.9k vs
    /// 64.4k node-graph entries), which is why the factorization compares the two.
    #[test]
    fn nested_dissection_beats_amd_on_a_block() {
        let block = box_graph([16, 16, 16]);
        let (nd, amd) = (
            factor_entries(&block, &metis_nested_dissection(&block).unwrap()),
            factor_entries(&block, &amd_order(&block).unwrap()),
        );
        assert!(
            (nd as f64) < 0.8 * amd as f64,
            "block: ND {nd} vs AMD {amd}"
        );
        let beam = box_graph([24, 6, 6]);
        let (nd, amd) = (
            factor_entries(&beam, &metis_nested_dissection(&beam).unwrap()),
            factor_entries(&beam, &amd_order(&beam).unwrap()),
        );
        assert!(
            (nd as f64) > 0.9 * amd as f64,
            "short beam: ND {nd} vs AMD {amd}"
        );
    }

    #[test]
    fn disconnected_pieces_are_ordered() {
        // Two copies of a 10 × 10 × 2 box without edges between them.
        let one = box_graph([10, 10, 2]);
        let n1 = one.nrows();
        let mut ptr = one.col_ptr().to_vec();
        let mut idx = one.row_idx().to_vec();
        for j in 0..n1 {
            for &i in &one.row_idx()[one.col_ptr()[j]..one.col_ptr()[j + 1]] {
                idx.push(i + n1);
            }
            ptr.push(idx.len());
        }
        let g = SymbolicSparseColMat::new_checked(2 * n1, 2 * n1, ptr, None, idx);
        assert_permutation(&metis_nested_dissection(&g).unwrap(), 2 * n1);
    }
}
