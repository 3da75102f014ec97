//! [`DcrResponseParams`] (with [`DcrAttenuationParams`]) and their enumeration codes.
//!
//! Enumerations that the caller writes are plain `uint32_t` codes (`DCR_METHOD_*`, …), so that
//! an unknown value is an error the library reports, never undefined behaviour.

use dcr_runtime::response::{
    AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceKind, Sampling, TablePolicy, Variant,
};
use dcr_runtime::{Launch, Method, ResponseParams};

use crate::guard::guard;
use crate::ptr::{arg_slice, check_struct_size, write_out};
use crate::status::{DcrStatus, Failure};

/// Response model (`DcrResponseParams.method`): one of `DCR_METHOD_*`.
pub type DcrMethod = u32;
/// Modal vibration (Eq. 9–13) only, even when the base has a transfer table.
pub const DCR_METHOD_MODAL: DcrMethod = 0;
/// Spatial attenuation of a local amplitude (Eq. 14–16), set by
/// `DcrResponseParams.attenuation`.
pub const DCR_METHOD_ATTENUATION: DcrMethod = 1;
/// The base's bake-time peak-transfer table where it applies, else modal (default); what
/// served each contact is reported in `DcrContactResponse.served_by`.
pub const DCR_METHOD_TRANSFER: DcrMethod = 2;

/// Filter sampling period choice (`DcrResponseParams.sampling`): one of `DCR_SAMPLING_*`.
pub type DcrSampling = u32;
/// The paper's T = π / (2 ω_max), four samples per period of the highest mode (default).
pub const DCR_SAMPLING_PAPER_T: DcrSampling = 0;
/// T = π / (2 ω_max) / K with K = `sampling_value` ≥ 1 (finer peak search).
pub const DCR_SAMPLING_OVERSAMPLE: DcrSampling = 1;
/// T = `sampling_value` (s).
pub const DCR_SAMPLING_SUBSTEP: DcrSampling = 2;

/// Peak variant (`DcrResponseParams.variant`): one of `DCR_VARIANT_*`.
pub type DcrVariant = u32;
/// The peak of the contact's own interpolated mode row (default).
pub const DCR_VARIANT_PER_CONTACT: DcrVariant = 0;
/// Eq. 13: per-vertex peaks blended with the barycentric weights.
pub const DCR_VARIANT_PER_NODE: DcrVariant = 1;

/// How a resting contact's velocity change is formed (`DcrResponseParams.launch`): one of
/// `DCR_LAUNCH_*`.
pub type DcrLaunch = u32;
/// The paper's rule (Eq. 12): Δv = d/h added to the body on steps with impacts (default).
pub const DCR_LAUNCH_PEAK_OVER_STEP: DcrLaunch = 0;
/// d/h of the carried-over filters on every step the object rings, as a target for the
/// touching body's normal velocity (needs `carry_over`; not with `DCR_METHOD_ATTENUATION`).
pub const DCR_LAUNCH_SUSTAINED_PEAK: DcrLaunch = 1;

/// What `DCR_METHOD_TRANSFER` does when the base's table cannot serve the run
/// (`DcrResponseParams.table_policy`): one of `DCR_TABLE_POLICY_*`.
pub type DcrTablePolicy = u32;
/// Serve with the modal method and count the contacts in
/// `DcrStepInfo.contacts_table_fallback` (default).
pub const DCR_TABLE_POLICY_FALL_BACK_TO_MODAL: DcrTablePolicy = 0;
/// `dcr_response_create` / `dcr_world_add_object` fail (`DCR_STATUS_INVALID_ARGUMENT`, the
/// message says why) when the base has no table or it does not apply (another h or damping).
pub const DCR_TABLE_POLICY_REFUSE: DcrTablePolicy = 1;

/// Attenuation law s(r) (`DcrAttenuationParams.law`): one of `DCR_ATTENUATION_LAW_*`.
pub type DcrAttenuationLaw = u32;
/// Eq. 14: s = exp(−α (r − r0)) (r / r0)^−β, with `alpha` (1/m), `beta`, `r0` (m).
pub const DCR_ATTENUATION_LAW_FULL: DcrAttenuationLaw = 0;
/// §4.5: s = C r^−β with r in m (r0 = 1 m), with `c` and `beta` (default, C = 1, β = 1).
pub const DCR_ATTENUATION_LAW_SIMPLIFIED: DcrAttenuationLaw = 1;

