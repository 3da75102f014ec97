//! `Method::Transfer`: the base's bake-time peak-transfer table looked up at run time.
//!
//! Expectations: at region vertices the response is the table entry × the normal impulse
//! (exactly, up to f32 → f64); inside triangles it is the barycentric blend Σ β_a β_b T[a][b]
//! for a vertex-only table, and for a table with edge midpoints the P2 interpolant, which
//! reproduces a T that is quadratic in each point's position;
//! several impacts add; only the normal impulse component counts; contacts outside the region
//! are served by the modal method (same values as `Method::Modal`), and every step falls back to
//! the modal method when an impact is outside the region, the step has forces, or h, Rayleigh
//! damping or carry-over (without `Launch::SustainedPeak`) do not match the table; under
//! `Launch::SustainedPeak` the table and the carried filters serve together (the larger peak).

use std::sync::Arc;

use dcr_runtime::format::{ModesFile, TransferTable};
use dcr_runtime::response::{ForceInput, Impact, RestingContact, ServedBy};
use dcr_runtime::testing::{plate_base, SplitMix64};
use dcr_runtime::{DistantResponse, Launch, Method, ModalModel, ResponseParams};

const H: f64 = 0.01;

/// The plate base (z = 0, normals +z) with a synthetic symmetric table over the vertices with
/// x ≤ 0.5 m (whole grid cells: the plate's column 6 of 12 is at x = 0.5).
fn base_with_table() -> ModesFile {
    let mut b = plate_base();
    let vertices: Vec<u32> = (0..b.surface_vertices.len())
        .filter(|&v| b.surface_vertices[v][0] <= 0.5 + 1e-12)
        .map(|v| v as u32)
        .collect();
    let nr = vertices.len();
    let mut peaks = Vec::with_capacity(TransferTable::packed_len(nr));
    for i in 0..nr {
        for j in i..nr {
            peaks.push(1e-5 * (1.0 + ((i * 7 + j * 13) % 17) as f32));
        }
    }
    b.transfer = Some(TransferTable {
        h: H,
        rayleigh: b.rayleigh,
        modes: 100,
        samples: 400,
        vertices,
        order: 1,
        edges: Vec::new(),
        faces: Vec::new(),
        peaks,
    });
    b
}

fn params(method: Method) -> ResponseParams {
    ResponseParams {
        h: H,
        method,
        ..Default::default()
    }
}

fn region_index(t: &TransferTable, v: usize) -> usize {
    t.vertices.binary_search(&(v as u32)).expect("in region")
}

fn vertex_contacts(model: &ModalModel, vs: &[usize]) -> Vec<RestingContact> {
    vs.iter()
        .enumerate()
        .map(|(k, &v)| RestingContact {
            id: k as u64,
            point: model.base().surface_vertices[v],
        })
        .collect()
}

#[test]
fn lookup_at_vertices_reproduces_the_table() {
    let model = Arc::new(ModalModel::from_base(base_with_table()).unwrap());
    let t = model.base().transfer.clone().unwrap();
    let mut dr = DistantResponse::new(model.clone(), params(Method::Transfer)).unwrap();
    assert!(dr.transfer_active());
    let vs: Vec<usize> = t.vertices.iter().map(|&v| v as usize).step_by(5).collect();
    let resting = vertex_contacts(&model, &vs);
    for &src in &vs[..4] {
        let imp = [Impact {
            point: model.base().surface_vertices[src],
            direction: [0.0, 0.0, -1.0],
            impulse: 2.5,
        }];
        let out = dr.step(&imp, &resting).to_vec();
        let info = dr.last_step_info();
        assert_eq!(info.contacts_by_table as usize, resting.len());
        assert_eq!(info.impacts_applied, 1);
        for (o, &dst) in out.iter().zip(&vs) {
            assert_eq!(o.served_by, ServedBy::TransferTable);
            let want = 2.5 * t.peak(region_index(&t, src), region_index(&t, dst));
            assert!(
                (o.peak_displacement - want).abs() <= 1e-12 * want,
                "{src}→{dst}: {} vs {want}",
                o.peak_displacement
            );
            assert!((o.delta_v - o.peak_displacement / H).abs() <= 1e-15);
        }
    }
}

