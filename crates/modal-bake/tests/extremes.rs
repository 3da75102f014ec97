//! Stability of the bake at the extremes: materials (E 1e3…1e13 Pa, ρ 1…2e4 kg/m³), sizes
//! (1 mm … 1 km), a nearly singular K (one fixed node, one fixed face), repeated eigenvalues
//! and f32 storage. Each case: no panic, no NaN/Inf, and either a result within a stated
//! tolerance or a clear error.
//!
//! Exact scalings used (linear FEM on a fixed mesh): λ ∝ E, λ ∝ 1/ρ, λ ∝ 1/L² under a uniform
//! scale L of the geometry; the mode shapes are unchanged up to the mass normalisation
//! (U ∝ 1/√(ρ L³)).
//!
//! Run with `cargo test --release -p modal-bake --test extremes`.

use faer::Mat;
use modal_bake::bake::{
    bake_mesh, BakeError, BakeParams, MaterialSi, ModeRequest, ModesFile, ModesPrecision,
    MAX_RESIDUAL,
};
use modal_bake::eigen::{default_shift, solve_lowest, EigenParams};
use modal_bake::fem::{assemble_mass, assemble_stiffness, reduce_fixed, Material};
use modal_bake::mesh::TetMesh;

fn plate() -> TetMesh {
    TetMesh::structured_box([5, 3, 2], [1.0, 0.6, 0.2])
}

fn scaled(mut mesh: TetMesh, s: f64) -> TetMesh {
    for p in &mut mesh.nodes {
        for x in p.iter_mut() {
            *x *= s;
        }
    }
    mesh
}

fn params(e: f64, rho: f64, fixed: &[&str], modes: usize) -> BakeParams {
    BakeParams {
        material: MaterialSi {
            youngs: e,
            poisson: 0.3,
            density: rho,
        },
        modes: ModeRequest::Count(modes),
        fixed: fixed.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    }
}

fn check_base(b: &ModesFile, what: &str) {
    assert!(
        b.eigenvalues.iter().all(|l| l.is_finite() && *l > 0.0),
        "{what}: {:?}",
        b.eigenvalues
    );
    assert!(
        b.modes.iter().all(|x| x.is_finite()),
        "{what}: non-finite mode entry"
    );
    assert!(
        b.residuals.iter().all(|&r| r <= MAX_RESIDUAL),
        "{what}: residuals {:?}",
        b.residuals
    );
    assert!(
        b.eigenvalues.windows(2).all(|w| w[0] <= w[1]),
        "{what}: not ascending"
    );
}

/// max |λ_i(a)·scale − λ_i(b)| / λ_i(b).
fn ratio_err(a: &[f64], b: &[f64], scale: f64) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x * scale - y).abs() / y.abs())
        .fold(0.0, f64::max)
}

/// λ ∝ E exactly from 1e3 to 1e13 Pa (clamped and free-free): relative deviation ≤ 1e-8.
#[test]
fn youngs_modulus_sweep_scales_eigenvalues() {
    for fixed in [&["xmin"][..], &[][..]] {
        let (reference, _) = bake_mesh(
            plate(),
            &params(1e9, 1000.0, fixed, 12),
            "plate",
            &mut |_| {},
        )
        .unwrap();
        for e in [1e3, 1e6, 1e9, 1e11, 1e13] {
            let (b, _) =
                bake_mesh(plate(), &params(e, 1000.0, fixed, 12), "plate", &mut |_| {}).unwrap();
            check_base(&b, &format!("E = {e:e}"));
            let err = ratio_err(&b.eigenvalues, &reference.eigenvalues, 1e9 / e);
            assert!(
                err <= 1e-8,
                "E = {e:e}, fixed {fixed:?}: λ/E deviates by {err:.2e}"
            );
        }
    }
}

/// λ ∝ 1/ρ exactly from 1 to 2e4 kg/m³: relative deviation ≤ 1e-8; mode entries ∝ 1/√ρ.
#[test]
fn density_sweep_scales_eigenvalues() {
    for fixed in [&["xmin"][..], &[][..]] {
        let (reference, _) = bake_mesh(
            plate(),
            &params(1e9, 1000.0, fixed, 12),
            "plate",
            &mut |_| {},
        )
        .unwrap();
        for rho in [1.0, 10.0, 770.0, 7850.0, 2e4] {
            let (b, _) =
                bake_mesh(plate(), &params(1e9, rho, fixed, 12), "plate", &mut |_| {}).unwrap();
            check_base(&b, &format!("rho = {rho}"));
            let err = ratio_err(&b.eigenvalues, &reference.eigenvalues, rho / 1000.0);
            assert!(
                err <= 1e-8,
                "rho = {rho}, fixed {fixed:?}: λ·ρ deviates by {err:.2e}"
            );
            // Largest entry of the first mode (sign-normalised positive) scales as 1/√ρ.
            let m = b.num_modes();
            let amax = |f: &ModesFile| {
                (0..f.modes.len() / m)
                    .map(|r| f.modes[r * m].abs())
                    .fold(0.0, f64::max)
            };
            let s = amax(&b) * (rho / 1000.0).sqrt() / amax(&reference);
            assert!(
                (s - 1.0).abs() <= 1e-6,
                "rho = {rho}: mode amplitude ratio {s}"
            );
        }
    }
}

