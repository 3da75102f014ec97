//! [`ModalResponse`]: the modal method (paper Eq. 9–13).
//!
//! The step's impacts (impulse ≥ threshold) are mapped to the surface and summed into one
//! reduced impulse `r = Σ Uᵀ H_c d_c λ_c` applied at t = 0; the exact mode filters give q(k) at
//! t = k·h/S, k = 1..S, S = ⌈h/T⌉; each resting contact's peak `d = max_k |w_c · q(k)|` (or
//! Eq. 13 per node) gives Δv = d/h. Without carry-over the filters start from rest every step,
//! so q(k) = g(kT) ∘ r with the impulse-response table g_j(kT) precomputed at set-up; the
//! per-step work is one dense multiply-max over S × m × contacts. With carry-over (or forces,
//! held constant over the step) the bank is stepped sample by sample.

use super::impulse_table::ImpulseTable;
use super::peak_kernel::{peak_abs_rows, LANES};
use super::step_ctx::{mapped_response, unmapped_response, StepCtx};
use super::{
    prepared_vec, ForceInput, Impact, RestingContact, ServedBy, Variant, PREPARED_CONTACTS,
};
use crate::filter::ModalBank;
use crate::math::normalize;

/// Marks a contact without a channel (not mapped).
pub(crate) const UNMAPPED: u32 = u32::MAX;

/// The modal method's filters, tables and per-step buffers.
#[derive(Debug)]
pub(crate) struct ModalResponse {
    m: usize,
    samples: usize,
    bank: ModalBank,
    /// g_j(kT), row-major samples × m.
    g_table: Vec<f64>,
    /// g_j(kT) mode-major (m × `stride`, samples padded with zeros): the kernel's layout.
    g_t: Vec<f64>,
    /// Sample stride of `g_t` / `q_t`: S rounded up to a multiple of [`LANES`].
    stride: usize,
    /// This step's q_j(kT) mode-major (m × `stride`) when the kernel needs it.
    q_t: Vec<f64>,
    /// g_j(h) and ġ_j(h): the state at the end of a reset step per unit impulse.
    g_end: Vec<f64>,
    g_dot_end: Vec<f64>,
    q_table: Vec<f64>,
    r: Vec<f64>,
    f: Vec<f64>,
    tmp_q: Vec<f64>,
    tmp_v: Vec<f64>,
    chan: Vec<u32>,
    /// The step's channel weights, mode-major (m × nch, one column per channel).
    w_step: Vec<f64>,
    /// (cache generation, slots) the current `w_step` was built for.
    w_key: (u64, Vec<u32>),
    w_scaled: Vec<f64>,
    q_stale: bool,
    peaks: Vec<f64>,
    asleep: bool,
    energy_ref: f64,
}

impl ModalResponse {
    /// The method's state over the filters of `table` (h = `h` s), its buffers sized for
    /// [`PREPARED_CONTACTS`] resting contacts of `variant`'s channels.
    pub fn new(table: ImpulseTable, h: f64, variant: Variant) -> ModalResponse {
        let ImpulseTable {
            samples,
            bank,
            g_table,
            ..
        } = table;
        let m = bank.filters().len();
        // Channels per contact: one, or one per corner of its triangle.
        let width = if variant == Variant::PerNode { 3 } else { 1 };
        let channels = width * PREPARED_CONTACTS;
        let stride = samples.div_ceil(LANES) * LANES;
        let mut g_t = vec![0.0; m * stride];
        for k in 0..samples {
            for j in 0..m {
                g_t[j * stride + k] = g_table[k * m + j];
            }
        }
        let g_end = g_table[(samples - 1) * m..].to_vec();
        let g_dot_end: Vec<f64> = bank
            .filters()
            .iter()
            .zip(&g_end)
            .map(|(f, g)| f.free_response(h) - 2.0 * f.xi * f.omega * g)
            .collect();
        // The kernel's first call detects the CPU's SIMD features (CPUID, a trap to the
        // hypervisor in a virtual machine): done here, at set-up, not in the first step.
        let mut peak = [0.0];
        peak_abs_rows(&[0.0; LANES], LANES, 1, &[0.0], 1, &mut peak);
        ModalResponse {
            m,
            samples,
            g_t,
            stride,
            q_t: vec![0.0; m * stride],
            g_end,
            g_dot_end,
            q_table: vec![0.0; samples * m],
            r: vec![0.0; m],
            f: vec![0.0; m],
            tmp_q: vec![0.0; m],
            tmp_v: vec![0.0; m],
            chan: prepared_vec(PREPARED_CONTACTS, 0),
            w_step: prepared_vec(channels * m, 0.0),
            w_key: (u64::MAX, prepared_vec(PREPARED_CONTACTS, 0)),
            w_scaled: prepared_vec(channels * m, 0.0),
            q_stale: false,
            peaks: prepared_vec(channels, 0.0),
            asleep: true,
            energy_ref: 0.0,
            bank,
            g_table,
        }
    }

