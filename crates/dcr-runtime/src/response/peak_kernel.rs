//! The hot loop of Eq. 11: peak |wᵀ q(k)| over the step's samples for every channel.
//!
//! A dense multiply-max blocked over 8 channels × several samples held in registers
//! (independent accumulator chains, so the loop is throughput- rather than latency-bound). The
//! channel matrix is stored as panels of 8 channels (`(block·m + j)·8 + i`) so every inner
//! load is one contiguous 8-wide row. On x86-64 CPUs with AVX2 + FMA the same safe loop is
//! compiled for those features and picked at run time (`pulp` dispatch); elsewhere the
//! baseline build is used.

/// Channels per panel (channel counts are padded to a multiple of this).
pub const BLOCK: usize = 8;

/// Index of channel `c`, mode `j` in the panel layout for `m` modes.
#[inline]
pub(crate) fn panel_index(c: usize, j: usize, m: usize) -> usize {
    ((c / BLOCK) * m + j) * BLOCK + c % BLOCK
}

/// `peaks[c] = max_k |Σ_j q[k·m + j] · W(j, c)|` for `c < nch`: the largest normal displacement
/// magnitude (m) of channel c over `samples` rows of modal displacements `q` (row-major
/// `samples × m`). `w` holds W in panels of 8 channels: `w[((c/8)·m + j)·8 + c%8]`, length
/// `m × nch`. Does not allocate.
///
/// # Panics
/// If `nch` is not a multiple of 8 or a slice is too short.
pub fn peak_abs_projection(
    q: &[f64],
    samples: usize,
    m: usize,
    w: &[f64],
    nch: usize,
    peaks: &mut [f64],
) {
    assert!(
        nch % BLOCK == 0,
        "channel count must be padded to a multiple of {BLOCK}"
    );
    assert!(q.len() >= samples * m && w.len() >= m * nch && peaks.len() >= nch);
    if m == 0 {
        peaks[..nch].iter_mut().for_each(|p| *p = 0.0);
        return;
    }
    let (q, w, peaks) = (&q[..samples * m], &w[..m * nch], &mut peaks[..nch]);
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        simd.vectorize(
            #[inline(always)]
            || kernel::<true>(q, m, w, peaks),
        );
        return;
    }
    kernel::<false>(q, m, w, peaks);
}

#[inline(always)]
fn fmadd<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA {
        a.mul_add(b, c)
    } else {
        c + a * b
    }
}

#[inline(always)]
fn kernel<const FMA: bool>(q: &[f64], m: usize, w: &[f64], peaks: &mut [f64]) {
    for (panel, pk_out) in w.chunks_exact(m * BLOCK).zip(peaks.chunks_exact_mut(BLOCK)) {
        let mut pk = [0.0f64; BLOCK];
        // Four samples at a time (8 independent 4-wide chains with AVX2).
        let mut quads = q.chunks_exact(4 * m);
        for qq in &mut quads {
            let (r0, rest) = qq.split_at(m);
            let (r1, rest) = rest.split_at(m);
            let (r2, r3) = rest.split_at(m);
            let mut acc = [[0.0f64; BLOCK]; 4];
            for ((((&a0, &a1), &a2), &a3), wj) in r0
                .iter()
                .zip(r1)
                .zip(r2)
                .zip(r3)
                .zip(panel.chunks_exact(BLOCK))
            {
                for i in 0..BLOCK {
                    acc[0][i] = fmadd::<FMA>(a0, wj[i], acc[0][i]);
                    acc[1][i] = fmadd::<FMA>(a1, wj[i], acc[1][i]);
                    acc[2][i] = fmadd::<FMA>(a2, wj[i], acc[2][i]);
                    acc[3][i] = fmadd::<FMA>(a3, wj[i], acc[3][i]);
                }
            }
            for a in &acc {
                for i in 0..BLOCK {
                    pk[i] = pk[i].max(a[i].abs());
                }
            }
        }
        for qk in quads.remainder().chunks_exact(m) {
            let mut acc = [0.0f64; BLOCK];
            for (&a, wj) in qk.iter().zip(panel.chunks_exact(BLOCK)) {
                for i in 0..BLOCK {
                    acc[i] = fmadd::<FMA>(a, wj[i], acc[i]);
                }
            }
            for i in 0..BLOCK {
                pk[i] = pk[i].max(acc[i].abs());
            }
        }
        pk_out.copy_from_slice(&pk);
    }
}

/// The baseline (non-dispatched) kernel, for tests on machines that dispatch to AVX2.
#[cfg(test)]
pub(crate) fn peak_abs_projection_baseline(
    q: &[f64],
    samples: usize,
    m: usize,
    w: &[f64],
    nch: usize,
    peaks: &mut [f64],
) {
    kernel::<false>(&q[..samples * m], m, &w[..m * nch], &mut peaks[..nch]);
}
