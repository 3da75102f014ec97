//! FEM assembly and eigensolver: invariants over a corpus of meshes, a dense reference,
//! analytic beam/rod frequencies, and bit-determinism across rayon pools.
//!
//! Run in release mode (faer is ~100× slower in debug):
//! `cargo test --release -p modal-bake --test fem_eigen`.

use std::f64::consts::PI;

use faer::sparse::SparseColMat;
use faer::{Mat, MatRef, Par, Side};
use modal_bake::eigen::{default_shift, solve_lowest, EigenError, EigenParams, EigenResult};
use modal_bake::fem::{
    assemble_clamped, assemble_mass, assemble_stiffness, reduce_fixed, rigid_body_modes, DofMap,
    DofMapError, Material, MaterialError,
};
use modal_bake::mesh::{signed_volume, TetMesh};

fn steelish() -> Material {
    Material::new(2.0e9, 0.3, 1200.0).unwrap()
}

/// Seeded splitmix64 in [−1, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64) / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// A structured box with every node moved by up to `amp`·h per axis (seeded), still positively
/// oriented.
fn distorted_box(n: [usize; 3], l: [f64; 3], amp: f64, seed: u64) -> TetMesh {
    let mut mesh = TetMesh::structured_box(n, l);
    let mut rng = Rng(seed);
    for p in &mut mesh.nodes {
        for a in 0..3 {
            p[a] += amp * l[a] / n[a] as f64 * rng.next();
        }
    }
    for t in &mesh.tets {
        let v = signed_volume(
            mesh.nodes[t[0]],
            mesh.nodes[t[1]],
            mesh.nodes[t[2]],
            mesh.nodes[t[3]],
        );
        assert!(v > 0.0, "distortion inverted a tetrahedron");
    }
    mesh
}

fn corpus() -> Vec<(&'static str, TetMesh)> {
    vec![
        (
            "cube 1x1x1",
            TetMesh::structured_box([1, 1, 1], [1.0, 1.0, 1.0]),
        ),
        (
            "box 3x2x4",
            TetMesh::structured_box([3, 2, 4], [0.3, 0.2, 0.5]),
        ),
        (
            "beam 8x2x2",
            TetMesh::structured_box([8, 2, 2], [1.0, 0.1, 0.1]),
        ),
        (
            "distorted 4x3x3",
            distorted_box([4, 3, 3], [0.4, 0.3, 0.3], 0.2, 7),
        ),
    ]
}

fn dense(a: &SparseColMat<usize, f64>) -> Mat<f64> {
    a.to_dense()
}

fn frob(a: MatRef<'_, f64>) -> f64 {
    a.norm_l2()
}

/// Eigenvalues of K u = λ M u by the dense route: M = LLᵀ, eig(L⁻¹ K L⁻ᵀ).
fn dense_generalized_eigenvalues(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
) -> Vec<f64> {
    let kd = dense(k);
    let md = dense(m);
    let llt = md.llt(Side::Lower).expect("M positive definite");
    let l = llt.L();
    let mut x = kd.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
    let mut y = x.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, y.as_mut(), Par::Seq);
    let c = Mat::from_fn(y.nrows(), y.ncols(), |i, j| 0.5 * (y[(i, j)] + y[(j, i)]));
    c.self_adjoint_eigenvalues(Side::Lower).unwrap()
}

fn m_orthonormality_error(m: &SparseColMat<usize, f64>, u: MatRef<'_, f64>) -> f64 {
    let g = u.transpose() * (m * u);
    let mut worst = 0.0f64;
    for i in 0..g.nrows() {
        for j in 0..g.ncols() {
            let e = g[(i, j)] - if i == j { 1.0 } else { 0.0 };
            worst = worst.max(e.abs());
        }
    }
    worst
}

fn clamped(
    mesh: &TetMesh,
    mat: &Material,
) -> (DofMap, SparseColMat<usize, f64>, SparseColMat<usize, f64>) {
    let k = assemble_stiffness(mesh, mat);
    let m = assemble_mass(mesh, mat, false);
    reduce_fixed(&k, &m, &mesh.groups["xmin"]).unwrap()
}

