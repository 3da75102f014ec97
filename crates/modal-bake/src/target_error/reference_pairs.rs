//! [`ReferencePairs`]: seeded impact/contact points in a region of a base's surface, the
//! converged full-order peaks there, and the errors of any base read through the runtime.

use std::sync::Arc;

use dcr_runtime::format::ModesFile;
use dcr_runtime::response::{Impact, RestingContact};
use dcr_runtime::{DistantResponse, Method, ModalModel, ResponseParams};

use crate::eigen::SplitMix64;
use crate::full_order::{
    converged_peaks, ConvergedPeaks, FullOrderError, FullOrderSystem, ModalAll, PeakSolver,
    PeakWindow, RefineParams, RefineProgress,
};

/// A sampled surface point: position (m, object frame) and whether it is a region vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplePoint {
    /// Position (m, object frame).
    pub at: [f64; 3],
    /// At a vertex (else inside a triangle).
    pub vertex: bool,
}

/// `n` seeded points in the triangles of `base` whose corners are all in `region` (ascending
/// surface-vertex indices) and free: the first third at their vertices, the second at triangle
/// centroids, the last at uniformly random points inside triangles. Empty when the region has
/// no such triangle.
pub fn sample_points(
    base: &ModesFile,
    region: &[u32],
    n: usize,
    rng: &mut SplitMix64,
) -> Vec<SamplePoint> {
    let fixed: std::collections::HashSet<u32> = base.fixed_nodes.iter().copied().collect();
    let ok = |v: u32| {
        region.binary_search(&v).is_ok() && !fixed.contains(&base.surface_to_volume[v as usize])
    };
    let tris: Vec<usize> = (0..base.surface_triangles.len())
        .filter(|&t| base.surface_triangles[t].iter().all(|&v| ok(v)))
        .collect();
    if tris.is_empty() {
        return Vec::new();
    }
    let mut verts: Vec<u32> = tris
        .iter()
        .flat_map(|&t| base.surface_triangles[t])
        .collect();
    verts.sort_unstable();
    verts.dedup();
    let x = &base.surface_vertices;
    (0..n)
        .map(|k| match 3 * k / n {
            0 => SamplePoint {
                at: x[verts[rng.below(verts.len())] as usize],
                vertex: true,
            },
            c => {
                let t = base.surface_triangles[tris[rng.below(tris.len())]];
                let (mut a, mut b) = if c == 1 {
                    (1.0 / 3.0, 1.0 / 3.0)
                } else {
                    (rng.next_f64(), rng.next_f64())
                };
                if a + b > 1.0 {
                    (a, b) = (1.0 - a, 1.0 - b);
                }
                let w = [a, b, 1.0 - a - b];
                let v = t.map(|i| x[i as usize]);
                SamplePoint {
                    at: [0, 1, 2].map(|k| w[0] * v[0][k] + w[1] * v[1][k] + w[2] * v[2][k]),
                    vertex: false,
                }
            }
        })
        .collect()
}

/// The truth [`ReferencePairs::with_truth`] asks for: the arguments of [`converged_peaks`]
/// (on the pairs' [`FullOrderSystem`]).
pub struct TruthProblem<'a> {
    /// Dense all-mode sum or Newmark.
    pub solver: PeakSolver<'a>,
    /// One impulse per impact (N·s, free dofs).
    pub loads: &'a [Vec<f64>],
    /// One measurement row per resting contact (free dofs).
    pub rows: &'a [Vec<f64>],
    /// Window and first step (s).
    pub window: PeakWindow,
    /// Refinement.
    pub refine: &'a RefineParams,
}

/// Seeded impacts and resting contacts with their converged full-order peaks.
#[derive(Clone, Debug)]
pub struct ReferencePairs {
    /// Impacts: on the surface, into it (−normal), `impulse` N·s.
    pub impacts: Vec<Impact>,
    /// Resting contacts on the surface.
    pub resting: Vec<RestingContact>,
    /// Which contacts are at a vertex (else inside a triangle).
    pub contact_at_vertex: Vec<bool>,
    /// `pair_ok[i][c]`: the pair counts (at least the minimum distance apart).
    pub pair_ok: Vec<Vec<bool>>,
    /// The converged truth: `truth.peaks[i][c]` (m).
    pub truth: ConvergedPeaks,
    /// `all-modes` (dense sum) or `newmark`.
    pub truth_method: &'static str,
    /// Window h (s).
    pub h: f64,
}

/// How [`ReferencePairs::new`] samples and solves (SI units).
#[derive(Clone, Debug, PartialEq)]
pub struct PairsParams {
    /// Impacts. Default 4.
    pub impacts: usize,
    /// Resting contacts. Default 12.
    pub contacts: usize,
    /// Seed. Default 1.
    pub seed: u64,
    /// Pairs closer than this (m) do not count. Default 0.1.
    pub min_distance: f64,
    /// Impulse of each impact (N·s). Default 1.
    pub impulse: f64,
    /// Window h (s). Default 0.01.
    pub h: f64,
    /// First step of the truth (s). Default 1e-5.
    pub dt0: f64,
    /// Refinement of the truth. Default 0.5 %, 8 halvings.
    pub refine: RefineParams,
}

impl Default for PairsParams {
    fn default() -> Self {
        PairsParams {
            impacts: 4,
            contacts: 12,
            seed: 1,
            min_distance: 0.1,
            impulse: 1.0,
            h: 0.01,
            dt0: 1e-5,
            refine: RefineParams {
                max_refinements: 8,
                ..RefineParams::default()
            },
        }
    }
}

