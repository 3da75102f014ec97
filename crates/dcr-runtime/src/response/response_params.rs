//! [`ResponseParams`] and the method / variant choices.

use crate::attenuation::AttenuationParams;
use crate::filter::Sampling;

/// How the peak at a contact is formed from the modal response (paper §4.3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Variant {
    /// Peak of the contact's own interpolated row: `max_k |nᵀ Σ_i b_i U_i q(k)|` (default).
    #[default]
    PerContact,
    /// Eq. 13: per-vertex peaks `d_i = max_k |n_iᵀ U_i q(k)|`, then `Δv = Σ b_i d_i / h`.
    PerNode,
}

/// How a resting contact's velocity change is formed from the modal response.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Launch {
    /// The paper's rule (Eq. 12): `Δv = d/h` with d the step's peak normal displacement under
    /// the contact, added to the body's velocity on the steps with impacts (default).
    #[default]
    PeakOverStep,
    /// Eq. 12's `Δv = d/h`, d the peak normal displacement under the contact over the step of
    /// the **carried-over** filters, on every step the object rings, not only on steps with
    /// impacts; taken as a **target** for the body's normal velocity at the contact (relative
    /// to the object's rigid motion) rather than added to it: [`crate::DcrWorld`] raises a
    /// touching body (its contact carried an impulse this step) to it, so a prop keeps being
    /// carried by a ringing object after the impact without the pushes adding up. Its energy
    /// bound also counts the object's modal energy (`η (D + R + E_modal)`), and the kinetic
    /// energy the pushes give is drained from the carried filters, so the ringing pays for what
    /// it lifts ([`crate::DistantResponse::drain`]). Needs
    /// `carry_over = true` and the modal filters: [`Method::Modal`], or [`Method::Transfer`],
    /// whose table then serves together with the carried filters (each contact takes the
    /// larger peak: the table's for the step's impacts, the filters' with the earlier ringing;
    /// the filters alone on the steps after); set-up refuses it with [`Method::Attenuation`]
    /// or without carry-over. Measured against the coupled reference
    /// in `docs/outcomes-analysis.md`.
    SustainedPeak,
}

/// Which distant-response model is used.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Method {
    /// Modal vibration (Eq. 9–13) only, even when the base has a transfer table.
    Modal,
    /// Spatial attenuation of a local amplitude (Eq. 14–16).
    Attenuation(AttenuationParams),
    /// The base's bake-time peak-transfer table when it has one (many modes, `modal-bake bake
    /// --transfer-h`), else [`Method::Modal`] (default). `d = Σ λ_N max(0, Σ_p Σ_q N_p N_q
    /// T[p][q])` with the P2 weights N over each triangle's vertices and edge midpoints (normal
    /// impulse component only; several impacts' peaks are summed, an upper bound). The modal
    /// method serves instead — reported in `ContactResponse::served_by`, counted with its
    /// reason in [`crate::response::StepInfo`] — when the base has no table, its h or Rayleigh damping
    /// differs (relative tolerance 1e-9) or `carry_over` is on without
    /// [`Launch::SustainedPeak`] (all decided at set-up, where
    /// [`TablePolicy::Refuse`] makes them errors instead), the step has forces, or an impact
    /// (whole step) or a contact (that contact) is outside the table's region. `sampling` and
    /// `variant` do not apply to table-served contacts (the table fixed its own sampling).
    ///
    /// Why it is the default: wherever a table exists it is both more accurate and cheaper than
    /// the modal query over the base's modes (measured in docs/accuracy.md, `scripts/accuracy.sh`,
    /// and docs/benchmarks.md), and a base without a table behaves exactly as
    /// [`Method::Modal`]. Tables are opt-in at bake time (minutes and megabytes per region).
    #[default]
    Transfer,
}

/// Parameters of a [`crate::DistantResponse`].
#[derive(Clone, Debug, PartialEq)]
pub struct ResponseParams {
    /// Rigid-body time step h (s). Default 0.01.
    pub h: f64,
    /// Filter period choice. Default [`Sampling::PaperT`].
    pub sampling: Sampling,
    /// Rayleigh damping [α0 (1/s), α1 (s)]; `None` (default) uses the base's.
    pub rayleigh: Option<[f64; 2]>,
    /// Impacts with impulse below this (N·s) are ignored (§4.5). Default 1e-3 N·s.
    pub impact_threshold: f64,
    /// Farthest a point may be from the surface and still be mapped (m). Default `NaN` =
    /// automatic: 5% of the base's bounding-box diagonal.
    pub max_map_distance: f64,
    /// Peak variant. Default [`Variant::PerContact`].
    pub variant: Variant,
    /// Response model. Default [`Method::Transfer`]: the base's transfer table when it has one
    /// that applies, else the modal method.
    pub method: Method,
    /// `false` (default): the filters restart from rest every step (§4.5). `true`: the state
    /// runs on across steps and the bank sleeps when its energy falls below
    /// `sleep_energy_rel` × the energy injected by the last impact.
    pub carry_over: bool,
    /// Relative sleep threshold for `carry_over`. Default 1e-12.
    pub sleep_energy_rel: f64,
    /// Cached resting contacts unseen for more than this many rigid-body steps are evicted
    /// (steps passed without a call count, see [`crate::DistantResponse::skip_steps`]).
    /// Default 120.
    pub evict_after_steps: u32,
    /// What [`Method::Transfer`] does when the base's table cannot serve. Default
    /// [`TablePolicy::FallBackToModal`].
    pub table_policy: TablePolicy,
    /// The lateral kick (paper §5.4): also report the peak tangential displacement at each
    /// contact as a tangential velocity change ([`crate::response::ContactResponse::lateral_delta_v`]),
    /// which [`crate::DcrWorld`] adds to the impulse. Computed from the modal base (3 mode rows
    /// per vertex) whichever method serves the normal part. Default `false`.
    pub lateral_kick: bool,
    /// How a resting contact's velocity change is formed. Default [`Launch::PeakOverStep`]
    /// (Eq. 12).
    pub launch: Launch,
}

