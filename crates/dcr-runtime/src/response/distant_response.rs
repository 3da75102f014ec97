//! [`DistantResponse`]: one object instance's per-step distant collision response.
//!
//! Modal method (paper Eq. 9–13): the step's impacts (impulse ≥ threshold) are mapped to the
//! surface and summed into one reduced impulse `r = Σ Uᵀ H_c d_c λ_c` applied at t = 0; the
//! exact mode filters give q(k) at t = k·h/S, k = 1..S, S = ⌈h/T⌉; each resting contact's peak
//! `d = max_k |w_c · q(k)|` (or Eq. 13 per node) gives Δv = d/h. Without carry-over the filters
//! start from rest every step, so q(k) = g(kT) ∘ r with the impulse-response table g_j(kT)
//! precomputed at set-up; the per-step work is one dense multiply-max over S × m × contacts.
//!
//! Attenuation method (Eq. 14–16): Δx_c = q̂ᵀ h_c λ_N per impact, Δv_p = Σ_c s(r_cp) Δx_c / h.

use std::sync::Arc;

mod transfer;

use super::peak_kernel::{peak_abs_rows, LANES};
use super::{
    ContactResponse, ForceInput, Impact, Method, ParamsError, ResponseParams, RestingContact,
    ServedBy, StepInfo, TablePolicy, TableStatus, Variant,
};
use crate::attenuation::{
    AmplitudeKind, AttenuationParams, DistanceCache, DistanceKind, HeatWorkspace,
};
use crate::filter::{damping_ratio, samples_per_step, ModalBank};
use crate::mapping::ContactCache;
use crate::math::{dot, norm, normalize, sub};
use crate::model::{ModalModel, SurfacePoint};

/// Largest number of filter samples per step accepted.
const MAX_SAMPLES: f64 = 1e6;

const UNMAPPED: u32 = u32::MAX;

/// Attenuation-method state.
#[derive(Debug)]
struct AttenuationState {
    params: AttenuationParams,
    /// Local amplitude q̂ per surface vertex (m per N·s).
    amplitude: Vec<f64>,
    /// Mean amplitude for [`AmplitudeKind::Mean`] / `MeanOver`.
    mean: f64,
    fields: DistanceCache,
    ws: Option<HeatWorkspace>,
    /// This step's applied impacts: surface point and local displacement Δx_c (m).
    hits: Vec<(SurfacePoint, f64)>,
    /// Heat distance fields (m) from this step's impacts, one per hit (`hits.len() × ns`),
    /// when they serve the uncached contacts (the cost rule of [`DistanceKind::Heat`]).
    hit_fields: Vec<f64>,
}

/// The distant collision response of one object instance (paper §4.2–4.5).
///
/// Set up once per object ([`DistantResponse::new`]); call [`DistantResponse::step`] once per
/// rigid-body step with the step's new impacts and the current resting contacts. After warm-up
/// (buffers are sized at set-up and grown on first sight of more contacts) a step does not
/// allocate. Everything is in the object frame of the model (m, s, N·s).
///
/// ```
/// use std::sync::Arc;
/// use dcr_runtime::{testing, DistantResponse, Impact, ModalModel, ResponseParams, RestingContact};
///
/// // A synthetic 1 m × 0.6 m plate base (8 modes); real bases come from `ModalModel::load`.
/// let model = Arc::new(ModalModel::from_base(testing::plate_base())?);
/// let mut resp = DistantResponse::new(model, ResponseParams::default())?;
/// // A 2 N·s hit pushing into the plate (−z) at its middle; a box resting near a corner.
/// let impacts = [Impact { point: [0.5, 0.3, 0.0], direction: [0.0, 0.0, -1.0], impulse: 2.0 }];
/// let resting = [RestingContact { id: 7, point: [0.9, 0.5, 0.001] }];
/// let out = resp.step(&impacts, &resting);
/// assert!(out[0].mapped && out[0].delta_v > 0.0);
/// // Eq. 17–18: the impulse for a 1 kg box (no rotation) along the contact normal.
/// let m_eff = dcr_runtime::effective_mass(1.0, [[0.0; 3]; 3], [0.0; 3], out[0].normal);
/// let j = dcr_runtime::response_impulse(m_eff, out[0].delta_v, out[0].normal);
/// assert!(j[2] > 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct DistantResponse {
    model: Arc<ModalModel>,
    params: ResponseParams,
    m: usize,
    samples: usize,
    period: f64,
    max_map: f64,
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
    cache: ContactCache,
    slots: Vec<u32>,
    chan: Vec<u32>,
    /// The step's channel weights, mode-major (m × nch, one column per channel).
    w_step: Vec<f64>,
    /// (cache generation, slots) the current `w_step` was built for.
    w_key: (u64, Vec<u32>),
    w_scaled: Vec<f64>,
    q_stale: bool,
    peaks: Vec<f64>,
    out: Vec<ContactResponse>,
    step_index: u64,
    asleep: bool,
    energy_ref: f64,
    info: StepInfo,
    att: Option<AttenuationState>,
    /// Transfer-table method state (`None`: not requested or the base's table does not apply).
    transfer: Option<transfer::TransferState>,
    table_status: TableStatus,
}