#[test]
fn inside_triangles_is_the_barycentric_blend_and_impacts_add() {
    let model = Arc::new(ModalModel::from_base(base_with_table()).unwrap());
    let t = model.base().transfer.clone().unwrap();
    let mut dr = DistantResponse::new(model.clone(), params(Method::Transfer)).unwrap();
    let mut rng = SplitMix64(5);
    let mut pt = || [rng.range(0.0, 0.5), rng.range(0.0, 0.6), 0.0];
    let resting: Vec<RestingContact> = (0..12)
        .map(|i| RestingContact { id: i, point: pt() })
        .collect();
    let imps: Vec<Impact> = (0..3)
        .map(|k| Impact {
            point: pt(),
            // Tilted: only the normal component (0.8) counts.
            direction: if k == 1 {
                [0.6, 0.0, -0.8]
            } else {
                [0.0, 0.0, -1.0]
            },
            impulse: 1.0 + k as f64,
        })
        .collect();
    let blend = |a: [f64; 3], b: [f64; 3]| {
        let sa = model.project(a, 1.0).unwrap();
        let sb = model.project(b, 1.0).unwrap();
        let (ta, tb) = (model.triangle(sa.triangle), model.triangle(sb.triangle));
        let mut p = 0.0;
        for (&va, ba) in ta.iter().zip(sa.bary) {
            for (&vb, bb) in tb.iter().zip(sb.bary) {
                p += ba * bb * t.peak(region_index(&t, va), region_index(&t, vb));
            }
        }
        p
    };
    let out = dr.step(&imps, &resting).to_vec();
    for (o, rc) in out.iter().zip(&resting) {
        assert_eq!(o.served_by, ServedBy::TransferTable);
        let want: f64 = imps
            .iter()
            .enumerate()
            .map(|(k, imp)| {
                let normal = if k == 1 { 0.8 } else { 1.0 };
                imp.impulse * normal * blend(imp.point, rc.point)
            })
            .sum();
        assert!(
            (o.peak_displacement - want).abs() <= 1e-12 * want,
            "{} vs {want}",
            o.peak_displacement
        );
    }
    // The blend is not the value at a vertex: it must move with the point.
    assert!((out[0].peak_displacement - out[1].peak_displacement).abs() > 0.0);
}

/// Steps the same input through a `Method::Modal` instance for comparison.
fn modal_out(
    model: &Arc<ModalModel>,
    p: ResponseParams,
    imp: &[Impact],
    rc: &[RestingContact],
) -> Vec<f64> {
    let mut dr = DistantResponse::new(
        model.clone(),
        ResponseParams {
            method: Method::Modal,
            ..p
        },
    )
    .unwrap();
    dr.step(imp, rc)
        .iter()
        .map(|o| o.peak_displacement)
        .collect()
}

#[test]
fn outside_the_region_falls_back_to_the_modal_method() {
    let model = Arc::new(ModalModel::from_base(base_with_table()).unwrap());
    let mut dr = DistantResponse::new(model.clone(), params(Method::Transfer)).unwrap();
    let inside = RestingContact {
        id: 1,
        point: [0.2, 0.3, 0.0],
    };
    let outside = RestingContact {
        id: 2,
        point: [0.9, 0.3, 0.0],
    };
    let resting = [inside, outside];
    let imp_in = [Impact {
        point: [0.3, 0.2, 0.0],
        direction: [0.0, 0.0, -1.0],
        impulse: 3.0,
    }];
    let modal = modal_out(&model, params(Method::Modal), &imp_in, &resting);
    let out = dr.step(&imp_in, &resting).to_vec();
    assert_eq!(out[0].served_by, ServedBy::TransferTable);
    assert_eq!(out[1].served_by, ServedBy::Modal);
    assert_eq!(out[1].peak_displacement, modal[1]);
    assert_ne!(out[0].peak_displacement, modal[0]);
    let info = dr.last_step_info();
    assert_eq!(
        (info.contacts_by_table, info.contacts_table_fallback),
        (1, 1)
    );
    assert_eq!(info.impacts_applied, 1);

    // An impact outside the region: the whole step is modal.
    let imp_out = [Impact {
        point: [0.8, 0.2, 0.0],
        direction: [0.0, 0.0, -1.0],
        impulse: 3.0,
    }];
    let modal = modal_out(&model, params(Method::Modal), &imp_out, &resting);
    let out = dr.step(&imp_out, &resting).to_vec();
    assert!(out.iter().all(|o| o.served_by == ServedBy::Modal));
    assert_eq!(
        out.iter().map(|o| o.peak_displacement).collect::<Vec<_>>(),
        modal
    );
    assert_eq!(dr.last_step_info().contacts_by_table, 0);

    // Forces: modal.
    let f = [ForceInput {
        point: [0.2, 0.2, 0.0],
        force: [0.0, 0.0, -1.0],
    }];
    let out = dr.step_with_forces(&imp_in, &f, &resting).to_vec();
    assert!(out.iter().all(|o| o.served_by == ServedBy::Modal));

    // Back in the region: the table again.
    let out = dr.step(&imp_in, &[inside]).to_vec();
    assert_eq!(out[0].served_by, ServedBy::TransferTable);
}