/// What a [`Method::Transfer`] response does when the base's transfer table cannot serve it.
///
/// Whether the table applies to the whole run (the base has one, baked for this h and
/// Rayleigh damping, filters restarting every step) is known at set-up
/// ([`crate::DistantResponse::table_status`]); whether it serves a step is known per step (an
/// impact or resting contact outside the table's region, a force input). Per-step cases
/// always fall back to the modal method, counted in
/// [`crate::response::StepInfo::contacts_table_fallback`] with the reason in
/// [`crate::response::StepInfo::table_fallback`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TablePolicy {
    /// A table that does not apply to the run is not used: the modal method serves, and every
    /// resting contact of every step counts in `contacts_table_fallback` (reason
    /// [`crate::response::TableFallback::Unavailable`]). A base without any table is plain modal (not
    /// counted; [`crate::response::TableStatus::NoTable`]). Default.
    #[default]
    FallBackToModal,
    /// Set-up fails ([`ParamsError::TableRefused`], with the numbers) when the base has no
    /// table or its table does not apply to the run.
    Refuse,
}

impl Default for ResponseParams {
    fn default() -> Self {
        ResponseParams {
            h: 0.01,
            sampling: Sampling::PaperT,
            rayleigh: None,
            impact_threshold: 1e-3,
            max_map_distance: f64::NAN,
            variant: Variant::PerContact,
            method: Method::Transfer,
            carry_over: false,
            sleep_energy_rel: 1e-12,
            evict_after_steps: 120,
            table_policy: TablePolicy::FallBackToModal,
            lateral_kick: false,
            launch: Launch::PeakOverStep,
        }
    }
}

/// Invalid [`ResponseParams`] (reported by [`crate::DistantResponse::new`], never per step).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ParamsError {
    /// A parameter is out of range.
    #[error("invalid {field}: {detail}")]
    Invalid {
        /// Parameter name.
        field: &'static str,
        /// What is wrong.
        detail: String,
    },
    /// The sampling asks for more filter samples per step than supported (10⁶).
    #[error("{samples:.3e} filter samples per step (h/T) exceed the limit of 1e6: use a shorter step h or a longer filter period T")]
    TooManySamples {
        /// S = ⌈h/T⌉.
        samples: f64,
    },
    /// The heat-method operators could not be built for this surface.
    #[error("heat geodesics: {0}")]
    Geodesic(String),
    /// [`TablePolicy::Refuse`]: the base's transfer table does not apply to this response.
    #[error("transfer table refused: {status}")]
    TableRefused {
        /// Why (with the numbers).
        status: TableStatus,
    },
}

/// Whether a response's transfer table is in use, and if not, why
/// ([`crate::DistantResponse::table_status`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TableStatus {
    /// The table serves the steps (contacts and impacts inside its region).
    Active,
    /// The method is not [`Method::Transfer`].
    NotRequested,
    /// The base has no transfer table: the modal method serves.
    NoTable,
    /// The table was baked for another rigid-body step (relative tolerance 1e-9).
    StepMismatch {
        /// The table's h (s).
        table_h: f64,
        /// The response's h (s).
        h: f64,
    },
    /// The table was baked with other Rayleigh damping (relative tolerance 1e-9).
    DampingMismatch {
        /// The table's [α0 (1/s), α1 (s)].
        table: [f64; 2],
        /// The response's [α0, α1].
        response: [f64; 2],
    },
    /// `carry_over` is on without [`Launch::SustainedPeak`]: the table assumes filters at
    /// rest at every step's start.
    CarryOver,
}

impl std::fmt::Display for TableStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            TableStatus::Active => write!(f, "the table applies"),
            TableStatus::NotRequested => write!(f, "the method is not Transfer"),
            TableStatus::NoTable => write!(
                f,
                "the base has no transfer table (bake one with `modal-bake bake --transfer-h H`)"
            ),
            TableStatus::StepMismatch { table_h, h } => write!(
                f,
                "the table was baked for h = {table_h} s but the response steps h = {h} s \
                 (rebake with --transfer-h {h})"
            ),
            TableStatus::DampingMismatch { table, response } => write!(
                f,
                "the table was baked with Rayleigh damping [{}, {}] but the response uses \
                 [{}, {}]",
                table[0], table[1], response[0], response[1]
            ),
            TableStatus::CarryOver => write!(
                f,
                "carry_over is on without launch SustainedPeak, but the table assumes filters \
                 at rest at each step's start"
            ),
        }
    }
}
