//! The `--fixed-near` selector ([`FixedNear`]): the nodes it fixes are exactly those within its
//! distance of the given triangles and points (checked against the analytic distance on a
//! structured box), a region of any shape (two patches whose bounding box covers much more),
//! the mid-edge rule on second-order meshes, its parse errors with line numbers, and that a
//! bake fixed by a face given as triangles equals the same bake fixed by a half-space.
//!
//! Run in release mode: `cargo test --release --workspace --test fixed_near`.

use modal_bake::bake::{bake_mesh, BakeParams, FixedBelow, FixedNear, ModeRequest};
use modal_bake::mesh::TetMesh;

/// Two squares on the top face z = 1 of the unit box, at opposite corners
/// ([0, 0.25]² and [0.75, 1]²), as OBJ text (two quads).
const TWO_PATCHES: &str = "# two patches on the top face\n\
    v 0 0 1\nv 0.25 0 1\nv 0.25 0.25 1\nv 0 0.25 1\n\
    v 0.75 0.75 1\nv 1 0.75 1\nv 1 1 1\nv 0.75 1 1\n\
    f 1 2 3 4\nf -4 -3 -2 -1\n";

/// Distance from `p` to the axis-aligned square [x0, x1] × [y0, y1] on the plane z = 1.
fn square_distance(p: [f64; 3], x: [f64; 2], y: [f64; 2]) -> f64 {
    let dx = (x[0] - p[0]).max(p[0] - x[1]).max(0.0);
    let dy = (y[0] - p[1]).max(p[1] - y[1]).max(0.0);
    (dx * dx + dy * dy + (p[2] - 1.0).powi(2)).sqrt()
}

/// The selected nodes are exactly those within the distance of either patch (analytic
/// distance), so a node inside the patches' common bounding box but far from both (the centre
/// of the top face) stays free.
#[test]
fn selects_exactly_the_nodes_near_the_triangles() {
    let mesh = TetMesh::structured_box([8, 8, 4], [1.0, 1.0, 1.0]);
    let mut near = FixedNear::parse(TWO_PATCHES, "patches.obj").unwrap();
    assert_eq!(near.points.len(), 8);
    assert_eq!(near.triangles.len(), 4, "two quads, two triangles each");
    for d in [1e-9, 0.05, 0.2] {
        near.distance = Some(d);
        let got = near.select(&mesh.nodes, &[], mesh.extent());
        let want: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&v| {
                let p = mesh.nodes[v];
                square_distance(p, [0.0, 0.25], [0.0, 0.25]) <= d
                    || square_distance(p, [0.75, 1.0], [0.75, 1.0]) <= d
            })
            .collect();
        assert_eq!(got, want, "distance {d}");
        assert!(!want.is_empty());
        let centre = mesh
            .nodes
            .iter()
            .position(|p| *p == [0.5, 0.5, 1.0])
            .unwrap();
        assert!(
            !got.contains(&centre),
            "distance {d}: the face centre is fixed"
        );
    }
    // At the smallest distance: the 3 × 3 grid nodes of each patch on the top face.
    near.distance = Some(1e-9);
    assert_eq!(near.select(&mesh.nodes, &[], mesh.extent()).len(), 18);
}

/// Points without faces: the nodes within the distance of any point (brute force), and the
/// default distance is 1/200 of the mesh's diagonal.
#[test]
fn points_alone_select_nodes_within_the_distance() {
    let mesh = TetMesh::structured_box([5, 5, 5], [1.0, 1.0, 1.0]);
    let text = "v 0 0 0\nv 1 1 1\nv 0.5 0.5 0.5\nv 0.31 0.2 0.0\n";
    let near = FixedNear::parse(text, "points.obj").unwrap();
    assert!(near.triangles.is_empty());
    assert_eq!(
        near.distance_for(mesh.extent()),
        mesh.extent() / 200.0,
        "default distance"
    );
    for d in [0.005, 0.12, 0.3] {
        let near = FixedNear {
            distance: Some(d),
            ..near.clone()
        };
        let got = near.select(&mesh.nodes, &[], mesh.extent());
        let want: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&v| {
                near.points.iter().any(|q| {
                    let p = mesh.nodes[v];
                    (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>() <= d * d
                })
            })
            .collect();
        assert_eq!(got, want, "distance {d}");
    }
}