fn solve(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    p: &EigenParams,
) -> EigenResult {
    solve_lowest(k, m, p, &mut |_| {}).unwrap()
}

// ---------------------------------------------------------------------------------------------
// Assembly invariants

/// 1ᵀ M_axis 1 = ρV for consistent and lumped mass, on every corpus mesh.
#[test]
fn mass_sums_to_rho_v_per_axis() {
    let mat = steelish();
    for (name, mesh) in corpus() {
        let rv = mat.density * mesh.volume();
        for lumped in [false, true] {
            let m = assemble_mass(&mesh, &mat, lumped);
            for axis in 0..3 {
                let mut s = 0.0;
                for t in m.triplet_iter() {
                    let (i, j, v) = (t.row, t.col, *t.val);
                    if i % 3 == axis && j % 3 == axis {
                        s += v;
                    }
                    assert!(i % 3 == j % 3 || v == 0.0, "mass couples axes");
                }
                assert!(
                    (s - rv).abs() <= 1e-12 * rv,
                    "{name} lumped={lumped} axis {axis}: {s} vs {rv}"
                );
            }
        }
    }
}

/// K and M are bit-exactly symmetric, K has a non-negative diagonal.
#[test]
fn matrices_are_symmetric() {
    let mat = steelish();
    for (name, mesh) in corpus() {
        for a in [
            assemble_stiffness(&mesh, &mat),
            assemble_mass(&mesh, &mat, false),
        ] {
            let d = dense(&a);
            for i in 0..d.nrows() {
                assert!(d[(i, i)] > 0.0, "{name}: diagonal {i}");
                for j in 0..i {
                    assert_eq!(
                        d[(i, j)].to_bits(),
                        d[(j, i)].to_bits(),
                        "{name}: ({i},{j})"
                    );
                }
            }
        }
    }
}

/// K annihilates the six rigid motions: ‖K R‖ ≤ 1e-12 ‖K‖ ‖R‖; and R is really rank 6.
#[test]
fn stiffness_annihilates_rigid_motions() {
    let mat = steelish();
    for (name, mesh) in corpus() {
        let k = assemble_stiffness(&mesh, &mat);
        let r = rigid_body_modes(&mesh);
        let kr = &k * &r;
        let rel = frob(kr.as_ref()) / (frob(dense(&k).as_ref()) * frob(r.as_ref()));
        assert!(rel < 1e-13, "{name}: ‖KR‖/‖K‖‖R‖ = {rel:e}");
        let g = r.transpose() * &r;
        let ev = g.self_adjoint_eigenvalues(Side::Lower).unwrap();
        assert!(ev[0] > 1e-6 * ev[5], "{name}: rigid modes degenerate");
        // And K has exactly a 6-dimensional null space (checked densely on small meshes).
        if mesh.dofs() <= 300 {
            let m = assemble_mass(&mesh, &mat, false);
            let lam = dense_generalized_eigenvalues(&k, &m);
            assert!(lam[5].abs() < 1e-9 * lam[6], "{name}: {:?}", &lam[..7]);
            assert!(lam[6] > 0.0);
        }
    }
}

/// Assembly is bit-identical on rayon pools of 1 and 2 threads.
#[test]
fn assembly_is_deterministic_across_thread_counts() {
    let mat = steelish();
    let mesh = distorted_box([12, 6, 5], [1.2, 0.6, 0.5], 0.15, 3);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let k = assemble_stiffness(&mesh, &mat);
            let m = assemble_mass(&mesh, &mat, false);
            let ml = assemble_mass(&mesh, &mat, true);
            let bits = |a: &SparseColMat<usize, f64>| {
                a.val().iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            };
            (
                bits(&k),
                bits(&m),
                bits(&ml),
                k.symbolic().row_idx().to_vec(),
            )
        })
    };
    assert_eq!(run(1), run(2));
}

