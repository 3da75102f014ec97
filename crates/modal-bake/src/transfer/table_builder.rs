//! [`build_transfer_table`]: every table entry from the series of region-vertex pairs.
//!
//! A table point p is a barycentric blend of up to three region vertices (λ_pa), so its
//! normal-displacement series under an impulse at another point q is the same blend of
//! vertex-pair series (P1 interpolation of the FEM field, reciprocity):
//! `y_pq(t) = Σ_a Σ_b λ_pa λ_qb Y_ab(t)`, `Y_ab(t) = −Σ_l w_al w_bl g_l(t)`,
//! with `w_al = n_aᵀ U_al` and g_l the exact impulse response of mode l. The vertex series of one
//! source vertex against many target vertices is one GEMM, `Y_a = (G ∘ w_a) W`, with G the S × m
//! table of g_l(kT) and W the m × nr normal rows; a point's series against every target vertex is
//! then the blend `Z_p = Σ_a λ_pa Y_a`, and a target point's series the blend of ≤ 3 columns of
//! Z_p. So the GEMMs scale with the region's vertices (not its points, ≈ 4× more for P2 and 9×
//! for P3) and every unordered pair is computed once.
//!
//! Locality: points are processed in a breadth-first order of the region's vertices (a point
//! comes right after the last of its vertices), in clusters; a cluster computes `Y_a` for its
//! points' vertices against the target vertices still in use by the points from the cluster on
//! (about half of them on average: reciprocity) and keeps the series it can reuse for the next
//! cluster. A cluster holds at most [`CLUSTER_BYTES`] of series.
//!
//! Precision: the series are f32 (the table stores f32): the GEMMs run twice as fast as in f64
//! and the entries differ from an f64 build by at most 1.7e-6 relative (1.2e-7 median) on the
//! ground slab's 1926-mode cubic table (1.2 million entries).
//!
//! Deterministic: each GEMM runs sequentially (`Par::Seq`) with a fixed shape, clusters run in
//! order and the points of a cluster in parallel without shared sums, so the bits do not depend
//! on the thread count.

use std::collections::HashMap;

use dcr_runtime::filter::{damping_ratio, samples_per_step, ModeFilter};
use dcr_runtime::format::{ModesFile, TransferTable, MAX_TRANSFER_POINTS};
use dcr_runtime::response::Sampling;
use dcr_runtime::ModalModel;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use rayon::prelude::*;

use super::{
    OverBudget, TablePlan, TransferError, TransferModes, TransferParams, TransferProgress,
};
use crate::bake::Budget;

/// Budget of one cluster's vertex series (bytes).
pub const CLUSTER_BYTES: usize = 384 << 20;

/// Scalar of the series (the GEMMs and blends); the table stores f32.
type Real = f32;

/// A table's skeleton (region, order, points; no peaks), the model and the sampling, before any
/// series is computed.
struct Prepared {
    model: ModalModel,
    table: TransferTable,
    /// Modes summed.
    m: usize,
    /// Sampling period (s).
    period: f64,
    plan: TablePlan,
}

