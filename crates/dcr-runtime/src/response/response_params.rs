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
    /// impulse component only; several impacts' peaks are summed, an upper bound). Falls back
    /// to [`Method::Modal`] — per step, reported in `ContactResponse::served_by` — when the base
    /// has no table, its h or Rayleigh damping differs (relative tolerance 1e-9), `carry_over`
    /// is on, the step has forces, or an impact (whole step) or a contact (that contact) is
    /// outside the table's region. `sampling` and `variant` do not apply to table-served
    /// contacts (the table fixed its own sampling).
    ///
    /// Why it is the default (docs/accuracy.md, `scripts/accuracy.sh`): wherever a table
    /// exists it is both more accurate and cheaper than the 20-mode modal query — a 640-mode
    /// table on the paper's table: median / max error 0.9 / 9.6 % vs 16.2 / 69.0 % at 0.73× the
    /// query time — and a base without a table behaves exactly as [`Method::Modal`]. Tables are
    /// opt-in at bake time (minutes and megabytes per region).
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
    /// Cached resting contacts unseen for more than this many steps are evicted. Default 120.
    pub evict_after_steps: u32,
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
}
