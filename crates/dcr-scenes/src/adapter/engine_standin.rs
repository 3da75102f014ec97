//! Minimal stand-in for `dcr_runtime`'s response API (same types and signatures as the
//! contract), used only until the runtime's own `DistantResponse` lands. Modal response:
//! paper Eq. 9–13 with a bank restarted every step; attenuation: Euclidean distance,
//! amplitude from the self-response at the impact point, s = C r^−β (r ≥ 0.1 m).

use std::sync::Arc;

pub use dcr_runtime::filter::Sampling;
use dcr_runtime::filter::{damping_ratio, samples_per_step, ModalBank};
pub use dcr_runtime::model::{LoadError, ModalModel};

/// An impact on the elastic object (object frame).
#[derive(Clone, Copy, Debug)]
pub struct Impact {
    /// Point (m, object frame).
    pub point: [f64; 3],
    /// Unit direction the impulse acts on the object.
    pub direction: [f64; 3],
    /// Impulse (N·s).
    pub impulse: f64,
}

/// A resting contact (object frame).
#[derive(Clone, Copy, Debug)]
pub struct RestingContact {
    /// Caller's id.
    pub id: u64,
    /// Point (m, object frame).
    pub point: [f64; 3],
}

/// The response at one resting contact.
#[derive(Clone, Copy, Debug)]
pub struct ContactResponse {
    /// Caller's id.
    pub id: u64,
    /// Mapped point (object frame).
    pub point: [f64; 3],
    /// Outward normal (object frame).
    pub normal: [f64; 3],
    /// Peak normal displacement (m).
    pub peak_displacement: f64,
    /// Δv (m/s).
    pub delta_v: f64,
    /// Was the point mapped onto the surface?
    pub mapped: bool,
}

/// Per-contact or per-node response.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Variant {
    /// Per contact.
    #[default]
    PerContact,
    /// Per node.
    PerNode,
}

/// Attenuation law.
#[derive(Clone, Copy, Debug)]
pub enum AttenuationLaw {
    /// Eq. 14.
    Full {
        /// α.
        alpha: f64,
        /// β.
        beta: f64,
        /// r0.
        r0: f64,
    },
    /// s = C r^−β.
    Simplified {
        /// C.
        c: f64,
        /// β.
        beta: f64,
    },
}

/// Distance kind.
#[derive(Clone, Copy, Debug)]
pub enum DistanceKind {
    /// Heat geodesics.
    Heat,
    /// Euclidean.
    Euclidean,
}

/// Amplitude kind.
#[derive(Clone, Debug)]
pub enum AmplitudeKind {
    /// Per vertex.
    PerVertex,
    /// Mean over all.
    Mean,
    /// Mean over these surface vertices.
    MeanOver(Vec<u32>),
}

/// Attenuation parameters.
#[derive(Clone, Debug)]
pub struct AttenuationParams {
    /// Law.
    pub law: AttenuationLaw,
    /// Distance.
    pub distance: DistanceKind,
    /// Amplitude.
    pub amplitude: AmplitudeKind,
    /// Cache capacity.
    pub cache_capacity: usize,
}

impl Default for AttenuationParams {
    fn default() -> Self {
        AttenuationParams {
            law: AttenuationLaw::Simplified { c: 1.0, beta: 1.0 },
            distance: DistanceKind::Heat,
            amplitude: AmplitudeKind::PerVertex,
            cache_capacity: 256,
        }
    }
}

/// Method.
#[derive(Clone, Debug, Default)]
pub enum Method {
    /// Modal.
    #[default]
    Modal,
    /// Attenuation.
    Attenuation(AttenuationParams),
}

/// Response parameters.
#[derive(Clone, Debug)]
pub struct ResponseParams {
    /// h (s).
    pub h: f64,
    /// Sampling.
    pub sampling: Sampling,
    /// Rayleigh override.
    pub rayleigh: Option<[f64; 2]>,
    /// Threshold (N·s).
    pub impact_threshold: f64,
    /// Max map distance (m).
    pub max_map_distance: f64,
    /// Variant.
    pub variant: Variant,
    /// Method.
    pub method: Method,
    /// Carry-over.
    pub carry_over: bool,
}

impl Default for ResponseParams {
    fn default() -> Self {
        ResponseParams {
            h: 0.01,
            sampling: Sampling::PaperT,
            rayleigh: None,
            impact_threshold: 0.0,
            max_map_distance: 0.05,
            variant: Variant::PerContact,
            method: Method::Modal,
            carry_over: false,
        }
    }
}

/// The stand-in response.
pub struct DistantResponse {
    model: Arc<ModalModel>,
    params: ResponseParams,
    bank: ModalBank,
    t: f64,
    samples: usize,
    table: Vec<f64>,
    r: Vec<f64>,
    w: Vec<f64>,
    out: Vec<ContactResponse>,
}