#[test]
fn mismatched_h_rayleigh_or_carry_over_use_the_modal_method() {
    let model = Arc::new(ModalModel::from_base(base_with_table()).unwrap());
    let plain = Arc::new(ModalModel::from_base(plate_base()).unwrap());
    let resting = [RestingContact {
        id: 1,
        point: [0.2, 0.3, 0.0],
    }];
    let imp = [Impact {
        point: [0.3, 0.2, 0.0],
        direction: [0.0, 0.0, -1.0],
        impulse: 3.0,
    }];
    let base_r = model.base().rayleigh;
    let cases = [
        (
            model.clone(),
            ResponseParams {
                h: H * (1.0 + 1e-6),
                ..params(Method::Transfer)
            },
        ),
        (
            model.clone(),
            ResponseParams {
                rayleigh: Some([base_r[0] * 2.0, base_r[1]]),
                ..params(Method::Transfer)
            },
        ),
        (
            model.clone(),
            ResponseParams {
                carry_over: true,
                ..params(Method::Transfer)
            },
        ),
        (plain.clone(), params(Method::Transfer)),
    ];
    for (k, (m, p)) in cases.into_iter().enumerate() {
        let mut dr = DistantResponse::new(m.clone(), p.clone()).unwrap();
        assert!(!dr.transfer_active(), "case {k}");
        let want = modal_out(&m, p, &imp, &resting);
        let out = dr.step(&imp, &resting).to_vec();
        assert_eq!(out[0].served_by, ServedBy::Modal, "case {k}");
        assert_eq!(out[0].peak_displacement, want[0], "case {k}");
    }
    // Within the 1e-9 tolerance the table applies.
    let dr = DistantResponse::new(
        model,
        ResponseParams {
            h: H * (1.0 + 1e-12),
            ..params(Method::Transfer)
        },
    )
    .unwrap();
    assert!(dr.transfer_active());
}

/// Position (m) of table point `p`: the blend of its region vertices.
fn table_point(t: &TransferTable, x: &[[f64; 3]], p: usize) -> [f64; 3] {
    let (vs, ws) = t.point_support(p);
    let mut q = [0.0; 3];
    for k in 0..3 {
        for c in 0..3 {
            q[c] += ws[k] * x[t.vertices[vs[k] as usize] as usize][c];
        }
    }
    q
}

/// A symmetric kernel quadratic in each argument's (x, y) (m): P2 interpolation on flat
/// triangles reproduces it exactly. Positive on the plate; units m per N·s.
fn quadratic_kernel(a: [f64; 3], b: [f64; 3]) -> f64 {
    1e-5 * (3.0 + a[0] * b[1] + a[1] * b[0] + a[1] * a[1] + b[1] * b[1] + a[0] * a[1] * b[0] * b[1]
        - 0.5 * (a[0] * a[0] + b[0] * b[0]))
}

