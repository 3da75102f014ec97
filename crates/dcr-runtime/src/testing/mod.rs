//! Synthetic surfaces and modal bases for tests, benchmarks and doctests (not for production):
//! a flat plate grid, an icosphere, a subdivided box surface, smooth random mode shapes, and a
//! seeded PRNG. Every generator is deterministic.

use std::collections::HashMap;

use crate::format::{MaterialSi, ModesFile, ModesMeta, ModesPrecision, FORMAT_VERSION};

/// A surface: vertex positions (m) and outward (counter-clockwise from outside) triangles.
pub type Surface = (Vec<[f64; 3]>, Vec<[u32; 3]>);

pub use crate::rng::SplitMix64;

/// A nested-dissection-like vertex order of a connected surface, for tests of split solves: the
/// vertices nearer (in breadth-first hops from vertex 0) than the median hop count, then those
/// farther, then the ring at the median (a vertex separator between the two). Each side must be
/// connected for the halves to be single subtrees (true for boxes, spheres and plates).
pub fn bisection_order(n: usize, triangles: &[[u32; 3]]) -> Vec<u32> {
    let mut adj = vec![Vec::new(); n];
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i] as usize, t[(i + 1) % 3] as usize);
            adj[a].push(b);
            adj[b].push(a);
        }
    }
    let mut hops = vec![usize::MAX; n];
    let mut queue = std::collections::VecDeque::from([0usize]);
    hops[0] = 0;
    while let Some(v) = queue.pop_front() {
        for &w in &adj[v] {
            if hops[w] == usize::MAX {
                hops[w] = hops[v] + 1;
                queue.push_back(w);
            }
        }
    }
    let mut sorted = hops.clone();
    sorted.sort_unstable();
    let mid = sorted[n / 2];
    let side = |f: fn(usize, usize) -> bool| {
        let hops = &hops;
        (0..n as u32).filter(move |&v| f(hops[v as usize], mid))
    };
    side(|h, m| h < m)
        .chain(side(|h, m| h > m))
        .chain(side(|h, m| h == m))
        .collect()
}

/// A flat `lx × ly` (m) plate in the z = 0 plane with `nx × ny` cells, normals +z (open surface).
pub fn plate_grid(nx: usize, ny: usize, lx: f64, ly: f64) -> Surface {
    let mut v = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            v.push([lx * i as f64 / nx as f64, ly * j as f64 / ny as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut t = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            // Alternate the diagonal so the mesh has no preferred direction.
            if (i + j) % 2 == 0 {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                t.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                t.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    (v, t)
}

/// An icosphere of `radius` (m) centred at the origin after `subdivisions` 4-to-1 splits
/// (12, 42, 162, 642, 2562, 10242 vertices).
pub fn icosphere(subdivisions: u32, radius: f64) -> Surface {
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, p, 0.0],
        [1.0, p, 0.0],
        [-1.0, -p, 0.0],
        [1.0, -p, 0.0],
        [0.0, -1.0, p],
        [0.0, 1.0, p],
        [0.0, -1.0, -p],
        [0.0, 1.0, -p],
        [p, 0.0, -1.0],
        [p, 0.0, 1.0],
        [-p, 0.0, -1.0],
        [-p, 0.0, 1.0],
    ];
    let mut t: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |a: [f64; 3]| {
        let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        [a[0] / n, a[1] / n, a[2] / n]
    };
    for x in &mut v {
        *x = unit(*x);
    }
    for _ in 0..subdivisions {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut nt = Vec::with_capacity(t.len() * 4);
        for tri in &t {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[k] = *mid.entry(key).or_insert_with(|| {
                    let (pa, pb) = (v[a as usize], v[b as usize]);
                    v.push(unit([pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]]));
                    (v.len() - 1) as u32
                });
            }
            nt.push([tri[0], m[0], m[2]]);
            nt.push([tri[1], m[1], m[0]]);
            nt.push([tri[2], m[2], m[1]]);
            nt.push([m[0], m[1], m[2]]);
        }
        t = nt;
    }
    for x in &mut v {
        *x = [x[0] * radius, x[1] * radius, x[2] * radius];
    }
    (v, t)
}

