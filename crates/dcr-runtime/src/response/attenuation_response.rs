//! [`AttenuationResponse`]: the spatial attenuation method (paper Eq. 14–16).
//!
//! Per applied impact c, the local displacement `Δx_c = q̂ᵀ h_c λ_N` with q̂ the local amplitude
//! (the §4.3 peak procedure for a unit normal impulse at the impacted point, seen at that point)
//! and λ_N the impulse's normal component; each resting contact p gets
//! `Δv_p = Σ_c s(r_cp) Δx_c / h` with the attenuation law s (Eq. 14 or the §4.5 simplification)
//! of the impact–contact distance r (heat-method geodesic, Crane et al. 2013: per-contact fields
//! cached, or read from an all-pairs vertex table; or Euclidean).

use super::impulse_table::ImpulseTable;
use super::step_ctx::{mapped_response, unmapped_response, StepCtx};
use super::{ForceInput, Impact, ParamsError, RestingContact, ServedBy, PREPARED_CONTACTS};
use crate::attenuation::{
    AmplitudeKind, AttenuationLaw, AttenuationParams, DistanceCache, DistanceKind, GeodesicTable,
    HeatWorkspace,
};
use crate::math::{dot, norm, normalize, sub};
use crate::model::{ModalModel, SurfacePoint};

/// The attenuation method's amplitudes, distance fields and per-step buffers.
#[derive(Debug)]
pub(crate) struct AttenuationResponse {
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

fn invalid(field: &'static str, detail: impl Into<String>) -> ParamsError {
    ParamsError::Invalid {
        field,
        detail: detail.into(),
    }
}

impl AttenuationResponse {
    /// The local amplitudes from the filters of `table`, the heat solver (for heat distances)
    /// and an empty field cache.
    ///
    /// # Errors
    /// [`ParamsError`] for an invalid law or amplitude subset, or a surface the heat method
    /// cannot factor.
    pub fn new(
        model: &ModalModel,
        a: &AttenuationParams,
        table: &ImpulseTable,
    ) -> Result<AttenuationResponse, ParamsError> {
        let finite_nonneg = |x: f64| x.is_finite() && x >= 0.0;
        match a.law {
            AttenuationLaw::Full { alpha, beta, r0 } => {
                if !(finite_nonneg(alpha) && finite_nonneg(beta) && r0.is_finite() && r0 > 0.0) {
                    return Err(invalid(
                        "attenuation law",
                        format!(
                            "α = {alpha} 1/m, β = {beta}, r0 = {r0} m (need α ≥ 0, β ≥ 0, r0 > 0, all finite)"
                        ),
                    ));
                }
            }
            AttenuationLaw::Simplified { c, beta } => {
                if !(finite_nonneg(c) && finite_nonneg(beta)) {
                    return Err(invalid(
                        "attenuation law",
                        format!("C = {c}, β = {beta} (need C ≥ 0 and β ≥ 0, both finite)"),
                    ));
                }
            }
        }
        let m = model.num_modes();
        let ns = model.num_vertices();
        let rows = model.normal_mode_rows();
        let (g_table, samples) = (&table.g_table, table.samples);
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
            DistanceKind::HeatTable => {
                let ns = model.num_vertices();
                if ns > GeodesicTable::MAX_VERTICES {
                    return Err(invalid(
                        "distance",
                        format!(
                            "HeatTable over {ns} surface vertices would take {:.0} MiB (ns² × 4 \
                             bytes); the limit is {} vertices: use DistanceKind::Heat",
                            (ns * ns * 4) as f64 / (1 << 20) as f64,
                            GeodesicTable::MAX_VERTICES
                        ),
                    ));
                }
                model
                    .geodesic_table()
                    .map_err(|e| ParamsError::Geodesic(e.to_string()))?;
                None
            }
            DistanceKind::Euclidean => None,
        };
        let capacity = if a.distance == DistanceKind::Heat {
            a.cache_capacity
        } else {
            1
        };
        Ok(AttenuationResponse {
            params: a.clone(),
            amplitude,
            mean,
            fields: DistanceCache::new(ns, capacity),
            ws,
            hits: Vec::with_capacity(PREPARED_CONTACTS),
            hit_fields: Vec::new(),
        })
    }