#[test]
fn with_midpoints_the_lookup_reproduces_a_quadratic_table() {
    let mut b = base_with_table();
    let x = b.surface_vertices.clone();
    let t = b.transfer.as_mut().unwrap();
    t.order = 2;
    t.edges = TransferTable::region_edges(&b.surface_triangles, &t.vertices);
    assert!(!t.edges.is_empty());
    let point = |p: usize| table_point(t, &x, p);
    let np = t.num_points();
    let mut peaks = Vec::with_capacity(TransferTable::packed_len(np));
    for p in 0..np {
        for q in p..np {
            peaks.push(quadratic_kernel(point(p), point(q)) as f32);
        }
    }
    t.peaks = peaks;
    let model = Arc::new(ModalModel::from_base(b).unwrap());
    let mut dr = DistantResponse::new(model.clone(), params(Method::Transfer)).unwrap();
    let mut rng = SplitMix64(11);
    let mut pt = || [rng.range(0.0, 0.5), rng.range(0.0, 0.6), 0.0];
    let resting: Vec<RestingContact> = (0..16)
        .map(|i| RestingContact { id: i, point: pt() })
        .collect();
    for _ in 0..4 {
        let imp = Impact {
            point: pt(),
            direction: [0.0, 0.0, -1.0],
            impulse: 2.0,
        };
        let out = dr.step(&[imp], &resting).to_vec();
        let mut linear_off = 0.0f64;
        for (o, rc) in out.iter().zip(&resting) {
            assert_eq!(o.served_by, ServedBy::TransferTable);
            let want = 2.0 * quadratic_kernel(imp.point, rc.point);
            let rel = (o.peak_displacement - want).abs() / want;
            // f32 table entries: ≈ 6e-8 relative each.
            assert!(
                rel < 1e-6,
                "{:?}→{:?}: {} vs {want}",
                imp.point,
                rc.point,
                o.peak_displacement
            );
            // The vertex-only blend of the same kernel is off inside triangles (so this test
            // sees the midpoints).
            let sa = model.project(imp.point, 1.0).unwrap();
            let sb = model.project(rc.point, 1.0).unwrap();
            let (ta, tb) = (model.triangle(sa.triangle), model.triangle(sb.triangle));
            let mut lin = 0.0;
            for (&va, ba) in ta.iter().zip(sa.bary) {
                for (&vb, bb) in tb.iter().zip(sb.bary) {
                    lin += ba * bb * quadratic_kernel(x[va], x[vb]);
                }
            }
            linear_off = linear_off.max((2.0 * lin - want).abs() / want);
        }
        assert!(
            linear_off > 1e-4,
            "linear blend unexpectedly exact: {linear_off:e}"
        );
    }
}

/// A symmetric kernel cubic in each argument's (x, y) (m): P3 interpolation on flat triangles
/// reproduces it exactly, P2 does not. Positive on the plate; units m per N·s.
fn cubic_kernel(a: [f64; 3], b: [f64; 3]) -> f64 {
    // In units of 0.25 m, so the cubic terms matter on the 0.5 m × 0.6 m region.
    let f = |p: [f64; 3]| {
        let (x, y) = (4.0 * p[0], 4.0 * p[1]);
        2.0 + x * x * y - 0.2 * y * y * y + 0.5 * x * x * x + 3.0
    };
    let g = |p: [f64; 3]| {
        let (x, y) = (4.0 * p[0], 4.0 * p[1]);
        1.0 + x * y * y + x
    };
    1e-5 * (f(a) * f(b) + g(a) * g(b))
}

/// An order-3 table (two points per edge, face centroids) of a cubic kernel is reproduced
/// exactly at random interior impacts and contacts, including points on the region's edge;
/// the same kernel on an order-2 table is not (so the test sees the cubic nodes).
#[test]
fn order_three_lookup_reproduces_a_cubic_table() {
    let table_for = |order: u8| {
        let mut b = base_with_table();
        let x = b.surface_vertices.clone();
        let t = b.transfer.as_mut().unwrap();
        t.order = order;
        t.edges = TransferTable::region_edges(&b.surface_triangles, &t.vertices);
        t.faces = if order == 3 {
            TransferTable::region_faces(&b.surface_triangles, &t.vertices)
        } else {
            Vec::new()
        };
        let np = t.num_points();
        let mut peaks = Vec::with_capacity(TransferTable::packed_len(np));
        for p in 0..np {
            for q in p..np {
                peaks.push(cubic_kernel(table_point(t, &x, p), table_point(t, &x, q)) as f32);
            }
        }
        t.peaks = peaks;
        assert_eq!(t.check(x.len()), Ok(()));
        Arc::new(ModalModel::from_base(b).unwrap())
    };
    let (m3, m2) = (table_for(3), table_for(2));
    let mut rng = SplitMix64(5);
    let mut pt = || [rng.range(0.0, 0.5), rng.range(0.0, 0.6), 0.0];
    let mut resting: Vec<RestingContact> = (0..16)
        .map(|i| RestingContact { id: i, point: pt() })
        .collect();
    // On the region's boundary edge x = 0.5 (its triangles outside have weight 0 there).
    resting.push(RestingContact {
        id: 99,
        point: [0.5, 0.37, 0.0],
    });
    let mut worst2 = 0.0f64;
    for _ in 0..4 {
        let imp = Impact {
            point: pt(),
            direction: [0.0, 0.0, -1.0],
            impulse: 1.5,
        };
        let mut d3 = DistantResponse::new(m3.clone(), params(Method::Transfer)).unwrap();
        let mut d2 = DistantResponse::new(m2.clone(), params(Method::Transfer)).unwrap();
        let o3 = d3.step(&[imp], &resting).to_vec();
        let o2 = d2.step(&[imp], &resting).to_vec();
        for ((a, b), rc) in o3.iter().zip(&o2).zip(&resting) {
            assert_eq!(a.served_by, ServedBy::TransferTable);
            let want = 1.5 * cubic_kernel(imp.point, rc.point);
            let rel = (a.peak_displacement - want).abs() / want;
            assert!(
                rel < 1e-6,
                "{:?}→{:?}: {} vs {want}",
                imp.point,
                rc.point,
                a.peak_displacement
            );
            worst2 = worst2.max((b.peak_displacement - want).abs() / want);
        }
    }
    assert!(
        worst2 > 1e-4,
        "P2 unexpectedly exact on a cubic kernel: {worst2:e}"
    );
}

