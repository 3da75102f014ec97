//! Triangle meshes of collider shapes (parry's own discretisations) for export.

use anyhow::{bail, Result};
use rapier3d_f64::prelude::*;

/// A triangle mesh: positions (m, in the frame given by the caller) and triangles
/// (counter-clockwise seen from outside for parry's closed shapes).
#[derive(Clone, Debug, Default)]
pub struct ShapeMesh {
    /// Vertex positions (m).
    pub positions: Vec<[f64; 3]>,
    /// Triangles (indices into `positions`).
    pub triangles: Vec<[u32; 3]>,
}

impl ShapeMesh {
    /// Appends `other` transformed by `pose` (collider frame → body frame).
    pub fn append(&mut self, other: &ShapeMesh, pose: &Pose) {
        let base = self.positions.len() as u32;
        for p in &other.positions {
            let q = pose.transform_point(rapier3d_f64::math::Vector::new(p[0], p[1], p[2]));
            self.positions.push([q.x, q.y, q.z]);
        }
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }
}

fn to_mesh<P>(pts: Vec<P>, tris: Vec<[u32; 3]>, f: impl Fn(&P) -> [f64; 3]) -> ShapeMesh {
    ShapeMesh {
        positions: pts.iter().map(f).collect(),
        triangles: tris,
    }
}

/// The boundary of a collider shape as triangles in the shape's own frame (m): cuboids
/// exactly, balls 24 × 12, cylinders and cones 24 sides, capsules 24 × 6, convex hulls and
/// triangle meshes as stored.
///
/// # Errors
/// A shape kind without a discretisation here (height fields, compounds, 2D shapes...).
pub fn shape_triangles(shape: &dyn Shape) -> Result<ShapeMesh> {
    Ok(match shape.as_typed_shape() {
        TypedShape::Cuboid(c) => {
            let (p, t) = c.to_trimesh();
            to_mesh(p, t, |v| [v.x, v.y, v.z])
        }
        TypedShape::Ball(b) => {
            let (p, t) = b.to_trimesh(24, 12);
            to_mesh(p, t, |v| [v.x, v.y, v.z])
        }
        TypedShape::Cylinder(c) => {
            let (p, t) = c.to_trimesh(24);
            to_mesh(p, t, |v| [v.x, v.y, v.z])
        }
        TypedShape::Cone(c) => {
            let (p, t) = c.to_trimesh(24);
            to_mesh(p, t, |v| [v.x, v.y, v.z])
        }
        TypedShape::Capsule(c) => {
            let (p, t) = c.to_trimesh(24, 6);
            to_mesh(p, t, |v| [v.x, v.y, v.z])
        }
        TypedShape::ConvexPolyhedron(c) => {
            let (p, t) = c.to_trimesh();
            to_mesh(p, t, |v| [v.x, v.y, v.z])
        }
        TypedShape::TriMesh(m) => ShapeMesh {
            positions: m.vertices().iter().map(|v| [v.x, v.y, v.z]).collect(),
            triangles: m.indices().to_vec(),
        },
        _ => bail!("no triangle mesh for this collider shape kind"),
    })
}