impl ReferencePairs {
    /// Samples the points in `region` of `base` (a base of `sys`'s mesh) and computes the
    /// converged truth: the dense sum over `modal_all`'s modes when given, else Newmark.
    ///
    /// # Errors
    /// [`FullOrderError::Params`] when the region has no free triangle or a point does not map
    /// onto the surface; errors of the truth.
    pub fn new(
        sys: &FullOrderSystem,
        modal_all: Option<&ModalAll>,
        base: &ModesFile,
        region: &[u32],
        params: &PairsParams,
        progress: &mut dyn FnMut(RefineProgress),
    ) -> Result<ReferencePairs, FullOrderError> {
        Self::with_truth(sys, modal_all, base, region, params, &mut |t| {
            converged_peaks(sys, t.solver, t.loads, t.rows, t.window, t.refine, progress)
        })
    }

    /// As [`ReferencePairs::new`], with the converged peaks computed by `truth` from the
    /// sampled problem (e.g. read from a cache of [`converged_peaks`] results keyed by it).
    ///
    /// # Errors
    /// As [`ReferencePairs::new`], and `truth`'s.
    pub fn with_truth(
        sys: &FullOrderSystem,
        modal_all: Option<&ModalAll>,
        base: &ModesFile,
        region: &[u32],
        params: &PairsParams,
        truth: &mut dyn FnMut(&TruthProblem) -> Result<ConvergedPeaks, FullOrderError>,
    ) -> Result<ReferencePairs, FullOrderError> {
        let mut rng = SplitMix64(params.seed);
        let imp = sample_points(base, region, params.impacts, &mut rng);
        let con = sample_points(base, region, params.contacts, &mut rng);
        if imp.is_empty() || con.is_empty() {
            return Err(FullOrderError::Params(
                "the region has no triangle with three free corners to sample points in".into(),
            ));
        }
        let project = |p: &SamplePoint| {
            sys.surface.project(p.at).ok_or_else(|| {
                FullOrderError::Params(format!("point {:?} does not map onto the surface", p.at))
            })
        };
        let isp = imp.iter().map(project).collect::<Result<Vec<_>, _>>()?;
        let csp = con.iter().map(project).collect::<Result<Vec<_>, _>>()?;
        let loads: Vec<Vec<f64>> = isp
            .iter()
            .map(|s| sys.load_vector(s, s.normal.map(|x| -x), params.impulse))
            .collect();
        let rows: Vec<Vec<f64>> = csp.iter().map(|c| sys.contact_row(c)).collect();
        let (solver, truth_method) = match modal_all {
            Some(m) => (PeakSolver::ModalAll(m, None), "all-modes"),
            None => (PeakSolver::Newmark, "newmark"),
        };
        let window = PeakWindow {
            h: params.h,
            dt: params.dt0,
        };
        let truth = truth(&TruthProblem {
            solver,
            loads: &loads,
            rows: &rows,
            window,
            refine: &params.refine,
        })?;
        let impacts: Vec<Impact> = isp
            .iter()
            .map(|s| Impact {
                point: s.point,
                direction: s.normal.map(|x| -x),
                impulse: params.impulse,
            })
            .collect();
        let resting: Vec<RestingContact> = csp
            .iter()
            .enumerate()
            .map(|(i, c)| RestingContact {
                id: i as u64,
                point: c.point,
            })
            .collect();
        let dist = |a: [f64; 3], b: [f64; 3]| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        let pair_ok = impacts
            .iter()
            .map(|i| {
                resting
                    .iter()
                    .map(|c| dist(i.point, c.point) >= params.min_distance)
                    .collect()
            })
            .collect();
        Ok(ReferencePairs {
            impacts,
            resting,
            contact_at_vertex: con.iter().map(|p| p.vertex).collect(),
            pair_ok,
            truth,
            truth_method,
            h: params.h,
        })
    }

    /// Pairs that count.
    pub fn pairs(&self) -> usize {
        self.pair_ok.iter().flatten().filter(|x| **x).count()
    }

    /// A response for `model` with `method` at this h, ready for [`ReferencePairs::errors`].
    ///
    /// # Panics
    /// If the response parameters are invalid (they are built here from valid values).
    pub fn response(&self, model: Arc<ModalModel>, method: Method) -> DistantResponse {
        let params = ResponseParams {
            h: self.h,
            method,
            ..Default::default()
        };
        DistantResponse::new(model, params).expect("valid response parameters")
    }

    /// Signed errors (%) of `dr`'s peaks (scaled by `gain`) against the truth, over the pairs
    /// that count, with whether the contact is at a vertex; and who served each contact.
    pub fn errors(
        &self,
        dr: &mut DistantResponse,
        gain: f64,
    ) -> (Vec<(f64, bool)>, Vec<dcr_runtime::response::ServedBy>) {
        let mut errors = Vec::new();
        let mut served = Vec::new();
        for (i, imp) in self.impacts.iter().enumerate() {
            let out = dr.step(std::slice::from_ref(imp), &self.resting);
            for (c, o) in out.iter().enumerate() {
                served.push(o.served_by);
                if self.pair_ok[i][c] {
                    let t = self.truth.peaks[i][c];
                    errors.push((
                        100.0 * (gain * o.peak_displacement - t) / t,
                        self.contact_at_vertex[c],
                    ));
                }
            }
        }
        (errors, served)
    }
}
