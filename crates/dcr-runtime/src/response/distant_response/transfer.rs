//! The transfer-table method ([`crate::Method::Transfer`]): the step's distant peaks looked up in
//! the base's bake-time peak-transfer table ([`crate::format::TransferTable`]) instead of
//! filtering the truncated modal base.
//!
//! The table's points are the region's vertices and its edge midpoints
//! ([`crate::format::TransferTable`]). A mapped point with barycentric weights β in triangle
//! (v₀, v₁, v₂) is spread over the triangle's six P2 nodes with the quadratic Lagrange weights
//! `N_k = β_k(2β_k − 1)` at vertex k and `N_jk = 4β_jβ_k` at the midpoint of edge (j, k); the
//! peak normal displacement at a resting contact is
//! `d = Σ_impacts λ_N max(0, Σ_p Σ_q N_p(β_impact) N_q(β_contact) T[p][q])`, where
//! λ_N = λ·|d̂·n| is the normal component of the impulse (N·s; the tangential part is ignored).
//! T is the peak for a unit inward-normal impulse at one table point seen at another, computed
//! at bake time with many modes. The weights sum to 1 and reproduce T exactly at the nodes.
//!
//! Why quadratic: the exact peak is a convex function of β on each side (a maximum of absolute
//! values of linear functions), so the linear blend of vertex peaks overestimates inside
//! triangles where the vertex responses are out of phase (by up to +214 % on the ground slab);
//! the P2 interpolant, which also sees the midpoints, is measured in `docs/accuracy.md`. It may
//! undershoot, hence the clamp at 0. A table without midpoints (written before they existed)
//! is blended linearly, as is any triangle one of whose needed midpoints is missing. With
//! several impacts in one step their peaks are summed, an upper bound of the peak of the summed
//! response.
//!
//! The table serves a step only when it applies: the base has a table whose `h` equals the
//! step's (relative tolerance 1e-9) and whose Rayleigh damping equals the response's, the
//! filters restart every step (`carry_over = false`), the step has no force input, and every
//! applied impact lies on a triangle whose three vertices are in the table's region (a corner
//! outside with a barycentric weight ≤ 1e-9 is ignored). A contact whose triangle is not
//! entirely in the region is served by the modal method (the whole modal
//! step is then run and the in-region contacts are overwritten with the table's values).

use std::sync::Arc;

use super::{mapped_response, unmapped_response, DistantResponse, UNMAPPED};
use crate::math::{dot, normalize};
use crate::response::{ForceInput, Impact, RestingContact, ServedBy};

/// Relative tolerance on h and the Rayleigh coefficients for the table to apply.
const MATCH_REL_TOL: f64 = 1e-9;

/// A triangle corner outside the region is ignored when its barycentric weight is at most
/// this (a point at a region vertex may map to a neighbouring triangle outside the region).
const NEGLIGIBLE_WEIGHT: f64 = 1e-9;

/// Table nodes of a mapped point (vertices and edge midpoints) with their interpolation
/// weights; unused slots have weight 0.
type Nodes = ([u32; 6], [f64; 6]);

/// The P2 (or, lacking midpoints, P1) nodes and weights of a point with barycentric weights
/// `bary` in surface triangle `t` (corners `tri`), or `None` when a corner with a weight above
/// [`NEGLIGIBLE_WEIGHT`] is outside the region (negligible ones get weight 0).
#[inline]
fn table_nodes(ts: &TransferState, t: u32, tri: [usize; 3], bary: [f64; 3]) -> Option<Nodes> {
    let mut idx = [0u32; 6];
    let mut w = bary;
    for k in 0..3 {
        let l = ts.local[tri[k]];
        if l == UNMAPPED {
            if bary[k] > NEGLIGIBLE_WEIGHT {
                return None;
            }
            w[k] = 0.0;
        } else {
            idx[k] = l;
        }
    }
    let mids = ts.tri_mids[t as usize];
    // Midpoint k sits on the edge opposite corner k.
    let mid_w = [0, 1, 2].map(|k| 4.0 * w[(k + 1) % 3] * w[(k + 2) % 3]);
    if (0..3).any(|k| mid_w[k] > 0.0 && mids[k] == UNMAPPED) {
        return Some((idx, [w[0], w[1], w[2], 0.0, 0.0, 0.0]));
    }
    let mut nw = [0.0; 6];
    for k in 0..3 {
        nw[k] = w[k] * (2.0 * w[k] - 1.0);
        if mid_w[k] > 0.0 {
            idx[3 + k] = mids[k];
            nw[3 + k] = mid_w[k];
        }
    }
    Some((idx, nw))
}

/// Per-instance state of the transfer-table method.
#[derive(Debug)]
pub(super) struct TransferState {
    /// Region index (= table point) of each surface vertex ([`UNMAPPED`]: outside the region).
    local: Vec<u32>,
    /// Per surface triangle: the table point of the midpoint of the edge opposite each corner
    /// ([`UNMAPPED`]: not tabulated).
    tri_mids: Vec<[u32; 3]>,
    /// This step's applied impacts: table nodes and weights, λ_N (N·s).
    hits: Vec<(Nodes, f64)>,
    /// Table peak per resting contact this step (m); NaN: not served by the table.
    peaks: Vec<f64>,
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= MATCH_REL_TOL * a.abs().max(b.abs())
}

