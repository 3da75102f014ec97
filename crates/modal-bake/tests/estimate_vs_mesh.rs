//! The size estimate before meshing ([`modal_bake::bake::SizeEstimate::of_surface`] at
//! [`modal_bake::mesh::sizing::equivalent_size`], as `modal-bake mesh` and `bake` print it)
//! against the degrees of freedom gmsh then really makes at the defaults (order 2, 1/20 of the
//! diagonal, curvature and thickness-aware sizing): within [`FACTOR`] either way on compact,
//! curved and thin-walled shapes and on gmsh's thin-walled tutorial part (when the PyPI gmsh
//! ships it), within [`CURVED_FACTOR`] on a slender rod, whose elements gmsh's curvature
//! sizing sets.
//!
//! Skips with a message when gmsh is missing, unless `DCR_REQUIRE_GMSH=1`.
//!
//! `cargo test --release --workspace --test estimate_vs_mesh -- --nocapture` prints the ratios.

#[path = "common/gmsh_gate.rs"]
mod gmsh_gate;
#[path = "common/shapes.rs"]
mod shapes;
use gmsh_gate::have_gmsh;
use modal_bake::bake::{SizeEstimate, SurfaceMeasures};
use modal_bake::mesh::sizing::{default_size, equivalent_size};
use modal_bake::mesh::surface::SurfaceMesh;
use modal_bake::mesh::{mesh_surface, MeshParams};
use shapes::{cylinder, uv_sphere};

/// The estimate is within this factor of the meshed degrees of freedom, either way, where
/// its terms (volume, boundary at the equivalent size, thin walls) describe what gmsh does.
const FACTOR: f64 = 1.35;

/// Where gmsh's curvature sizing sets the elements (a slender rod), the estimate's curvature
/// term is only this good: it sees up to 1.5/R on long strips ([`equivalent_size`]), and
/// gmsh's own curvature estimate differs from asset to asset (docs/artist-guide.md § 7).
const CURVED_FACTOR: f64 = 2.6;

/// An axis-aligned box [0, l] as 12 triangles.
fn box_surface(l: [f64; 3]) -> SurfaceMesh {
    extrude_caps(
        &[[0.0, 0.0], [l[0], 0.0], [l[0], l[1]], [0.0, l[1]]],
        &[vec![0, 1, 2, 3]],
        l[2],
        1,
    )
}

/// The prism of a simple polygon `p` (counter-clockwise, m) extruded along z by `depth`, its
/// caps split into the convex polygons `caps` (indices into `p`, counter-clockwise), its sides
/// in `stacks` rows of triangles; outward.
fn extrude_caps(p: &[[f64; 2]], caps: &[Vec<usize>], depth: f64, stacks: usize) -> SurfaceMesh {
    let n = p.len();
    let vertices: Vec<[f64; 3]> = (0..=stacks)
        .flat_map(|s| {
            let z = depth * s as f64 / stacks as f64;
            p.iter().map(move |q| [q[0], q[1], z])
        })
        .collect();
    let top = n * stacks;
    let mut triangles = Vec::new();
    for c in caps {
        for k in 1..c.len() - 1 {
            triangles.push([c[0], c[k + 1], c[k]]);
            triangles.push([top + c[0], top + c[k], top + c[k + 1]]);
        }
    }
    for s in 0..stacks {
        let (a, b) = (s * n, (s + 1) * n);
        for i in 0..n {
            let j = (i + 1) % n;
            triangles.push([a + i, a + j, b + j]);
            triangles.push([a + i, b + j, b + i]);
        }
    }
    SurfaceMesh {
        vertices,
        triangles,
    }
}

/// A U-channel (width `w`, height `h`, wall `t`, length `len`, m): a thin-walled part,
/// `stacks` triangle rows along its length.
fn channel(w: f64, h: f64, t: f64, len: f64, stacks: usize) -> SurfaceMesh {
    let p = [
        [0.0, 0.0],
        [w, 0.0],
        [w, t],
        [w, h],
        [w - t, h],
        [w - t, t],
        [t, t],
        [t, h],
        [0.0, h],
        [0.0, t],
    ];
    let caps = vec![vec![0, 1, 2, 5, 6, 9], vec![5, 2, 3, 4], vec![9, 6, 7, 8]];
    extrude_caps(&p, &caps, len, stacks)
}

/// gmsh's tutorial STL (mm), shipped by the PyPI gmsh under `<prefix>/share/doc/gmsh`.
fn t13() -> Option<SurfaceMesh> {
    let out = std::process::Command::new("python3")
        .args(["-c", "import sys; print(sys.prefix)"])
        .output()
        .ok()?;
    let prefix = String::from_utf8(out.stdout).ok()?;
    let path = std::path::Path::new(prefix.trim()).join("share/doc/gmsh/tutorials/t13_data.stl");
    let mut s = modal_bake::mesh::surface::read_surface(&path).ok()?;
    s.scale(1e-3);
    Some(s)
}