    /// Local amplitudes q̂_v (m per N·s of normal impulse) per surface vertex.
    pub fn amplitudes(&self) -> &[f64] {
        &self.amplitude
    }

    /// Drops the cached distance field of contact-cache slot `slot` (evicted or re-mapped).
    pub fn invalidate(&mut self, slot: u32) {
        self.fields.invalidate(slot);
    }

    /// One step of the attenuation method: fills `ctx.out` with one response per resting
    /// contact. Forces are ignored (counted in `forces_ignored`).
    pub fn step(
        &mut self,
        ctx: &mut StepCtx<'_>,
        impacts: &[Impact],
        forces: &[ForceInput],
        resting: &[RestingContact],
    ) {
        let model = ctx.model;
        let step = ctx.step;
        let h = ctx.params.h;
        ctx.info.forces_ignored += forces.iter().filter(|f| f.force != [0.0; 3]).count() as u32;
        let mut hits = std::mem::take(&mut self.hits);
        hits.clear();
        for imp in impacts {
            if !ctx.accept(imp.impulse) {
                continue;
            }
            let Some(sp) = model.project(imp.point, ctx.max_map) else {
                ctx.info.impacts_unmapped += 1;
                continue;
            };
            // λ_N: the impulse's component along the surface normal (q̂ is per unit normal impulse).
            let lambda_n = imp.impulse * dot(normalize(imp.direction), sp.normal).abs();
            let amp = match self.params.amplitude {
                AmplitudeKind::PerVertex => model.interpolate(&self.amplitude, &sp),
                _ => self.mean,
            };
            hits.push((sp, amp * lambda_n));
            ctx.info.impacts_applied += 1;
        }
        let law = self.params.law;
        let distance = self.params.distance;
        let contacts = ctx.contacts;
        let slots = contacts.slots();
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
                .zip(slots)
                .filter(|&(_, &s)| contacts.slot(s).surface.is_some() && !self.fields.contains(s))
                .count();
            let solves = if self.fields.caches() { 2 } else { 1 } * hits.len();
            if uncached > solves {
                budget = if self.fields.caches() { hits.len() } else { 0 };
                let heat = model.heat_geodesic().expect("checked at set-up");
                let ws = self.ws.as_mut().expect("heat workspace");
                let ns = model.num_vertices();
                self.hit_fields.resize(hits.len() * ns, 0.0);
                for ((hp, _), field) in hits.iter().zip(self.hit_fields.chunks_exact_mut(ns)) {
                    heat.distances_from_point_with(hp, field, ws);
                }
                ctx.info.distance_fields_computed += hits.len() as u32;
            }
        }
        ctx.out.clear();
        for (rc, &s) in resting.iter().zip(slots) {
            let Some(sp) = contacts.slot(s).surface else {
                ctx.out.push(unmapped_response(rc));
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
                    DistanceKind::HeatTable => {
                        let table = model.geodesic_table().expect("built at set-up");
                        let tri = model.triangle(sp.triangle);
                        for (hp, dx) in &hits {
                            let r = table.distance(&sp, tri, hp, model.triangle(hp.triangle));
                            total += law.factor(r) * dx;
                        }
                    }
                    DistanceKind::Heat if budget == 0 && !self.fields.contains(s) => {
                        // Served from the impacts' fields, read at the contact.
                        let ns = model.num_vertices();
                        for ((_, dx), field) in hits.iter().zip(self.hit_fields.chunks_exact(ns)) {
                            total += law.factor(model.interpolate(field, &sp)) * dx;
                        }
                    }
                    DistanceKind::Heat => {
                        let heat = model.heat_geodesic().expect("checked at set-up");
                        let ws = self.ws.as_mut().expect("heat workspace");
                        let before = self.fields.computed;
                        let field = self
                            .fields
                            .get(s, step, |out| heat.distances_from_point_with(&sp, out, ws));
                        for (hp, dx) in &hits {
                            total += law.factor(model.interpolate(field, hp)) * dx;
                        }
                        let computed = (self.fields.computed - before) as usize;
                        budget = budget.saturating_sub(computed);
                        ctx.info.distance_fields_computed += computed as u32;
                    }
                }
            }
            ctx.out
                .push(mapped_response(rc, &sp, total, h, ServedBy::Attenuation));
        }
        self.hits = hits;
    }
}