fn invalid(field: &'static str, detail: impl Into<String>) -> ParamsError {
    ParamsError::Invalid {
        field,
        detail: detail.into(),
    }
}

impl DistantResponse {
    /// Sets up the filters (and, for attenuation, the local amplitudes and distance solver).
    ///
    /// # Errors
    /// [`ParamsError`] for a non-positive or non-finite h, sampling, threshold, map distance,
    /// negative Rayleigh coefficients, more than 10⁶ samples per step, invalid attenuation
    /// parameters, or a surface the heat method cannot factor.
    pub fn new(model: Arc<ModalModel>, params: ResponseParams) -> Result<Self, ParamsError> {
        let p = &params;
        if !(p.h.is_finite() && p.h > 0.0) {
            return Err(invalid("h", format!("{} s (must be finite and > 0)", p.h)));
        }
        let rayleigh = p.rayleigh.unwrap_or(model.base().rayleigh);
        if !rayleigh.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(invalid(
                "rayleigh",
                format!("{rayleigh:?} (must be finite and ≥ 0)"),
            ));
        }
        if !(p.impact_threshold >= 0.0 && p.impact_threshold.is_finite()) {
            return Err(invalid(
                "impact_threshold",
                format!("{} N·s", p.impact_threshold),
            ));
        }
        let max_map = if p.max_map_distance.is_nan() {
            0.05 * model.bounding_box_diagonal()
        } else {
            p.max_map_distance
        };
        if !(max_map >= 0.0) {
            return Err(invalid("max_map_distance", format!("{max_map} m")));
        }
        if !(p.sleep_energy_rel >= 0.0 && p.sleep_energy_rel.is_finite()) {
            return Err(invalid(
                "sleep_energy_rel",
                format!("{}", p.sleep_energy_rel),
            ));
        }
        let omega = model.omega();
        let m = omega.len();
        let omega_max = omega[m - 1];
        let t_req = p.sampling.period(omega_max);
        if !(t_req.is_finite() && t_req > 0.0) {
            return Err(invalid(
                "sampling",
                format!("{:?} gives T = {t_req} s", p.sampling),
            ));
        }
        if p.h / t_req > MAX_SAMPLES {
            return Err(ParamsError::TooManySamples {
                samples: (p.h / t_req).ceil(),
            });
        }
        let samples = samples_per_step(p.h, t_req);
        let period = p.h / samples as f64;
        let xi: Vec<f64> = omega.iter().map(|&w| damping_ratio(w, rayleigh)).collect();
        let bank = ModalBank::new(omega, &xi, period);
        let mut g_table = vec![0.0; samples * m];
        for k in 0..samples {
            for (j, f) in bank.filters().iter().enumerate() {
                g_table[k * m + j] = f.impulse_response((k + 1) as f64 * period);
            }
        }
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
            .map(|(f, g)| f.free_response(p.h) - 2.0 * f.xi * f.omega * g)
            .collect();
        let att = match &p.method {
            Method::Modal | Method::Transfer => None,
            Method::Attenuation(a) => Some(Self::attenuation_setup(&model, a, &g_table, samples)?),
        };
        let (transfer, table_status) = match p.method {
            Method::Transfer => {
                match transfer::TransferState::new(&model, p.h, rayleigh, p.carry_over) {
                    Ok(t) => (Some(t), TableStatus::Active),
                    Err(status) => {
                        if p.table_policy == TablePolicy::Refuse {
                            return Err(ParamsError::TableRefused { status });
                        }
                        (None, status)
                    }
                }
            }
            _ => (None, TableStatus::NotRequested),
        };
        let remap_tolerance = 0.01 * model.mean_edge_length();
        Ok(DistantResponse {
            m,
            samples,
            period,
            max_map,
            bank,
            g_table,
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
            cache: ContactCache::new(m, remap_tolerance),
            slots: Vec::new(),
            chan: Vec::new(),
            w_step: Vec::new(),
            w_key: (u64::MAX, Vec::new()),
            w_scaled: Vec::new(),
            q_stale: false,
            peaks: Vec::new(),
            out: Vec::new(),
            step_index: 0,
            asleep: true,
            energy_ref: 0.0,
            info: StepInfo::default(),
            att,
            transfer,
            table_status,
            model,
            params,
        })
    }

    fn attenuation_setup(
        model: &ModalModel,
        a: &AttenuationParams,
        g_table: &[f64],
        samples: usize,
    ) -> Result<AttenuationState, ParamsError> {
        use crate::attenuation::AttenuationLaw;
        let finite_nonneg = |x: f64| x.is_finite() && x >= 0.0;
        match a.law {
            AttenuationLaw::Full { alpha, beta, r0 } => {
                if !(finite_nonneg(alpha) && finite_nonneg(beta) && r0.is_finite() && r0 > 0.0) {
                    return Err(invalid("attenuation law", format!("{:?}", a.law)));
                }
            }
            AttenuationLaw::Simplified { c, beta } => {
                if !(finite_nonneg(c) && finite_nonneg(beta)) {
                    return Err(invalid("attenuation law", format!("{:?}", a.law)));
                }
            }
        }
        let m = model.num_modes();
        let ns = model.num_vertices();
        let rows = model.normal_mode_rows();
        // q̂_v = max_k |Σ_j (n_vᵀU_v)_j² g_j(kT)|: unit normal impulse at v, seen at v (§4.4).
        let mut amplitude = vec![0.0; ns];
        let mut sq = vec![0.0; m];
        for (v, amp) in amplitude.iter_mut().enumerate() {
            for (s, x) in sq.iter_mut().zip(&rows[v * m..(v + 1) * m]) {
                *s = x * x;
            }
            let mut peak = 0.0f64;
            for k in 0..samples {
                let y: f64 = g_table[k * m..(k + 1) * m]
                    .iter()
                    .zip(&sq)
                    .map(|(g, s)| g * s)
                    .sum();
                peak = peak.max(y.abs());
            }
            *amp = peak;
        }
        let mean = match &a.amplitude {
            AmplitudeKind::PerVertex => 0.0,
            AmplitudeKind::Mean => amplitude.iter().sum::<f64>() / ns as f64,
            AmplitudeKind::MeanOver(subset) => {
                if subset.is_empty() {
                    return Err(invalid("amplitude", "MeanOver subset is empty"));
                }
                if let Some(bad) = subset.iter().find(|&&v| v as usize >= ns) {
                    return Err(invalid(
                        "amplitude",
                        format!("MeanOver names vertex {bad} ≥ {ns}"),
                    ));
                }
                subset.iter().map(|&v| amplitude[v as usize]).sum::<f64>() / subset.len() as f64
            }
        };
        let ws = match a.distance {
            DistanceKind::Heat => {
                let heat = model
                    .heat_geodesic()
                    .map_err(|e| ParamsError::Geodesic(e.to_string()))?;
                let mut ws = heat.workspace();
                ws.set_parallel(a.parallel_heat);
                Some(ws)
            }
            DistanceKind::Euclidean => None,
        };
        let capacity = if a.distance == DistanceKind::Heat {
            a.cache_capacity
        } else {
            1
        };
        Ok(AttenuationState {
            params: a.clone(),
            amplitude,
            mean,
            fields: DistanceCache::new(ns, capacity),
            ws,
            hits: Vec::new(),
            hit_fields: Vec::new(),
        })
    }

    /// The shared model.
    pub fn model(&self) -> &Arc<ModalModel> {
        &self.model
    }

    /// The parameters as given.
    pub fn params(&self) -> &ResponseParams {
        &self.params
    }

    /// Filter samples per rigid-body step, S = ⌈h/T⌉ (relative tolerance 1e-9).
    pub fn samples_per_step(&self) -> usize {
        self.samples
    }

    /// Effective filter period T_eff = h/S (s).
    pub fn substep(&self) -> f64 {
        self.period
    }

    /// The mapping distance in use (m): the parameter, or 5% of the bounding-box diagonal.
    pub fn max_map_distance(&self) -> f64 {
        self.max_map
    }

    /// Local amplitudes q̂_v (m per N·s of normal impulse) per surface vertex (attenuation
    /// method only; the §4.3 peak procedure at the impacted vertex itself).
    pub fn local_amplitudes(&self) -> Option<&[f64]> {
        self.att.as_ref().map(|a| &a.amplitude[..])
    }

    /// Counters of the last step.
    pub fn last_step_info(&self) -> StepInfo {
        self.info
    }

    /// Whether the transfer table serves this response, and if not, why (set-up time; see
    /// [`TablePolicy`]).
    pub fn table_status(&self) -> TableStatus {
        self.table_status
    }

    /// Counts `n` rigid-body steps that passed without a call: cache eviction
    /// ([`ResponseParams::evict_after_steps`]) is counted in steps, not calls. A caller that
    /// queries only on steps with impacts reports the steps in between here.
    pub fn skip_steps(&mut self, n: u64) {
        self.step_index += n;
    }

    /// Whether the response must run this step even without impacts: carry-over filters that
    /// still ring (not asleep). `false` for the default restart-every-step mode.
    pub fn needs_step(&self) -> bool {
        self.params.carry_over && !self.asleep
    }

    /// Number of resting contacts currently cached.
    pub fn cached_contacts(&self) -> usize {
        self.cache.len()
    }

    /// Modal energy ½ Σ (q̇² + ω² q²) of the filter state at the end of the last step
    /// (J for the mass-normalised base). 0 for the attenuation method.
    pub fn modal_energy(&self) -> f64 {
        self.bank.energy()
    }

    /// Modal displacements q (kg^1/2·m) at the end of the last step.
    pub fn modal_state(&self) -> &[f64] {
        self.bank.q()
    }

    /// The last step's modal displacement samples q(k) (kg^1/2·m), k = 1..S (row-major S × m;
    /// zeros when the bank was idle or for the attenuation method).
    pub fn modal_samples(&mut self) -> &[f64] {
        if self.q_stale {
            self.fill_q_from_table();
        }
        &self.q_table
    }

    fn fill_q_from_table(&mut self) {
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

    /// Returns the filters to rest (and wakes nothing); cached contacts and distance fields are
    /// kept (they depend only on geometry).
    pub fn reset(&mut self) {
        self.bank.reset();
        self.asleep = true;
        self.energy_ref = 0.0;
        self.q_table.iter_mut().for_each(|x| *x = 0.0);
        self.q_stale = false;
    }

    /// One rigid-body step with the step's new `impacts` and the current `resting` contacts;
    /// returns one [`ContactResponse`] per resting contact in the same order, valid until the
    /// next call. Does not allocate after warm-up.
    pub fn step(&mut self, impacts: &[Impact], resting: &[RestingContact]) -> &[ContactResponse] {
        self.step_with_forces(impacts, &[], resting)
    }

    /// As [`DistantResponse::step`], plus forces held constant over the step (zero-order hold,
    /// modal method only; the attenuation method ignores them and counts them in
    /// [`StepInfo::forces_ignored`]).
    pub fn step_with_forces(
        &mut self,
        impacts: &[Impact],
        forces: &[ForceInput],
        resting: &[RestingContact],
    ) -> &[ContactResponse] {
        self.step_index += 1;
        self.info = StepInfo::default();
        let step = self.step_index;
        {
            let att = &mut self.att;
            self.cache
                .evict_unseen(step, self.params.evict_after_steps, |s| {
                    if let Some(a) = att.as_mut() {
                        a.fields.invalidate(s);
                    }
                });
        }
        // Last step's slot at the same list position is tried first (contact lists repeat).
        self.slots.resize(resting.len(), u32::MAX);
        for (i, rc) in resting.iter().enumerate() {
            let (s, mapped_now) = self.cache.lookup_with_hint(
                &self.model,
                rc.id,
                rc.point,
                step,
                self.max_map,
                self.slots[i],
            );
            if mapped_now {
                self.info.contacts_mapped_now += 1;
                if let Some(a) = self.att.as_mut() {
                    a.fields.invalidate(s);
                }
            }
            if self.cache.slot(s).surface.is_none() {
                self.info.contacts_unmapped += 1;
            }
            self.slots[i] = s;
        }
        if self.att.is_some() {
            self.step_attenuation(impacts, forces, resting);
        } else if !self.step_transfer(impacts, forces, resting) {
            self.step_modal(impacts, forces, resting);
        }
        &self.out
    }

    fn accept(&mut self, impulse: f64) -> bool {
        let ok = impulse.is_finite() && impulse > 0.0 && impulse >= self.params.impact_threshold;
        if !ok {
            self.info.impacts_below_threshold += 1;
        }
        ok
    }

    fn step_modal(
        &mut self,
        impacts: &[Impact],
        forces: &[ForceInput],
        resting: &[RestingContact],
    ) {
        let m = self.m;
        let model = Arc::clone(&self.model);
        self.r.iter_mut().for_each(|x| *x = 0.0);
        let mut have_impulse = false;
        for imp in impacts {
            if !self.accept(imp.impulse) {
                continue;
            }
            match model.project(imp.point, self.max_map) {
                Some(sp) => {
                    model.add_reduced_impulse(
                        &sp,
                        normalize(imp.direction),
                        imp.impulse,
                        &mut self.r,
                    );
                    have_impulse = true;
                    self.info.impacts_applied += 1;
                }
                None => self.info.impacts_unmapped += 1,
            }
        }
        self.f.iter_mut().for_each(|x| *x = 0.0);
        let mut have_force = false;
        for fi in forces {
            if fi.force == [0.0; 3] || !fi.force.iter().all(|x| x.is_finite()) {
                continue;
            }
            match model.project(fi.point, self.max_map) {
                Some(sp) => {
                    model.add_reduced_impulse(&sp, fi.force, 1.0, &mut self.f);
                    have_force = true;
                    self.info.forces_applied += 1;
                }
                None => self.info.forces_ignored += 1,
            }
        }

        // Channels: one per mapped contact (PerContact) or one per corner vertex (PerNode).
        let per_node = self.params.variant == Variant::PerNode;
        let width = if per_node { 3 } else { 1 };
        self.chan.clear();
        let mut nmapped = 0u32;
        for &s in &self.slots {
            if self.cache.slot(s).surface.is_some() {
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
        // Rebuild the step's channel weights only when the contact list or the cache changed
        // (steady state: resting contacts repeat step after step).
        if self.w_key.0 != self.cache.generation() || self.w_key.1 != self.slots {
            self.w_key.0 = self.cache.generation();
            self.w_key.1.clear();
            self.w_key.1.extend_from_slice(&self.slots);
            if self.w_step.len() < nch * m {
                self.w_step.resize(nch * m, 0.0);
            }
            let w = &mut self.w_step[..nch * m];
            let rows = model.normal_mode_rows();
            for (&s, &c) in self.slots.iter().zip(&self.chan) {
                if c == UNMAPPED {
                    continue;
                }
                if per_node {
                    let sp = self.cache.slot(s).surface.expect("mapped");
                    for (corner, v) in model.triangle(sp.triangle).into_iter().enumerate() {
                        let col = c as usize * 3 + corner;
                        for (j, x) in rows[v * m..(v + 1) * m].iter().enumerate() {
                            w[j * nch + col] = *x;
                        }
                    }
                } else {
                    for (j, x) in self.cache.row(s).iter().enumerate() {
                        w[j * nch + c as usize] = *x;
                    }
                }
            }
        }

        let carry = self.params.carry_over;
        if !carry {
            self.bank.reset();
            self.asleep = false;
        }
        let active = have_impulse || have_force || (carry && !self.asleep);
        let mut peaks_buf = std::mem::take(&mut self.peaks);
        let peaks = &mut peaks_buf[..nch];
        if active {
            let s = self.samples;
            let stride = self.stride;
            if !carry && !have_force {
                // Reset path: q(k) = g(kT) ∘ r. Fold r into whichever operand is smaller:
                // the S × m table or the m × nch channel weights. (The comparison uses nch
                // rounded up to 8, as the earlier 8-channel-panel kernel did, so each
                // workload keeps its rounding: results are bit-identical to that kernel.)
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
                // The row-major samples are filled on demand (`modal_samples`).
                self.q_stale = true;
                for j in 0..m {
                    self.tmp_q[j] = self.g_end[j] * self.r[j];
                    self.tmp_v[j] = self.g_dot_end[j] * self.r[j];
                }
                self.bank.set_state(&self.tmp_q, &self.tmp_v);
            } else {
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
            if carry {
                self.asleep = false;
                if have_impulse {
                    self.energy_ref = 0.5 * self.r.iter().map(|x| x * x).sum::<f64>();
                }
                let e = self.bank.energy();
                if have_force {
                    self.energy_ref = self.energy_ref.max(e);
                } else if e <= self.params.sleep_energy_rel * self.energy_ref {
                    self.asleep = true;
                    self.bank.reset();
                }
            }
        } else {
            peaks.iter_mut().for_each(|x| *x = 0.0);
            self.q_table.iter_mut().for_each(|x| *x = 0.0);
            self.q_stale = false;
            self.info.asleep = carry;
        }
        self.peaks = peaks_buf;

        let h = self.params.h;
        self.out.clear();
        for ((rc, &s), &c) in resting.iter().zip(&self.slots).zip(&self.chan) {
            let cached = self.cache.slot(s);
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
            self.out.push(resp);
        }
    }

    fn step_attenuation(
        &mut self,
        impacts: &[Impact],
        forces: &[ForceInput],
        resting: &[RestingContact],
    ) {
        let model = Arc::clone(&self.model);
        let step = self.step_index;
        let h = self.params.h;
        self.info.forces_ignored += forces.iter().filter(|f| f.force != [0.0; 3]).count() as u32;
        let mut hits = std::mem::take(&mut self.att.as_mut().expect("attenuation").hits);
        hits.clear();
        for imp in impacts {
            if !self.accept(imp.impulse) {
                continue;
            }
            let Some(sp) = model.project(imp.point, self.max_map) else {
                self.info.impacts_unmapped += 1;
                continue;
            };
            let att = self.att.as_ref().expect("attenuation");
            // λ_N: the impulse's component along the surface normal (q̂ is per unit normal impulse).
            let lambda_n = imp.impulse * dot(normalize(imp.direction), sp.normal).abs();
            let amp = match att.params.amplitude {
                AmplitudeKind::PerVertex => model.interpolate(&att.amplitude, &sp),
                _ => att.mean,
            };
            hits.push((sp, amp * lambda_n));
            self.info.impacts_applied += 1;
        }
        let att = self.att.as_mut().expect("attenuation");
        let law = att.params.law;
        let distance = att.params.distance;
        // Heat distances: a contact's field, cached, is the cheap path over many steps, but a
        // step that brings many new contacts and few impacts would solve once per contact. When
        // the uncached contacts outnumber twice the impacts, this step computes (and caches)
        // the fields of only as many of them as there are impacts, and serves the rest from
        // one field per impact (the heat distance is symmetric up to its discretisation
        // error): at most 2 × impacts solves per step, and a stream of new contacts still ends
        // up cached. Without a cache (capacity 0) only the impact fields are solved.
        let mut budget = usize::MAX;
        if distance == DistanceKind::Heat && !hits.is_empty() {
            let uncached = resting
                .iter()
                .zip(&self.slots)
                .filter(|&(_, &s)| self.cache.slot(s).surface.is_some() && !att.fields.contains(s))
                .count();
            let solves = if att.fields.caches() { 2 } else { 1 } * hits.len();
            if uncached > solves {
                budget = if att.fields.caches() { hits.len() } else { 0 };
                let heat = model.heat_geodesic().expect("checked at set-up");
                let ws = att.ws.as_mut().expect("heat workspace");
                let ns = model.num_vertices();
                att.hit_fields.resize(hits.len() * ns, 0.0);
                for ((hp, _), field) in hits.iter().zip(att.hit_fields.chunks_exact_mut(ns)) {
                    heat.distances_from_point_with(hp, field, ws);
                }
                self.info.distance_fields_computed += hits.len() as u32;
            }
        }
        self.out.clear();
        for (rc, &s) in resting.iter().zip(&self.slots) {
            let Some(sp) = self.cache.slot(s).surface else {
                self.out.push(unmapped_response(rc));
                continue;
            };
            let mut total = 0.0;
            if !hits.is_empty() {
                match distance {
                    DistanceKind::Euclidean => {
                        for (hp, dx) in &hits {
                            total += law.factor(norm(sub(hp.point, sp.point))) * dx;
                        }
                    }
                    DistanceKind::Heat if budget == 0 && !att.fields.contains(s) => {
                        // Served from the impacts' fields, read at the contact.
                        let ns = model.num_vertices();
                        for ((_, dx), field) in hits.iter().zip(att.hit_fields.chunks_exact(ns)) {
                            total += law.factor(model.interpolate(field, &sp)) * dx;
                        }
                    }
                    DistanceKind::Heat => {
                        let heat = model.heat_geodesic().expect("checked at set-up");
                        let ws = att.ws.as_mut().expect("heat workspace");
                        let before = att.fields.computed;
                        let field = att
                            .fields
                            .get(s, step, |out| heat.distances_from_point_with(&sp, out, ws));
                        for (hp, dx) in &hits {
                            total += law.factor(model.interpolate(field, hp)) * dx;
                        }
                        let computed = (att.fields.computed - before) as usize;
                        budget = budget.saturating_sub(computed);
                        self.info.distance_fields_computed += computed as u32;
                    }
                }
            }
            self.out
                .push(mapped_response(rc, &sp, total, h, ServedBy::Attenuation));
        }
        att.hits = hits;
    }
}

/// The response of a mapped contact: peak normal displacement `d` (m) over the step `h` (s),
/// Δv = d/h (Eq. 12), at the contact's surface point and normal (object frame).
fn mapped_response(
    rc: &RestingContact,
    sp: &SurfacePoint,
    d: f64,
    h: f64,
    served_by: ServedBy,
) -> ContactResponse {
    ContactResponse {
        id: rc.id,
        point: sp.point,
        normal: sp.normal,
        peak_displacement: d,
        delta_v: d / h,
        lateral_delta_v: [0.0; 3],
        mapped: true,
        served_by,
    }
}

fn unmapped_response(rc: &RestingContact) -> ContactResponse {
    ContactResponse {
        id: rc.id,
        point: rc.point,
        normal: [0.0; 3],
        peak_displacement: 0.0,
        delta_v: 0.0,
        lateral_delta_v: [0.0; 3],
        mapped: false,
        served_by: ServedBy::Unmapped,
    }
}
