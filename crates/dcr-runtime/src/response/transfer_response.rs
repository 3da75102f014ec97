//! [`TransferResponse`]: the transfer-table method ([`crate::Method::Transfer`]): the step's
//! distant peaks looked up in the base's bake-time peak-transfer table ([`crate::format::TransferTable`]) instead of
//! filtering the truncated modal base.
//!
//! The table's points are the nodes of a Lagrange interpolant of its order on every region
//! triangle ([`crate::format::TransferTable`]). A mapped point with barycentric weights β in
//! triangle (v₀, v₁, v₂) is spread over the triangle's nodes with the Lagrange weights N:
//! - order 3 (ten nodes): `½β_k(3β_k − 1)(3β_k − 2)` at vertex k, `(9/2)β_jβ_k(3β_j − 1)` at the
//!   point of edge (j, k) at a third of the way from j, `27β₀β₁β₂` at the centroid;
//! - order 2 (six nodes): `β_k(2β_k − 1)` at vertex k, `4β_jβ_k` at the midpoint of edge (j, k);
//! - order 1: `β_k` at vertex k.
//!
//! The peak normal displacement at a resting contact is
//! `d = Σ_impacts λ_N max(0, Σ_p Σ_q N_p(β_impact) N_q(β_contact) T[p][q])`, where
//! λ_N = λ·|d̂·n| is the normal component of the impulse (N·s; the tangential part is ignored).
//! T is the peak for a unit inward-normal impulse at one table point seen at another, computed
//! at bake time with many modes. The weights sum to 1 and reproduce T exactly at the nodes.
//!
//! Why not the linear blend: the exact peak is a convex function of β on each side (a maximum
//! of absolute values of linear functions), so blending vertex peaks overestimates inside
//! triangles where the vertex responses are out of phase (by up to +214 % on the ground slab,
//! whose waves are a few triangles long); the higher-order interpolants, which see points
//! inside the triangle, are measured in `docs/accuracy.md`. They may undershoot, hence the
//! clamp at 0. A triangle one of whose needed points is missing is blended linearly. With
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
//! Whether the table applies to the run at all is decided at set-up
//! ([`crate::response::TablePolicy`]); per-step fallbacks are counted with their reason
//! ([`crate::response::StepInfo::table_fallback`]).
//!
//! Under [`Launch::SustainedPeak`] (carry-over) the table and the carried modal filters serve
//! together: every step runs the modal method on its carried-over state (the step's impulse
//! applied to it), and a contact the table can serve takes the larger of the two peaks — the
//! table's, from rest and every mode, for this step's impacts, and the filters', which also hold
//! the ringing of earlier impacts over the truncated base. On the steps after an impact (no
//! impacts) the table's peak is 0 and the filters serve.

use super::modal_response::{ModalResponse, UNMAPPED};
use super::step_ctx::{mapped_response, unmapped_response, StepCtx};
use super::{
    ForceInput, Impact, Launch, RestingContact, ServedBy, TableFallback, TableStatus,
    PREPARED_CONTACTS,
};
use crate::math::{dot, normalize};
use crate::model::ModalModel;

/// Relative tolerance on h and the Rayleigh coefficients for the table to apply.
const MATCH_REL_TOL: f64 = 1e-9;

/// A triangle corner outside the region is ignored when its barycentric weight is at most
/// this (a point at a region vertex may map to a neighbouring triangle outside the region).
const NEGLIGIBLE_WEIGHT: f64 = 1e-9;

/// Table nodes of a mapped point (vertices, edge points, centroid) with their interpolation
/// weights; unused slots have weight 0.
type Nodes = ([u32; 10], [f64; 10]);