/// The body of an XR controller as shipped (data/assets/hp_body.obj, m): closed and faceted.
fn hp_body() -> SurfaceMesh {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/assets/hp_body.obj");
    modal_bake::mesh::surface::read_surface(&path).unwrap()
}

/// (estimated dofs, meshed dofs) at the defaults, order 2 (`curvature` false: one size
/// apart from thin walls, `--uniform-size`).
fn estimate_and_mesh(name: &str, s: &SurfaceMesh, curvature: bool) -> (f64, usize) {
    let size = default_size(s.bounding_box());
    let measures = SurfaceMeasures::of(&s.vertices, &s.triangles);
    let h = equivalent_size(s, size, curvature, true);
    let e = SizeEstimate::of_surface(&measures, h, false, 2, 26);
    let p = MeshParams {
        order: 2,
        curvature,
        ..Default::default()
    };
    let m = mesh_surface(s, &p, name, &|_| {}).unwrap_or_else(|e| panic!("{name}: {e}"));
    (e.dofs, m.mesh.dofs())
}

#[test]
fn estimated_dofs_are_within_the_stated_factor_of_the_mesh() {
    if !have_gmsh("estimated_dofs_are_within_the_stated_factor_of_the_mesh") {
        return;
    }
    // (name, surface, curvature sizing on, allowed factor)
    let mut corpus: Vec<(&str, SurfaceMesh, bool, f64)> = vec![
        ("cube 0.1 m", box_surface([0.1, 0.1, 0.1]), true, FACTOR),
        (
            "box 0.3 × 0.2 × 0.1 m",
            box_surface([0.3, 0.2, 0.1]),
            true,
            FACTOR,
        ),
        (
            "slab 0.3 × 0.3 × 0.006 m",
            box_surface([0.3, 0.3, 0.006]),
            true,
            FACTOR,
        ),
        ("sphere r 0.05 m", uv_sphere(0.05, 24, 48), true, FACTOR),
        (
            "rod r 0.025 × 1 m",
            cylinder(0.025, 1.0, 48, 40),
            true,
            CURVED_FACTOR,
        ),
        // gmsh's curvature sizing refines the 4 mm rims of a faceted channel and the faces
        // beside them far below what the estimate's curvature term sees (docs/artist-guide.md
        // § 7): the thickness term is checked with one size elsewhere.
        (
            "U-channel 0.1 × 0.06 m, 4 mm wall, 0.3 m, --uniform-size",
            channel(0.1, 0.06, 0.004, 0.3, 30),
            false,
            FACTOR,
        ),
    ];
    // A low-poly game asset: at one size, gmsh's sizes must not spread from its short
    // feature curves (`Mesh.MeshSizeExtendFromBoundary` off; else 36 times the estimate).
    corpus.push((
        "HP controller body (npm, faceted), --uniform-size",
        hp_body(),
        false,
        FACTOR,
    ));
    match t13() {
        Some(s) => corpus.push(("gmsh tutorial t13 (mm)", s, true, FACTOR)),
        None => {
            eprintln!("t13_data.stl not found beside the PyPI gmsh; the corpus goes without it")
        }
    }
    let mut worst: f64 = 1.0;
    let mut failures = Vec::new();
    for (name, s, curvature, factor) in &corpus {
        let (est, dofs) = estimate_and_mesh(name, s, *curvature);
        let ratio = est / dofs as f64;
        eprintln!("{name}: estimated {est:.0} dofs, meshed {dofs}: ratio {ratio:.3}");
        worst = worst.max(ratio.max(1.0 / ratio));
        if !(ratio <= *factor && ratio >= 1.0 / factor) {
            failures.push(format!(
                "{name}: estimated {est:.0}, meshed {dofs} (ratio {ratio:.3})"
            ));
        }
    }
    eprintln!("worst factor {worst:.3} (allowed {FACTOR}, {CURVED_FACTOR} for the rod)");
    assert!(
        failures.is_empty(),
        "outside the allowed factor: {failures:?}"
    );
}

/// A 24-sided prism, radius 0.05 m and 0.1 m tall, its rims chamfered by `c` (m): faceted,
/// with narrow faces between sharp edges; outward.
fn chamfered_prism(c: f64) -> SurfaceMesh {
    use std::f64::consts::TAU;
    let (n, r, h) = (24, 0.05, 0.1);
    let rings = [(r - c, 0.0), (r, c), (r, h - c), (r - c, h)];
    let mut vertices: Vec<[f64; 3]> = rings
        .iter()
        .flat_map(|&(rr, z)| {
            (0..n).map(move |i| {
                let a = TAU * i as f64 / n as f64;
                [rr * a.cos(), rr * a.sin(), z]
            })
        })
        .collect();
    vertices.extend([[0.0, 0.0, 0.0], [0.0, 0.0, h]]);
    let (bottom, top) = (4 * n, 4 * n + 1);
    let mut triangles = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        for k in 0..3 {
            let (p, q, u, w) = (k * n + i, k * n + j, (k + 1) * n + j, (k + 1) * n + i);
            triangles.extend([[p, q, u], [p, u, w]]);
        }
        triangles.extend([[bottom, j, i], [top, 3 * n + i, 3 * n + j]]);
    }
    SurfaceMesh {
        vertices,
        triangles,
    }
}

