//! Mapping invariants (barycentric weights, BVH vs brute force, normals) and load errors.

use std::path::Path;

use super::*;
use crate::math::{add, dot, norm, scale, sub};
use crate::testing::{
    box_surface, geometric_omegas, icosphere, plate_base, synthetic_base, SplitMix64,
};

/// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5).
fn closest_on_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return add(a, scale(ab, d1 / (d1 - d3)));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return add(a, scale(ac, d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return add(b, scale(sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    add(a, add(scale(ab, vb * denom), scale(ac, vc * denom)))
}

fn models() -> Vec<ModalModel> {
    let om = geometric_omegas(4, 50.0, 500.0);
    vec![
        ModalModel::from_base(plate_base()).unwrap(),
        ModalModel::from_base(synthetic_base(icosphere(2, 0.7), &om, [1.0, 1e-5], 3)).unwrap(),
        ModalModel::from_base(synthetic_base(
            box_surface(5, [1.0, 0.5, 0.3]),
            &om,
            [1.0, 1e-5],
            4,
        ))
        .unwrap(),
    ]
}

/// Over random points near each surface: the BVH distance equals the brute-force minimum over
/// all triangles, the barycentric weights are ≥ 0, sum to 1 and reconstruct the projected point.
#[test]
fn projection_matches_brute_force_and_bary_reconstructs() {
    let mut rng = SplitMix64(42);
    for model in models() {
        let base = model.base();
        let diag = model.bounding_box_diagonal();
        for _ in 0..400 {
            let v = base.surface_vertices
                [(rng.next_u64() % base.surface_vertices.len() as u64) as usize];
            let p = [0, 1, 2].map(|k| v[k] + rng.range(-0.2, 0.2) * diag);
            let sp = model.project(p, f64::MAX).expect("mapped");
            let brute = base
                .surface_triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| base.surface_vertices[i as usize]);
                    norm(sub(p, closest_on_triangle(p, a, b, c)))
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                (sp.distance - brute).abs() <= 1e-9 * diag,
                "{} vs {brute}",
                sp.distance
            );
            let s: f64 = sp.bary.iter().sum();
            assert!(
                (s - 1.0).abs() < 1e-12 && sp.bary.iter().all(|&b| b >= 0.0),
                "{:?}",
                sp.bary
            );
            let vs = model.triangle(sp.triangle);
            let rec = (0..3).fold([0.0; 3], |acc, i| {
                add(acc, scale(base.surface_vertices[vs[i]], sp.bary[i]))
            });
            assert!(norm(sub(rec, sp.point)) <= 1e-12 * diag);
            assert!((norm(sp.normal) - 1.0).abs() < 1e-12);
        }
    }
}

/// A point farther than the limit is not mapped (never snapped); one inside is.
#[test]
fn max_distance_is_respected() {
    let model = ModalModel::from_base(plate_base()).unwrap();
    assert!(model.project([0.5, 0.3, 0.2], 0.1).is_none());
    let sp = model.project([0.5, 0.3, 0.05], 0.1).unwrap();
    assert!((sp.distance - 0.05).abs() < 1e-12);
    assert!(model.project([f64::NAN, 0.0, 0.0], 1.0).is_none());
}

/// Area-weighted vertex normals are unit and outward on closed surfaces.
#[test]
fn vertex_normals_are_unit_and_outward() {
    let om = [100.0];
    let sphere =
        ModalModel::from_base(synthetic_base(icosphere(3, 2.0), &om, [0.0, 0.0], 1)).unwrap();
    for (n, x) in sphere
        .vertex_normals()
        .iter()
        .zip(&sphere.base().surface_vertices)
    {
        assert!((norm(*n) - 1.0).abs() < 1e-12);
        assert!(dot(*n, *x) / norm(*x) > 0.99);
    }
    let cube = ModalModel::from_base(synthetic_base(box_surface(4, [1.0; 3]), &om, [0.0, 0.0], 1))
        .unwrap();
    for (n, x) in cube
        .vertex_normals()
        .iter()
        .zip(&cube.base().surface_vertices)
    {
        assert!(dot(*n, sub(*x, [0.5; 3])) > 0.0);
    }
    let plate = ModalModel::from_base(plate_base()).unwrap();
    assert!(plate
        .vertex_normals()
        .iter()
        .all(|n| (n[2] - 1.0).abs() < 1e-12));
}

/// Truncated, mismatched and NaN files give a LoadError naming the file.
#[test]
fn bad_files_are_load_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.modes");
    plate_base().write_atomic(&good).unwrap();
    let model = ModalModel::load(&good).unwrap();
    assert_eq!(model.num_modes(), 8);

    let bytes = std::fs::read(&good).unwrap();
    let cut = dir.path().join("cut.modes");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let err = ModalModel::load(&cut).unwrap_err().to_string();
    assert!(err.contains("cut.modes"), "{err}");

    let mut nan = plate_base();
    nan.modes[10] = f64::NAN;
    let p = dir.path().join("nan.modes");
    std::fs::write(&p, nan.to_bytes().unwrap()).unwrap();
    let err = ModalModel::load(&p).unwrap_err().to_string();
    assert!(
        err.contains("nan.modes") && err.contains("modes[0][1][2] = NaN (must be finite)"),
        "{err}"
    );

    let mut mis = plate_base();
    mis.surface_to_volume.pop();
    let p = dir.path().join("mis.modes");
    std::fs::write(&p, mis.to_bytes().unwrap()).unwrap();
    let err = ModalModel::load(&p).unwrap_err().to_string();
    assert!(err.contains("mis.modes"), "{err}");

    let err = ModalModel::load(Path::new("/nonexistent/x.modes"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("x.modes"), "{err}");

    let mut bad = plate_base();
    bad.eigenvalues[0] = -1.0;
    assert!(ModalModel::from_base(bad)
        .unwrap_err()
        .to_string()
        .contains("<memory>"));
}

/// The contact row equals nᵀ Σ b_i U_i assembled by hand.
#[test]
fn contact_row_is_interpolated_normal_projection() {
    let model = ModalModel::from_base(plate_base()).unwrap();
    let m = model.num_modes();
    let sp = model.project([0.37, 0.21, 0.01], 1.0).unwrap();
    let mut w = vec![0.0; m];
    model.contact_row(&sp, &mut w);
    let vs = model.triangle(sp.triangle);
    for j in 0..m {
        let mut e = 0.0;
        for i in 0..3 {
            for axis in 0..3 {
                e += sp.bary[i] * sp.normal[axis] * model.base().modes[(vs[i] * 3 + axis) * m + j];
            }
        }
        assert!((w[j] - e).abs() < 1e-15);
    }
}

/// The model is shared between threads (Arc) and instances can move to worker threads.
#[test]
fn model_is_send_sync_and_response_is_send() {
    fn send_sync<T: Send + Sync>() {}
    fn send<T: Send>() {}
    send_sync::<ModalModel>();
    send::<crate::DistantResponse>();
}