/// The nodes and weights of a point with barycentric weights `bary` in surface triangle `t`
/// (corners `tri`) at the table's order (linear where a needed point is missing), or `None`
/// when a corner with a weight above [`NEGLIGIBLE_WEIGHT`] is outside the region (negligible
/// ones get weight 0).
#[inline]
fn table_nodes(ts: &TransferResponse, t: u32, tri: [usize; 3], bary: [f64; 3]) -> Option<Nodes> {
    let mut idx = [0u32; 10];
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
    let linear = |idx: [u32; 10]| {
        let mut nw = [0.0; 10];
        nw[..3].copy_from_slice(&w);
        Some((idx, nw))
    };
    if ts.order != 3 {
        return table_nodes_quadratic(ts, t, idx, w, linear);
    }
    let pts = &ts.tri_pts[t as usize];
    let mut nw = [0.0; 10];
    for k in 0..3 {
        nw[k] = 0.5 * w[k] * (3.0 * w[k] - 1.0) * (3.0 * w[k] - 2.0);
        // Edge opposite corner k, from corner j = k+1 to corner l = k+2: the point nearer j,
        // then the point nearer l.
        let (j, l) = ((k + 1) % 3, (k + 2) % 3);
        nw[3 + 2 * k] = 4.5 * w[j] * w[l] * (3.0 * w[j] - 1.0);
        nw[4 + 2 * k] = 4.5 * w[j] * w[l] * (3.0 * w[l] - 1.0);
    }
    nw[9] = 27.0 * w[0] * w[1] * w[2];
    for s in 3..10 {
        if nw[s] != 0.0 {
            if pts[s - 3] == UNMAPPED {
                return linear(idx);
            }
            idx[s] = pts[s - 3];
        }
    }
    Some((idx, nw))
}

/// Order 1 or 2: the P2 nodes and weights, or the linear blend when a needed midpoint is
/// missing (`idx`: the corners' table points, `w`: their weights).
#[inline]
fn table_nodes_quadratic(
    ts: &TransferResponse,
    t: u32,
    mut idx: [u32; 10],
    w: [f64; 3],
    linear: impl Fn([u32; 10]) -> Option<Nodes>,
) -> Option<Nodes> {
    let mids = ts.tri_pts[t as usize];
    // Midpoint k sits on the edge opposite corner k.
    let mid_w = [0, 1, 2].map(|k| 4.0 * w[(k + 1) % 3] * w[(k + 2) % 3]);
    if ts.order == 1 || (0..3).any(|k| mid_w[k] > 0.0 && mids[k] == UNMAPPED) {
        return linear(idx);
    }
    let mut nw = [0.0; 10];
    for k in 0..3 {
        nw[k] = w[k] * (2.0 * w[k] - 1.0);
        if mid_w[k] > 0.0 {
            idx[3 + k] = mids[k];
            nw[3 + k] = mid_w[k];
        }
    }
    Some((idx, nw))
}

/// The transfer-table method: table lookups, and the modal method for what the table cannot
/// serve.
#[derive(Debug)]
pub(crate) struct TransferResponse {
    /// Region index (= table point) of each surface vertex ([`UNMAPPED`]: outside the region).
    local: Vec<u32>,
    /// The table's interpolation order (1, 2, 3).
    order: u8,
    /// Per surface triangle, its table points ([`UNMAPPED`]: not tabulated): order 2, slot k
    /// the midpoint of the edge opposite corner k; order 3, slots 2k and 2k + 1 the points of
    /// the edge opposite corner k (from corner k+1 to k+2) nearer k+1 and nearer k+2, slot 6
    /// the centroid.
    tri_pts: Vec<[u32; 7]>,
    /// This step's applied impacts: table nodes and weights, λ_N (N·s).
    hits: Vec<(Nodes, f64)>,
    /// Table peak per resting contact this step (m); NaN: not served by the table.
    peaks: Vec<f64>,
    /// The modal method: serves the steps and contacts the table cannot.
    modal: ModalResponse,
}

