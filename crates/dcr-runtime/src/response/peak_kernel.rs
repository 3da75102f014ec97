//! The hot loop of Eq. 11: peak |wᵀ q(k)| over the step's samples for every channel.
//!
//! Two layouts of the same dense multiply-max:
//! - [`peak_abs_rows`] (used by [`DistantResponse`](super::DistantResponse)): samples along the
//!   SIMD lanes, channels broadcast. Samples and channel weights are both stored mode-major
//!   (`m × stride` with samples zero-padded to a multiple of 4, and `m × nb`), so a tile reads
//!   one contiguous run of each per mode. Register tiles of 6 channels × 2 four-sample vectors
//!   (12 independent FMA chains, no spills), 8 × 1 when a step has at most 4 samples; the last
//!   tile in each direction overlaps its predecessor instead of being narrower. The running
//!   max over samples stays in registers and is reduced across lanes once per channel. Nothing
//!   is padded to a channel block, so few-contact / many-sample rows (fridge: 6 × 117) waste
//!   nothing (the 8-channel panels computed 8 channels for 6).
//! - [`peak_abs_projection`]: channels along the lanes in panels of 8 (the earlier layout,
//!   kept for callers of the public function).
//!
//! Every accumulator is the same sequential FMA chain over the modes j = 0..m in both, so the
//! results are bit-identical whatever the layout or blocking. On x86-64 CPUs with AVX2 + FMA
//! the kernels are compiled for those features and picked at run time (`pulp` dispatch);
//! elsewhere the baseline build is used.

// The panel kernel serves the benchmarks and tests only (the step uses the rows kernel).
#![cfg_attr(not(any(test, feature = "bench-internals")), allow(dead_code))]

use crate::math::fmadd;

/// Samples per SIMD vector in [`peak_abs_rows`] (its sample stride is a multiple of this).
pub const LANES: usize = 4;

/// Per-lane arithmetic of the rows kernel on `[f64; 4]` (LLVM keeps each in one register):
/// fused multiply-add where the dispatch enabled FMA, `c + a·b` in the baseline build.
#[inline(always)]
fn fma4<const FMA: bool>(a: f64, b: &[f64; LANES], c: &mut [f64; LANES]) {
    for i in 0..LANES {
        c[i] = if FMA {
            a.mul_add(b[i], c[i])
        } else {
            c[i] + a * b[i]
        };
    }
}

/// `pk = max(|acc|, pk)` per lane, keeping `pk` where `acc` is NaN (as `f64::max` does; written
/// as a compare-select so it compiles to a single `maxpd`).
#[inline(always)]
fn abs_max4(acc: &[f64; LANES], pk: &mut [f64; LANES]) {
    for i in 0..LANES {
        let a = acc[i].abs();
        pk[i] = if a > pk[i] { a } else { pk[i] };
    }
}

/// `peaks[c] = max_k |Σ_j b[j·nb + c] · v[j·stride + k]|` for `c < nb`: the largest normal
/// displacement magnitude (m) of channel c over the step's samples. `v` holds the modal samples
/// mode-major (`m × stride`, `stride` a multiple of `LANES` (4), unused samples zero); `b` holds
/// the channel weights mode-major too (`m × nb`, one column per channel). Does not allocate.
///
/// # Panics
/// If `stride` is not a multiple of `LANES` (4) or a slice is too short.
pub fn peak_abs_rows(v: &[f64], stride: usize, m: usize, b: &[f64], nb: usize, peaks: &mut [f64]) {
    assert!(
        stride.is_multiple_of(LANES),
        "sample stride must be a multiple of {LANES}"
    );
    assert!(v.len() >= m * stride && b.len() >= nb * m && peaks.len() >= nb);
    let peaks = &mut peaks[..nb];
    if m == 0 || stride == 0 {
        peaks.iter_mut().for_each(|p| *p = 0.0);
        return;
    }
    let (v, _) = pulp::as_arrays::<LANES, f64>(&v[..m * stride]);
    let b = &b[..nb * m];
    let nv = stride / LANES;
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        // Through `WithSimd` rather than a closure: a closure's `FnOnce` shim is only an inline
        // hint, and LLVM declined it for this kernel, compiling it without AVX2/FMA (10× slower).
        pulp::Simd::vectorize(
            simd,
            RowsKernel {
                v,
                nv,
                b,
                nb,
                peaks,
            },
        );
        return;
    }
    rows_kernel::<false>(v, nv, b, nb, peaks);
}

/// [`peak_abs_rows`]' arguments, run under `pulp` dispatch.
struct RowsKernel<'a> {
    v: &'a [[f64; LANES]],
    nv: usize,
    b: &'a [f64],
    nb: usize,
    peaks: &'a mut [f64],
}

impl pulp::WithSimd for RowsKernel<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        rows_kernel::<true>(self.v, self.nv, self.b, self.nb, self.peaks);
    }
}

#[inline(always)]
fn rows_kernel<const FMA: bool>(
    v: &[[f64; LANES]],
    nv: usize,
    b: &[f64],
    nb: usize,
    peaks: &mut [f64],
) {
    if nv == 1 {
        channel_blocks::<FMA, 8, 1>(v, nv, b, nb, peaks);
    } else {
        channel_blocks::<FMA, 6, 2>(v, nv, b, nb, peaks);
    }
}

