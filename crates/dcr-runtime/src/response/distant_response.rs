//! [`DistantResponse`]: one object instance's per-step distant collision response — the
//! shared contact mapping ([`ContactSet`]) and one method type serving the step: modal
//! ([`ModalResponse`], Eq. 9–13), spatial attenuation ([`AttenuationResponse`], Eq. 14–16) or
//! the bake-time transfer table ([`TransferResponse`], with the modal method for what the table
//! cannot serve), plus the optional lateral kick ([`LateralKick`], §5.4).

use std::sync::Arc;

use super::attenuation_response::AttenuationResponse;
use super::contact_set::ContactSet;
use super::impulse_table::ImpulseTable;
use super::lateral_kick::LateralKick;
use super::modal_response::ModalResponse;
use super::step_ctx::{unmapped_response, StepCtx};
use super::transfer_response::TransferResponse;
use super::{
    prepared_vec, ContactResponse, ForceInput, Impact, Launch, Method, ParamsError, ResponseParams,
    RestingContact, StepInfo, TableFallback, TablePolicy, TableStatus, PREPARED_CONTACTS,
};
use crate::model::ModalModel;

/// The method serving the steps.
#[derive(Debug)]
enum MethodResponse {
    Modal(ModalResponse),
    Attenuation(AttenuationResponse),
    Transfer(TransferResponse),
}

impl MethodResponse {
    /// The modal filters, when the method has them.
    fn modal(&self) -> Option<&ModalResponse> {
        match self {
            MethodResponse::Modal(m) => Some(m),
            MethodResponse::Transfer(t) => Some(t.modal()),
            MethodResponse::Attenuation(_) => None,
        }
    }

    fn modal_mut(&mut self) -> Option<&mut ModalResponse> {
        match self {
            MethodResponse::Modal(m) => Some(m),
            MethodResponse::Transfer(t) => Some(t.modal_mut()),
            MethodResponse::Attenuation(_) => None,
        }
    }
}