    /// Modal energy ½ Σ (q̇² + ω² q²) of the filter state at the end of the last step.
    pub fn energy(&self) -> f64 {
        self.bank.energy()
    }

    /// Modal displacements q at the end of the last step.
    pub fn state(&self) -> &[f64] {
        self.bank.q()
    }

    /// Whether the filters are at rest (carry-over: asleep; no work until an impact).
    pub fn asleep(&self) -> bool {
        self.asleep
    }

    /// The last step's samples q(k), row-major S × m (filled on demand).
    pub fn samples(&mut self) -> &[f64] {
        if self.q_stale {
            let m = self.m;
            for (qk, gk) in self
                .q_table
                .chunks_exact_mut(m)
                .zip(self.g_table.chunks_exact(m))
            {
                for ((q, g), r) in qk.iter_mut().zip(gk).zip(&self.r) {
                    *q = g * r;
                }
            }
            self.q_stale = false;
        }
        &self.q_table
    }

    /// Takes `energy` (J, ≥ 0) out of the carried filter state by scaling every mode's (q, q̇)
    /// by `√(1 − energy / E)` (E the modal energy), so the phases and the modal mix are kept;
    /// at `energy ≥ E` the filters come to rest and sleep. The samples of the step already
    /// run are not touched. No effect for `energy ≤ 0` or NaN.
    pub fn drain(&mut self, energy: f64) {
        if !(energy > 0.0) {
            return;
        }
        let e = self.bank.energy();
        if energy >= e {
            self.bank.reset();
            self.asleep = true;
        } else {
            self.bank.scale_state((1.0 - energy / e).sqrt());
        }
    }

    /// Returns the filters to rest.
    pub fn reset(&mut self) {
        self.bank.reset();
        self.asleep = true;
        self.energy_ref = 0.0;
        self.q_table.iter_mut().for_each(|x| *x = 0.0);
        self.q_stale = false;
    }

    /// One step of the modal method: fills `ctx.out` with one response per resting contact.
    pub fn step(
        &mut self,
        ctx: &mut StepCtx<'_>,
        impacts: &[Impact],
        forces: &[ForceInput],
        resting: &[RestingContact],
    ) {
        // Eq. 9: the step's impacts (and forces) as one reduced impulse r (and force f).
        let have_impulse = self.reduce_impacts(ctx, impacts);
        let have_force = self.reduce_forces(ctx, forces);
        // The channels whose peaks Eq. 11 takes, and their weights n_cᵀU_c.
        let nch = self.build_channels(ctx);
        // Eq. 10–11: the filters' response over the step and each channel's peak |w_c · q(k)|.
        self.peak_displacements(ctx, nch, have_impulse, have_force);
        // Eq. 12–13: Δv = d/h per resting contact.
        self.velocity_changes(ctx, resting);
    }

    /// Eq. 9: `self.r = Σ Uᵀ H_c n_c λ_c` over the accepted impacts that map to the surface.
    /// Returns whether any did.
    fn reduce_impacts(&mut self, ctx: &mut StepCtx<'_>, impacts: &[Impact]) -> bool {
        let model = ctx.model;
        self.r.iter_mut().for_each(|x| *x = 0.0);
        let mut have_impulse = false;
        for imp in impacts {
            if !ctx.accept(imp.impulse) {
                continue;
            }
            match model.project(imp.point, ctx.max_map) {
                Some(sp) => {
                    model.add_reduced_impulse(
                        &sp,
                        normalize(imp.direction),
                        imp.impulse,
                        &mut self.r,
                    );
                    have_impulse = true;
                    ctx.info.impacts_applied += 1;
                }
                None => ctx.info.impacts_unmapped += 1,
            }
        }
        have_impulse
    }