/// The closed surface of an axis-aligned box `[0, size]` (m) with `n × n` cells per face
/// (6n² + 2 vertices), outward triangles.
pub fn box_surface(n: usize, size: [f64; 3]) -> Surface {
    let mut index: HashMap<[usize; 3], u32> = HashMap::new();
    let mut v = Vec::new();
    let mut t = Vec::new();
    let mut vid = |g: [usize; 3], v: &mut Vec<[f64; 3]>| -> u32 {
        *index.entry(g).or_insert_with(|| {
            v.push([0, 1, 2].map(|k| size[k] * g[k] as f64 / n as f64));
            (v.len() - 1) as u32
        })
    };
    // Each face: fixed axis `a` at side s ∈ {0, n}; (u, w) the other two axes, ordered so that
    // u × w points outward.
    for a in 0..3 {
        for side in [0, n] {
            let (mut u, mut w) = ((a + 1) % 3, (a + 2) % 3);
            if side == 0 {
                std::mem::swap(&mut u, &mut w);
            }
            for i in 0..n {
                for j in 0..n {
                    let g = |di: usize, dj: usize| {
                        let mut c = [0; 3];
                        c[a] = side;
                        c[u] = i + di;
                        c[w] = j + dj;
                        c
                    };
                    let q = [g(0, 0), g(1, 0), g(1, 1), g(0, 1)].map(|c| vid(c, &mut v));
                    if (i + j) % 2 == 0 {
                        t.push([q[0], q[1], q[2]]);
                        t.push([q[0], q[2], q[3]]);
                    } else {
                        t.push([q[0], q[1], q[3]]);
                        t.push([q[1], q[2], q[3]]);
                    }
                }
            }
        }
    }
    (v, t)
}

/// A valid [`ModesFile`] over `surface` with the given angular frequencies `omega` (rad/s,
/// ascending) and smooth random mode shapes (sums of a few sinusoids of position whose
/// wavelength shrinks with the mode index, amplitude ~0.05 m·kg^-1/2), seeded.
pub fn synthetic_base(surface: Surface, omega: &[f64], rayleigh: [f64; 2], seed: u64) -> ModesFile {
    let (vertices, triangles) = surface;
    let m = omega.len();
    let ns = vertices.len();
    let mut rng = SplitMix64(seed);
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(1e-9);
    let mut modes = vec![0.0; ns * 3 * m];
    for j in 0..m {
        let waves = 1.0 + j as f64 * 0.5;
        for axis in 0..3 {
            let mut terms = Vec::new();
            for _ in 0..3 {
                let dir = [
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                ];
                let k = std::f64::consts::PI * waves / size;
                terms.push((
                    dir.map(|d| d * k),
                    rng.range(0.0, std::f64::consts::TAU),
                    rng.range(0.01, 0.05),
                ));
            }
            for (v, p) in vertices.iter().enumerate() {
                let val: f64 = terms
                    .iter()
                    .map(|(k, ph, a)| a * (k[0] * p[0] + k[1] * p[1] + k[2] * p[2] + ph).sin())
                    .sum();
                modes[(v * 3 + axis) * m + j] = val;
            }
        }
    }
    ModesFile {
        eigenvalues: omega.iter().map(|w| w * w).collect(),
        surface_vertices: vertices,
        surface_triangles: triangles,
        surface_to_volume: (0..ns as u32).collect(),
        modes,
        material: MaterialSi {
            youngs: 1e9,
            poisson: 0.3,
            density: 700.0,
        },
        rayleigh,
        fixed_nodes: vec![],
        residuals: vec![0.0; m],
        meta: ModesMeta {
            format_version: FORMAT_VERSION,
            tool_version: "dcr-runtime testing".into(),
            source_hash: "sha256:synthetic".into(),
            params_hash: "sha256:synthetic".into(),
            bake_params: serde_json::json!({ "synthetic": true, "seed": seed }),
            volume_nodes: ns,
            volume_tets: 0,
            rigid_modes_excluded: 6,
            mass_kg: 1.0,
            reoriented_tets: 0,
            accuracy: None,
        },
        precision: ModesPrecision::F64,
        transfer: None,
        surface_order: None,
        quadratic: None,
    }
}

/// `m` angular frequencies (rad/s) spread geometrically from `omega_min` to `omega_max`.
pub fn geometric_omegas(m: usize, omega_min: f64, omega_max: f64) -> Vec<f64> {
    (0..m)
        .map(|j| {
            if m == 1 {
                omega_min
            } else {
                omega_min * (omega_max / omega_min).powf(j as f64 / (m - 1) as f64)
            }
        })
        .collect()
}

/// A small ready-made base: a 1 m × 0.6 m plate (12 × 8 cells, 117 vertices), 8 modes from
/// 60 to 900 rad/s, Rayleigh [2, 1e-5].
pub fn plate_base() -> ModesFile {
    synthetic_base(
        plate_grid(12, 8, 1.0, 0.6),
        &geometric_omegas(8, 60.0, 900.0),
        [2.0, 1e-5],
        7,
    )
}