/// `assemble_clamped` is bit for bit `reduce_fixed` of the full matrices (pattern and
/// values), for consistent and lumped mass, clamped or free, on pools of 1, 2 and 3 threads.
#[test]
fn clamped_assembly_equals_restricted_full_assembly() {
    let mat = steelish();
    let mesh = distorted_box([12, 6, 5], [1.2, 0.6, 0.5], 0.15, 3);
    let bits = |a: &SparseColMat<usize, f64>| {
        (
            a.symbolic().col_ptr().to_vec(),
            a.symbolic().row_idx().to_vec(),
            a.val().iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        )
    };
    let ends: Vec<usize> = mesh.groups["xmin"]
        .iter()
        .chain(&mesh.groups["xmax"])
        .copied()
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    for fixed in [
        vec![],
        mesh.groups["xmin"].clone(),
        ends,
        vec![0, 7, 8, 200],
    ] {
        for lumped in [false, true] {
            let k = assemble_stiffness(&mesh, &mat);
            let m = assemble_mass(&mesh, &mat, lumped);
            let (map, kf, mf) = reduce_fixed(&k, &m, &fixed).unwrap();
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let (map2, kc, mc) =
                    pool.install(|| assemble_clamped(&mesh, &mat, lumped, &fixed).unwrap());
                let what = format!("{} fixed, lumped {lumped}, {threads} threads", fixed.len());
                assert_eq!(map2, map, "{what}");
                assert!(bits(&kc) == bits(&kf), "{what}: K");
                assert!(bits(&mc) == bits(&mf), "{what}: M");
            }
        }
    }
    assert!(matches!(
        assemble_clamped(&mesh, &mat, false, &[3, 2]),
        Err(DofMapError::NotSorted { .. })
    ));
}

#[test]
fn material_and_dof_map_validation() {
    assert!(matches!(
        Material::new(-1.0, 0.3, 1.0),
        Err(MaterialError::Youngs(_))
    ));
    assert!(matches!(
        Material::new(1.0, 0.5, 1.0),
        Err(MaterialError::Poisson(_))
    ));
    assert!(matches!(
        Material::new(1.0, -1.0, 1.0),
        Err(MaterialError::Poisson(_))
    ));
    assert!(matches!(
        Material::new(1.0, 0.3, f64::NAN),
        Err(MaterialError::Density(_))
    ));
    assert!(matches!(
        DofMap::new(4, &[1, 1]),
        Err(DofMapError::NotSorted { position: 1 })
    ));
    assert!(matches!(
        DofMap::new(4, &[4]),
        Err(DofMapError::NodeOutOfRange { node: 4, .. })
    ));
    let map = DofMap::new(3, &[1]).unwrap();
    assert_eq!(map.free_dofs(), &[0, 1, 2, 6, 7, 8]);
    assert_eq!(map.free_index(7), Some(4));
    assert_eq!(map.free_index(4), None);
    let u = Mat::from_fn(6, 1, |i, _| i as f64 + 1.0);
    let full = map.expand(u.as_ref());
    assert_eq!(
        full.col(0).iter().copied().collect::<Vec<_>>(),
        vec![1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 4.0, 5.0, 6.0]
    );
}

// ---------------------------------------------------------------------------------------------
// Eigensolver against a dense generalized solve