/// λ ∝ 1/L² from 1 mm to 1 km (uniform scale of the same mesh): relative deviation ≤ 1e-8,
/// free-free rigid modes still detected (6) at every size.
#[test]
fn size_sweep_scales_eigenvalues() {
    for fixed in [&["xmin"][..], &[][..]] {
        let (reference, _) = bake_mesh(
            plate(),
            &params(1e9, 1000.0, fixed, 12),
            "plate",
            &mut |_| {},
        )
        .unwrap();
        for l in [1e-3, 1e-2, 1.0, 1e2, 1e3] {
            let (b, rep) = bake_mesh(
                scaled(plate(), l),
                &params(1e9, 1000.0, fixed, 12),
                "plate",
                &mut |_| {},
            )
            .unwrap();
            check_base(&b, &format!("L = {l}"));
            let err = ratio_err(&b.eigenvalues, &reference.eigenvalues, l * l);
            assert!(
                err <= 1e-8,
                "L = {l}, fixed {fixed:?}: λ·L² deviates by {err:.2e}"
            );
            if fixed.is_empty() {
                assert_eq!(rep.rigid_modes_excluded, 6);
            }
        }
    }
}

/// The corner of E, ρ and size all at once: E 1e13, ρ 1, 1 mm (λ ≈ 1e19) and E 1e3, ρ 2e4,
/// 1 km (λ ≈ 1e-7): finite, converged, λ scales by the combined factor to 1e-8.
#[test]
fn combined_extremes_scale() {
    let (reference, _) =
        bake_mesh(plate(), &params(1e9, 1000.0, &[], 8), "plate", &mut |_| {}).unwrap();
    for (e, rho, l) in [(1e13, 1.0, 1e-3), (1e3, 2e4, 1e3)] {
        let (b, _) = bake_mesh(
            scaled(plate(), l),
            &params(e, rho, &[], 8),
            "plate",
            &mut |_| {},
        )
        .unwrap();
        check_base(&b, &format!("E {e:e} ρ {rho} L {l}"));
        let scale = (1e9 / e) * (rho / 1000.0) * (l * l);
        let err = ratio_err(&b.eigenvalues, &reference.eigenvalues, scale);
        assert!(err <= 1e-8, "E {e:e} ρ {rho} L {l}: deviation {err:.2e}");
    }
}

fn dense(a: &faer::sparse::SparseColMat<usize, f64>) -> Mat<f64> {
    a.to_dense()
}

/// max |UᵀMU − I| and max relative residual ‖Ku − λMu‖/‖Ku‖ of a solve.
fn orthonormality_and_residual(
    k: &Mat<f64>,
    m: &Mat<f64>,
    lam: &[f64],
    u: &Mat<f64>,
) -> (f64, f64) {
    let g = u.transpose() * m * u;
    let mut orth = 0.0f64;
    for i in 0..g.nrows() {
        for j in 0..g.ncols() {
            let d = if i == j { 1.0 } else { 0.0 };
            orth = orth.max((g[(i, j)] - d).abs());
        }
    }
    let ku = k * u;
    let mu = m * u;
    let mut res = 0.0f64;
    for j in 0..u.ncols() {
        let mut num = 0.0;
        let mut den = 0.0;
        for i in 0..u.nrows() {
            num += (ku[(i, j)] - lam[j] * mu[(i, j)]).powi(2);
            den += ku[(i, j)].powi(2);
        }
        res = res.max(num.sqrt() / den.sqrt());
    }
    (orth, res)
}

/// Repeated eigenvalues: a cube (Kuhn subdivision, 3-fold symmetric about its diagonal) has
/// degenerate pairs. The solver still returns an M-orthonormal basis of each cluster
/// (|UᵀMU − I| ≤ 1e-10), residuals ≤ 1e-8, and the base bakes.
#[test]
fn repeated_eigenvalues_symmetric_cube() {
    let mesh = TetMesh::structured_box([4, 4, 4], [1.0, 1.0, 1.0]);
    let mat = Material::new(1e9, 0.3, 1000.0).unwrap();
    let (k, m) = (
        assemble_stiffness(&mesh, &mat),
        assemble_mass(&mesh, &mat, false),
    );
    let (_, kf, mf) = reduce_fixed(&k, &m, &[]).unwrap();
    let ep = EigenParams {
        nev: 26,
        shift: default_shift(&mesh, &mat),
        ..Default::default()
    };
    let res = solve_lowest(&kf, &mf, &ep, &mut |_| {}).unwrap();
    let lam = &res.eigenvalues[6..];
    let pairs = lam
        .windows(2)
        .filter(|w| (w[1] - w[0]) / w[1] < 1e-8)
        .count();
    assert!(pairs >= 3, "expected degenerate pairs, eigenvalues {lam:?}");
    let (orth, resid) =
        orthonormality_and_residual(&dense(&kf), &dense(&mf), &res.eigenvalues, &res.vectors);
    let u = res.vectors.subcols(6, res.vectors.ncols() - 6).to_owned();
    let (_, resid_el) = orthonormality_and_residual(&dense(&kf), &dense(&mf), lam, &u);
    println!("cube: {pairs} degenerate pairs, |UᵀMU − I| = {orth:.2e}, elastic residual {resid_el:.2e} (all {resid:.2e})");
    assert!(orth <= 1e-10, "M-orthonormality {orth:.2e}");
    assert!(resid_el <= 1e-8, "residual {resid_el:.2e}");
    let (b, _) = bake_mesh(mesh, &params(1e9, 1000.0, &[], 20), "cube", &mut |_| {}).unwrap();
    check_base(&b, "cube");
}