/// Where gmsh's curvature sizing makes far more elements than the estimate (a faceted prism
/// with 1 mm chamfers: about five times), the mesh report says so and the asset is meshed
/// again with the curvature sizes the estimate measures, which lands within the estimate's
/// curved-shape factor; a sphere's mesh, within the estimate's spread, is gmsh's own and says
/// nothing.
#[test]
fn a_mesh_far_past_its_estimate_is_made_again_with_the_estimates_sizes() {
    if !have_gmsh("a_mesh_far_past_its_estimate_is_made_again_with_the_estimates_sizes") {
        return;
    }
    let p = MeshParams {
        order: 1,
        ..Default::default()
    };
    let prism = chamfered_prism(0.001);
    let m = mesh_surface(&prism, &p, "prism", &|_| {}).unwrap();
    let note = m
        .report
        .excess
        .as_deref()
        .unwrap_or_else(|| panic!("prism: {} tetrahedra, no excess", m.mesh.tets.len()));
    eprintln!("{note}");
    assert!(
        note.contains("times the tetrahedra") && note.contains("meshed again"),
        "{note}"
    );
    assert!(m.report.curvature_from_surface);
    let ratio = estimated_tets(&prism, 1) / m.mesh.tets.len() as f64;
    eprintln!(
        "prism: {} tetrahedra, estimate / mesh {ratio:.3}",
        m.mesh.tets.len()
    );
    assert!(
        (1.0 / CURVED_FACTOR..=CURVED_FACTOR).contains(&ratio),
        "{ratio}"
    );
    let sphere = mesh_surface(&uv_sphere(0.05, 24, 48), &p, "sphere", &|_| {}).unwrap();
    assert_eq!(sphere.report.excess, None);
    assert!(!sphere.report.curvature_from_surface);
}

/// The size estimate's tetrahedra for `s` at the defaults (curvature and thickness sizing).
fn estimated_tets(s: &SurfaceMesh, order: u8) -> f64 {
    let size = default_size(s.bounding_box());
    let measures = SurfaceMeasures::of(&s.vertices, &s.triangles);
    let h = equivalent_size(s, size, true, true);
    SizeEstimate::of_surface(&measures, h, false, order, 26).tets
}

/// A low-poly game asset at the defaults (the npm HP controller's body, 3,314 triangles):
/// gmsh's curvature sizing follows its facets (its surface mesh alone is 20 times the
/// estimate's boundary; the volume would be 233,386 tetrahedra, a 30 GB bake), so gmsh is
/// stopped before the volume and the body meshed with the estimate's curvature sizes: within
/// the curved-shape factor of the estimate, the same solid (volume within 3 % of the asset's)
/// and the same surface (Hausdorff distance within 3 % of the diagonal).
#[test]
fn a_faceted_asset_at_the_defaults_is_meshed_with_the_estimates_sizes() {
    if !have_gmsh("a_faceted_asset_at_the_defaults_is_meshed_with_the_estimates_sizes") {
        return;
    }
    let body = hp_body();
    let p = MeshParams {
        order: 2,
        ..Default::default()
    };
    let m = mesh_surface(&body, &p, "hp_body", &|_| {}).unwrap();
    let note = m.report.excess.as_deref().unwrap_or("(none)");
    eprintln!("{note}");
    assert!(
        note.contains("surface mesh had") && note.contains("meshed again"),
        "{note}"
    );
    assert!(m.report.curvature_from_surface);
    let ratio = estimated_tets(&body, 2) / m.mesh.tets.len() as f64;
    eprintln!(
        "hp body: {} tetrahedra, estimate / mesh {ratio:.3}",
        m.mesh.tets.len()
    );
    assert!(
        (1.0 / CURVED_FACTOR..=CURVED_FACTOR).contains(&ratio),
        "{ratio}"
    );
    let asset_volume = SurfaceMeasures::of(&body.vertices, &body.triangles).volume_m3;
    let volume = m.mesh.volume();
    assert!(
        (volume / asset_volume - 1.0).abs() < 0.03,
        "{volume:e} vs {asset_volume:e} m³"
    );
    assert!(m.report.distance.relative < 0.03, "{:?}", m.report.distance);
}