/// Lanczos eigenvalues equal the dense generalized solve to 1e-9 relative, on clamped and
/// free-free small meshes (sizes above the solver's dense cut-off, so Lanczos runs).
#[test]
fn lanczos_matches_dense_generalized_solve() {
    let mat = steelish();
    for (name, mesh, free) in [
        (
            "beam 8x2x2 clamped",
            TetMesh::structured_box([8, 2, 2], [1.0, 0.1, 0.1]),
            false,
        ),
        (
            "distorted 4x3x3 clamped",
            distorted_box([4, 3, 3], [0.4, 0.3, 0.3], 0.2, 7),
            false,
        ),
        (
            "box 3x3x3 free",
            TetMesh::structured_box([3, 3, 3], [0.3, 0.3, 0.3]),
            true,
        ),
        (
            "distorted 4x3x3 free",
            distorted_box([4, 3, 3], [0.4, 0.3, 0.3], 0.2, 11),
            true,
        ),
    ] {
        let (k, m, shift, nev) = if free {
            let k = assemble_stiffness(&mesh, &mat);
            let m = assemble_mass(&mesh, &mat, false);
            (k, m, default_shift(&mesh, &mat), 12)
        } else {
            let (_, k, m) = clamped(&mesh, &mat);
            (k, m, 0.0, 8)
        };
        assert!(k.nrows() <= 300);
        let p = EigenParams {
            nev,
            shift,
            block: 4,
            ..Default::default()
        };
        let res = solve(&k, &m, &p);
        assert!(!res.info.dense, "{name}: expected the Lanczos path");
        let reference = dense_generalized_eigenvalues(&k, &m);
        let scale = reference[nev - 1];
        #[allow(clippy::needless_range_loop)]
        for i in 0..nev {
            let err = (res.eigenvalues[i] - reference[i]).abs();
            // Rigid modes (λ ≈ 0) are compared on the scale of the spectrum.
            let denom = if free && i < 6 { scale } else { reference[i] };
            assert!(
                err <= 1e-9 * denom,
                "{name} mode {i}: {} vs {}",
                res.eigenvalues[i],
                reference[i]
            );
        }
        assert!(
            m_orthonormality_error(&m, res.vectors.as_ref()) <= 1e-10,
            "{name}"
        );
        assert!(
            res.residuals.iter().all(|&r| r <= 1e-8),
            "{name}: {:?}",
            res.residuals
        );
    }
}

/// Free-free cube: exactly six near-zero modes (|λ| ≪ λ₇) spanning the rigid motions; the
/// elastic modes meet the tolerance; modes are M-orthonormal; repeated eigenvalues (cube
/// symmetry) are fine.
#[test]
fn free_free_cube_has_six_rigid_modes() {
    let mat = steelish();
    let mesh = TetMesh::structured_box([6, 6, 6], [0.5, 0.5, 0.5]);
    let k = assemble_stiffness(&mesh, &mat);
    let m = assemble_mass(&mesh, &mat, false);
    let p = EigenParams {
        nev: 26,
        shift: default_shift(&mesh, &mat),
        ..Default::default()
    };
    let res = solve(&k, &m, &p);
    let l7 = res.eigenvalues[6];
    for i in 0..6 {
        assert!(
            res.eigenvalues[i].abs() < 1e-9 * l7,
            "rigid {i}: {} vs λ7 {l7}",
            res.eigenvalues[i]
        );
    }
    assert!(l7 > 0.0);
    for w in res.eigenvalues.windows(2) {
        assert!(w[0] <= w[1]);
    }
    // The first six modes span the rigid motions: M-projecting R onto them keeps R.
    let r = rigid_body_modes(&mesh);
    let u6 = res.vectors.as_ref().subcols(0, 6);
    let proj = u6 * (u6.transpose() * (&m * &r));
    let rel = frob((&proj - &r).as_ref()) / frob(r.as_ref());
    assert!(rel < 1e-8, "rigid span error {rel:e}");
    assert!(m_orthonormality_error(&m, res.vectors.as_ref()) <= 1e-10);
    assert!(
        res.residuals.iter().all(|&x| x <= 1e-8),
        "{:?}",
        res.residuals
    );
    assert!(res.residuals[6..]
        .iter()
        .all(|&x| x <= p.tol.max(8.0 * 1e-16 * 1e6)));
    // UᵀKU is diagonal with the eigenvalues.
    let kq = res.vectors.transpose() * (&k * &res.vectors);
    for i in 0..26 {
        for j in 0..26 {
            let expect = if i == j { res.eigenvalues[i] } else { 0.0 };
            assert!(
                (kq[(i, j)] - expect).abs() <= 1e-8 * res.eigenvalues[25],
                "Kq[{i},{j}]"
            );
        }
    }
    // Sign convention: the largest-magnitude entry of each mode is positive.
    for j in 0..26 {
        let col = res.vectors.col(j);
        let mut best = 0.0f64;
        let mut val = 0.0;
        for &x in col.iter() {
            if x.abs() > best {
                best = x.abs();
                val = x;
            }
        }
        assert!(val > 0.0);
    }
}