/// Second order: the mid-edge node of an edge whose two corners are fixed is fixed, even
/// when the distance alone would not reach it; no other mid-edge node is added.
#[test]
fn mid_edge_nodes_between_fixed_corners_are_fixed() {
    let p2 = TetMesh::structured_box([2, 2, 2], [1.0, 1.0, 1.0]).to_quadratic();
    let mid_table = p2.edge_mid_nodes().unwrap();
    // The corners (0,0,0) and (0.5,0,0) as points, at a distance below the half edge.
    let near = FixedNear {
        points: vec![[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]],
        triangles: vec![],
        distance: Some(0.01),
        label: "two corners".into(),
    };
    let got = near.select(&p2.nodes, &mid_table, p2.extent());
    let find = |q: [f64; 3]| p2.nodes.iter().position(|p| *p == q).unwrap();
    let mut want = vec![
        find([0.0, 0.0, 0.0]),
        find([0.5, 0.0, 0.0]),
        find([0.25, 0.0, 0.0]),
    ];
    want.sort_unstable();
    assert_eq!(got, want);
}

/// A bake fixed by the bottom face given as two triangles (`fixed_near`) equals the bake
/// fixed by the half-space z ≤ 0 (the same nodes), on a second-order mesh; a region away from
/// the mesh is refused with the mesh's extent.
#[test]
fn bake_fixed_near_a_face_equals_fixed_below() {
    let mesh = TetMesh::structured_box([4, 2, 2], [0.4, 0.2, 0.2]).to_quadratic();
    let base = BakeParams {
        modes: ModeRequest::Count(4),
        ..Default::default()
    };
    let bottom = FixedNear::parse(
        "v 0 0 0\nv 0.4 0 0\nv 0.4 0.2 0\nv 0 0.2 0\nf 1 2 3\nf 1 3 4\n",
        "bottom.obj",
    )
    .unwrap();
    let near = BakeParams {
        fixed_near: vec![FixedNear {
            distance: Some(1e-6),
            ..bottom.clone()
        }],
        ..base.clone()
    };
    let below = BakeParams {
        fixed_below: vec![FixedBelow {
            axis: 2,
            value: 0.0,
        }],
        ..base.clone()
    };
    let (a, ra) = bake_mesh(mesh.clone(), &near, "box", &mut |_| {}).unwrap();
    let (b, rb) = bake_mesh(mesh.clone(), &below, "box", &mut |_| {}).unwrap();
    assert_eq!(ra.fixed_nodes, rb.fixed_nodes);
    assert_eq!(ra.fixed_by[0].1, rb.fixed_nodes);
    assert!(ra.fixed_by[0]
        .0
        .starts_with("near bottom.obj (4 points, 2 triangles"));
    assert_eq!(a.frequencies_hz(), b.frequencies_hz());
    assert_ne!(near.hash(), below.hash());

    let away = BakeParams {
        fixed_near: vec![FixedNear {
            points: vec![[5.0, 5.0, 5.0]],
            triangles: vec![],
            distance: None,
            label: "away.obj".into(),
        }],
        ..base.clone()
    };
    let err = bake_mesh(mesh.clone(), &away, "box", &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("parameter `fixed_near` (near away.obj")
            && err.contains("fixes no node")
            && err.contains("the mesh spans x 0.000000…0.400000"),
        "{err}"
    );
    // Triangles indexing beyond the points are refused before any work.
    let bad = BakeParams {
        fixed_near: vec![FixedNear {
            triangles: vec![[0, 1, 9]],
            ..bottom
        }],
        ..base
    };
    let err = bake_mesh(mesh, &bad, "box", &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("parameter `fixed_near`"), "{err}");
}

/// Parse errors name the file, the line and the expected format.
#[test]
fn parse_errors_name_the_line() {
    for (text, line, what) in [
        ("v 0 0 0\nv 1 x 0\n", 2, "not a number"),
        ("v 0 0\n", 1, "three finite coordinates"),
        ("v 0 0 inf\n", 1, "three finite coordinates"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n", 5, "within 1…3"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least three vertices"),
    ] {
        let err = FixedNear::parse(text, "ears.obj").unwrap_err().to_string();
        assert!(
            err.contains(&format!("ears.obj:{line}: --fixed-near: "))
                && err.contains(what)
                && err.contains("`v x y z` lines (m)"),
            "{text:?}: {err}"
        );
    }
    let err = FixedNear::parse("# nothing\nf 1 2 3\n", "empty.obj")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("empty.obj") && err.contains("no `v x y z`"),
        "{err}"
    );
    let dir = tempfile::tempdir().unwrap();
    let err = FixedNear::read(dir.path()).unwrap_err().to_string();
    assert!(err.contains("not a regular file"), "{err}");
}
