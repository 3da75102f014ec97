//! Exploratory: where does the interpolation of peaks across triangles fail, and what fixes it?
//! `cargo run --release -p dcr-lab --example interp_study -- OBJECT`

use std::path::Path;

use dcr_runtime::filter::{damping_ratio, ModeFilter};
use dcr_runtime::rng::SplitMix64;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use modal_bake::full_order::{FullOrderSystem, MaterialSi, ModalAll, SystemParams};
use modal_bake::mesh::{read_mesh, TetMesh};

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    s[s.len() / 2]
}
fn maxv(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, b| a.max(b.abs()))
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or("ground".into());
    let (mesh, fixed, mat, up, bx): (TetMesh, Vec<String>, MaterialSi, usize, Option<[f64; 6]>) =
        match which.as_str() {
            "ground" => (
                read_mesh(Path::new("data/scenes/ground.msh")).unwrap(),
                vec!["bottom".into(), "sides".into()],
                MaterialSi {
                    youngs: 10e9,
                    poisson: 0.3,
                    density: 500.0,
                },
                1,
                Some([-7.5, -0.5, -5.0, 7.5, 0.5, 0.0]),
            ),
            "table" => (
                read_mesh(Path::new("data/scenes/table.msh")).unwrap(),
                vec!["feet".into()],
                MaterialSi {
                    youngs: 1.1e9,
                    poisson: 0.3,
                    density: 770.0,
                },
                1,
                None,
            ),
            "slab" => (
                TetMesh::structured_box([20, 20, 3], [4.0, 4.0, 0.3]),
                vec!["zmin".into()],
                MaterialSi {
                    youngs: 10e9,
                    poisson: 0.3,
                    density: 500.0,
                },
                2,
                None,
            ),
            "floor" => (
                read_mesh(Path::new("data/scenes/floor.msh")).unwrap(),
                vec!["edges".into()],
                MaterialSi {
                    youngs: 10e9,
                    poisson: 0.3,
                    density: 540.0,
                },
                1,
                None,
            ),
            _ => panic!("object"),
        };
    let sp = SystemParams {
        material: mat,
        fixed,
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let sys = FullOrderSystem::new(mesh, &sp, &which).unwrap();
    let ma = ModalAll::new(&sys, 8000).unwrap();
    eprintln!(
        "{which}: {} dofs, {} modes, {:.1} s",
        sys.n(),
        ma.eigenvalues.len(),
        t0.elapsed().as_secs_f64()
    );
    let s = &sys.surface;
    let nv = s.vertices.len();
    let m = ma.eigenvalues.len();
    // Normal rows per surface vertex (modal coordinates).
    let mut rows = vec![0.0; nv * m];
    let mut free = vec![true; nv];
    for v in 0..nv {
        let vol = s.surface_to_volume[v];
        for ax in 0..3 {
            match sys.map.free_index(3 * vol + ax) {
                Some(i) => {
                    for j in 0..m {
                        rows[v * m + j] += s.normals[v][ax] * ma.vectors[(i, j)];
                    }
                }
                None => free[v] = false,
            }
        }
    }
    // Region: upward, in the box, free.
    let in_region = |v: usize| {
        let p = s.vertices[v];
        free[v]
            && s.normals[v][up] >= 0.5
            && bx.is_none_or(|b| (0..3).all(|k| p[k] >= b[k] && p[k] <= b[k + 3]))
    };
    let tris: Vec<usize> = (0..s.triangles.len())
        .filter(|&t| s.triangles[t].iter().all(|&v| in_region(v as usize)))
        .collect();
    let verts: Vec<usize> = (0..nv).filter(|&v| in_region(v)).collect();
    // Time grid: 4 samples per period of the top mode.
    let h = 0.01;
    let wmax = ma.eigenvalues[m - 1].sqrt();
    let steps = dcr_runtime::filter::samples_per_step(h, std::f64::consts::FRAC_PI_2 / wmax / 2.0);
    let dt = h / steps as f64;
    eprintln!(
        "steps {steps}, dt {dt:.2e}, region {} vertices, {} triangles",
        verts.len(),
        tris.len()
    );
    let g = Mat::from_fn(steps, m, |k, l| {
        let w = ma.eigenvalues[l].sqrt();
        ModeFilter::new(w, damping_ratio(w, sp.rayleigh), dt).impulse_response((k + 1) as f64 * dt)
    });
    // Points: (triangle, bary).
    let mut rng = SplitMix64(2);
    let mut pick = |n: usize| -> Vec<(usize, [f64; 3], &'static str)> {
        (0..n)
            .map(|k| match 3 * k / n {
                0 => {
                    let v = verts[rng.below(verts.len())];
                    let t = tris
                        .iter()
                        .copied()
                        .find(|&t| s.triangles[t].contains(&(v as u32)))
                        .unwrap();
                    let c = s.triangles[t].iter().position(|&x| x == v as u32).unwrap();
                    let mut b = [0.0; 3];
                    b[c] = 1.0;
                    (t, b, "vertex")
                }
                1 => (tris[rng.below(tris.len())], [1.0 / 3.0; 3], "centroid"),
                _ => {
                    let (mut a, mut b) = (rng.next_f64(), rng.next_f64());
                    if a + b > 1.0 {
                        (a, b) = (1.0 - a, 1.0 - b);
                    }
                    (tris[rng.below(tris.len())], [a, b, 1.0 - a - b], "random")
                }
            })
            .collect()
    };
    let imps = pick(6);
    let cons = pick(24);
    let pos = |t: usize, b: [f64; 3]| {
        let v = s.triangles[t].map(|i| s.vertices[i as usize]);
        [0, 1, 2].map(|k| b[0] * v[0][k] + b[1] * v[1][k] + b[2] * v[2][k])
    };
    // Series of a point pair (vertex-level exact, each vertex its own normal):
    // y(t) = Σ_l (Σ_a β_a r_al)(Σ_b γ_b r_bl) g_l(t).
    let row_of = |t: usize, b: [f64; 3]| -> Vec<f64> {
        let mut r = vec![0.0; m];
        for (k, &v) in s.triangles[t].iter().enumerate() {
            for j in 0..m {
                r[j] += b[k] * rows[v as usize * m + j];
            }
        }
        r
    };
    let series = |ra: &[f64], rb: &[f64]| -> Vec<f64> {
        let c = Mat::from_fn(m, 1, |l, _| ra[l] * rb[l]);
        let mut y = Mat::<f64>::zeros(steps, 1);
        matmul(
            y.as_mut(),
            Accum::Replace,
            g.as_ref(),
            c.as_ref(),
            1.0,
            Par::Seq,
        );
        (0..steps).map(|k| y[(k, 0)]).collect()
    };
    let peak = |y: &[f64]| y.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    // P2 node rows of a point.
    let p2 = |t: usize, b: [f64; 3]| -> Vec<(Vec<f64>, f64)> {
        let tri = s.triangles[t].map(|v| v as usize);
        let mut out = Vec::new();
        for k in 0..3 {
            out.push((
                rows[tri[k] * m..(tri[k] + 1) * m].to_vec(),
                b[k] * (2.0 * b[k] - 1.0),
            ));
        }
        for k in 0..3 {
            let (a, c) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let r: Vec<f64> = (0..m)
                .map(|j| 0.5 * (rows[a * m + j] + rows[c * m + j]))
                .collect();
            out.push((r, 4.0 * b[(k + 1) % 3] * b[(k + 2) % 3]));
        }
        out
    };
    // Nodes of a scheme: (barycentric position, weight) in triangle t.
    let p3 = |b: [f64; 3]| -> Vec<([f64; 3], f64)> {
        let mut out = Vec::new();
        for i in 0..3 {
            let mut e = [0.0; 3];
            e[i] = 1.0;
            out.push((e, 0.5 * b[i] * (3.0 * b[i] - 1.0) * (3.0 * b[i] - 2.0)));
        }
        for i in 0..3 {
            for j in 0..3 {
                if i != j {
                    let mut e = [0.0; 3];
                    e[i] = 2.0 / 3.0;
                    e[j] = 1.0 / 3.0;
                    out.push((e, 4.5 * b[i] * b[j] * (3.0 * b[i] - 1.0)));
                }
            }
        }
        out.push(([1.0 / 3.0; 3], 27.0 * b[0] * b[1] * b[2]));
        out
    };
    // P2 on the triangle split into 4 (corner triangles and the middle one).
    let p2sub = |b: [f64; 3]| -> Vec<([f64; 3], f64)> {
        // Which sub-triangle: corner k if b[k] >= 1/2, else middle.
        let corner = (0..3).find(|&k| b[k] >= 0.5);
        let (verts, lb): ([[f64; 3]; 3], [f64; 3]) = match corner {
            Some(k) => {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                let mut vk = [0.0; 3];
                vk[k] = 1.0;
                let mut mki = [0.0; 3];
                mki[k] = 0.5;
                mki[i] = 0.5;
                let mut mkj = [0.0; 3];
                mkj[k] = 0.5;
                mkj[j] = 0.5;
                // local coords: b = lk vk + li mki + lj mkj
                let li = 2.0 * b[i];
                let lj = 2.0 * b[j];
                ([vk, mki, mkj], [1.0 - li - lj, li, lj])
            }
            None => {
                // middle: vertices m01 (opposite 2), m12 (opp 0), m20 (opp 1)
                let m12 = [0.0, 0.5, 0.5];
                let m20 = [0.5, 0.0, 0.5];
                let m01 = [0.5, 0.5, 0.0];
                // b = l0 m12 + l1 m20 + l2 m01 -> b0 = (l1+l2)/2 -> l0 = 1 - 2 b0
                (
                    [m12, m20, m01],
                    [1.0 - 2.0 * b[0], 1.0 - 2.0 * b[1], 1.0 - 2.0 * b[2]],
                )
            }
        };
        let mut out = Vec::new();
        for k in 0..3 {
            out.push((verts[k], lb[k] * (2.0 * lb[k] - 1.0)));
        }
        for k in 0..3 {
            let (a, c) = ((k + 1) % 3, (k + 2) % 3);
            let pos = [0, 1, 2].map(|x| 0.5 * (verts[a][x] + verts[c][x]));
            out.push((pos, 4.0 * lb[a] * lb[c]));
        }
        out
    };
    let scheme_peak =
        |ti: usize, ni: &[([f64; 3], f64)], tc: usize, nc: &[([f64; 3], f64)]| -> f64 {
            let mut q = 0.0;
            for (ba, wa) in ni {
                if *wa == 0.0 {
                    continue;
                }
                let ra = row_of(ti, *ba);
                for (bb, wb) in nc {
                    if *wb != 0.0 {
                        q += wa * wb * peak(&series(&ra, &row_of(tc, *bb)));
                    }
                }
            }
            q.max(0.0)
        };
    let p2b = |b: [f64; 3]| -> Vec<([f64; 3], f64)> {
        let bub = b[0] * b[1] * b[2];
        let mut out = Vec::new();
        for i in 0..3 {
            let mut e = [0.0; 3];
            e[i] = 1.0;
            out.push((e, b[i] * (2.0 * b[i] - 1.0) + 3.0 * bub));
        }
        for k in 0..3 {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let mut e = [0.0; 3];
            e[i] = 0.5;
            e[j] = 0.5;
            out.push((e, 4.0 * b[i] * b[j] - 12.0 * bub));
        }
        out.push(([1.0 / 3.0; 3], 27.0 * bub));
        out
    };
    // P3 with each table entry's peak taken on every other sample (oversample 1).
    let peak2 = |y: &[f64]| {
        y.iter()
            .skip(1)
            .step_by(2)
            .fold(0.0f64, |a, b| a.max(b.abs()))
    };
    let scheme_peak2 =
        |ti: usize, ni: &[([f64; 3], f64)], tc: usize, nc: &[([f64; 3], f64)]| -> f64 {
            let mut q = 0.0;
            for (ba, wa) in ni {
                if *wa == 0.0 {
                    continue;
                }
                let ra = row_of(ti, *ba);
                for (bb, wb) in nc {
                    if *wb != 0.0 {
                        q += wa * wb * peak2(&series(&ra, &row_of(tc, *bb)));
                    }
                }
            }
            q.max(0.0)
        };
    let mut err_p2b = vec![];
    let mut err_p3c = vec![];
    let mut err_p3 = vec![];
    let mut err_sub = vec![];
    println!("kind_i kind_c dist truth p1blend p2 p3 p2sub");
    let mut err_p2 = vec![];
    let mut err_p1 = vec![];
    for &(ti, bi, ki) in &imps {
        let ri = row_of(ti, bi);
        let pi = pos(ti, bi);
        let ni = p2(ti, bi);
        for &(tc, bc, kc) in &cons {
            let pc = pos(tc, bc);
            let d = ((pi[0] - pc[0]).powi(2) + (pi[1] - pc[1]).powi(2) + (pi[2] - pc[2]).powi(2))
                .sqrt();
            if d < 0.1 {
                continue;
            }
            let rc = row_of(tc, bc);
            let truth = peak(&series(&ri, &rc));
            // P1 blend of vertex peaks.
            let tri_i = s.triangles[ti].map(|v| v as usize);
            let tri_c = s.triangles[tc].map(|v| v as usize);
            let mut p1 = 0.0;
            for a in 0..3 {
                for b in 0..3 {
                    if bi[a] * bc[b] != 0.0 {
                        p1 += bi[a]
                            * bc[b]
                            * peak(&series(
                                &rows[tri_i[a] * m..(tri_i[a] + 1) * m],
                                &rows[tri_c[b] * m..(tri_c[b] + 1) * m],
                            ));
                    }
                }
            }
            let nc = p2(tc, bc);
            let mut q2 = 0.0;
            for (ra, wa) in &ni {
                for (rb, wb) in &nc {
                    if wa * wb != 0.0 {
                        q2 += wa * wb * peak(&series(ra, rb));
                    }
                }
            }
            let q2 = q2.max(0.0);
            let e2 = 100.0 * (q2 - truth) / truth;
            let e1 = 100.0 * (p1 - truth) / truth;
            err_p2.push(e2);
            err_p1.push(e1);
            let e3 = 100.0 * (scheme_peak(ti, &p3(bi), tc, &p3(bc)) - truth) / truth;
            let es = 100.0 * (scheme_peak(ti, &p2sub(bi), tc, &p2sub(bc)) - truth) / truth;
            err_p3.push(e3);
            err_sub.push(es);
            err_p2b.push(100.0 * (scheme_peak(ti, &p2b(bi), tc, &p2b(bc)) - truth) / truth);
            err_p3c.push(100.0 * (scheme_peak2(ti, &p3(bi), tc, &p3(bc)) - truth) / truth);
            println!("{ki:8} {kc:8} {d:7.3} {truth:.3e} {e1:+7.1} {e2:+7.1} {e3:+7.1} {es:+7.1}");
        }
    }
    let stat = |e: &[f64]| {
        (
            median(&e.iter().map(|x| x.abs()).collect::<Vec<_>>()),
            maxv(e),
        )
    };
    println!(
        "P3 {:?} P2sub {:?} P2+bubble {:?} P3 at oversample 1 {:?}",
        stat(&err_p3),
        stat(&err_sub),
        stat(&err_p2b),
        stat(&err_p3c)
    );
    println!(
        "P1: median {:.1} max {:.1}; P2: median {:.1} max {:.1}",
        median(&err_p1.iter().map(|x| x.abs()).collect::<Vec<_>>()),
        maxv(&err_p1),
        median(&err_p2.iter().map(|x| x.abs()).collect::<Vec<_>>()),
        maxv(&err_p2)
    );
}