/// The distant collision response of one object instance (paper §4.2–4.5).
///
/// Set up once per object ([`DistantResponse::new`]); call [`DistantResponse::step`] once per
/// rigid-body step with the step's new impacts and the current resting contacts. After warm-up
/// (buffers are sized at set-up for [`PREPARED_CONTACTS`] resting contacts and grown on first
/// sight of more) a step does not allocate. Everything is in the object frame of the model (m,
/// s, N·s).
///
/// ```
/// use std::sync::Arc;
/// use dcr_runtime::{testing, DistantResponse, ModalModel, ResponseParams};
/// use dcr_runtime::response::{Impact, RestingContact};
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
/// let m_eff = dcr_runtime::response::effective_mass(1.0, [[0.0; 3]; 3], [0.0; 3], out[0].normal);
/// let j = dcr_runtime::response::response_impulse(m_eff, out[0].delta_v, out[0].normal);
/// assert!(j[2] > 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct DistantResponse {
    model: Arc<ModalModel>,
    params: ResponseParams,
    samples: usize,
    period: f64,
    max_map: f64,
    contacts: ContactSet,
    method: MethodResponse,
    lateral: Option<LateralKick>,
    table_status: TableStatus,
    out: Vec<ContactResponse>,
    step_index: u64,
    info: StepInfo,
    /// Zero modal state and samples (m and S × m) for the methods without filters.
    idle: Vec<f64>,
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
    /// parameters, a surface the heat method cannot factor, or (under [`TablePolicy::Refuse`])
    /// a transfer table that does not apply ([`ParamsError::TableRefused`]), or
    /// [`Launch::SustainedPeak`] without `carry_over` or with the attenuation method.
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
        if p.launch != Launch::PeakOverStep {
            if !p.carry_over {
                return Err(invalid(
                    "launch",
                    format!(
                        "{:?} reads the carried-over filters: set carry_over = true",
                        p.launch
                    ),
                ));
            }
            if matches!(p.method, Method::Attenuation(_)) {
                return Err(invalid(
                    "launch",
                    format!(
                        "{:?} needs the modal filters; the attenuation method has none (use \
                         Method::Modal)",
                        p.launch
                    ),
                ));
            }
        }
        let table = ImpulseTable::new(&model, p, rayleigh)?;
        let (samples, period, m) = (table.samples, table.period, model.num_modes());
        let lateral = p
            .lateral_kick
            .then(|| LateralKick::new(table.g_table.clone(), samples, m));
        let mut idle = Vec::new();
        let (method, table_status) = match &p.method {
            Method::Attenuation(a) => {
                idle = vec![0.0; samples * m];
                let att = AttenuationResponse::new(&model, a, &table)?;
                (MethodResponse::Attenuation(att), TableStatus::NotRequested)
            }
            Method::Modal => (
                MethodResponse::Modal(ModalResponse::new(table, p.h, p.variant)),
                TableStatus::NotRequested,
            ),
            Method::Transfer => {
                let modal = ModalResponse::new(table, p.h, p.variant);
                match TransferResponse::check(&model, p.h, rayleigh, p.carry_over, p.launch) {
                    Ok(()) => (
                        MethodResponse::Transfer(TransferResponse::new(&model, modal)),
                        TableStatus::Active,
                    ),
                    Err(status) if p.table_policy == TablePolicy::Refuse => {
                        return Err(ParamsError::TableRefused { status });
                    }
                    Err(status) => (MethodResponse::Modal(modal), status),
                }
            }
        };
        let remap_tolerance = 0.01 * model.mean_edge_length();
        Ok(DistantResponse {
            samples,
            period,
            max_map,
            contacts: ContactSet::new(m, remap_tolerance, max_map, p.evict_after_steps),
            method,
            lateral,
            table_status,
            out: prepared_vec(
                PREPARED_CONTACTS,
                unmapped_response(&RestingContact {
                    id: 0,
                    point: [0.0; 3],
                }),
            ),
            step_index: 0,
            info: StepInfo::default(),
            idle,
            model,
            params,
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

    /// Sets the impact threshold (N·s) from the next step on: impacts below it are ignored
    /// ([`ResponseParams::impact_threshold`]).
    ///
    /// # Errors
    /// [`ParamsError::Invalid`] for a negative or non-finite threshold (the old one is kept).
    pub fn set_impact_threshold(&mut self, threshold: f64) -> Result<(), ParamsError> {
        if !(threshold >= 0.0 && threshold.is_finite()) {
            return Err(invalid("impact_threshold", format!("{threshold} N·s")));
        }
        self.params.impact_threshold = threshold;
        Ok(())
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
        match &self.method {
            MethodResponse::Attenuation(a) => Some(a.amplitudes()),
            _ => None,
        }
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

    /// Whether the transfer table is in use for this instance (the base has one that matches
    /// h, Rayleigh damping and `carry_over = false`, and the method is [`Method::Transfer`]).
    pub fn transfer_active(&self) -> bool {
        matches!(self.method, MethodResponse::Transfer(_))
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
        self.params.carry_over && self.method.modal().is_some_and(|m| !m.asleep())
    }

    /// Number of resting contacts currently cached.
    pub fn cached_contacts(&self) -> usize {
        self.contacts.len()
    }

    /// Modal energy ½ Σ (q̇² + ω² q²) of the filter state at the end of the last step
    /// (J for the mass-normalised base). 0 for the attenuation method.
    pub fn modal_energy(&self) -> f64 {
        self.method.modal().map_or(0.0, |m| m.energy())
    }

    /// Takes `energy` (J, ≥ 0) out of the carried modal filters at the end of the last step
    /// (scaling every mode's state alike; at or above [`DistantResponse::modal_energy`] the
    /// filters rest). Under [`Launch::SustainedPeak`] the world drains in this way the kinetic
    /// energy the step's pushes gave the resting bodies: the ringing pays for what it lifts.
    /// No effect without carry-over, for the attenuation method, or for `energy ≤ 0`.
    pub fn drain(&mut self, energy: f64) {
        if !self.params.carry_over {
            return;
        }
        if let Some(m) = self.method.modal_mut() {
            m.drain(energy);
        }
    }

    /// Modal displacements q (kg^1/2·m) at the end of the last step (zeros for the
    /// attenuation method).
    pub fn modal_state(&self) -> &[f64] {
        match self.method.modal() {
            Some(m) => m.state(),
            None => &self.idle[..self.model.num_modes()],
        }
    }

    /// The last step's modal displacement samples q(k) (kg^1/2·m), k = 1..S (row-major S × m;
    /// zeros when the bank was idle or for the attenuation method).
    pub fn modal_samples(&mut self) -> &[f64] {
        match self.method.modal_mut() {
            Some(m) => m.samples(),
            None => &self.idle,
        }
    }

    /// Returns the filters to rest (and wakes nothing); cached contacts and distance fields are
    /// kept (they depend only on geometry).
    pub fn reset(&mut self) {
        if let Some(m) = self.method.modal_mut() {
            m.reset();
        }
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
        let method = &mut self.method;
        self.contacts
            .map(&self.model, resting, step, &mut self.info, |s| {
                if let MethodResponse::Attenuation(a) = method {
                    a.invalidate(s);
                }
            });
        let mut ctx = StepCtx {
            model: &self.model,
            params: &self.params,
            max_map: self.max_map,
            contacts: &self.contacts,
            step,
            info: &mut self.info,
            out: &mut self.out,
        };
        match &mut self.method {
            MethodResponse::Modal(m) => {
                if !matches!(
                    self.table_status,
                    TableStatus::NotRequested | TableStatus::NoTable
                ) {
                    ctx.info.contacts_table_fallback += resting.len() as u32;
                    ctx.info.table_fallback = Some(TableFallback::Unavailable);
                }
                m.step(&mut ctx, impacts, forces, resting);
            }
            MethodResponse::Attenuation(a) => a.step(&mut ctx, impacts, forces, resting),
            MethodResponse::Transfer(t) => t.step(&mut ctx, impacts, forces, resting),
        }
        if let Some(l) = self.lateral.as_mut() {
            l.apply(&mut ctx, impacts);
        }
        &self.out
    }
}