/// How the impact-to-contact distance is measured (`DcrAttenuationParams.distance`).
pub type DcrDistanceKind = u32;
/// Heat-method geodesic distance on the surface (m), cached per contact (default).
pub const DCR_DISTANCE_HEAT: DcrDistanceKind = 0;
/// Straight-line distance between the mapped surface points (m).
pub const DCR_DISTANCE_EUCLIDEAN: DcrDistanceKind = 1;
/// Heat-method geodesic distances between all surface vertices, computed once per model at
/// set-up (4 bytes per vertex pair, shared by the model's instances) and read bilinearly per
/// step: no solve per step. For surfaces up to the runtime's table size limit.
pub const DCR_DISTANCE_HEAT_TABLE: DcrDistanceKind = 2;

/// Where the local amplitude comes from (`DcrAttenuationParams.amplitude`).
pub type DcrAmplitudeKind = u32;
/// The impacted vertices' own amplitudes, interpolated at the impact (Eq. 15; default).
pub const DCR_AMPLITUDE_PER_VERTEX: DcrAmplitudeKind = 0;
/// The mean amplitude over all surface vertices.
pub const DCR_AMPLITUDE_MEAN: DcrAmplitudeKind = 1;
/// The mean amplitude over the surface vertices listed in `amplitude_vertices`.
pub const DCR_AMPLITUDE_MEAN_OVER: DcrAmplitudeKind = 2;

/// Parameters of `DCR_METHOD_ATTENUATION` (paper Eq. 14–16). Ignored by the other methods.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcrAttenuationParams {
    /// s(r) law, `DCR_ATTENUATION_LAW_*`. Default `DCR_ATTENUATION_LAW_SIMPLIFIED`.
    pub law: DcrAttenuationLaw,
    /// Material absorption α (1/m, ≥ 0) of the full law. Default 0.
    pub alpha: f64,
    /// Spreading exponent β (≥ 0; ≈ 0 rods, 0.5 shells, 1 volumes), both laws. Default 1.
    pub beta: f64,
    /// Minimum distance r0 (m, > 0) of the full law. Default 1.
    pub r0: f64,
    /// Constant C (≥ 0) of the simplified law. Default 1.
    pub c: f64,
    /// Distance measure, `DCR_DISTANCE_*`. Default `DCR_DISTANCE_HEAT`.
    pub distance: DcrDistanceKind,
    /// Local amplitude source, `DCR_AMPLITUDE_*`. Default `DCR_AMPLITUDE_PER_VERTEX`.
    pub amplitude: DcrAmplitudeKind,
    /// Surface vertex indices for `DCR_AMPLITUDE_MEAN_OVER` (copied at set-up; may be NULL
    /// otherwise). Default NULL.
    pub amplitude_vertices: *const u32,
    /// Number of entries of `amplitude_vertices`. Default 0.
    pub num_amplitude_vertices: usize,
    /// Most heat-method distance fields kept (one per resting contact, least recently used
    /// evicted; 8 bytes per surface vertex each). Default 64.
    pub cache_capacity: usize,
    /// Solve new heat-method fields on two threads where that pays (bit-identical results).
    /// Default false.
    pub parallel_heat: bool,
}