/// `Launch::SustainedPeak` with the table: the table applies under carry-over; on a step with
/// an impact each contact takes the larger of the table's peak (from rest) and the carried
/// 20-mode filters' (the same as a `Method::Modal` carried response's), served by whichever
/// gave it; on the following steps without impacts the carried filters serve alone, and
/// contacts outside the region are the modal ones throughout.
#[test]
fn sustained_peak_takes_the_larger_of_table_and_carried_filters() {
    let model = Arc::new(ModalModel::from_base(base_with_table()).unwrap());
    let sustained = |method| ResponseParams {
        carry_over: true,
        launch: Launch::SustainedPeak,
        ..params(method)
    };
    let mut hybrid = DistantResponse::new(model.clone(), sustained(Method::Transfer)).unwrap();
    assert!(hybrid.transfer_active());
    let mut carried = DistantResponse::new(model.clone(), sustained(Method::Modal)).unwrap();
    let mut table = DistantResponse::new(model.clone(), params(Method::Transfer)).unwrap();
    // In the region (x ≤ 0.5) near and far from the impact, and outside it.
    let resting: Vec<RestingContact> = [[0.2, 0.3, 0.0], [0.45, 0.05, 0.0], [0.9, 0.5, 0.0]]
        .iter()
        .enumerate()
        .map(|(i, &point)| RestingContact {
            id: i as u64,
            point,
        })
        .collect();
    let imp = [Impact {
        point: [0.1, 0.1, 0.0],
        direction: [0.0, 0.0, -1.0],
        impulse: 3.0,
    }];
    let (mut by_table, mut by_filters) = (0, 0);
    for step in 0..4 {
        let imps: &[Impact] = if step == 0 { &imp } else { &[] };
        let got = hybrid.step(imps, &resting).to_vec();
        let modal = carried.step(imps, &resting).to_vec();
        let from_rest = table.step(imps, &resting).to_vec();
        for ((g, m), t) in got.iter().zip(&modal).zip(&from_rest) {
            let tag = format!("step {step} contact {}", g.id);
            let in_region = t.served_by == ServedBy::TransferTable;
            let want = if in_region {
                m.peak_displacement.max(t.peak_displacement)
            } else {
                m.peak_displacement
            };
            assert_eq!(g.peak_displacement, want, "{tag}");
            assert_eq!(g.delta_v, want / H, "{tag}");
            let table_won = in_region && t.peak_displacement > m.peak_displacement;
            let served = if table_won {
                ServedBy::TransferTable
            } else {
                ServedBy::Modal
            };
            assert_eq!(g.served_by, served, "{tag}");
            if table_won {
                by_table += 1;
            } else if g.peak_displacement > 0.0 {
                by_filters += 1;
            }
            if step > 0 {
                assert_eq!(
                    t.peak_displacement, 0.0,
                    "{tag}: no impact, nothing from rest"
                );
            }
        }
    }
    // Both sources serve somewhere: the table on the impact's step, the ringing after it.
    assert!(by_table > 0 && by_filters > 0, "{by_table} {by_filters}");
}