impl DistantResponse {
    /// New response over `model`.
    pub fn new(model: Arc<ModalModel>, params: ResponseParams) -> DistantResponse {
        let omega = model.omega().to_vec();
        let ray = params.rayleigh.unwrap_or(model.base().rayleigh);
        let xi: Vec<f64> = omega.iter().map(|&w| damping_ratio(w, ray)).collect();
        let wmax = omega.iter().copied().fold(0.0, f64::max);
        let samples = samples_per_step(params.h, params.sampling.period(wmax));
        let t = params.h / samples as f64;
        let m = omega.len();
        DistantResponse {
            bank: ModalBank::new(&omega, &xi, t),
            model,
            params,
            t,
            samples,
            table: vec![0.0; samples * m],
            r: vec![0.0; m],
            w: vec![0.0; m],
            out: Vec::new(),
        }
    }

    /// T (s).
    pub fn substep(&self) -> f64 {
        self.t
    }

    /// h/T.
    pub fn samples_per_step(&self) -> usize {
        self.samples
    }

    fn peak(&self, w: &[f64]) -> f64 {
        let m = w.len();
        self.table.chunks_exact(m).map(|q| q.iter().zip(w).map(|(a, b)| a * b).sum::<f64>().abs()).fold(0.0, f64::max)
    }

    /// One step.
    pub fn step(&mut self, impacts: &[Impact], resting: &[RestingContact]) -> &[ContactResponse] {
        self.out.clear();
        let h = self.params.h;
        let maxd = self.params.max_map_distance;
        let model = self.model.clone();
        let impacts: Vec<&Impact> = impacts.iter().filter(|i| i.impulse >= self.params.impact_threshold).collect();
        if impacts.is_empty() {
            return &self.out;
        }
        match self.params.method.clone() {
            Method::Modal => {
                self.bank.reset();
                self.r.iter_mut().for_each(|x| *x = 0.0);
                for imp in &impacts {
                    if let Some(sp) = model.project(imp.point, maxd) {
                        model.add_reduced_impulse(&sp, imp.direction, imp.impulse, &mut self.r);
                    }
                }
                self.bank.apply_impulse(&self.r);
                self.bank.run(self.samples, None, &mut self.table);
                for c in resting {
                    let Some(sp) = model.project(c.point, maxd) else {
                        self.out.push(ContactResponse { id: c.id, point: c.point, normal: [0.0; 3], peak_displacement: 0.0, delta_v: 0.0, mapped: false });
                        continue;
                    };
                    let mut w = std::mem::take(&mut self.w);
                    model.contact_row(&sp, &mut w);
                    let d = self.peak(&w);
                    self.w = w;
                    self.out.push(ContactResponse { id: c.id, point: sp.point, normal: sp.normal, peak_displacement: d, delta_v: d / h, mapped: true });
                }
            }
            Method::Attenuation(ap) => {
                let (c0, beta) = match ap.law {
                    AttenuationLaw::Simplified { c, beta } => (c, beta),
                    AttenuationLaw::Full { beta, .. } => (1.0, beta),
                };
                let mut sources = Vec::new();
                for imp in &impacts {
                    if let Some(sp) = model.project(imp.point, maxd) {
                        self.bank.reset();
                        self.r.iter_mut().for_each(|x| *x = 0.0);
                        model.add_reduced_impulse(&sp, sp.normal, 1.0, &mut self.r);
                        self.bank.apply_impulse(&self.r);
                        self.bank.run(self.samples, None, &mut self.table);
                        let mut w = std::mem::take(&mut self.w);
                        model.contact_row(&sp, &mut w);
                        let amp = self.peak(&w) * imp.impulse;
                        self.w = w;
                        sources.push((sp.point, amp));
                    }
                }
                for c in resting {
                    let Some(sp) = model.project(c.point, maxd) else { continue };
                    let mut dx: f64 = 0.0;
                    for (p, amp) in &sources {
                        let r = ((p[0] - sp.point[0]).powi(2) + (p[1] - sp.point[1]).powi(2) + (p[2] - sp.point[2]).powi(2)).sqrt().max(0.1);
                        dx += c0 * r.powf(-beta) * amp;
                    }
                    self.out.push(ContactResponse { id: c.id, point: sp.point, normal: sp.normal, peak_displacement: dx, delta_v: dx / h, mapped: true });
                }
            }
        }
        &self.out
    }
}

/// Eq. 17.
pub fn effective_mass(inv_mass: f64, inv_inertia_world: [[f64; 3]; 3], r: [f64; 3], n: [f64; 3]) -> f64 {
    let rn = [r[1] * n[2] - r[2] * n[1], r[2] * n[0] - r[0] * n[2], r[0] * n[1] - r[1] * n[0]];
    let mut k = inv_mass;
    for i in 0..3 {
        for j in 0..3 {
            k += rn[i] * inv_inertia_world[i][j] * rn[j];
        }
    }
    if k > 0.0 { 1.0 / k } else { 0.0 }
}

/// Eq. 18.
pub fn response_impulse(m_eff: f64, delta_v: f64, n: [f64; 3]) -> [f64; 3] {
    [m_eff * delta_v * n[0], m_eff * delta_v * n[1], m_eff * delta_v * n[2]]
}
