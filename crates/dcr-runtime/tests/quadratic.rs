//! Second-order bases: the quadratic shape functions of the 6-node surface triangles, contact
//! rows that reproduce a quadratic field exactly, the version-2 format (round trip, refusals),
//! and a version-1 base written by the release before second-order support still loading.
//!
//! `cargo test --release -p dcr-runtime --test quadratic`

use std::io::Cursor;
use std::path::Path;

use dcr_runtime::format::{FormatError, ModesFile, QuadraticSurface, TransferTable};
use dcr_runtime::model::quadratic_triangle_weights;
use dcr_runtime::testing::{box_surface, geometric_omegas, icosphere, synthetic_base, SplitMix64};
use dcr_runtime::ModalModel;

/// A quadratic vector field (one value per axis and mode j), the "mode shape" of the tests.
fn field(p: [f64; 3], j: usize) -> [f64; 3] {
    let s = 1.0 + j as f64;
    [
        0.3 * p[0] * p[0] - s * p[1] * p[2] + 0.1,
        s * p[0] * p[1] + 0.5 * p[2] * p[2],
        -p[0] * p[2] + 0.2 * s * p[1] * p[1] - 0.3 * p[0],
    ]
}

/// `base` with every corner row and a mid-edge row per surface edge set to [`field`] at the
/// node: a second-order base whose modes are exactly quadratic.
fn quadratic_base(mut base: ModesFile) -> ModesFile {
    let m = base.num_modes();
    for (v, p) in base.surface_vertices.iter().enumerate() {
        for j in 0..m {
            let f = field(*p, j);
            for axis in 0..3 {
                base.modes[(v * 3 + axis) * m + j] = f[axis];
            }
        }
    }
    let edges = QuadraticSurface::edges_of(&base.surface_triangles);
    let mut modes = vec![0.0; edges.len() * 3 * m];
    for (e, &[a, b]) in edges.iter().enumerate() {
        let (x, y) = (
            base.surface_vertices[a as usize],
            base.surface_vertices[b as usize],
        );
        let mid = [0, 1, 2].map(|k| 0.5 * (x[k] + y[k]));
        for j in 0..m {
            let f = field(mid, j);
            for axis in 0..3 {
                modes[(e * 3 + axis) * m + j] = f[axis];
            }
        }
    }
    base.quadratic = Some(QuadraticSurface {
        edge_to_volume: (0..edges.len() as u32).map(|e| 1000 + e).collect(),
        edges,
        modes,
    });
    base.meta.format_version = 2;
    base
}

/// The six weights sum to 1, are nodal (1 at their node, 0 at the others) and interpolate any
/// quadratic function of position exactly.
#[test]
fn quadratic_weights_are_nodal_and_reproduce_quadratics() {
    let nodes: [[f64; 3]; 6] = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
    ];
    for (i, b) in nodes.iter().enumerate() {
        let w = quadratic_triangle_weights(*b);
        for (k, &wk) in w.iter().enumerate() {
            assert_eq!(wk, if k == i { 1.0 } else { 0.0 }, "node {i}, weight {k}");
        }
    }
    let x = [[0.1, 0.2, -0.3], [1.3, 0.1, 0.2], [0.4, 0.9, 0.5]];
    let node_pos = |b: [f64; 3]| [0, 1, 2].map(|k| (0..3).map(|i| b[i] * x[i][k]).sum::<f64>());
    let mut rng = SplitMix64(3);
    for _ in 0..200 {
        let (r, s) = (rng.range(0.0, 1.0), rng.range(0.0, 1.0));
        let (r, s) = if r + s > 1.0 {
            (1.0 - r, 1.0 - s)
        } else {
            (r, s)
        };
        let b = [1.0 - r - s, r, s];
        let w = quadratic_triangle_weights(b);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let p = node_pos(b);
        for j in 0..3 {
            let exact = field(p, j);
            let mut got = [0.0; 3];
            for (k, nb) in nodes.iter().enumerate() {
                let f = field(node_pos(*nb), j);
                for a in 0..3 {
                    got[a] += w[k] * f[a];
                }
            }
            for a in 0..3 {
                assert!((got[a] - exact[a]).abs() < 1e-13, "{got:?} vs {exact:?}");
            }
        }
    }
}