// ---------------------------------------------------------------------------------------------
// Analytics

/// Cantilever square beam (L = 1 m, 0.1 × 0.1 m, clamped at x = 0): the first bending frequency
/// decreases monotonically under refinement toward Euler–Bernoulli/Timoshenko (P1 is stiff, so
/// from above), with an estimated convergence order ≥ 1.
#[test]
fn cantilever_first_bending_converges_from_above() {
    let mat = Material::new(1.0e9, 0.3, 1000.0).unwrap();
    let (l, a) = (1.0, 0.1);
    // Euler–Bernoulli: f = (β₁L)²/(2π L²) √(EI/ρA), β₁L = 1.875104, I = a⁴/12.
    let f_eb = 1.875104068711961f64.powi(2) / (2.0 * PI * l * l)
        * (mat.youngs * a * a / 12.0 / mat.density).sqrt();
    let mut f = Vec::new();
    for r in [1usize, 2, 4, 8] {
        let mesh = TetMesh::structured_box([10 * r, r, r], [l, a, a]);
        let (_, k, m) = clamped(&mesh, &mat);
        let res = solve(
            &k,
            &m,
            &EigenParams {
                nev: 2,
                ..Default::default()
            },
        );
        let f1 = res.frequencies_hz()[0];
        println!(
            "cantilever {}x{r}x{r}: {} dofs, f1 = {f1:.4} Hz (EB {f_eb:.4} Hz, +{:.2}%)",
            10 * r,
            k.nrows(),
            100.0 * (f1 / f_eb - 1.0)
        );
        f.push(f1);
    }
    for w in f.windows(2) {
        assert!(w[1] < w[0], "not monotone: {f:?}");
    }
    // Timoshenko shear/rotary inertia lowers the exact value ~0.5% below EB at L/a = 10.
    assert!(*f.last().unwrap() > 0.98 * f_eb, "{f:?} vs EB {f_eb}");
    let n = f.len();
    let order = ((f[n - 3] - f[n - 2]) / (f[n - 2] - f[n - 1])).log2();
    println!("estimated convergence order of f1 in h: {order:.2}");
    assert!(order > 1.0, "order {order}");
    // Richardson extrapolation lands within 2% of Euler–Bernoulli.
    let ratio = 2f64.powf(order);
    let f_inf = f[n - 1] + (f[n - 1] - f[n - 2]) / (ratio - 1.0);
    println!(
        "extrapolated f1 = {f_inf:.4} Hz ({:+.2}% vs EB)",
        100.0 * (f_inf / f_eb - 1.0)
    );
    assert!((f_inf / f_eb - 1.0).abs() < 0.02);
}