/// The skeleton and plan of the table `params` select from the mode set `modes`: checks, region,
/// order, points, samples per step, bent points (errors as [`build_transfer_table`]'s, never
/// over a budget).
fn prepare(
    modes: &ModesFile,
    params: &TransferParams,
    rayleigh: [f64; 2],
) -> Result<Prepared, TransferError> {
    params.check()?;
    let m = match params.modes {
        TransferModes::All | TransferModes::Auto => modes.num_modes(),
        TransferModes::Count(n) => n.min(modes.num_modes()),
    };
    let mut set = modes.clone();
    set.transfer = None;
    let model =
        ModalModel::from_base(set).map_err(|e| TransferError::Params(format!("mode set: {e}")))?;
    let region = super::select_region(&model, &params.boxes, params.up, params.up_min_cos);
    let nr = region.len();
    if nr == 0 {
        return Err(TransferError::Params(
            "the region (boxes / up direction) selects no surface vertex".into(),
        ));
    }
    let tris = &model.base().surface_triangles;
    let edges = TransferTable::region_edges(tris, &region);
    let faces = TransferTable::region_faces(tris, &region);
    let order = params.order.resolve(nr, edges.len(), faces.len());
    let np = TransferTable::points_for(order, nr, edges.len(), faces.len());
    if np > MAX_TRANSFER_POINTS {
        return Err(TransferError::Params(format!(
            "the region selects {nr} surface vertices, {} edges and {} faces: {np} table points at order {order}, more than the {MAX_TRANSFER_POINTS} supported; restrict the region or lower the order",
            edges.len(),
            faces.len()
        )));
    }
    let omega = &model.omega()[..m];
    let s = samples_for(params, omega[m - 1])?;
    let table = TransferTable {
        h: params.h,
        rayleigh,
        modes: m as u32,
        samples: s as u32,
        vertices: region,
        order,
        edges: if order >= 2 { edges } else { Vec::new() },
        faces: if order == 3 { faces } else { Vec::new() },
        peaks: Vec::new(),
    };
    let normals = model.vertex_normals();
    let bent = (table.len()..table.num_points())
        .filter(|&p| bent_normal(&table, normals, p).is_some())
        .count();
    let plan = TablePlan {
        order,
        vertices: nr,
        points: np,
        bent,
        modes: m,
        samples: s,
        omega_max: omega[m - 1],
        h: params.h,
        surface_vertices: modes.num_surface_vertices(),
        set_modes: modes.num_modes(),
        threads: rayon::current_num_threads(),
    };
    Ok(Prepared {
        period: params.h / s as f64,
        model,
        table,
        m,
        plan,
    })
}

/// Samples per step S for a table whose highest mode is `omega_max` (rad/s).
fn samples_for(params: &TransferParams, omega_max: f64) -> Result<usize, TransferError> {
    let t_req = Sampling::Oversample(params.oversample).period(omega_max);
    if params.h / t_req > 1e7 {
        return Err(TransferError::Params(format!(
            "{:.0} samples per step (h/T) exceed the limit of 1e7; use fewer table modes or a shorter step",
            params.h / t_req
        )));
    }
    Ok(samples_per_step(params.h, t_req))
}

/// What building the table over the region selected by `params` from the mode set `modes`
/// would compute and cost ([`TablePlan`]), without building it.
///
/// # Errors
/// As [`build_transfer_table`], but never [`TransferError::OverBudget`].
pub fn plan_transfer_table(
    modes: &ModesFile,
    params: &TransferParams,
) -> Result<TablePlan, TransferError> {
    prepare(modes, params, [0.0; 2]).map(|p| p.plan)
}

/// The most of the set's lowest modes (at most the plan's) whose table fits `budget`, with its
/// plan ([`OverBudget::most_modes`]).
fn most_modes_fitting(
    prep: &Prepared,
    params: &TransferParams,
    budget: &Budget,
) -> Option<TablePlan> {
    let plan = &prep.plan;
    if plan.fits(budget) {
        return Some(*plan);
    }
    let omega = prep.model.omega();
    let with_modes = |m: usize| -> Option<TablePlan> {
        let s = samples_for(params, omega[m - 1]).ok()?;
        Some(TablePlan {
            modes: m,
            samples: s,
            omega_max: omega[m - 1],
            ..*plan
        })
    };
    // The plan's cost grows with m (m and ω_m both grow): bisect for the most modes that fit.
    let fits = |m: usize| with_modes(m).is_some_and(|p| p.fits(budget));
    if !fits(1) {
        return None;
    }
    let (mut lo, mut hi) = (1, plan.modes);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    with_modes(lo)
}