/// On a second-order base whose modes are a quadratic field, the contact row at any mapped
/// surface point is nᵀ field(point) exactly; the same base without its mid-edge rows (linear
/// interpolation) is measurably off, so the test sees the difference.
#[test]
fn contact_rows_of_a_quadratic_base_are_exact() {
    let om = geometric_omegas(3, 50.0, 400.0);
    for surface in [icosphere(2, 0.7), box_surface(3, [1.0, 0.5, 0.3])] {
        let base = quadratic_base(synthetic_base(surface, &om, [1.0, 1e-5], 5));
        let mut linear = base.clone();
        linear.quadratic = None;
        linear.meta.format_version = 1;
        let p2 = ModalModel::from_base(base).unwrap();
        let p1 = ModalModel::from_base(linear).unwrap();
        assert!(p2.is_quadratic() && !p1.is_quadratic());
        let diag = p2.bounding_box_diagonal();
        let mut rng = SplitMix64(17);
        let (mut worst2, mut worst1) = (0.0f64, 0.0f64);
        for _ in 0..300 {
            let v =
                p2.base().surface_vertices[(rng.next_u64() % p2.num_vertices() as u64) as usize];
            let q = [0, 1, 2].map(|k| v[k] + rng.range(-0.05, 0.05) * diag);
            let sp = p2.project(q, f64::MAX).unwrap();
            let mut w2 = vec![0.0; 3];
            let mut w1 = vec![0.0; 3];
            p2.contact_row(&sp, &mut w2);
            p1.contact_row(&sp, &mut w1);
            for j in 0..3 {
                let f = field(sp.point, j);
                let exact: f64 = (0..3).map(|a| sp.normal[a] * f[a]).sum();
                worst2 = worst2.max((w2[j] - exact).abs());
                worst1 = worst1.max((w1[j] - exact).abs());
            }
        }
        assert!(worst2 < 1e-12, "quadratic base off by {worst2:e}");
        assert!(
            worst1 > 1e-4,
            "linear interpolation unexpectedly exact ({worst1:e})"
        );
    }
}

/// A second-order base round-trips through the file (f64 and f32), is version 2, and the
/// inconsistent cases are refused: version 1 claiming mid-edge rows, edges that are not the
/// triangles', a transfer table on a second-order base, a missing entry of the group.
#[test]
fn version_2_round_trip_and_refusals() {
    let om = geometric_omegas(2, 50.0, 200.0);
    let base = quadratic_base(synthetic_base(
        box_surface(2, [1.0, 1.0, 1.0]),
        &om,
        [1.0, 1e-5],
        7,
    ));
    assert_eq!(base.required_format_version(), 2);
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("p2.modes");
    base.write_atomic(&p).unwrap();
    let back = ModesFile::read(&p).unwrap();
    assert_eq!(back, base);
    let mut f32b = base.clone();
    f32b.precision = dcr_runtime::format::ModesPrecision::F32;
    f32b.write_atomic(&p).unwrap();
    let back = ModesFile::read(&p).unwrap();
    let q = back.quadratic.as_ref().unwrap();
    let q0 = base.quadratic.as_ref().unwrap();
    assert!(q
        .modes
        .iter()
        .zip(&q0.modes)
        .all(|(a, b)| (a - b).abs() <= 1e-6 * b.abs().max(1.0)));

    let mut v1 = base.clone();
    v1.meta.format_version = 1;
    let err = v1.write_atomic(&p).unwrap_err().to_string();
    assert!(err.contains("cannot hold a second-order surface"), "{err}");

    let mut bad = base.clone();
    bad.quadratic.as_mut().unwrap().edges.pop();
    let err = bad.write_atomic(&p).unwrap_err().to_string();
    assert!(err.contains("not exactly the edges"), "{err}");

    let mut table = base.clone();
    table.transfer = Some(TransferTable {
        h: 0.01,
        rayleigh: [1.0, 1e-5],
        modes: 2,
        samples: 4,
        vertices: vec![0, 1],
        order: 1,
        edges: vec![],
        faces: vec![],
        peaks: vec![1e-6; 3],
    });
    let err = table.write_atomic(&p).unwrap_err().to_string();
    assert!(err.contains("second-order base is not supported"), "{err}");

    // Drop `edge_modes` from a valid archive: the group's missing entry is named.
    base.write_atomic(&p).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    let mut zin = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
    let mut out = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for i in 0..zin.len() {
        let f = zin.by_index_raw(i).unwrap();
        if f.name() != "edge_modes.npy" {
            out.raw_copy_file(f).unwrap();
        }
    }
    let cut = out.finish().unwrap().into_inner();
    let err = ModesFile::read_from(Cursor::new(cut), Path::new("cut.modes")).unwrap_err();
    assert!(
        matches!(
            err,
            FormatError::Missing {
                entry: "edge_modes",
                ..
            }
        ),
        "{err}"
    );
}

/// A base written by modal-bake before second-order support (format version 1,
/// `scripts/gen_v1_base.sh` → data/bases/v1_beam.modes) loads, with linear interpolation.
#[test]
fn version_1_base_from_the_previous_release_loads() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/bases/v1_beam.modes");
    let model = ModalModel::load(&p).unwrap();
    let base = model.base();
    assert_eq!(base.meta.format_version, 1);
    assert!(base.quadratic.is_none() && !model.is_quadratic());
    assert_eq!(base.num_modes(), 3);
    assert!(base.meta.tool_version.starts_with("modal-bake"));
    // First bending mode of the 1 × 0.1 × 0.1 m clamped beam (E 2 GPa, ρ 1200): ≈ 20.9 Hz
    // Euler–Bernoulli; linear tets are stiffer.
    let f0 = base.frequencies_hz()[0];
    assert!(f0 > 20.0 && f0 < 40.0, "{f0}");
}
