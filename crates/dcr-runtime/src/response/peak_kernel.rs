//! The hot loop of Eq. 11: peak |wᵀ q(k)| over the step's samples for every channel.
//!
//! A dense multiply-max register-blocked over 16 channels × 3 samples (8 channels × 6 samples
//! for a last odd panel): 12 independent 4-wide accumulator chains per pass over the modes, so
//! the loop is FMA-throughput- rather than latency- or load-bound. The
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

/// One register block: `NP` panels (8·NP channels) × `NS` samples of accumulators
/// (NP·NS·2 four-wide chains with AVX2; 2 × 3 → 12 of the 16 ymm registers), folded into
/// the running channel peaks `pk`. Each accumulator is the same sequential FMA chain over j as
/// the unblocked loop, so results are bit-identical whatever the blocking.
#[inline(always)]
fn block<const FMA: bool, const NP: usize, const NS: usize>(
    q: &[f64],
    m: usize,
    panels: &[f64],
    pk: &mut [[f64; BLOCK]; NP],
) {
    let rows: [&[f64]; NS] = std::array::from_fn(|s| &q[s * m..(s + 1) * m]);
    let pan: [&[f64]; NP] = std::array::from_fn(|p| &panels[p * m * BLOCK..(p + 1) * m * BLOCK]);
    let mut acc = [[[0.0f64; BLOCK]; NP]; NS];
    for j in 0..m {
        let a: [f64; NS] = std::array::from_fn(|s| rows[s][j]);
        let w: [&[f64]; NP] = std::array::from_fn(|p| &pan[p][j * BLOCK..(j + 1) * BLOCK]);
        for p in 0..NP {
            for i in 0..BLOCK {
                let wv = w[p][i];
                for s in 0..NS {
                    acc[s][p][i] = fmadd::<FMA>(a[s], wv, acc[s][p][i]);
                }
            }
        }
    }
    for acc_s in &acc {
        for p in 0..NP {
            for i in 0..BLOCK {
                pk[p][i] = pk[p][i].max(acc_s[p][i].abs());
            }
        }
    }
}

/// All samples for `NP` panels: blocks of `NS` samples, then single samples.
#[inline(always)]
fn panels_pass<const FMA: bool, const NP: usize, const NS: usize>(
    q: &[f64],
    m: usize,
    panels: &[f64],
    out: &mut [f64],
) {
    let mut pk = [[0.0f64; BLOCK]; NP];
    let mut groups = q.chunks_exact(NS * m);
    for qq in &mut groups {
        block::<FMA, NP, NS>(qq, m, panels, &mut pk);
    }
    let mut rest = groups.remainder();
    if NS == 6 && rest.len() >= 3 * m {
        block::<FMA, NP, 3>(&rest[..3 * m], m, panels, &mut pk);
        rest = &rest[3 * m..];
    }
    for qk in rest.chunks_exact(m) {
        block::<FMA, NP, 1>(qk, m, panels, &mut pk);
    }
    for (o, p) in out.chunks_exact_mut(BLOCK).zip(&pk) {
        o.copy_from_slice(p);
    }
}

#[inline(always)]
fn kernel<const FMA: bool>(q: &[f64], m: usize, w: &[f64], peaks: &mut [f64]) {
    // Pairs of panels (16 channels) × 3 samples, then a last single panel × 6 samples.
    let mut pairs = w.chunks_exact(2 * m * BLOCK);
    let mut outs = peaks.chunks_exact_mut(2 * BLOCK);
    for (panels, out) in (&mut pairs).zip(&mut outs) {
        panels_pass::<FMA, 2, 3>(q, m, panels, out);
    }
    let rest = pairs.remainder();
    if !rest.is_empty() {
        panels_pass::<FMA, 1, 6>(q, m, rest, outs.into_remainder());
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