/// Parameters of a per-object response (`dcr_response_create`, and
/// `DcrElasticObjectDesc.response`). Fill with `dcr_response_params_default`, then change
/// fields; `struct_size` must stay `sizeof(DcrResponseParams)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcrResponseParams {
    /// `sizeof(DcrResponseParams)`, set by `dcr_response_params_default`; another value is
    /// `DCR_STATUS_INVALID_ARGUMENT` (a header from another version, or an unfilled struct).
    pub struct_size: u32,
    /// Rigid-body time step h (s, > 0). Default 0.01. Replaced by `DcrWorldParams.h` in a
    /// world.
    pub h: f64,
    /// Filter period choice, `DCR_SAMPLING_*`. Default `DCR_SAMPLING_PAPER_T`.
    pub sampling: DcrSampling,
    /// K (≥ 1) for `DCR_SAMPLING_OVERSAMPLE`, T (s, > 0) for `DCR_SAMPLING_SUBSTEP`; ignored
    /// for `DCR_SAMPLING_PAPER_T`. Default 1.
    pub sampling_value: f64,
    /// true: use `rayleigh` instead of the base's damping. Default false.
    pub override_rayleigh: bool,
    /// Rayleigh damping α0 (1/s, ≥ 0), α1 (s, ≥ 0) when `override_rayleigh`. Default the
    /// base's values are used (this field is then ignored; default 0, 0).
    pub rayleigh: [f64; 2],
    /// Impacts with a normal impulse below this (N·s, ≥ 0) are ignored (§4.5); in a world, also
    /// the impact classification threshold. Default 1e-3 N·s.
    pub impact_threshold: f64,
    /// Farthest a contact may be from the surface and still be mapped (m, ≥ 0). NaN (default):
    /// 5% of the base's bounding-box diagonal.
    pub max_map_distance: f64,
    /// Peak variant, `DCR_VARIANT_*`. Default `DCR_VARIANT_PER_CONTACT`.
    pub variant: DcrVariant,
    /// Response model, `DCR_METHOD_*`. Default `DCR_METHOD_TRANSFER`.
    pub method: DcrMethod,
    /// Parameters of `DCR_METHOD_ATTENUATION`.
    pub attenuation: DcrAttenuationParams,
    /// false (default): the filters restart from rest every step (§4.5). true: the modal state
    /// runs on across steps and sleeps once its energy falls below `sleep_energy_rel` × the
    /// energy the last impact injected.
    pub carry_over: bool,
    /// Relative sleep threshold for `carry_over` (≥ 0). Default 1e-12.
    pub sleep_energy_rel: f64,
    /// Cached resting contacts unseen for more than this many rigid-body steps are evicted.
    /// Default 120.
    pub evict_after_steps: u32,
    /// What `DCR_METHOD_TRANSFER` does when the table cannot serve, `DCR_TABLE_POLICY_*`.
    /// Default `DCR_TABLE_POLICY_FALL_BACK_TO_MODAL`.
    pub table_policy: DcrTablePolicy,
    /// Also report the peak tangential displacement as a tangential velocity change
    /// (`DcrContactResponse.lateral_delta_v`; the paper's lateral kick, §5.4). Default false.
    pub lateral_kick: bool,
    /// How a resting contact's velocity change is formed, `DCR_LAUNCH_*`. Default
    /// `DCR_LAUNCH_PEAK_OVER_STEP`.
    pub launch: DcrLaunch,
}

impl DcrResponseParams {
    /// The documented defaults (those of the Rust `ResponseParams::default`).
    pub fn defaults() -> DcrResponseParams {
        let r = ResponseParams::default();
        let a = AttenuationParams::default();
        let (law, alpha, beta, r0, c) = match a.law {
            AttenuationLaw::Full { alpha, beta, r0 } => {
                (DCR_ATTENUATION_LAW_FULL, alpha, beta, r0, 1.0)
            }
            AttenuationLaw::Simplified { c, beta } => {
                (DCR_ATTENUATION_LAW_SIMPLIFIED, 0.0, beta, 1.0, c)
            }
        };
        DcrResponseParams {
            struct_size: std::mem::size_of::<DcrResponseParams>() as u32,
            h: r.h,
            sampling: DCR_SAMPLING_PAPER_T,
            sampling_value: 1.0,
            override_rayleigh: false,
            rayleigh: [0.0; 2],
            impact_threshold: r.impact_threshold,
            max_map_distance: r.max_map_distance,
            variant: DCR_VARIANT_PER_CONTACT,
            method: DCR_METHOD_TRANSFER,
            attenuation: DcrAttenuationParams {
                law,
                alpha,
                beta,
                r0,
                c,
                distance: DCR_DISTANCE_HEAT,
                amplitude: DCR_AMPLITUDE_PER_VERTEX,
                amplitude_vertices: std::ptr::null(),
                num_amplitude_vertices: 0,
                cache_capacity: a.cache_capacity,
                parallel_heat: a.parallel_heat,
            },
            carry_over: r.carry_over,
            sleep_energy_rel: r.sleep_energy_rel,
            evict_after_steps: r.evict_after_steps,
            table_policy: DCR_TABLE_POLICY_FALL_BACK_TO_MODAL,
            lateral_kick: r.lateral_kick,
            launch: DCR_LAUNCH_PEAK_OVER_STEP,
        }
    }

