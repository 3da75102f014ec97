//! The hot loop of Eq. 11: peak |wᵀ q(k)| over the step's samples for every channel.
//!
//! A dense multiply-max blocked over 8 channels × KB samples held in registers (independent
//! accumulator chains, so the loop is throughput- rather than latency-bound). On x86-64 CPUs
//! with AVX2 + FMA the same safe loop is compiled for those features and picked at run time
//! (`pulp` dispatch); elsewhere the baseline build is used.

/// Channels per register block (the channel count passed in must be a multiple of this).
pub(crate) const BLOCK: usize = 8;

/// `peaks[c] = max_k |Σ_j q[k·m + j] · w[j·nch + c]|` for `c < nch`: the largest normal
/// displacement magnitude (m) of channel c over `samples` rows of modal displacements `q`
/// (row-major `samples × m`), with the channel rows stored mode-major in `w` (`m × nch`).
/// Does not allocate.
///
/// # Panics
/// If `nch` is not a multiple of 8 or a slice is too short.
pub fn peak_abs_projection(q: &[f64], samples: usize, m: usize, w: &[f64], nch: usize, peaks: &mut [f64]) {
    assert!(nch % BLOCK == 0, "channel count must be padded to a multiple of {BLOCK}");
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
            || kernel::<4, true>(q, m, w, nch, peaks),
        );
        return;
    }
    kernel::<2, false>(q, m, w, nch, peaks);
}

#[inline(always)]
fn kernel<const KB: usize, const FMA: bool>(q: &[f64], m: usize, w: &[f64], nch: usize, peaks: &mut [f64]) {
    for cb in (0..nch).step_by(BLOCK) {
        let mut pk = [0.0f64; BLOCK];
        let mut groups = q.chunks_exact(KB * m);
        for qq in &mut groups {
            let mut acc = [[0.0f64; BLOCK]; KB];
            for (j, wrow) in w.chunks_exact(nch).enumerate() {
                let wj: &[f64; BLOCK] = wrow[cb..cb + BLOCK].try_into().expect("block");
                for s in 0..KB {
                    let a = qq[s * m + j];
                    for i in 0..BLOCK {
                        acc[s][i] = if FMA { a.mul_add(wj[i], acc[s][i]) } else { acc[s][i] + a * wj[i] };
                    }
                }
            }
            for s in 0..KB {
                for i in 0..BLOCK {
                    pk[i] = pk[i].max(acc[s][i].abs());
                }
            }
        }
        for qk in groups.remainder().chunks_exact(m) {
            let mut acc = [0.0f64; BLOCK];
            for (&a, wrow) in qk.iter().zip(w.chunks_exact(nch)) {
                let wj: &[f64; BLOCK] = wrow[cb..cb + BLOCK].try_into().expect("block");
                for i in 0..BLOCK {
                    acc[i] = if FMA { a.mul_add(wj[i], acc[i]) } else { acc[i] + a * wj[i] };
                }
            }
            for i in 0..BLOCK {
                pk[i] = pk[i].max(acc[i].abs());
            }
        }
        peaks[cb..cb + BLOCK].copy_from_slice(&pk);
    }
}