    /// The reduced force `self.f = Σ Uᵀ H_c F_c` of the non-zero, finite forces that map to the
    /// surface (held constant over the step). Returns whether any did.
    fn reduce_forces(&mut self, ctx: &mut StepCtx<'_>, forces: &[ForceInput]) -> bool {
        let model = ctx.model;
        self.f.iter_mut().for_each(|x| *x = 0.0);
        let mut have_force = false;
        for fi in forces {
            if fi.force == [0.0; 3] || !fi.force.iter().all(|x| x.is_finite()) {
                continue;
            }
            match model.project(fi.point, ctx.max_map) {
                Some(sp) => {
                    model.add_reduced_impulse(&sp, fi.force, 1.0, &mut self.f);
                    have_force = true;
                    ctx.info.forces_applied += 1;
                }
                None => ctx.info.forces_ignored += 1,
            }
        }
        have_force
    }

    /// Assigns the channels, one per mapped contact (`PerContact`) or one per corner vertex of
    /// its triangle (`PerNode`), and rebuilds their weights `w_step` (mode-major, m × nch) when
    /// the contact list or the cache changed (steady state: resting contacts repeat step after
    /// step). Returns the number of channels nch.
    fn build_channels(&mut self, ctx: &StepCtx<'_>) -> usize {
        let m = self.m;
        let model = ctx.model;
        let contacts = ctx.contacts;
        let slots = contacts.slots();
        let per_node = ctx.params.variant == Variant::PerNode;
        let width = if per_node { 3 } else { 1 };
        self.chan.clear();
        let mut nmapped = 0u32;
        for &s in slots {
            if contacts.slot(s).surface.is_some() {
                self.chan.push(nmapped);
                nmapped += 1;
            } else {
                self.chan.push(UNMAPPED);
            }
        }
        let nch = nmapped as usize * width;
        if self.peaks.len() < nch {
            self.peaks.resize(nch, 0.0);
        }
        if self.w_key.0 != contacts.generation() || self.w_key.1 != slots {
            self.w_key.0 = contacts.generation();
            self.w_key.1.clear();
            self.w_key.1.extend_from_slice(slots);
            if self.w_step.len() < nch * m {
                self.w_step.resize(nch * m, 0.0);
            }
            let w = &mut self.w_step[..nch * m];
            let rows = model.normal_mode_rows();
            for (&s, &c) in slots.iter().zip(&self.chan) {
                if c == UNMAPPED {
                    continue;
                }
                if per_node {
                    let sp = contacts.slot(s).surface.expect("mapped");
                    for (corner, v) in model.triangle(sp.triangle).into_iter().enumerate() {
                        let col = c as usize * 3 + corner;
                        for (j, x) in rows[v * m..(v + 1) * m].iter().enumerate() {
                            w[j * nch + col] = *x;
                        }
                    }
                } else {
                    for (j, x) in contacts.row(s).iter().enumerate() {
                        w[j * nch + c as usize] = *x;
                    }
                }
            }
        }
        nch
    }

    /// Eq. 10–11: runs the filters over the step (from rest through the impulse-response
    /// table, or sample by sample with carry-over or forces) and fills `peaks[..nch]` with each
    /// channel's `max_k |w_c · q(k)|` (zeros when nothing moves); then the sleep test of the
    /// carried-over state.
    fn peak_displacements(
        &mut self,
        ctx: &mut StepCtx<'_>,
        nch: usize,
        have_impulse: bool,
        have_force: bool,
    ) {
        let carry = ctx.params.carry_over;
        if !carry {
            self.bank.reset();
            self.asleep = false;
        }
        let active = have_impulse || have_force || (carry && !self.asleep);
        let mut peaks_buf = std::mem::take(&mut self.peaks);
        let peaks = &mut peaks_buf[..nch];
        if active {
            if !carry && !have_force {
                self.peaks_from_rest(nch, peaks);
            } else {
                self.peaks_by_stepping(nch, have_impulse, have_force, peaks);
            }
            if carry {
                self.asleep = false;
                if have_impulse {
                    self.energy_ref = 0.5 * self.r.iter().map(|x| x * x).sum::<f64>();
                }
                let e = self.bank.energy();
                if have_force {
                    self.energy_ref = self.energy_ref.max(e);
                } else if e <= ctx.params.sleep_energy_rel * self.energy_ref {
                    self.asleep = true;
                    self.bank.reset();
                }
            }
        } else {
            peaks.iter_mut().for_each(|x| *x = 0.0);
            self.q_table.iter_mut().for_each(|x| *x = 0.0);
            self.q_stale = false;
            ctx.info.asleep = carry;
        }
        self.peaks = peaks_buf;
    }