/// Clamped-free rod with ν = 0: the first axial mode is f = √(E/ρ) / (4L) within 2%, found
/// with the max-frequency mode (all modes below 300 Hz) and identified by its x-motion.
#[test]
fn clamped_free_rod_first_axial_mode() {
    let mat = Material::new(1.0e9, 0.0, 1000.0).unwrap();
    let l = 1.0;
    let f_axial = (mat.youngs / mat.density).sqrt() / (4.0 * l);
    let mesh = TetMesh::structured_box([40, 3, 3], [l, 0.1, 0.1]);
    let (map, k, m) = clamped(&mesh, &mat);
    let p = EigenParams {
        nev: 0,
        max_freq_hz: Some(300.0),
        ..Default::default()
    };
    let res = solve(&k, &m, &p);
    let f = res.frequencies_hz();
    assert!(f.iter().all(|&x| x < 300.0));
    assert!(!f.is_empty());
    let full = map.expand(res.vectors.as_ref());
    let mut best = (0.0, 0);
    for j in 0..full.ncols() {
        let (mut ex, mut e) = (0.0, 0.0);
        for i in 0..full.nrows() {
            let v = full[(i, j)] * full[(i, j)];
            e += v;
            if i % 3 == 0 {
                ex += v;
            }
        }
        if ex / e > best.0 {
            best = (ex / e, j);
        }
    }
    println!(
        "modes below 300 Hz: {:?}; axial = mode {} ({:.1}% x-motion), {:.3} Hz vs {f_axial:.3} Hz",
        f,
        best.1,
        100.0 * best.0,
        f[best.1]
    );
    assert!(best.0 > 0.9);
    assert!((f[best.1] / f_axial - 1.0).abs() < 0.02);
    // Max-frequency mode really found everything below the limit: compare with nev mode.
    let all = solve(
        &k,
        &m,
        &EigenParams {
            nev: f.len() + 1,
            ..Default::default()
        },
    );
    assert!(all.frequencies_hz()[f.len()] >= 300.0);
    for (a, b) in all.eigenvalues.iter().zip(&res.eigenvalues) {
        assert!((a - b).abs() <= 1e-9 * a);
    }
}

// ---------------------------------------------------------------------------------------------
// Errors

#[test]
fn shift_above_lowest_eigenvalue_is_a_factorization_error() {
    let mat = steelish();
    let mesh = TetMesh::structured_box([10, 2, 2], [1.0, 0.1, 0.1]);
    let (_, k, m) = clamped(&mesh, &mat);
    let lam1 = solve(
        &k,
        &m,
        &EigenParams {
            nev: 1,
            ..Default::default()
        },
    )
    .eigenvalues[0];
    let p = EigenParams {
        nev: 4,
        shift: 2.0 * lam1,
        ..Default::default()
    };
    assert!(matches!(
        solve_lowest(&k, &m, &p, &mut |_| {}),
        Err(EigenError::Factorization(_))
    ));
    // On a problem this small, what Lanczos cannot meet in its steps the dense path solves.
    let p = EigenParams {
        nev: 20,
        max_iters: 2,
        ..Default::default()
    };
    let r = solve(&k, &m, &p);
    assert!(r.info.dense && r.eigenvalues.len() == 20);
    // Above the dense path's size (2000 free dofs), the step limit is an error.
    let big = TetMesh::structured_box([24, 6, 6], [1.0, 0.1, 0.1]);
    let (_, kb, mb) = clamped(&big, &mat);
    assert!(kb.nrows() > 2000);
    match solve_lowest(&kb, &mb, &p, &mut |_| {}) {
        Err(EigenError::NotConverged {
            requested,
            worst_residual,
            ..
        }) => {
            assert_eq!(requested, 20);
            assert!(worst_residual > p.tol);
        }
        other => panic!("expected NotConverged, got {other:?}"),
    }
    let p = EigenParams {
        nev: k.nrows() + 1,
        ..Default::default()
    };
    assert!(matches!(
        solve_lowest(&k, &m, &p, &mut |_| {}),
        Err(EigenError::InvalidInput(_))
    ));
}

// ---------------------------------------------------------------------------------------------
// Determinism

