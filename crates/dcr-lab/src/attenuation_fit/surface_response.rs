//! [`SurfaceResponse`]: the normal-displacement rows of every surface vertex in modal
//! coordinates, and the peaks of the exact modal impulse responses at surface pairs.

use dcr_runtime::filter::{damping_ratio, ModeFilter};
use modal_bake::bake::ModesFile;
use modal_bake::full_order::{FullOrderSystem, ModalAll};
use rayon::prelude::*;

/// The normal-displacement rows of every surface vertex in modal coordinates, with the modes'
/// eigenvalues: enough to evaluate the response at any surface vertex to an impulse at any
/// other.
#[derive(Clone, Debug)]
pub struct SurfaceResponse {
    /// λ_j = ω_j² (rad²/s²) of the modes used, ascending.
    pub eigenvalues: Vec<f64>,
    /// Row-major (ns × m): `rows[v * m + j] = n_vᵀ U_v,j` (m·kg^-1/2), n_v the area-weighted
    /// outward vertex normal.
    pub rows: Vec<f64>,
    /// Surface vertex positions (m).
    pub vertices: Vec<[f64; 3]>,
    /// Outward surface triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Vertices that can be struck and measured (not fixed; non-zero row).
    pub eligible: Vec<bool>,
}

/// Area-weighted outward unit vertex normals (as `SurfaceMap` and `ModalModel`).
fn vertex_normals(v: &[[f64; 3]], t: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let mut n = vec![[0.0; 3]; v.len()];
    for tri in t {
        let [a, b, c] = tri.map(|i| i as usize);
        let (e1, e2) = (sub(v[b], v[a]), sub(v[c], v[a]));
        let x = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        for k in [a, b, c] {
            for ax in 0..3 {
                n[k][ax] += x[ax];
            }
        }
    }
    for x in &mut n {
        let l = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        if l > 0.0 {
            x.iter_mut().for_each(|c| *c /= l);
        }
    }
    n
}

impl SurfaceResponse {
    fn finish(
        eigenvalues: Vec<f64>,
        rows: Vec<f64>,
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        fixed: &[bool],
    ) -> SurfaceResponse {
        let m = eigenvalues.len();
        let eligible = (0..vertices.len())
            .map(|v| !fixed[v] && rows[v * m..(v + 1) * m].iter().any(|x| *x != 0.0))
            .collect();
        SurfaceResponse {
            eigenvalues,
            rows,
            vertices,
            triangles,
            eligible,
        }
    }

    /// From a dense all-mode solve of `sys`, keeping the lowest `modes` (`None`: all).
    pub fn from_modal_all(sys: &FullOrderSystem, ma: &ModalAll, modes: Option<usize>) -> Self {
        let m = modes.unwrap_or(usize::MAX).min(ma.eigenvalues.len());
        let s = &sys.surface;
        let ns = s.vertices.len();
        let mut rows = vec![0.0; ns * m];
        let mut fixed = vec![false; ns];
        rows.par_chunks_mut(m.max(1))
            .enumerate()
            .for_each(|(v, row)| {
                let vol = s.surface_to_volume[v];
                for ax in 0..3 {
                    if let Some(i) = sys.map.free_index(3 * vol + ax) {
                        let n = s.normals[v][ax];
                        for (j, x) in row.iter_mut().enumerate() {
                            *x += n * ma.vectors[(i, j)];
                        }
                    }
                }
            });
        for (v, f) in fixed.iter_mut().enumerate() {
            *f = sys.map.free_index(3 * s.surface_to_volume[v]).is_none();
        }
        Self::finish(
            ma.eigenvalues[..m].to_vec(),
            rows,
            s.vertices.clone(),
            s.triangles.clone(),
            &fixed,
        )
    }

    /// From a baked base (its surface rows of U).
    pub fn from_base(base: &ModesFile) -> Self {
        let m = base.eigenvalues.len();
        let ns = base.surface_vertices.len();
        let normals = vertex_normals(&base.surface_vertices, &base.surface_triangles);
        let mut rows = vec![0.0; ns * m];
        for v in 0..ns {
            for ax in 0..3 {
                let n = normals[v][ax];
                let src = &base.modes[(v * 3 + ax) * m..(v * 3 + ax + 1) * m];
                for (x, u) in rows[v * m..(v + 1) * m].iter_mut().zip(src) {
                    *x += n * u;
                }
            }
        }
        let mut is_fixed = vec![false; ns];
        let fixed: std::collections::HashSet<u32> = base.fixed_nodes.iter().copied().collect();
        for (v, f) in is_fixed.iter_mut().enumerate() {
            *f = fixed.contains(&base.surface_to_volume[v]);
        }
        Self::finish(
            base.eigenvalues.clone(),
            rows,
            base.surface_vertices.clone(),
            base.surface_triangles.clone(),
            &is_fixed,
        )
    }

    /// Number of modes.
    pub fn num_modes(&self) -> usize {
        self.eigenvalues.len()
    }

    /// The default sample period: a quarter of the paper's T = π/(2ω_max) (16 samples per
    /// period of the highest mode used), in s.
    pub fn default_dt(&self) -> f64 {
        let wmax = self.eigenvalues.last().copied().unwrap_or(1.0).sqrt();
        std::f64::consts::FRAC_PI_2 / wmax / 4.0
    }

    /// Per-mode sampled impulse-response recursions (g(Δt), a1, a2).
    pub(super) fn filters(&self, rayleigh: [f64; 2], dt: f64) -> Vec<(f64, f64, f64)> {
        self.eigenvalues
            .iter()
            .map(|&lam| {
                if !(lam > 0.0) {
                    return (0.0, 0.0, 0.0);
                }
                let w = lam.sqrt();
                let f = ModeFilter::new(w, damping_ratio(w, rayleigh), dt);
                (f.g, f.a1, f.a2)
            })
            .collect()
    }

    /// (local peak at `a`, peak at each of `contacts`) (m) of the normal displacement over
    /// k = 1 … `steps` samples of `dt` (s) after a unit impulse (1 N·s) at surface vertex `a`
    /// along −n_a.
    pub(super) fn pair_peaks(
        &self,
        filters: &[(f64, f64, f64)],
        a: usize,
        contacts: &[usize],
        steps: usize,
    ) -> (f64, Vec<f64>) {
        let m = self.num_modes();
        let ra = &self.rows[a * m..(a + 1) * m];
        let nc = contacts.len() + 1;
        let mut y = vec![0.0; nc * steps];
        let mut coef = vec![0.0; nc];
        for (j, &(g1, a1, a2)) in filters.iter().enumerate() {
            // Load r_j = −ra_j (1 N·s along −n_a); measured n_bᵀ u_b = Σ_j rb_j r_j g_j(t).
            let r = -ra[j];
            if r == 0.0 || g1 == 0.0 {
                continue;
            }
            coef[0] = ra[j] * r;
            for (c, &b) in contacts.iter().enumerate() {
                coef[c + 1] = self.rows[b * m + j] * r;
            }
            let (mut gm2, mut gm1) = (0.0, 0.0);
            for k in 0..steps {
                let g = if k == 0 { g1 } else { a1 * gm1 - a2 * gm2 };
                gm2 = gm1;
                gm1 = g;
                for (c, cf) in coef.iter().enumerate() {
                    y[c * steps + k] += cf * g;
                }
            }
        }
        let peak = |c: usize| {
            y[c * steps..(c + 1) * steps]
                .iter()
                .fold(0.0f64, |p, v| p.max(v.abs()))
        };
        (peak(0), (1..nc).map(peak).collect())
    }
}