impl TransferState {
    /// The state when the base's table applies to steps of length `h` (s) with Rayleigh damping
    /// `rayleigh` and `carry_over`; `None` otherwise (the modal method serves every step).
    pub(super) fn new(
        model: &crate::ModalModel,
        h: f64,
        rayleigh: [f64; 2],
        carry_over: bool,
    ) -> Option<TransferState> {
        let t = model.base().transfer.as_ref()?;
        if carry_over
            || !close(t.h, h)
            || !close(t.rayleigh[0], rayleigh[0])
            || !close(t.rayleigh[1], rayleigh[1])
        {
            return None;
        }
        let mut local = vec![UNMAPPED; model.num_vertices()];
        for (k, &v) in t.vertices.iter().enumerate() {
            local[v as usize] = k as u32;
        }
        let nr = t.vertices.len();
        let tri_mids = (0..model.base().surface_triangles.len())
            .map(|f| {
                let tri = model.triangle(f as u32).map(|v| local[v]);
                [0, 1, 2].map(|k| {
                    let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
                    if a == UNMAPPED || b == UNMAPPED {
                        return UNMAPPED;
                    }
                    t.edges
                        .binary_search(&[a.min(b), a.max(b)])
                        .map_or(UNMAPPED, |e| (nr + e) as u32)
                })
            })
            .collect();
        Some(TransferState {
            local,
            tri_mids,
            hits: Vec::new(),
            peaks: Vec::new(),
        })
    }
}

impl DistantResponse {
    /// Whether the transfer table is in use for this instance (the base has one that matches
    /// h, Rayleigh damping and `carry_over = false`, and the method is [`crate::Method::Transfer`]).
    pub fn transfer_active(&self) -> bool {
        self.transfer.is_some()
    }

    /// Serves the step from the table when it applies; returns `false` (nothing done) when the
    /// modal method must serve the whole step.
    pub(super) fn step_transfer(
        &mut self,
        impacts: &[Impact],
        forces: &[ForceInput],
        resting: &[RestingContact],
    ) -> bool {
        let Some(mut ts) = self.transfer.take() else {
            return false;
        };
        let served = self.step_transfer_with(&mut ts, impacts, forces, resting);
        self.transfer = Some(ts);
        served
    }

    fn step_transfer_with(
        &mut self,
        ts: &mut TransferState,
        impacts: &[Impact],
        forces: &[ForceInput],
        resting: &[RestingContact],
    ) -> bool {
        let nonzero_force = forces
            .iter()
            .any(|f| f.force != [0.0; 3] && f.force.iter().all(|x| x.is_finite()));
        if nonzero_force {
            self.info.contacts_table_fallback += resting.len() as u32;
            return false;
        }
        let model = Arc::clone(&self.model);
        let table = model.base().transfer.as_ref().expect("checked at set-up");
        ts.hits.clear();
        let (mut below, mut unmapped) = (0u32, 0u32);
        for imp in impacts {
            let ok = imp.impulse.is_finite()
                && imp.impulse > 0.0
                && imp.impulse >= self.params.impact_threshold;
            if !ok {
                below += 1;
                continue;
            }
            let Some(sp) = model.project(imp.point, self.max_map) else {
                unmapped += 1;
                continue;
            };
            let Some(nodes) = table_nodes(ts, sp.triangle, model.triangle(sp.triangle), sp.bary)
            else {
                self.info.contacts_table_fallback += resting.len() as u32;
                return false;
            };
            let lambda_n = imp.impulse * dot(normalize(imp.direction), sp.normal).abs();
            ts.hits.push((nodes, lambda_n));
        }
        ts.peaks.clear();
        let mut outside = 0u32;
        for &s in &self.slots {
            let d = match self.cache.slot(s).surface {
                Some(sp) => {
                    match table_nodes(ts, sp.triangle, model.triangle(sp.triangle), sp.bary) {
                        None => {
                            outside += 1;
                            f64::NAN
                        }
                        Some((loc, wb)) => {
                            let mut d = 0.0;
                            for ((src, beta), lambda_n) in &ts.hits {
                                let mut p = 0.0;
                                for (a, ba) in src.iter().zip(beta) {
                                    if *ba == 0.0 {
                                        continue;
                                    }
                                    for (b, bb) in loc.iter().zip(&wb) {
                                        if *bb != 0.0 {
                                            p += ba * bb * table.peak(*a as usize, *b as usize);
                                        }
                                    }
                                }
                                d += lambda_n * p.max(0.0);
                            }
                            d
                        }
                    }
                }
                None => f64::NAN,
            };
            ts.peaks.push(d);
        }
        let h = self.params.h;
        if outside > 0 {
            // Some contacts lie outside the region: the modal step serves them (and counts the
            // impacts); the in-region contacts take the table's values.
            self.step_modal(impacts, forces, resting);
            self.info.contacts_table_fallback += outside;
            for (o, &d) in self.out.iter_mut().zip(&ts.peaks) {
                if d.is_finite() && o.mapped {
                    o.peak_displacement = d;
                    o.delta_v = d / h;
                    o.served_by = ServedBy::TransferTable;
                    self.info.contacts_by_table += 1;
                }
            }
            return true;
        }
        self.info.impacts_below_threshold += below;
        self.info.impacts_unmapped += unmapped;
        self.info.impacts_applied += ts.hits.len() as u32;
        // The filters are not run: leave them at rest (diagnostics read zeros).
        if !self.asleep {
            self.reset();
        }
        self.out.clear();
        for ((rc, &s), &d) in resting.iter().zip(&self.slots).zip(&ts.peaks) {
            let resp = match self.cache.slot(s).surface {
                Some(sp) if d.is_finite() => {
                    self.info.contacts_by_table += 1;
                    mapped_response(rc, &sp, d, h, ServedBy::TransferTable)
                }
                _ => unmapped_response(rc),
            };
            self.out.push(resp);
        }
        true
    }
}
