//! Nested-dissection orderings (METIS 5 `METIS_NodeND`): the one FFI call behind the bake's
//! fill-reducing orderings of the volume stiffness (`eigen/ordering.rs`) and of the surface
//! Laplacian ([`super::plan_surface_order`], stored in the base as `surface_order`).
//!
//! Only the baker builds METIS (through `metis-sys`, from vendored C): engines linking
//! `dcr-runtime` read the stored order and need no C compiler. METIS rather than our own
//! dissection: a breadth-first level-set dissection fills 205k entries on a 5k-vertex box
//! surface where AMD fills 117k and METIS 93k.

/// METIS nested-dissection order of the symmetric graph whose adjacency is the CSC pattern
/// (`col_ptr`, `row_idx`; a self-loop on the diagonal is ignored): `order[k]` is the vertex
/// eliminated k-th. Deterministic for a given graph (METIS's default seed; calls are serialised
/// because METIS draws from the C library's global `rand` state, which concurrent calls would
/// interleave; in the `modal-bake` program that `rand` is [`super::c_rand`]'s, the same on every
/// platform). `None` if METIS fails or the graph exceeds its 32-bit indices.
pub fn nested_dissection(col_ptr: &[usize], row_idx: &[usize]) -> Option<Vec<usize>> {
    use metis_sys::idx_t;
    let n = col_ptr.len().checked_sub(1)?;
    let mut xadj: Vec<idx_t> = Vec::with_capacity(n + 1);
    let mut adjncy: Vec<idx_t> = Vec::with_capacity(row_idx.len());
    xadj.push(0);
    for v in 0..n {
        for &u in row_idx.get(col_ptr[v]..col_ptr[v + 1])? {
            if u != v {
                adjncy.push(idx_t::try_from(u).ok()?);
            }
        }
        xadj.push(idx_t::try_from(adjncy.len()).ok()?);
    }
    if n == 0 {
        return Some(Vec::new());
    }
    let mut nvtxs = idx_t::try_from(n).ok()?;
    let (mut perm, mut iperm) = (vec![0 as idx_t; n], vec![0 as idx_t; n]);
    let _one_at_a_time = super::c_rand::C_RAND_USERS
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    // SAFETY: xadj has n + 1 entries, adjncy xadj[n] entries (all < n), perm and iperm n
    // entries each; null weights and options select METIS's defaults. METIS only reads the
    // graph arrays and writes the two permutations within those bounds.
    #[allow(unsafe_code)]
    let status = unsafe {
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return None;
    }
    let order: Vec<usize> = perm
        .iter()
        .map(|&v| usize::try_from(v).ok())
        .collect::<Option<_>>()?;
    let mut seen = vec![false; n];
    order
        .iter()
        .all(|&v| v < n && !std::mem::replace(&mut seen[v], true))
        .then_some(order)
}