    /// The runtime's parameters. Ranges are checked by the runtime at set-up; this checks the
    /// struct size and the enumeration codes, and copies `amplitude_vertices`.
    ///
    /// # Safety
    /// `attenuation.amplitude_vertices` must point to `num_amplitude_vertices` readable `u32`
    /// when the amplitude is `DCR_AMPLITUDE_MEAN_OVER` and the method attenuation.
    pub(crate) unsafe fn runtime_params(&self, name: &str) -> Result<ResponseParams, Failure> {
        check_struct_size::<DcrResponseParams>(self.struct_size, name, "DcrResponseParams")?;
        let bad = |field: &str, code: u32| {
            Failure::invalid(format!("`{name}.{field}` = {code} is not a known code"))
        };
        let sampling = match self.sampling {
            DCR_SAMPLING_PAPER_T => Sampling::PaperT,
            DCR_SAMPLING_OVERSAMPLE => Sampling::Oversample(self.sampling_value),
            DCR_SAMPLING_SUBSTEP => Sampling::Substep(self.sampling_value),
            c => return Err(bad("sampling", c)),
        };
        let variant = match self.variant {
            DCR_VARIANT_PER_CONTACT => Variant::PerContact,
            DCR_VARIANT_PER_NODE => Variant::PerNode,
            c => return Err(bad("variant", c)),
        };
        let launch = match self.launch {
            DCR_LAUNCH_PEAK_OVER_STEP => Launch::PeakOverStep,
            DCR_LAUNCH_SUSTAINED_PEAK => Launch::SustainedPeak,
            c => return Err(bad("launch", c)),
        };
        let table_policy = match self.table_policy {
            DCR_TABLE_POLICY_FALL_BACK_TO_MODAL => TablePolicy::FallBackToModal,
            DCR_TABLE_POLICY_REFUSE => TablePolicy::Refuse,
            c => return Err(bad("table_policy", c)),
        };
        let method = match self.method {
            DCR_METHOD_MODAL => Method::Modal,
            DCR_METHOD_TRANSFER => Method::Transfer,
            DCR_METHOD_ATTENUATION => {
                let a = &self.attenuation;
                let law = match a.law {
                    DCR_ATTENUATION_LAW_FULL => AttenuationLaw::Full {
                        alpha: a.alpha,
                        beta: a.beta,
                        r0: a.r0,
                    },
                    DCR_ATTENUATION_LAW_SIMPLIFIED => AttenuationLaw::Simplified {
                        c: a.c,
                        beta: a.beta,
                    },
                    c => return Err(bad("attenuation.law", c)),
                };
                let distance = match a.distance {
                    DCR_DISTANCE_HEAT => DistanceKind::Heat,
                    DCR_DISTANCE_EUCLIDEAN => DistanceKind::Euclidean,
                    DCR_DISTANCE_HEAT_TABLE => DistanceKind::HeatTable,
                    c => return Err(bad("attenuation.distance", c)),
                };
                let amplitude = match a.amplitude {
                    DCR_AMPLITUDE_PER_VERTEX => AmplitudeKind::PerVertex,
                    DCR_AMPLITUDE_MEAN => AmplitudeKind::Mean,
                    DCR_AMPLITUDE_MEAN_OVER => {
                        // SAFETY: forwarded caller contract (documented on the field).
                        let v = unsafe {
                            arg_slice(
                                a.amplitude_vertices,
                                a.num_amplitude_vertices,
                                &format!("{name}.attenuation.amplitude_vertices"),
                            )?
                        };
                        AmplitudeKind::MeanOver(v.to_vec())
                    }
                    c => return Err(bad("attenuation.amplitude", c)),
                };
                Method::Attenuation(AttenuationParams {
                    law,
                    distance,
                    amplitude,
                    cache_capacity: a.cache_capacity,
                    parallel_heat: a.parallel_heat,
                })
            }
            c => return Err(bad("method", c)),
        };
        Ok(ResponseParams {
            h: self.h,
            sampling,
            rayleigh: self.override_rayleigh.then_some(self.rayleigh),
            impact_threshold: self.impact_threshold,
            max_map_distance: self.max_map_distance,
            variant,
            method,
            carry_over: self.carry_over,
            sleep_energy_rel: self.sleep_energy_rel,
            evict_after_steps: self.evict_after_steps,
            table_policy,
            lateral_kick: self.lateral_kick,
            launch,
        })
    }
}

/// Fills `out` with the documented defaults of every field (and `struct_size`).
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` when `out` is NULL.
///
/// # Safety
/// `out` must be NULL or valid for a write of a `DcrResponseParams`.
#[no_mangle]
pub unsafe extern "C" fn dcr_response_params_default(out: *mut DcrResponseParams) -> DcrStatus {
    guard("dcr_response_params_default", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, DcrResponseParams::defaults(), "out") }
    })
}