/// The table points of a triangle whose corners have region indices `tri` ([`UNMAPPED`]:
/// outside), in the slot layout of `TransferResponse::tri_pts`.
fn triangle_points(t: &crate::format::TransferTable, tri: [u32; 3]) -> [u32; 7] {
    let nr = t.vertices.len();
    let ne = t.edges.len();
    let mut pts = [UNMAPPED; 7];
    let edge = |a: u32, b: u32| {
        if a == UNMAPPED || b == UNMAPPED {
            return None;
        }
        t.edges.binary_search(&[a.min(b), a.max(b)]).ok()
    };
    for k in 0..3 {
        let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
        let Some(e) = edge(a, b) else { continue };
        match t.order {
            2 => pts[k] = (nr + e) as u32,
            3 => {
                // Point nr + 2e is nearer the edge's smaller region index.
                let (near_a, near_b) = ((nr + 2 * e) as u32, (nr + 2 * e + 1) as u32);
                (pts[2 * k], pts[2 * k + 1]) = if a < b {
                    (near_a, near_b)
                } else {
                    (near_b, near_a)
                };
            }
            _ => {}
        }
    }
    if t.order == 3 && tri.iter().all(|&v| v != UNMAPPED) {
        let mut f = tri;
        f.sort_unstable();
        if let Ok(c) = t.faces.binary_search(&f) {
            pts[6] = (nr + 2 * ne + c) as u32;
        }
    }
    pts
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= MATCH_REL_TOL * a.abs().max(b.abs())
}

impl TransferResponse {
    /// Whether the base's table applies to steps of length `h` (s) with Rayleigh damping
    /// `rayleigh`, `carry_over` and `launch` (carry-over only with [`Launch::SustainedPeak`]):
    /// `Ok` or why not.
    pub fn check(
        model: &ModalModel,
        h: f64,
        rayleigh: [f64; 2],
        carry_over: bool,
        launch: Launch,
    ) -> Result<(), TableStatus> {
        let t = model.base().transfer.as_ref().ok_or(TableStatus::NoTable)?;
        if !close(t.h, h) {
            return Err(TableStatus::StepMismatch { table_h: t.h, h });
        }
        if !close(t.rayleigh[0], rayleigh[0]) || !close(t.rayleigh[1], rayleigh[1]) {
            return Err(TableStatus::DampingMismatch {
                table: t.rayleigh,
                response: rayleigh,
            });
        }
        if carry_over && launch != Launch::SustainedPeak {
            return Err(TableStatus::CarryOver);
        }
        Ok(())
    }

    /// The method over `modal` for a base whose table applies ([`TransferResponse::check`]).
    ///
    /// # Panics
    /// If the base has no transfer table.
    pub fn new(model: &ModalModel, modal: ModalResponse) -> TransferResponse {
        let t = model
            .base()
            .transfer
            .as_ref()
            .expect("checked: the base has a table");
        let mut local = vec![UNMAPPED; model.num_vertices()];
        for (k, &v) in t.vertices.iter().enumerate() {
            local[v as usize] = k as u32;
        }
        let tri_pts = (0..model.base().surface_triangles.len())
            .map(|f| triangle_points(t, model.triangle(f as u32).map(|v| local[v])))
            .collect();
        TransferResponse {
            local,
            order: t.order,
            tri_pts,
            // Sized at set-up as the modal method's buffers (impacts are fewer than contacts).
            hits: Vec::with_capacity(PREPARED_CONTACTS),
            peaks: Vec::with_capacity(PREPARED_CONTACTS),
            modal,
        }
    }

    /// The modal method inside (its filters, for diagnostics).
    pub fn modal(&self) -> &ModalResponse {
        &self.modal
    }

    /// The modal method inside, mutably.
    pub fn modal_mut(&mut self) -> &mut ModalResponse {
        &mut self.modal
    }

