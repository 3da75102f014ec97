//! Second-order (10-node) tetrahedra: exactness of the P2 element matrices on quadratic fields,
//! the usual invariants, mesh checks (orientation, curved and non-conforming elements), the
//! eigenvalues against scikit-fem's `ElementTetP2`, and the P2 base end to end.
//!
//! Run in release mode: `cargo test --release -p modal-bake --test p2`.

use std::path::Path;

use faer::sparse::SparseColMat;
use modal_bake::bake::{bake_mesh, BakeParams, FixedBelow, MaterialSi, ModeRequest};
use modal_bake::fem::{
    assemble_clamped, assemble_mass, assemble_stiffness, rigid_body_modes, Material,
};
use modal_bake::mesh::{read_mesh, signed_volume, TetMesh, TET10_EDGES};

fn material() -> Material {
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

/// A P2 box whose interior corner nodes are moved by up to `amp`·h (seeded); the boundary
/// stays the box, mid-edge nodes at the (moved) midpoints.
fn distorted_p2_box(n: [usize; 3], l: [f64; 3], amp: f64, seed: u64) -> TetMesh {
    let mut mesh = TetMesh::structured_box(n, l);
    let mut rng = Rng(seed);
    for p in &mut mesh.nodes {
        for a in 0..3 {
            let inside = p[a] > 0.0 && p[a] < l[a];
            if inside {
                p[a] += amp * l[a] / n[a] as f64 * rng.next();
            }
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
    mesh.to_quadratic()
}

/// `uᵀ A v` for a sparse symmetric A.
fn form(a: &SparseColMat<usize, f64>, u: &[f64], v: &[f64]) -> f64 {
    let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut s = 0.0;
    for c in 0..a.ncols() {
        for p in cp[c]..cp[c + 1] {
            s += u[ri[p]] * val[p] * v[c];
        }
    }
    s
}

/// A nodal displacement field `f(x)` (m) as a dof vector.
fn field(mesh: &TetMesh, f: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<f64> {
    mesh.nodes.iter().flat_map(|&x| f(x)).collect()
}

/// Mass: 1ᵀM_axis 1 = ρV (consistent and HRZ-lumped), the lumped diagonal is positive, and the
/// consistent mass integrates a quartic exactly: uᵀMu = ρ∫x⁴ for u = (x², 0, 0).
#[test]
fn p2_mass_sums_to_rho_v_and_integrates_quartics_exactly() {
    let mat = material();
    let (a, b, c) = (0.4, 0.3, 0.2);
    for mesh in [
        TetMesh::structured_box([3, 2, 2], [a, b, c]).to_quadratic(),
        distorted_p2_box([3, 3, 2], [a, b, c], 0.25, 3),
    ] {
        let vol = mesh.volume();
        assert!((vol - a * b * c).abs() < 1e-14);
        for lumped in [false, true] {
            let m = assemble_mass(&mesh, &mat, lumped);
            let ones = field(&mesh, |_| [1.0, 0.0, 0.0]);
            let total = form(&m, &ones, &ones);
            assert!(
                (total - mat.density * vol).abs() < 1e-12 * total,
                "lumped {lumped}: {total}"
            );
            if lumped {
                assert!(m.val().iter().all(|&x| x > 0.0));
            }
        }
        let m = assemble_mass(&mesh, &mat, false);
        let u = field(&mesh, |x| [x[0] * x[0], 0.0, 0.0]);
        let exact = mat.density * a.powi(5) / 5.0 * b * c;
        let got = form(&m, &u, &u);
        assert!((got - exact).abs() < 1e-12 * exact, "{got} vs {exact}");
    }
}

/// Strain energy of quadratic displacement fields is exact (P1 cannot represent them):
/// u = (x², 0, 0) stores 2(λ+2μ)∫x², u = (y², 0, 0) stores 2μ∫y² (uᵀKu = 2W).
#[test]
fn p2_strain_energy_of_quadratic_fields_is_exact() {
    let mat = material();
    let (lam, mu) = mat.lame();
    let (a, b, c) = (0.4, 0.3, 0.2);
    let mesh = distorted_p2_box([3, 3, 2], [a, b, c], 0.25, 11);
    let k = assemble_stiffness(&mesh, &mat);
    let u = field(&mesh, |x| [x[0] * x[0], 0.0, 0.0]);
    let exact = 2.0 * 2.0 * (lam + 2.0 * mu) * a.powi(3) / 3.0 * b * c;
    let got = form(&k, &u, &u);
    assert!((got - exact).abs() < 1e-11 * exact, "{got} vs {exact}");
    let u = field(&mesh, |x| [x[1] * x[1], 0.0, 0.0]);
    let exact = 2.0 * 2.0 * mu * b.powi(3) / 3.0 * a * c;
    let got = form(&k, &u, &u);
    assert!((got - exact).abs() < 1e-11 * exact, "{got} vs {exact}");
}

/// K is bit-exactly symmetric, annihilates the six rigid motions, and is bit-identical on one
/// and two threads; the clamped assembly equals the restriction of the full one.
#[test]
fn p2_stiffness_invariants() {
    let mat = material();
    let mesh = distorted_p2_box([3, 2, 2], [0.3, 0.2, 0.2], 0.2, 5);
    let k = assemble_stiffness(&mesh, &mat);
    let d = k.to_dense();
    for i in 0..d.nrows() {
        for j in 0..i {
            assert_eq!(d[(i, j)].to_bits(), d[(j, i)].to_bits(), "({i}, {j})");
        }
    }
    let r = rigid_body_modes(&mesh);
    let scale = k.val().iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for j in 0..6 {
        let col: Vec<f64> = (0..r.nrows()).map(|i| r[(i, j)]).collect();
        let kr = &d * r.col(j);
        let worst = (0..kr.nrows()).fold(0.0f64, |m, i| m.max(kr[i].abs()));
        assert!(worst < 1e-10 * scale, "rigid mode {j}: ‖K r‖∞ = {worst:e}");
        assert!(form(&k, &col, &col).abs() < 1e-10 * scale);
    }
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let k1 = pool(1).install(|| assemble_stiffness(&mesh, &mat));
    let k2 = pool(2).install(|| assemble_stiffness(&mesh, &mat));
    assert_eq!(k1.val().len(), k2.val().len());
    assert!(k1
        .val()
        .iter()
        .zip(k2.val())
        .all(|(a, b)| a.to_bits() == b.to_bits()));

    let fixed = mesh.groups["xmin"].clone();
    let (map, kf, mf) = assemble_clamped(&mesh, &mat, false, &fixed).unwrap();
    let m = assemble_mass(&mesh, &mat, false).to_dense();
    let (kfd, mfd) = (kf.to_dense(), mf.to_dense());
    for (i, &fi) in map.free_dofs().iter().enumerate() {
        for (j, &fj) in map.free_dofs().iter().enumerate() {
            assert_eq!(kfd[(i, j)].to_bits(), d[(fi, fj)].to_bits());
            assert_eq!(mfd[(i, j)].to_bits(), m[(fi, fj)].to_bits());
        }
    }
}

/// An inverted 10-node tet (corners 0 ↔ 1 swapped, mid-edge nodes permuted with them, as a
/// file may list it) is reoriented with its mid-edge nodes on the right edges: it stays
/// straight and the stiffness equals the original's.
#[test]
fn p2_orientation_moves_mid_edge_nodes_with_the_corners() {
    let mat = material();
    let mesh = distorted_p2_box([2, 2, 1], [0.2, 0.2, 0.1], 0.2, 9);
    let k0 = assemble_stiffness(&mesh, &mat).to_dense();
    let mut flipped = mesh.clone();
    for t in [0, 3, 7] {
        flipped.tets[t].swap(0, 1);
        // Corners 0 ↔ 1: edges (1,2) ↔ (0,2) and (0,3) ↔ (1,3) trade places.
        flipped.mid_edges[t].swap(1, 2);
        flipped.mid_edges[t].swap(3, 5);
    }
    assert!(flipped.check_straight(1e-9).is_ok());
    assert_eq!(flipped.orient_tets(1e-10).unwrap(), 3);
    flipped.check_straight(1e-9).unwrap();
    for (t, e) in flipped.mid_edges.iter().enumerate() {
        for (k, &[a, b]) in TET10_EDGES.iter().enumerate() {
            let (x, y) = (
                flipped.nodes[flipped.tets[t][a]],
                flipped.nodes[flipped.tets[t][b]],
            );
            let m = flipped.nodes[e[k]];
            assert!((0..3).all(|i| (m[i] - 0.5 * (x[i] + y[i])).abs() < 1e-15));
        }
    }
    let k1 = assemble_stiffness(&flipped, &mat).to_dense();
    let scale = (0..k0.nrows()).fold(0.0f64, |m, i| m.max(k0[(i, i)].abs()));
    for i in 0..k0.nrows() {
        for j in 0..k0.ncols() {
            assert!((k0[(i, j)] - k1[(i, j)]).abs() < 1e-12 * scale);
        }
    }
}

/// Curved and non-conforming second-order meshes are refused with the element named.
#[test]
fn p2_curved_and_non_conforming_meshes_are_refused() {
    let mut params = BakeParams {
        modes: ModeRequest::Count(2),
        ..Default::default()
    };
    params.fixed = vec!["xmin".into()];
    let mesh = TetMesh::structured_box([2, 1, 1], [0.2, 0.1, 0.1]).to_quadratic();
    let mut curved = mesh.clone();
    let v = curved.mid_edges[4][2];
    curved.nodes[v][1] += 1e-3;
    let err = bake_mesh(curved, &params, "curved.msh", &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("curved.msh") && err.contains("curved 10-node tetrahedron"),
        "{err}"
    );

    let mut split = mesh.clone();
    // Give tetrahedron 2 its own node for an edge it shares with others.
    let (t, k) = (2, 0);
    let shared = split.mid_edges[t][k];
    assert!(
        split
            .mid_edges
            .iter()
            .filter(|e| e.contains(&shared))
            .count()
            > 1
    );
    split.nodes.push(split.nodes[shared]);
    split.mid_edges[t][k] = split.nodes.len() - 1;
    let err = bake_mesh(split, &params, "split.msh", &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("non-conforming 10-node tetrahedron"), "{err}");
}

/// The P2 eigenvalues of the clamped beam equal scikit-fem's `ElementTetP2` on the same
/// tetrahedra to 1e-8 relative (reference: `scripts/p2_reference.py` → data/p2_reference.json).
#[test]
fn p2_eigenvalues_equal_scikit_fem() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let reference: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("data/p2_reference.json")).unwrap(),
    )
    .unwrap();
    let expect: Vec<f64> = reference["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let mesh = read_mesh(&root.join("data/meshes/beam.msh"))
        .unwrap()
        .to_quadratic();
    let params = BakeParams {
        material: MaterialSi {
            youngs: reference["youngs_pa"].as_f64().unwrap(),
            poisson: reference["poisson"].as_f64().unwrap(),
            density: reference["density_kg_m3"].as_f64().unwrap(),
        },
        modes: ModeRequest::Count(expect.len()),
        fixed_below: vec![FixedBelow {
            axis: 0,
            value: 0.0,
        }],
        ..Default::default()
    };
    let (base, report) = bake_mesh(mesh, &params, "beam.msh (P2)", &mut |_| {}).unwrap();
    assert_eq!(
        report.free_dofs as u64,
        reference["free_dofs"].as_u64().unwrap()
    );
    assert_eq!(report.order, 2);
    for (j, (&got, &want)) in base.eigenvalues.iter().zip(&expect).enumerate() {
        let rel = (got - want).abs() / want;
        assert!(
            rel < 1e-8,
            "mode {j}: {got} vs scikit-fem {want} (rel {rel:.2e})"
        );
    }
}

/// P2 contains P1 on the same corners, so every P2 eigenvalue is at most the P1 one
/// (Courant–Fischer); the P2 base stores one mid-edge row per surface edge and is version 2.
#[test]
fn p2_base_bounds_p1_from_below_and_stores_mid_edge_rows() {
    let p1 = TetMesh::structured_box([6, 2, 2], [0.6, 0.1, 0.1]);
    let p2 = p1.to_quadratic();
    let params = BakeParams {
        modes: ModeRequest::Count(6),
        fixed_below: vec![FixedBelow {
            axis: 0,
            value: 0.0,
        }],
        ..Default::default()
    };
    let (b1, r1) = bake_mesh(p1, &params, "p1", &mut |_| {}).unwrap();
    let (b2, r2) = bake_mesh(p2, &params, "p2", &mut |_| {}).unwrap();
    for (l1, l2) in b1.eigenvalues.iter().zip(&b2.eigenvalues) {
        assert!(l2 <= l1, "P2 {l2} above P1 {l1}");
    }
    // On this coarse beam P1 locks in bending: P2 is far lower.
    assert!(b2.eigenvalues[0] < 0.8 * b1.eigenvalues[0]);
    assert_eq!(b1.meta.format_version, 1);
    assert!(b1.quadratic.is_none());
    assert_eq!(b2.meta.format_version, 2);
    let q = b2.quadratic.as_ref().unwrap();
    assert_eq!(q.edges.len(), r2.surface_edge_nodes);
    assert_eq!(r1.surface_vertices, r2.surface_vertices);
    // Euler: V − E + F = 2 on the closed surface.
    let (v, f) = (
        b2.num_surface_vertices() as i64,
        b2.surface_triangles.len() as i64,
    );
    assert_eq!(v - q.edges.len() as i64 + f, 2);
    // Fixed: corners and mid-edge nodes of the x = 0 face.
    assert_eq!(r2.fixed_by, vec![("below x=0".to_string(), 9 + 16)]);
}

/// NAFEMS FV32 (tapered membrane 10 m long, 5 m → 1 m, 0.05 m thick, steel, root clamped) as a
/// solid: the modes whose surface motion is in-plane (< 1% of Σ|u|² along z) are the published
/// in-plane ones (44.623, 130.03, 162.70, 246.05, 379.90, 391.44 Hz); out-of-plane bending
/// modes of the thin plate fall between them. P2 on data/meshes/fv32_p2_h1.msh (one layer,
/// ≤ 3,000 free dofs) is within 0.5% of each.
#[test]
fn p2_nafems_fv32_within_half_a_percent() {
    const PUBLISHED: [f64; 6] = [44.623, 130.03, 162.70, 246.05, 379.90, 391.44];
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mesh = read_mesh(&root.join("data/meshes/fv32_p2_h1.msh")).unwrap();
    assert!(mesh.is_quadratic());
    let params = BakeParams {
        material: MaterialSi {
            youngs: 200e9,
            poisson: 0.3,
            density: 8000.0,
        },
        modes: ModeRequest::MaxFreqHz(400.0),
        fixed_below: vec![FixedBelow {
            axis: 0,
            value: 0.0,
        }],
        ..Default::default()
    };
    let (base, report) = bake_mesh(mesh, &params, "fv32_p2_h1.msh", &mut |_| {}).unwrap();
    assert!(report.free_dofs <= 3000, "{} dofs", report.free_dofs);
    let m = base.num_modes();
    let q = base.quadratic.as_ref().unwrap();
    let freqs = base.frequencies_hz();
    let in_plane: Vec<f64> = (0..m)
        .filter(|&j| {
            let (mut z, mut all) = (0.0, 0.0);
            for rows in [&base.modes, &q.modes] {
                for node in 0..rows.len() / (3 * m) {
                    for axis in 0..3 {
                        let u = rows[(node * 3 + axis) * m + j];
                        all += u * u;
                        if axis == 2 {
                            z += u * u;
                        }
                    }
                }
            }
            z < 0.01 * all
        })
        .map(|j| freqs[j])
        .collect();
    assert_eq!(
        in_plane.len(),
        6,
        "in-plane modes below 400 Hz: {in_plane:?}"
    );
    for (got, want) in in_plane.iter().zip(PUBLISHED) {
        let err = (got - want).abs() / want;
        assert!(
            err < 5e-3,
            "{got:.3} Hz vs published {want} Hz ({:.3}%)",
            100.0 * err
        );
    }
}

/// `--fixed-below` / `--fixed-box` / `--fixed` combine by union with a count per selector; a
/// selector that fixes nothing is an error naming the mesh's extent; the selectors are bake
/// parameters (part of the hash), so `check` sees a change; the P1 parameter hash without them
/// is unchanged by their existence.
#[test]
fn fixed_selectors_count_union_refuse_empty_and_hash() {
    use modal_bake::bake::is_mesh_up_to_date;
    let mesh = TetMesh::structured_box([4, 2, 2], [0.4, 0.2, 0.2]);
    let base_params = BakeParams {
        modes: ModeRequest::Count(3),
        ..Default::default()
    };
    let params = BakeParams {
        fixed: vec!["xmin".into()],
        fixed_below: vec![FixedBelow {
            axis: 0,
            value: 0.1,
        }],
        fixed_boxes: vec![[0.35, -1.0, -1.0, 0.5, 1.0, 1.0]],
        ..base_params.clone()
    };
    let (_, report) = bake_mesh(mesh.clone(), &params, "box", &mut |_| {}).unwrap();
    assert_eq!(
        report.fixed_by,
        vec![
            ("group xmin".to_string(), 9),
            ("below x=0.1".to_string(), 18),
            ("box 0.35,-1,-1,0.5,1,1".to_string(), 9),
        ]
    );
    assert_eq!(report.fixed_nodes, 27);

    for (bad, what) in [
        (
            BakeParams {
                fixed_below: vec![FixedBelow {
                    axis: 2,
                    value: -0.01,
                }],
                ..base_params.clone()
            },
            "parameter `fixed_below` (z=-0.01) fixes no node",
        ),
        (
            BakeParams {
                fixed_boxes: vec![[1.0, 1.0, 1.0, 2.0, 2.0, 2.0]],
                ..base_params.clone()
            },
            "parameter `fixed_boxes` (1,1,1,2,2,2) fixes no node",
        ),
    ] {
        let err = bake_mesh(mesh.clone(), &bad, "box", &mut |_| {})
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(what) && err.contains("the mesh spans x 0.000000…0.400000"),
            "{err}"
        );
    }
    let inverted = BakeParams {
        fixed_boxes: vec![[1.0, 0.0, 0.0, 0.0, 1.0, 1.0]],
        ..base_params.clone()
    };
    assert!(bake_mesh(mesh.clone(), &inverted, "box", &mut |_| {}).is_err());

    // Part of the hash: a base baked with one selector is stale for another.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.modes");
    let below = BakeParams {
        fixed_below: vec![FixedBelow {
            axis: 0,
            value: 0.0,
        }],
        ..base_params.clone()
    };
    let (b, _) = bake_mesh(mesh.clone(), &below, "box", &mut |_| {}).unwrap();
    b.write_atomic(&out).unwrap();
    assert!(is_mesh_up_to_date(mesh.clone(), "box", &below, &out).unwrap());
    let other = BakeParams {
        fixed_below: vec![FixedBelow {
            axis: 0,
            value: 0.05,
        }],
        ..base_params.clone()
    };
    assert!(!is_mesh_up_to_date(mesh.clone(), "box", &other, &out).unwrap());
    let group = BakeParams {
        fixed: vec!["xmin".into()],
        ..base_params.clone()
    };
    assert_ne!(below.hash(), group.hash());
    // Absent selectors serialise as before: the JSON has no selector keys.
    let json = serde_json::to_string(&group).unwrap();
    assert!(
        !json.contains("fixed_below") && !json.contains("fixed_boxes"),
        "{json}"
    );
}

/// A meshio JSON `tetra10` block (VTK node order: its last two mid-edge nodes are (1,3), (2,3))
/// reads into the same second-order mesh as the one written, straight-sided.
#[test]
fn meshio_tetra10_reads_in_vtk_order() {
    let p2 = TetMesh::structured_box([2, 1, 1], [0.2, 0.1, 0.1]).to_quadratic();
    let rows: Vec<[usize; 10]> = (0..p2.tets.len())
        .map(|t| {
            let (c, e) = (p2.tets[t], p2.mid_edges[t]);
            // TET10_EDGES: (0,1) (1,2) (0,2) (0,3) (2,3) (1,3) → VTK: ... (0,3) (1,3) (2,3).
            [c[0], c[1], c[2], c[3], e[0], e[1], e[2], e[3], e[5], e[4]]
        })
        .collect();
    let json = serde_json::json!({
        "points": p2.nodes,
        "cells": [{"type": "tetra10", "data": rows}],
    });
    let back = modal_bake::mesh::read_json_bytes(json.to_string().as_bytes(), "p2.json").unwrap();
    assert!(back.is_quadratic());
    back.check_straight(1e-12).unwrap();
    let key = |m: &TetMesh| {
        let mut v: Vec<([usize; 4], [usize; 6])> = m
            .tets
            .iter()
            .copied()
            .zip(m.mid_edges.iter().copied())
            .collect();
        v.sort_unstable();
        v
    };
    assert_eq!(key(&back), key(&p2));
    assert_eq!(back.nodes, p2.nodes);
}

/// The P1-only consumers refuse a second-order mesh instead of treating its mid-edge nodes as
/// loose nodes: the full-order system, and a transfer table.
#[test]
fn p1_only_paths_refuse_second_order() {
    let p2 = TetMesh::structured_box([2, 1, 1], [0.2, 0.1, 0.1]).to_quadratic();
    let Err(err) = modal_bake::full_order::FullOrderSystem::new(
        p2.clone(),
        &modal_bake::full_order::SystemParams::default(),
        "p2.msh",
    ) else {
        panic!("the truth accepted a second-order mesh")
    };
    let err = err.to_string();
    assert!(err.contains("4-node tetrahedra only"), "{err}");
    let params = BakeParams {
        modes: ModeRequest::Count(2),
        transfer: Some(modal_bake::transfer::TransferParams::default()),
        ..Default::default()
    };
    let Err(err) = bake_mesh(p2, &params, "p2.msh", &mut |_| {}) else {
        panic!("a transfer table was built on a second-order mesh")
    };
    let err = err.to_string();
    assert!(err.contains("not supported for second-order"), "{err}");
}