/// The changes of `params` whose tables fit `budget` (the plan does not), each with its
/// estimate: the most modes that fit (`most`), and the lower orders.
fn fixes(
    prep: &Prepared,
    params: &TransferParams,
    budget: &Budget,
    most: Option<TablePlan>,
) -> Vec<String> {
    let plan = &prep.plan;
    let mut out = Vec::new();
    if let Some(p) = most {
        out.push(format!(
            "`transfer.modes` {} (the lowest {} modes, up to {:.3e} rad/s: {})",
            p.modes,
            p.modes,
            p.omega_max,
            p.describe()
        ));
    }
    let tris = &prep.model.base().surface_triangles;
    let t = &prep.table;
    let (ne, nf) = (
        TransferTable::region_edges(tris, &t.vertices).len(),
        TransferTable::region_faces(tris, &t.vertices).len(),
    );
    for order in (1..plan.order).rev() {
        let np = TransferTable::points_for(order, t.len(), ne, nf);
        // Bent points among the edge and face points, in proportion.
        let extra = plan.points - plan.vertices;
        let bent = (plan.bent * (np - plan.vertices))
            .checked_div(extra)
            .unwrap_or(0);
        let p = TablePlan {
            order,
            points: np,
            bent,
            ..*plan
        };
        if p.fits(budget) {
            let name = ["linear", "quadratic"][usize::from(order) - 1];
            out.push(format!(
                "`transfer.order` {order} ({name}: {})",
                p.describe()
            ));
            break;
        }
    }
    if params.up.is_none() && params.boxes.is_empty() {
        out.push(
            "a smaller region (`transfer.up`: the faces a prop can rest on; `transfer.boxes`)"
                .into(),
        );
    }
    out
}

/// Builds the table over the region selected by `params` from the mode set `modes` (a base
/// with many modes; its own Rayleigh damping is ignored in favour of `rayleigh`). With
/// `params.budget` set, the build is refused before it starts when its [`TablePlan`]'s estimate
/// is over the budget.
///
/// # Errors
/// [`TransferError::Params`] for invalid parameters, an empty region, or one whose points
/// exceed [`MAX_TRANSFER_POINTS`]; [`TransferError::OverBudget`] for a plan over
/// `params.budget`.
pub fn build_transfer_table(
    modes: &ModesFile,
    params: &TransferParams,
    rayleigh: [f64; 2],
    progress: &mut dyn FnMut(TransferProgress),
) -> Result<TransferTable, TransferError> {
    let prep = prepare(modes, params, rayleigh)?;
    if let Some(budget) = params.budget {
        if !prep.plan.fits(&budget) {
            let most = most_modes_fitting(&prep, params, &budget);
            return Err(TransferError::OverBudget(Box::new(OverBudget {
                plan: prep.plan,
                budget,
                most_modes: most,
                fixes: fixes(&prep, params, &budget, most),
            })));
        }
    }
    let Prepared {
        model,
        mut table,
        m,
        period,
        plan,
    } = prep;
    let mm = model.num_modes();
    let omega = &model.omega()[..m];
    let s = table.samples as usize;
    // G (S × m): g_l(kT), the exact impulse response the runtime uses.
    let filters: Vec<ModeFilter> = omega
        .iter()
        .map(|&w| ModeFilter::new(w, damping_ratio(w, rayleigh), period))
        .collect();
    let g = Mat::from_fn(s, m, |k, l| {
        filters[l].impulse_response((k + 1) as f64 * period)
    });
    // W (m × nr): normal rows of the region vertices, one column per vertex.
    let rows = model.normal_mode_rows();
    let nr = table.len();
    let w = Mat::from_fn(m, nr, |l, c| rows[table.vertices[c] as usize * mm + l]);
    let tris = &model.base().surface_triangles;
    let adjacency = TransferTable::region_edges(tris, &table.vertices);
    let g = Mat::<Real>::from_fn(s, m, |k, l| g[(k, l)] as Real);
    let w = Mat::<Real>::from_fn(m, nr, |l, c| w[(l, c)] as Real);
    let bent = bent_point_rows(&table, &model, m);
    table.peaks = tabulate(&table, &adjacency, &g, &w, &bent, &mut |done, total| {
        progress(TransferProgress { done, total, plan })
    });
    table
        .check(modes.num_surface_vertices())
        .map_err(TransferError::Params)?;
    Ok(table)
}

/// Normal rows of the points whose vertices' normals differ ("bent" points, next to edges and
/// corners of the surface): `rows` (m × n) with column k the row of point `points[k]`
/// (ascending).
struct BentRows {
    points: Vec<u32>,
    rows: Mat<Real>,
}