    /// One step: the table serves when it applies (see the module doc), else the modal
    /// method; fills `ctx.out`.
    pub fn step(
        &mut self,
        ctx: &mut StepCtx<'_>,
        impacts: &[Impact],
        forces: &[ForceInput],
        resting: &[RestingContact],
    ) {
        let nonzero_force = forces
            .iter()
            .any(|f| f.force != [0.0; 3] && f.force.iter().all(|x| x.is_finite()));
        if nonzero_force {
            ctx.info.contacts_table_fallback += resting.len() as u32;
            ctx.info.table_fallback = Some(TableFallback::Forces);
            self.modal.step(ctx, impacts, forces, resting);
            return;
        }
        let model = ctx.model;
        let table = model.base().transfer.as_ref().expect("checked at set-up");
        self.hits.clear();
        let (mut below, mut unmapped) = (0u32, 0u32);
        for imp in impacts {
            let ok = ctx.applies(imp.impulse);
            if !ok {
                below += 1;
                continue;
            }
            let Some(sp) = model.project(imp.point, ctx.max_map) else {
                unmapped += 1;
                continue;
            };
            let Some(nodes) = table_nodes(self, sp.triangle, model.triangle(sp.triangle), sp.bary)
            else {
                ctx.info.contacts_table_fallback += resting.len() as u32;
                ctx.info.table_fallback = Some(TableFallback::ImpactOutsideRegion);
                self.modal.step(ctx, impacts, forces, resting);
                return;
            };
            let lambda_n = imp.impulse * dot(normalize(imp.direction), sp.normal).abs();
            self.hits.push((nodes, lambda_n));
        }
        self.peaks.clear();
        let mut outside = 0u32;
        let contacts = ctx.contacts;
        for &s in contacts.slots() {
            let d = match contacts.slot(s).surface {
                Some(sp) => {
                    match table_nodes(self, sp.triangle, model.triangle(sp.triangle), sp.bary) {
                        None => {
                            outside += 1;
                            f64::NAN
                        }
                        Some((loc, wb)) => {
                            let mut d = 0.0;
                            for ((src, beta), lambda_n) in &self.hits {
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
            self.peaks.push(d);
        }
        let h = ctx.params.h;
        if ctx.params.carry_over {
            // Launch::SustainedPeak: the carried filters serve every contact (and count the
            // impacts); the table's peak replaces theirs where it is larger.
            self.modal.step(ctx, impacts, forces, resting);
            if outside > 0 {
                ctx.info.contacts_table_fallback += outside;
                ctx.info.table_fallback = Some(TableFallback::ContactsOutsideRegion);
            }
            for (o, &d) in ctx.out.iter_mut().zip(&self.peaks) {
                if d.is_finite() && o.mapped && d > o.peak_displacement {
                    o.peak_displacement = d;
                    o.delta_v = d / h;
                    o.served_by = ServedBy::TransferTable;
                    ctx.info.contacts_by_table += 1;
                }
            }
            return;
        }
        if outside > 0 {
            // Some contacts lie outside the region: the modal step serves them (and counts the
            // impacts); the in-region contacts take the table's values.
            self.modal.step(ctx, impacts, forces, resting);
            ctx.info.contacts_table_fallback += outside;
            ctx.info.table_fallback = Some(TableFallback::ContactsOutsideRegion);
            for (o, &d) in ctx.out.iter_mut().zip(&self.peaks) {
                if d.is_finite() && o.mapped {
                    o.peak_displacement = d;
                    o.delta_v = d / h;
                    o.served_by = ServedBy::TransferTable;
                    ctx.info.contacts_by_table += 1;
                }
            }
            return;
        }
        ctx.info.impacts_below_threshold += below;
        ctx.info.impacts_unmapped += unmapped;
        ctx.info.impacts_applied += self.hits.len() as u32;
        // The filters are not run: leave them at rest (diagnostics read zeros).
        if !self.modal.asleep() {
            self.modal.reset();
        }
        ctx.out.clear();
        for ((rc, &s), &d) in resting.iter().zip(contacts.slots()).zip(&self.peaks) {
            let resp = match contacts.slot(s).surface {
                Some(sp) if d.is_finite() => {
                    ctx.info.contacts_by_table += 1;
                    mapped_response(rc, &sp, d, h, ServedBy::TransferTable)
                }
                _ => unmapped_response(rc),
            };
            ctx.out.push(resp);
        }
    }
}