    /// The reset path of [`ModalResponse::peak_displacements`]: from rest, q(k) = g(kT) ∘ r,
    /// so the peaks are one dense multiply-max; leaves the filters in their end-of-step state.
    fn peaks_from_rest(&mut self, nch: usize, peaks: &mut [f64]) {
        let (m, s, stride) = (self.m, self.samples, self.stride);
        // Fold r into whichever operand is smaller: the S × m table or the m × nch channel
        // weights. (The comparison uses nch rounded up to 8, as the earlier 8-channel-panel
        // kernel did, so each workload keeps its rounding: results are bit-identical to that
        // kernel.)
        if nch > 0 && s > nch.div_ceil(8) * 8 {
            if self.w_scaled.len() < nch * m {
                self.w_scaled.resize(nch * m, 0.0);
            }
            let ws = &mut self.w_scaled[..nch * m];
            for ((dst, src), r) in ws
                .chunks_exact_mut(nch)
                .zip(self.w_step.chunks_exact(nch))
                .zip(&self.r)
            {
                for (d, x) in dst.iter_mut().zip(src) {
                    *d = x * r;
                }
            }
            peak_abs_rows(&self.g_t, stride, m, ws, nch, peaks);
        } else if nch > 0 {
            for ((qj, gj), r) in self
                .q_t
                .chunks_exact_mut(stride)
                .zip(self.g_t.chunks_exact(stride))
                .zip(&self.r)
            {
                for (q, g) in qj.iter_mut().zip(gj) {
                    *q = g * r;
                }
            }
            peak_abs_rows(&self.q_t, stride, m, &self.w_step[..nch * m], nch, peaks);
        }
        // The row-major samples are filled on demand (`samples`).
        self.q_stale = true;
        for j in 0..m {
            self.tmp_q[j] = self.g_end[j] * self.r[j];
            self.tmp_v[j] = self.g_dot_end[j] * self.r[j];
        }
        self.bank.set_state(&self.tmp_q, &self.tmp_v);
    }

    /// The stepping path of [`ModalResponse::peak_displacements`] (carry-over or forces): the
    /// impulse applied to the filters, then S samples with the force held constant, the
    /// samples transposed mode-major and the peaks taken.
    fn peaks_by_stepping(
        &mut self,
        nch: usize,
        have_impulse: bool,
        have_force: bool,
        peaks: &mut [f64],
    ) {
        let (m, s, stride) = (self.m, self.samples, self.stride);
        if have_impulse {
            self.bank.apply_impulse(&self.r);
        }
        let force = if have_force { Some(&self.f[..]) } else { None };
        self.bank.run(s, force, &mut self.q_table);
        self.q_stale = false;
        if nch > 0 {
            for (k, qk) in self.q_table[..s * m].chunks_exact(m).enumerate() {
                for (j, &q) in qk.iter().enumerate() {
                    self.q_t[j * stride + k] = q;
                }
            }
            peak_abs_rows(&self.q_t, stride, m, &self.w_step[..nch * m], nch, peaks);
        }
    }

    /// Eq. 12–13: one response per resting contact into `ctx.out`, `Δv = d/h` with d the
    /// contact's channel peak (`PerNode`: the corners' peaks blended with its barycentric
    /// weights); an unmapped contact gets an unmapped response.
    fn velocity_changes(&self, ctx: &mut StepCtx<'_>, resting: &[RestingContact]) {
        let contacts = ctx.contacts;
        let slots = contacts.slots();
        let per_node = ctx.params.variant == Variant::PerNode;
        let h = ctx.params.h;
        ctx.out.clear();
        for ((rc, &s), &c) in resting.iter().zip(slots).zip(&self.chan) {
            let cached = contacts.slot(s);
            let resp = match cached.surface {
                Some(sp) if c != UNMAPPED => {
                    let d = if per_node {
                        (0..3)
                            .map(|i| sp.bary[i] * self.peaks[c as usize * 3 + i])
                            .sum()
                    } else {
                        self.peaks[c as usize]
                    };
                    mapped_response(rc, &sp, d, h, ServedBy::Modal)
                }
                _ => unmapped_response(rc),
            };
            ctx.out.push(resp);
        }
    }
}
