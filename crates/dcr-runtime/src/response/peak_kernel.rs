//! The hot loop of Eq. 11: peak |wᵀ q(k)| over the step's samples for every channel.

/// Channels per register block (the channel count passed in must be a multiple of this).
pub(crate) const BLOCK: usize = 8;

/// `peaks[c] = max_k |Σ_j q[k·m + j] · w[j·nch + c]|` for `c < nch`: the largest normal
/// displacement magnitude (m) of channel c over `samples` rows of modal displacements `q`
/// (row-major `samples × m`), with the channel rows stored mode-major in `w` (`m × nch`).
///
/// Dense multiply-max, blocked over 8 channels held in registers; does not allocate.
///
/// # Panics
/// If `nch` is not a multiple of 8 or a slice is too short.
pub fn peak_abs_projection(q: &[f64], samples: usize, m: usize, w: &[f64], nch: usize, peaks: &mut [f64]) {
    assert!(nch % BLOCK == 0, "channel count must be padded to a multiple of {BLOCK}");
    assert!(q.len() >= samples * m && w.len() >= m * nch && peaks.len() >= nch);
    for cb in (0..nch).step_by(BLOCK) {
        let mut pk = [0.0f64; BLOCK];
        for qk in q[..samples * m].chunks_exact(m) {
            let mut acc = [0.0f64; BLOCK];
            for (j, &a) in qk.iter().enumerate() {
                let wj: &[f64; BLOCK] = w[j * nch + cb..j * nch + cb + BLOCK].try_into().expect("block");
                for i in 0..BLOCK {
                    acc[i] += a * wj[i];
                }
            }
            for i in 0..BLOCK {
                pk[i] = pk[i].max(acc[i].abs());
            }
        }
        peaks[cb..cb + BLOCK].copy_from_slice(&pk);
    }
}