/// Same input → bit-identical eigenvalues and vectors: run twice, on rayon pools of 1 and 2
/// threads, and with faer sequential (`threads: 0` → `Par::Seq` at this size) or parallel
/// (`threads: 1, 2` → `Par::rayon(n)`) factorization, solves and products.
#[test]
fn eigensolve_is_bit_deterministic_across_runs_and_pools() {
    let mat = steelish();
    let mesh = TetMesh::structured_box([40, 6, 6], [1.0, 0.15, 0.15]);
    let (_, k, m) = clamped(&mesh, &mat);
    let p = EigenParams {
        nev: 20,
        ..Default::default()
    };
    let bits = |r: &EigenResult| {
        let mut v: Vec<u64> = r.eigenvalues.iter().map(|x| x.to_bits()).collect();
        for j in 0..r.vectors.ncols() {
            v.extend(r.vectors.col(j).iter().map(|x| x.to_bits()));
        }
        v
    };
    let mut calls = 0;
    let first = solve_lowest(&k, &m, &p, &mut |_| calls += 1).unwrap();
    assert!(calls > 0);
    let reference = bits(&first);
    assert_eq!(reference, bits(&solve(&k, &m, &p)));
    for pool_threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(pool_threads)
            .build()
            .unwrap();
        for threads in [0, 1, 2] {
            let p = EigenParams {
                threads,
                ..p.clone()
            };
            let r = pool.install(|| solve(&k, &m, &p));
            assert_eq!(
                reference,
                bits(&r),
                "pool of {pool_threads}, faer threads {threads}"
            );
        }
    }
}

/// Many modes: more than one Lanczos run (48 pairs each, deflated against the ones found), on a
/// clamped beam of square section (every bending eigenvalue is double, so pairs straddle the
/// run boundaries), against the dense generalized solve; the same through `max_freq_hz`.
/// Guards the deflation: a single run for 160 modes drifts to residuals ≈ 1e-7 (thick restarts).
#[test]
fn many_modes_across_lanczos_runs_match_dense() {
    let mat = steelish();
    let mesh = TetMesh::structured_box([24, 3, 3], [1.2, 0.1, 0.1]);
    let (_, k, m) = clamped(&mesh, &mat);
    let nev = 150;
    assert!(
        k.nrows() > 2 * nev + 64,
        "{} dofs: must take the Lanczos path",
        k.nrows()
    );
    let reference = dense_generalized_eigenvalues(&k, &m);
    let p = EigenParams {
        nev,
        tol: 1e-8,
        ..Default::default()
    };
    // The dense reference is itself only accurate to ≈ ε·λ_max (absolute), which exceeds
    // 1e-9·λ for the lowest modes of this mesh (λ_max/λ₁ ≈ 1e7).
    let slack = 100.0 * f64::EPSILON * reference.last().unwrap();
    let tol = |i: usize| (1e-9 * reference[i]).max(slack);
    let res = solve(&k, &m, &p);
    assert!(!res.info.dense);
    assert_eq!(res.eigenvalues.len(), nev);
    for i in 0..nev {
        let err = (res.eigenvalues[i] - reference[i]).abs();
        assert!(
            err <= tol(i),
            "mode {i}: {} vs {}",
            res.eigenvalues[i],
            reference[i]
        );
    }
    assert!(
        res.residuals.iter().all(|&r| r <= 1e-8),
        "{:?}",
        res.residuals
    );
    assert!(m_orthonormality_error(&m, res.vectors.as_ref()) <= 1e-10);

    // Max-frequency mode across runs: every mode below the limit, none above.
    let lim = 0.5 * (reference[99] + reference[100]);
    let f_lim = lim.sqrt() / (2.0 * std::f64::consts::PI);
    let p = EigenParams {
        nev: 1,
        max_freq_hz: Some(f_lim),
        tol: 1e-8,
        ..Default::default()
    };
    let res = solve(&k, &m, &p);
    assert_eq!(res.eigenvalues.len(), 100, "modes below {f_lim:.1} Hz");
    assert!(!res.info.capped);
    for i in 0..100 {
        let err = (res.eigenvalues[i] - reference[i]).abs();
        assert!(err <= tol(i), "max-freq mode {i}: {err:.1e}");
    }
    assert!(m_orthonormality_error(&m, res.vectors.as_ref()) <= 1e-10);
}