/// A single fixed node (or a line of fixed nodes) leaves rotations free: K is singular on the
/// free dofs. The bake refuses it up front with an error that names the mechanism.
#[test]
fn collinear_fixed_nodes_are_refused_as_a_mechanism() {
    for set in [vec![0usize], vec![0, 1]] {
        let mut mesh = plate();
        mesh.groups.insert("corner".into(), set.clone());
        let e = bake_mesh(
            mesh,
            &params(1e9, 1000.0, &["corner"], 10),
            "plate",
            &mut |_| {},
        )
        .expect_err("a collinear fixed set must be refused");
        let msg = e.to_string();
        assert!(matches!(e, BakeError::Params(_)), "{e:?}");
        assert!(msg.contains("collinear") && msg.contains("plate"), "{msg}");
    }
}

/// One small fixed face (the 3 nodes of one boundary triangle at a corner of a plate): K is
/// non-singular but badly conditioned (very soft rocking modes). The bake converges with
/// residuals ≤ 1e-8, the lowest mode is far below the clamped-edge one, everything finite.
#[test]
fn one_small_fixed_face_converges() {
    let mut mesh = plate();
    // Triangle of the x = 0 face at the origin corner: nodes (0,0,0), (0,dy,0), (0,dy,dz).
    let id = |i: usize, j: usize, k: usize| i + 6 * (j + 4 * k);
    mesh.groups
        .insert("patch".into(), vec![id(0, 0, 0), id(0, 1, 0), id(0, 1, 1)]);
    let (b, _) = bake_mesh(
        mesh,
        &params(1e9, 1000.0, &["patch"], 10),
        "plate",
        &mut |_| {},
    )
    .unwrap();
    check_base(&b, "fixed face");
    let (clamped, _) = bake_mesh(
        plate(),
        &params(1e9, 1000.0, &["xmin"], 10),
        "plate",
        &mut |_| {},
    )
    .unwrap();
    println!(
        "small face: λ1 = {:.4e}, clamped edge λ1 = {:.4e}",
        b.eigenvalues[0], clamped.eigenvalues[0]
    );
    assert!(b.eigenvalues[0] < clamped.eigenvalues[0]);
}

/// f32 storage: surface mode entries round-trip through the file within f32 rounding
/// (|Δ| ≤ 2⁻²⁴·|u| + tiny), eigenvalues exact, and a modal peak changes by ≤ 1e-6 relative.
#[test]
fn f32_storage_matches_f64() {
    let dir = tempfile::tempdir().unwrap();
    let mut p = params(1.1e9, 770.0, &["xmin"], 20);
    let (b64, _) = bake_mesh(plate(), &p, "plate", &mut |_| {}).unwrap();
    p.precision = ModesPrecision::F32;
    let (b32, _) = bake_mesh(plate(), &p, "plate", &mut |_| {}).unwrap();
    let path = dir.path().join("p32.modes");
    b32.write_atomic(&path).unwrap();
    let r32 = ModesFile::read(&path).unwrap();
    assert_eq!(r32.eigenvalues, b64.eigenvalues);
    let umax = b64.modes.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for (a, b) in r32.modes.iter().zip(&b64.modes) {
        assert!(a.is_finite());
        assert!(
            (a - b).abs() <= 6.0e-8 * b.abs() + 1e-30 * umax,
            "{a} vs {b}"
        );
    }
    // A peak through the runtime's contact row.
    let m64 = dcr_runtime::ModalModel::from_base(b64).unwrap();
    let m32 = dcr_runtime::ModalModel::from_base(r32).unwrap();
    let peak = |mm: &dcr_runtime::ModalModel| {
        let sp = mm.project([0.9, 0.3, 0.2], 1.0).unwrap();
        let c = mm.project([0.4, 0.5, 0.2], 1.0).unwrap();
        let n = mm.num_modes();
        let (mut r, mut w) = (vec![0.0; n], vec![0.0; n]);
        mm.add_reduced_impulse(&sp, sp.normal.map(|x| -x), 1.0, &mut r);
        mm.contact_row(&c, &mut w);
        (0..n)
            .map(|j| (r[j] * w[j]).abs() / mm.omega()[j])
            .sum::<f64>()
    };
    let (a, b) = (peak(&m32), peak(&m64));
    assert!((a - b).abs() <= 1e-6 * b, "{a} vs {b}");
}
