//! The objects of the accuracy report: every elastic object of the six scenes (material and
//! fixed groups as the scenes bake them) and a thick slab, each with the region its scene
//! touches (where impacts land and where things rest); and the fridge once more on its whole
//! surface, more than its scene touches.

use std::path::Path;

use modal_bake::full_order::MaterialSi;
use modal_bake::mesh::{read_mesh, MeshError, TetMesh};

/// One object of the study.
#[derive(Clone, Debug)]
pub struct ObjectSpec {
    /// Short name (the scene's elastic object).
    pub name: &'static str,
    /// Where the mesh comes from (a file under the repository root, or a description).
    pub source: String,
    /// Scene and what happens there (one line).
    pub scene: &'static str,
    /// Fixed physical groups (empty: free-free).
    pub fixed: Vec<String>,
    /// Material (SI).
    pub material: MaterialSi,
    /// Region boxes (m, object frame); empty: no box filter.
    pub boxes: Vec<[f64; 6]>,
    /// Region normal filter (outward normal within 60° of it); `None`: any.
    pub up: Option<[f64; 3]>,
}

fn mat(youngs: f64, density: f64) -> MaterialSi {
    MaterialSi {
        youngs,
        poisson: 0.3,
        density,
    }
}

/// Every object, in report order. Scene meshes are read from `root/data/scenes`.
pub fn all_objects() -> Vec<ObjectSpec> {
    let up = Some([0.0, 1.0, 0.0]);
    let file = |n: &str| format!("data/scenes/{n}.msh");
    let groups = |g: &[&str]| g.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    vec![
        ObjectSpec {
            name: "table",
            source: file("table"),
            scene: "dinner: a pot dropped on the top, plates and cups on it",
            fixed: groups(&["feet"]),
            material: mat(1.1e9, 770.0),
            boxes: vec![],
            up,
        },
        ObjectSpec {
            name: "roof",
            source: file("roof"),
            scene: "roof: a toolbox hits the panel, a wrench and a nail box rest on it",
            fixed: groups(&["supports"]),
            material: mat(1.1e9, 770.0),
            boxes: vec![],
            up,
        },
        ObjectSpec {
            name: "scaffold",
            source: file("scaffold"),
            scene: "scaffold: a toolbox dropped on the top deck, tools on both decks",
            fixed: groups(&["feet"]),
            material: mat(10e9, 100.0),
            boxes: vec![],
            up,
        },
        ObjectSpec {
            name: "ground",
            source: file("ground"),
            scene:
                "lowrider: a bouncing truck, cones and posts around it (x ∈ [−8, 2] m, |z| ≤ 3 m)",
            fixed: groups(&["bottom", "sides"]),
            material: mat(10e9, 500.0),
            boxes: vec![[-8.0, -0.5, -3.0, 2.0, 0.5, 3.0]],
            up,
        },
        ObjectSpec {
            name: "cliff",
            source: file("cliff"),
            scene:
                "rockfall: a truck hits the face (x ∈ [−1, 2] m, y ≤ 1.8 m), rocks on the top ledge",
            fixed: groups(&["back", "bottom"]),
            material: mat(10e9, 500.0),
            boxes: vec![
                [-1.0, 0.2, 0.0, 2.0, 1.8, 1.2],
                [-4.0, 4.95, -0.5, 4.0, 5.05, 0.3],
            ],
            up: None,
        },
        ObjectSpec {
            name: "floor",
            source: file("floor"),
            scene: "washing: the machine shakes the floor, a box of bottles and the fridge on it",
            fixed: groups(&["edges"]),
            material: mat(10e9, 540.0),
            boxes: vec![],
            up,
        },
        ObjectSpec {
            name: "fridge",
            source: file("fridge"),
            scene: "washing: the floor kicks the fridge's bottom, a plant on its top (free-free)",
            fixed: vec![],
            material: mat(1e9, 100.0),
            boxes: vec![
                [-0.4, -0.05, -0.4, 0.4, 0.05, 0.4],
                [-0.4, 1.75, -0.4, 0.4, 1.85, 0.4],
            ],
            up: None,
        },
        ObjectSpec {
            name: "fridge-surface",
            source: file("fridge"),
            scene: "the fridge's whole surface, sides included (more than its scene touches)",
            fixed: vec![],
            material: mat(1e9, 100.0),
            boxes: vec![],
            up: None,
        },
        ObjectSpec {
            name: "slab",
            source: "4 × 4 × 0.3 m structured slab, 20 × 20 × 3 cells".into(),
            scene: "a thick slab (terrain-like): bottom fixed, impacts and contacts on the top",
            fixed: groups(&["zmin"]),
            material: mat(10e9, 500.0),
            boxes: vec![],
            up: Some([0.0, 0.0, 1.0]),
        },
    ]
}

/// The object's mesh (`root`: the repository root).
///
/// # Errors
/// The mesh file cannot be read.
pub fn load_mesh(spec: &ObjectSpec, root: &Path) -> Result<TetMesh, MeshError> {
    if spec.name == "slab" {
        return Ok(TetMesh::structured_box([20, 20, 3], [4.0, 4.0, 0.3]));
    }
    read_mesh(&root.join(&spec.source))
}