/// Bits of the eigenvalues and vectors of a result.
fn result_bits(r: &EigenResult) -> Vec<u64> {
    let mut v: Vec<u64> = r.eigenvalues.iter().map(|x| x.to_bits()).collect();
    for j in 0..r.vectors.ncols() {
        v.extend(r.vectors.col(j).iter().map(|x| x.to_bits()));
    }
    v
}

/// A frequency cap beyond the highest mode of a small free-free cube returns every mode (the
/// dense path, after Lanczos gives up): six rigid ones, the rest equal to the dense reference,
/// every residual within the bake's 1e-8, UᵀMU = I, and the same bits on rayon pools of 1, 2
/// and 4 threads whatever `threads` says.
#[test]
fn a_cap_beyond_the_spectrum_returns_every_mode_deterministically() {
    let mat = steelish();
    let mesh = TetMesh::structured_box([4, 4, 4], [0.3, 0.3, 0.3]);
    let k = assemble_stiffness(&mesh, &mat);
    let m = assemble_mass(&mesh, &mat, false);
    let n = k.nrows();
    let p = EigenParams {
        nev: 1,
        max_freq_hz: Some(1e300),
        shift: default_shift(&mesh, &mat),
        tol: 1e-8,
        ..Default::default()
    };
    let res = solve(&k, &m, &p);
    assert!(res.info.dense);
    assert!(!res.info.capped);
    assert_eq!(res.eigenvalues.len(), n, "every mode of {n} dofs");
    let l7 = res.eigenvalues[6];
    assert!(res.eigenvalues[..6].iter().all(|l| l.abs() < 1e-9 * l7));
    let reference = dense_generalized_eigenvalues(&k, &m);
    let slack = 100.0 * f64::EPSILON * reference.last().unwrap();
    for i in 6..n {
        let err = (res.eigenvalues[i] - reference[i]).abs();
        assert!(err <= (1e-9 * reference[i]).max(slack), "mode {i}: {err:e}");
    }
    for (r, f) in res.residuals.iter().zip(&res.residual_floors) {
        assert!(*r <= 1e-8f64.max(8.0 * f), "residual {r:e}");
    }
    assert!(m_orthonormality_error(&m, res.vectors.as_ref()) <= 1e-10);
    let reference_bits = result_bits(&res);
    for pool_threads in [1, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(pool_threads)
            .build()
            .unwrap();
        for threads in [0, 2] {
            let p = EigenParams {
                threads,
                ..p.clone()
            };
            let r = pool.install(|| solve(&k, &m, &p));
            assert!(
                reference_bits == result_bits(&r),
                "pool of {pool_threads}, faer threads {threads}"
            );
        }
    }
}

/// A count up to the exact limit (every free dof of a clamped beam) is met by the dense path:
/// n pairs, residuals within 1e-8, and the n − 1 lowest equal to those of the request for
/// n − 1 (the same dense solve).
#[test]
fn a_count_at_the_exact_limit_is_met() {
    let mat = steelish();
    let mesh = TetMesh::structured_box([12, 2, 2], [1.0, 0.1, 0.1]);
    let (_, k, m) = clamped(&mesh, &mat);
    let n = k.nrows();
    assert_eq!(n, 3 * mesh.nodes.len() - 3 * mesh.groups["xmin"].len());
    let p = EigenParams {
        nev: n,
        tol: 1e-8,
        ..Default::default()
    };
    let all = solve(&k, &m, &p);
    assert!(all.info.dense);
    assert_eq!(all.eigenvalues.len(), n);
    for (r, f) in all.residuals.iter().zip(&all.residual_floors) {
        assert!(*r <= 1e-8f64.max(8.0 * f), "residual {r:e}");
    }
    let reference = dense_generalized_eigenvalues(&k, &m);
    let slack = 100.0 * f64::EPSILON * reference.last().unwrap();
    for i in 0..n {
        let err = (all.eigenvalues[i] - reference[i]).abs();
        assert!(err <= (1e-9 * reference[i]).max(slack), "mode {i}: {err:e}");
    }
}