/// The rows of the bent points: `w̃_pl = n̂_pᵀ Σ_a λ_pa U_al` with `n̂_p` the normalised blend of
/// the vertices' normals — the runtime's (and the truth's) normal at that point. At the other
/// points every vertex has the same normal and the row is the blend of the vertex rows.
fn bent_point_rows(table: &TransferTable, model: &ModalModel, m: usize) -> BentRows {
    let normals = model.vertex_normals();
    let base = model.base();
    let mm = base.num_modes();
    let mut points = Vec::new();
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for p in table.len()..table.num_points() {
        let Some(n) = bent_normal(table, normals, p) else {
            continue;
        };
        let (vs, ws) = table.point_support(p);
        let used: Vec<(usize, f64)> = (0..3)
            .filter(|&k| ws[k] != 0.0)
            .map(|k| (table.vertices[vs[k] as usize] as usize, ws[k]))
            .collect();
        let mut row = vec![0.0f64; m];
        for &(v, l) in &used {
            for c in 0..3 {
                let u = &base.modes[(v * 3 + c) * mm..(v * 3 + c) * mm + m];
                for (r, x) in row.iter_mut().zip(u) {
                    *r += l * n[c] * x;
                }
            }
        }
        points.push(p as u32);
        cols.push(row);
    }
    let rows = Mat::<Real>::from_fn(m, points.len(), |l, k| cols[k][l] as Real);
    BentRows { points, rows }
}

/// The normal of table point `p` when its vertices' normals differ (a bent point: the normalised
/// blend of the vertices' normals, or the first vertex's when the blend vanishes); `None` when
/// every vertex of its support has the same normal.
fn bent_normal(table: &TransferTable, normals: &[[f64; 3]], p: usize) -> Option<[f64; 3]> {
    let (vs, ws) = table.point_support(p);
    let used: Vec<(usize, f64)> = (0..3)
        .filter(|&k| ws[k] != 0.0)
        .map(|k| (table.vertices[vs[k] as usize] as usize, ws[k]))
        .collect();
    let n0 = normals[used[0].0];
    if used
        .iter()
        .all(|&(v, _)| (0..3).all(|c| (normals[v][c] - n0[c]).abs() <= 1e-12))
    {
        return None;
    }
    let mut n = [0.0; 3];
    for &(v, l) in &used {
        for c in 0..3 {
            n[c] += l * normals[v][c];
        }
    }
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    Some(if len > 0.0 { n.map(|x| x / len) } else { n0 })
}

/// A table point's support: region vertices and barycentric weights (1 to 3 of them).
#[derive(Clone, Copy, Debug)]
struct Support {
    verts: [u32; 3],
    weights: [f64; 3],
    len: usize,
}

fn supports(table: &TransferTable) -> Vec<Support> {
    (0..table.num_points())
        .map(|p| {
            let (verts, weights) = table.point_support(p);
            let len = weights.iter().filter(|&&x| x != 0.0).count();
            Support {
                verts,
                weights,
                len,
            }
        })
        .collect()
}

/// Points in breadth-first order of the region's vertices over its edges (each point right
/// after the last of its vertices; components in order of their smallest vertex).
fn processing_order(nr: usize, edges: &[[u32; 2]], sup: &[Support]) -> Vec<u32> {
    let mut adj = vec![Vec::new(); nr];
    for &[a, b] in edges {
        adj[a as usize].push(b);
        adj[b as usize].push(a);
    }
    // Points by the vertex that completes them (its last vertex in visiting order).
    let mut visit_pos = vec![usize::MAX; nr];
    let mut order_v = Vec::with_capacity(nr);
    let mut queue = std::collections::VecDeque::new();
    for start in 0..nr {
        if visit_pos[start] != usize::MAX {
            continue;
        }
        visit_pos[start] = order_v.len();
        order_v.push(start);
        queue.push_back(start);
        while let Some(v) = queue.pop_front() {
            for &u in &adj[v] {
                let u = u as usize;
                if visit_pos[u] == usize::MAX {
                    visit_pos[u] = order_v.len();
                    order_v.push(u);
                    queue.push_back(u);
                }
            }
        }
    }
    let mut by_last: Vec<Vec<u32>> = vec![Vec::new(); nr];
    for (p, sp) in sup.iter().enumerate() {
        let last = sp.verts[..sp.len]
            .iter()
            .max_by_key(|&&v| visit_pos[v as usize])
            .expect("a point has a vertex");
        by_last[visit_pos[*last as usize]].push(p as u32);
    }
    by_last.into_iter().flatten().collect()
}