/// All channels in blocks of `NC`; the last block overlaps its predecessor instead of being
/// narrower (a channel's peak does not depend on its block, and narrow tiles compile badly).
#[inline(always)]
fn channel_blocks<const FMA: bool, const NC: usize, const NV: usize>(
    v: &[[f64; LANES]],
    nv: usize,
    b: &[f64],
    nb: usize,
    peaks: &mut [f64],
) {
    if nb >= NC {
        let mut c0 = 0;
        while c0 < nb {
            let c = c0.min(nb - NC);
            sample_pass::<FMA, NC, NV>(v, nv, b, nb, c, &mut peaks[c..c + NC]);
            c0 += NC;
        }
        return;
    }
    let c0 = 0;
    let out = &mut peaks[..];
    macro_rules! rest {
        ($($n:literal)*) => {
            match out.len() {
                $($n => sample_pass::<FMA, $n, NV>(v, nv, b, nb, c0, out),)*
                _ => {}
            }
        };
    }
    rest!(1 2 3 4 5 6 7);
}

/// Channels `c0..c0 + NC` over all samples in tiles of `NV` vectors, the last one overlapping
/// its predecessor (the max over samples is unaffected by seeing some twice).
#[inline(always)]
fn sample_pass<const FMA: bool, const NC: usize, const NV: usize>(
    v: &[[f64; LANES]],
    nv: usize,
    b: &[f64],
    nb: usize,
    c0: usize,
    out: &mut [f64],
) {
    let mut pk = [[0.0f64; LANES]; NC];
    if nv >= NV {
        let mut v0 = 0;
        while v0 < nv {
            tile::<FMA, NC, NV>(v, nv, v0.min(nv - NV), b, nb, c0, &mut pk);
            v0 += NV;
        }
    } else {
        for v0 in 0..nv {
            tile::<FMA, NC, 1>(v, nv, v0, b, nb, c0, &mut pk);
        }
    }
    for (p, x) in out.iter_mut().zip(pk) {
        *p = x.into_iter().fold(0.0, f64::max);
    }
}

/// One register tile: channels `c0..c0 + NC` × `NV` vectors of samples from vector `v0`, FMA
/// chains over all modes, folded into the running per-channel lane maxima `pk`.
#[inline(always)]
fn tile<const FMA: bool, const NC: usize, const NV: usize>(
    v: &[[f64; LANES]],
    nv: usize,
    v0: usize,
    b: &[f64],
    nb: usize,
    c0: usize,
    pk: &mut [[f64; LANES]; NC],
) {
    let mut acc = [[[0.0f64; LANES]; NV]; NC];
    for (vj, bj) in v.chunks_exact(nv).zip(b.chunks_exact(nb)) {
        let x: &[[f64; LANES]; NV] = vj[v0..v0 + NV].try_into().expect("tile in range");
        let w: &[f64; NC] = bj[c0..c0 + NC].try_into().expect("tile in range");
        for c in 0..NC {
            for t in 0..NV {
                fma4::<FMA>(w[c], &x[t], &mut acc[c][t]);
            }
        }
    }
    for (acc_c, pk_c) in acc.iter().zip(pk.iter_mut()) {
        for a in acc_c {
            abs_max4(a, pk_c);
        }
    }
}

/// Channels per panel of [`peak_abs_projection`] (channel counts are padded to a multiple).
pub const BLOCK: usize = 8;

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
        nch.is_multiple_of(BLOCK),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows kernel equals a naive loop with the same FMA order, bit for bit, for every
    /// tile remainder (channels 1..=20, 1..=13 samples), on the dispatched and baseline paths.
    #[test]
    fn rows_kernel_matches_naive_bitwise() {
        let mut rng = crate::testing::SplitMix64(11);
        let m = 7;
        for s in 1..=13usize {
            let stride = s.div_ceil(LANES) * LANES;
            for nb in 1..=20 {
                let mut v = vec![0.0; m * stride];
                for j in 0..m {
                    for k in 0..s {
                        v[j * stride + k] = rng.range(-1.0, 1.0);
                    }
                }
                let b: Vec<f64> = (0..nb * m).map(|_| rng.range(-1.0, 1.0)).collect();
                let mut peaks = vec![f64::NAN; nb];
                peak_abs_rows(&v, stride, m, &b, nb, &mut peaks);
                let mut base = vec![f64::NAN; nb];
                rows_kernel::<false>(pulp::as_arrays(&v).0, stride / LANES, &b, nb, &mut base);
                let fused = peaks != base;
                for c in 0..nb {
                    let naive = |fma: bool| {
                        (0..s)
                            .map(|k| {
                                (0..m)
                                    .fold(0.0f64, |acc, j| {
                                        let (x, y) = (b[j * nb + c], v[j * stride + k]);
                                        if fma {
                                            // Correctly rounded in software: the C library's
                                            // `fma` behind `mul_add` is not always (MinGW's
                                            // is off by an ulp on these inputs).
                                            libm::fma(x, y, acc)
                                        } else {
                                            acc + x * y
                                        }
                                    })
                                    .abs()
                            })
                            .fold(0.0, f64::max)
                    };
                    assert_eq!(base[c], naive(false), "baseline s={s} nb={nb} c={c}");
                    if fused {
                        assert_eq!(peaks[c], naive(true), "fma s={s} nb={nb} c={c}");
                    }
                }
            }
        }
    }
}
