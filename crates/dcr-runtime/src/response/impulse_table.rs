//! [`ImpulseTable`]: the per-step sampling of the mode filters and their impulse responses
//! g_j(kT), k = 1..S (Eq. 10), shared by the methods' set-ups.

use super::{ParamsError, ResponseParams};
use crate::filter::{damping_ratio, samples_per_step, ModalBank, Sampling};
use crate::model::ModalModel;

/// Largest number of filter samples per step accepted.
const MAX_SAMPLES: f64 = 1e6;

/// The filters of one response and their sampled impulse responses.
#[derive(Debug)]
pub(crate) struct ImpulseTable {
    /// Samples per step S = ⌈h/T⌉.
    pub samples: usize,
    /// T_eff = h/S (s).
    pub period: f64,
    /// The filter bank at rest.
    pub bank: ModalBank,
    /// g_j(kT), row-major S × m (m per unit reduced impulse).
    pub g_table: Vec<f64>,
}

impl ImpulseTable {
    /// The filters for `p.h` and `p.sampling` with Rayleigh damping `rayleigh`.
    ///
    /// # Errors
    /// [`ParamsError`] for an oversampling factor below 1 or not finite, a sampling that gives a
    /// non-positive or non-finite period, or more than 10⁶ samples per step.
    pub fn new(
        model: &ModalModel,
        p: &ResponseParams,
        rayleigh: [f64; 2],
    ) -> Result<ImpulseTable, ParamsError> {
        let omega = model.omega();
        let m = omega.len();
        let omega_max = omega[m - 1];
        if let Sampling::Oversample(k) = p.sampling {
            if !(k >= 1.0 && k.is_finite()) {
                return Err(ParamsError::Invalid {
                    field: "sampling",
                    detail: format!("oversampling factor K = {k} (must be finite and ≥ 1)"),
                });
            }
        }
        let t_req = p.sampling.period(omega_max);
        if !(t_req.is_finite() && t_req > 0.0) {
            return Err(ParamsError::Invalid {
                field: "sampling",
                detail: match p.sampling {
                    Sampling::PaperT => format!("the paper's T gives T = {t_req} s"),
                    Sampling::Oversample(k) => {
                        format!("oversampling K = {k} gives T = {t_req} s (need K ≥ 1, finite)")
                    }
                    Sampling::Substep(t) => format!("sub-step T = {t} s (need 0 < T ≤ h, finite)"),
                },
            });
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
        Ok(ImpulseTable {
            samples,
            period,
            bank,
            g_table,
        })
    }
}