/// The packed upper triangle of peaks (see the module docs); `edges`: the region's edges (for
/// the processing order); `bent`: the rows of the points whose vertices' normals differ;
/// `progress(done, total)` after each cluster of rows.
fn tabulate(
    table: &TransferTable,
    edges: &[[u32; 2]],
    g: &Mat<Real>,
    w: &Mat<Real>,
    bent: &BentRows,
    progress: &mut dyn FnMut(usize, usize),
) -> Vec<f32> {
    let np = table.num_points();
    let nr = table.len();
    let s = g.nrows();
    let m = g.ncols();
    let sup = supports(table);
    let order = processing_order(nr, edges, &sup);
    let mut bent_of = vec![usize::MAX; np];
    for (k, &p) in bent.points.iter().enumerate() {
        bent_of[p as usize] = k;
    }
    let mut pos = vec![0usize; np];
    for (i, &p) in order.iter().enumerate() {
        pos[p as usize] = i;
    }
    // Last position at which each vertex supports a point blended from vertex series.
    let mut last_use = vec![0usize; nr];
    for (i, &p) in order.iter().enumerate() {
        if bent_of[p as usize] != usize::MAX {
            continue;
        }
        let sp = &sup[p as usize];
        for &v in &sp.verts[..sp.len] {
            last_use[v as usize] = last_use[v as usize].max(i);
        }
    }
    let mut peaks = vec![0.0f32; TransferTable::packed_len(np)];
    let per_vertex = s * (nr + bent.points.len()) * std::mem::size_of::<Real>();
    let max_vertices = (CLUSTER_BYTES / per_vertex.max(1)).max(4);
    // Series kept from the previous cluster: vertex → (its column keys, S × columns). Column
    // keys: vertex v is v, bent point q is nr + q (ascending: vertices first).
    let mut kept: HashMap<u32, (Vec<u32>, Mat<Real>)> = HashMap::new();
    let mut start = 0;
    progress(0, np);
    while start < np {
        let end = cluster_end(&order, &sup, &bent_of, start, max_vertices);
        let mut verts: Vec<u32> = order[start..end]
            .iter()
            .filter(|&&p| bent_of[p as usize] == usize::MAX)
            .flat_map(|&p| {
                let sp = sup[p as usize];
                sp.verts.into_iter().take(sp.len)
            })
            .collect();
        verts.sort_unstable();
        verts.dedup();
        // Targets from `start` on: the vertices their blends need, and the bent points.
        let mut keys: Vec<u32> = (0..nr as u32)
            .filter(|&v| last_use[v as usize] >= start)
            .collect();
        keys.extend(
            bent.points
                .iter()
                .filter(|&&q| pos[q as usize] >= start)
                .map(|&q| nr as u32 + q),
        );
        let wc = Mat::<Real>::from_fn(m, keys.len(), |l, c| {
            let k = keys[c] as usize;
            if k < nr {
                w[(l, k)]
            } else {
                bent.rows[(l, bent_of[k - nr])]
            }
        });
        let col_of = |key: u32| keys.binary_search(&key).expect("target in use");
        // Per target (position start + j): its columns and weights.
        let targets: Vec<([usize; 3], [Real; 3], usize)> = order[start..]
            .iter()
            .map(|&q| {
                if bent_of[q as usize] != usize::MAX {
                    return ([col_of(nr as u32 + q), 0, 0], [1.0, 0.0, 0.0], 1);
                }
                let sq = &sup[q as usize];
                let mut c = [0usize; 3];
                for k in 0..sq.len {
                    c[k] = col_of(sq.verts[k]);
                }
                (c, sq.weights.map(|x| x as Real), sq.len)
            })
            .collect();
        // Vertex series over the columns: kept ones cut down to them, the rest computed.
        let series: HashMap<u32, Mat<Real>> = verts
            .par_iter()
            .map(|&a| {
                let y = match kept.get(&a) {
                    Some((kc, ky)) => {
                        let map: Vec<usize> = keys
                            .iter()
                            .map(|b| kc.binary_search(b).expect("kept columns cover"))
                            .collect();
                        Mat::from_fn(s, keys.len(), |t, c| ky[(t, map[c])])
                    }
                    None => series_against(g, w.col(a as usize), &wc),
                };
                (a, y)
            })
            .collect();
        let rows: Vec<Vec<(usize, f32)>> = order[start..end]
            .par_iter()
            .enumerate()
            .map_init(
                || Mat::<Real>::zeros(s, keys.len()),
                |z, (k, &p)| {
                    let bp = bent_of[p as usize];
                    if bp != usize::MAX {
                        *z = series_against(g, bent.rows.col(bp), &wc);
                    } else {
                        // Z_p: the blend of its vertices' series.
                        let sp = &sup[p as usize];
                        z.fill(0.0);
                        for (a, &la) in sp.verts[..sp.len].iter().zip(&sp.weights) {
                            let la = la as Real;
                            let ya = &series[a];
                            for c in 0..keys.len() {
                                let src = ya.col(c);
                                let mut dst = z.col_mut(c);
                                for t in 0..s {
                                    dst[t] += la * src[t];
                                }
                            }
                        }
                    }
                    (k..targets.len())
                        .map(|j| {
                            let q = order[start + j] as usize;
                            let (tc, tw, len) = &targets[j];
                            let peak = match len {
                                1 => {
                                    let c = z.col(tc[0]);
                                    let l0 = tw[0];
                                    (0..s).fold(0.0, |pk: Real, t| pk.max((l0 * c[t]).abs()))
                                }
                                2 => {
                                    let (c0, c1) = (z.col(tc[0]), z.col(tc[1]));
                                    let [l0, l1, _] = *tw;
                                    (0..s).fold(0.0, |pk: Real, t| {
                                        pk.max((l0 * c0[t] + l1 * c1[t]).abs())
                                    })
                                }
                                _ => {
                                    let (c0, c1, c2) = (z.col(tc[0]), z.col(tc[1]), z.col(tc[2]));
                                    let [l0, l1, l2] = *tw;
                                    (0..s).fold(0.0, |pk: Real, t| {
                                        pk.max((l0 * c0[t] + l1 * c1[t] + l2 * c2[t]).abs())
                                    })
                                }
                            };
                            (table.packed_index(p as usize, q), peak)
                        })
                        .collect()
                },
            )
            .collect();
        for row in rows {
            for (idx, v) in row {
                peaks[idx] = v;
            }
        }
        // Keep the series the next points still need.
        kept = series
            .into_iter()
            .filter(|(v, _)| last_use[*v as usize] >= end)
            .map(|(v, y)| (v, (keys.clone(), y)))
            .collect();
        start = end;
        progress(start, np);
    }
    peaks
}

/// End of the cluster of points starting at position `start` of `order`: as many points as
/// keep the cluster's vertices within `max_vertices` (one point at least).
fn cluster_end(
    order: &[u32],
    sup: &[Support],
    bent_of: &[usize],
    start: usize,
    max_vertices: usize,
) -> usize {
    let mut verts: Vec<u32> = Vec::new();
    let mut end = start;
    while end < order.len() {
        if bent_of[order[end] as usize] != usize::MAX {
            // Computed on its own: no vertex series.
            end += 1;
            continue;
        }
        let sp = &sup[order[end] as usize];
        let new = sp.verts[..sp.len]
            .iter()
            .filter(|v| !verts.contains(v))
            .count();
        if end > start && verts.len() + new > max_vertices {
            break;
        }
        for &v in &sp.verts[..sp.len] {
            if !verts.contains(&v) {
                verts.push(v);
            }
        }
        end += 1;
    }
    end
}

/// `(G ∘ r) Wc` (S × columns): the series at the target columns `wc` (m × columns) after a unit
/// inward impulse at a point of normal row `r` (m); the sign is dropped (only |·| is used).
fn series_against(g: &Mat<Real>, r: faer::ColRef<'_, Real>, wc: &Mat<Real>) -> Mat<Real> {
    let (s, m) = (g.nrows(), g.ncols());
    let gr = Mat::from_fn(s, m, |k, l| g[(k, l)] * r[l]);
    let mut y = Mat::<Real>::zeros(s, wc.ncols());
    matmul(
        y.as_mut(),
        Accum::Replace,
        gr.as_ref(),
        wc.as_ref(),
        1.0,
        Par::Seq,
    );
    y
}
