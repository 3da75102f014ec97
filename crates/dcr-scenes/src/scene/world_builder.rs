//! Builds a rapier3d-f64 [`PhysicsWorld`] from a [`SceneDesc`]: elastic objects (static or
//! dynamic, trimesh or primitive proxies), props with their masses, compliant joints.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{bail, Context, Result};
use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::prelude::*;

use super::scene_desc::{
    name_matches, BodyKind, ColliderDesc, ElasticDesc, JointDesc, PoseDesc, PropDesc, SceneDesc,
    ShapeDesc,
};

/// One body of the built world.
#[derive(Clone, Debug)]
pub struct BodyInfo {
    /// Name (props with copies: `name_i`).
    pub name: String,
    /// Rapier handle.
    pub handle: RigidBodyHandle,
    /// Index into [`SceneDesc::elastic`] if this body carries a modal base.
    pub elastic: Option<usize>,
    /// Dynamic (recorded in the trajectory)?
    pub dynamic: bool,
}

/// The rapier world of a scene plus the name ↔ handle bookkeeping.
pub struct BuiltWorld {
    /// The world (h, gravity, bodies, colliders, joints).
    pub world: PhysicsWorld,
    /// Every body, elastic objects first, in scene order.
    pub bodies: Vec<BodyInfo>,
    /// Collider → index into `bodies`.
    pub collider_body: HashMap<ColliderHandle, usize>,
    /// Elastic object i → index into `bodies`.
    pub elastic_body: Vec<usize>,
}

impl BuiltWorld {
    /// Index into `bodies` of the body named `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Moves every launched body (a dynamic body with a non-zero initial velocity: the
    /// scene's projectile) by `distance` (m) in a direction perpendicular to gravity (world
    /// frame), chosen per body from `member` by a fixed hash: member `m` of an ensemble of runs
    /// that differ only by where the projectile starts, far below what a user could set (a
    /// tenth of a millimetre), which shows how much an outcome depends on it. Resting bodies
    /// stay where they are (moved across gravity on a slope they would start inside their
    /// support). Member 0, a zero distance or zero gravity leaves the world as built. Call
    /// before the first step.
    pub fn perturb_placement(&mut self, member: usize, distance: f64) {
        let g = self.world.gravity;
        if member == 0 || distance == 0.0 || g.length() == 0.0 {
            return;
        }
        let up = -g.normalize();
        // Two unit vectors spanning the plane perpendicular to gravity.
        let a = if up.x.abs() < 0.9 {
            Vector::X
        } else {
            Vector::Z
        };
        let e1 = (a - up * a.dot(up)).normalize();
        let e2 = up.cross(e1);
        for (i, b) in self.bodies.iter().enumerate() {
            if !b.dynamic || self.world.bodies[b.handle].linvel().length() == 0.0 {
                continue;
            }
            // splitmix64 of (member, body): a fixed angle per pair.
            let mut z = (member as u64)
                .wrapping_mul(0x9e37_79b9_7f4a_7c15)
                .wrapping_add((i as u64).wrapping_mul(0xbf58_476d_1ce4_e5b9));
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            let theta = (z >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU;
            let rb = &mut self.world.bodies[b.handle];
            let t = rb.translation() + (e1 * theta.cos() + e2 * theta.sin()) * distance;
            rb.set_translation(t, true);
        }
    }
}

/// A pose from its description (translation m, rotation scaled axis in degrees).
pub fn pose_from_desc(p: &PoseDesc) -> Pose {
    let r = p.rotation_deg;
    let axis = Vector::new(r[0].to_radians(), r[1].to_radians(), r[2].to_radians());
    Pose::from_parts(
        Vector::new(p.translation[0], p.translation[1], p.translation[2]),
        Rotation::from_scaled_axis(axis),
    )
}

fn v3(a: [f64; 3]) -> Vector {
    Vector::new(a[0], a[1], a[2])
}

fn shape_builder(shape: &ShapeDesc) -> Result<ColliderBuilder> {
    Ok(match shape {
        ShapeDesc::Cuboid { half_extents: h } => ColliderBuilder::cuboid(h[0], h[1], h[2]),
        ShapeDesc::Ball { radius } => ColliderBuilder::ball(*radius),
        ShapeDesc::Cylinder {
            half_height,
            radius,
        } => ColliderBuilder::cylinder(*half_height, *radius),
        ShapeDesc::Cone {
            half_height,
            radius,
        } => ColliderBuilder::cone(*half_height, *radius),
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => ColliderBuilder::capsule_y(*half_height, *radius),
        ShapeDesc::ConvexHull { points } => {
            let pts: Vec<Vector> = points.iter().map(|p| v3(*p)).collect();
            match ColliderBuilder::convex_hull(&pts) {
                Some(b) => b,
                None => bail!("convex hull of {} points is degenerate", points.len()),
            }
        }
    })
}

fn collider_volume(c: &ColliderDesc) -> Result<f64> {
    let b = shape_builder(&c.shape)?.density(1.0).build();
    Ok(b.mass())
}

/// Builds the world. `root` is the repository root (mesh paths are relative to it).
///
/// # Errors
/// Unreadable meshes, degenerate shapes, joints naming unknown bodies.
pub fn build_world(desc: &SceneDesc, root: &Path) -> Result<BuiltWorld> {
    let mut world = PhysicsWorld::new();
    world.gravity = v3(desc.gravity);
    world.integration_parameters.dt = desc.h;
    let mut built = BuiltWorld {
        world,
        bodies: Vec::new(),
        collider_body: HashMap::new(),
        elastic_body: Vec::new(),
    };
    for (ei, e) in desc.elastic.iter().enumerate() {
        built.add_elastic(desc, root, ei, e)?;
    }
    for p in &desc.props {
        built.add_prop(desc, p)?;
    }
    for j in &desc.joints {
        built.add_joint(j)?;
    }
    Ok(built)
}

impl BuiltWorld {
    /// Adds elastic object `ei` (`e`): a fixed or dynamic body at its pose with its
    /// colliders (see [`elastic_colliders`]), friction `e.friction`, the scene's restitution.
    fn add_elastic(
        &mut self,
        desc: &SceneDesc,
        root: &Path,
        ei: usize,
        e: &ElasticDesc,
    ) -> Result<()> {
        let pose = pose_from_desc(&e.pose);
        let (rb, dynamic) = match &e.body {
            BodyKind::Static => (RigidBodyBuilder::fixed().pose(pose), false),
            BodyKind::Dynamic { .. } => (
                RigidBodyBuilder::dynamic().pose(pose).can_sleep(false),
                true,
            ),
        };
        let handle = self.world.insert_body(rb);
        let idx = self.bodies.len();
        let builders = elastic_colliders(e, dynamic, root)?;
        for b in builders {
            let ch = self.world.insert_collider(
                b.friction(e.friction).restitution(desc.restitution),
                Some(handle),
            );
            self.collider_body.insert(ch, idx);
        }
        self.bodies.push(BodyInfo {
            name: e.name.clone(),
            handle,
            elastic: Some(ei),
            dynamic,
        });
        self.elastic_body.push(idx);
        Ok(())
    }

    /// Adds prop `p`: one body per copy (`name_i` when it has copies) at its pose, offset by
    /// the copy's translation and placed in its `relative_to` object's frame, its colliders
    /// sharing the density that gives the prop its mass.
    fn add_prop(&mut self, desc: &SceneDesc, p: &PropDesc) -> Result<()> {
        let vol: f64 = p
            .colliders
            .iter()
            .map(collider_volume)
            .sum::<Result<f64>>()?;
        if !(vol > 0.0 && p.mass > 0.0) {
            bail!("prop {}: mass and collider volume must be positive", p.name);
        }
        let density = p.mass / vol;
        let frame = prop_frame(desc, p)?;
        let base = pose_from_desc(&p.pose);
        let copies: Vec<([f64; 3], String)> = if p.copies.is_empty() {
            vec![([0.0; 3], p.name.clone())]
        } else {
            p.copies
                .iter()
                .enumerate()
                .map(|(i, t)| (*t, format!("{}_{i}", p.name)))
                .collect()
        };
        for (t, name) in copies {
            let mut pose = base;
            pose.translation += v3(t);
            let pose = frame * pose;
            let rb = if p.fixed {
                RigidBodyBuilder::fixed()
            } else {
                RigidBodyBuilder::dynamic()
            };
            let rb = rb
                .pose(pose)
                .linvel(v3(p.linvel))
                .angvel(v3(p.angvel))
                .linear_damping(p.linear_damping)
                .angular_damping(p.angular_damping)
                .ccd_enabled(p.ccd);
            let handle = self.world.insert_body(rb);
            let idx = self.bodies.len();
            for c in &p.colliders {
                let b = shape_builder(&c.shape)?
                    .position(pose_from_desc(&c.offset))
                    .density(density)
                    .friction(p.friction)
                    .restitution(desc.restitution);
                let ch = self.world.insert_collider(b, Some(handle));
                self.collider_body.insert(ch, idx);
            }
            self.bodies.push(BodyInfo {
                name,
                handle,
                elastic: None,
                dynamic: !p.fixed,
            });
        }
        Ok(())
    }

    /// Adds joint `j`: a spring-loaded revolute joint from body `j.body1` to every body
    /// matching `j.body2`, at rest at the bodies' initial relative angle.
    fn add_joint(&mut self, j: &JointDesc) -> Result<()> {
        let bodies = &self.bodies;
        let i1 = bodies
            .iter()
            .position(|b| b.name == j.body1)
            .with_context(|| format!("joint: no body {}", j.body1))?;
        let children: Vec<usize> = (0..bodies.len())
            .filter(|&i| name_matches(&j.body2, &bodies[i].name))
            .collect();
        if children.is_empty() {
            bail!("joint: no body matches {}", j.body2);
        }
        for i2 in children {
            let p1 = *self.world.bodies[bodies[i1].handle].position();
            let p2 = *self.world.bodies[bodies[i2].handle].position();
            // The hinge sits at the same offset from every child's initial centre. The axis is
            // taken in both bodies' frames as given: the parent starts unrotated and a child
            // may only start rotated about the hinge axis itself.
            let anchor = p2.translation + v3(j.anchor_offset);
            let axis1 = v3(j.axis).normalize();
            let mut joint = RevoluteJointBuilder::new(axis1)
                .local_anchor1(p1.inverse_transform_point(anchor))
                .local_anchor2(p2.inverse_transform_point(anchor))
                .motor_model(MotorModel::ForceBased)
                .contacts_enabled(false)
                .build();
            // The spring's rest angle is the initial relative angle (a leaf starts at rest).
            let rest = joint.angle(&p1.rotation, &p2.rotation);
            joint.set_motor_position(rest, j.stiffness, j.damping);
            self.world
                .insert_impulse_joint(bodies[i1].handle, bodies[i2].handle, joint);
        }
        Ok(())
    }
}

/// Collider builders of elastic object `e` in its body frame: without `colliders`, the
/// surface trimesh of its mesh (static bodies only; `root`: repository root); else its
/// primitives at their offsets, a dynamic body's at the density giving its mass.
fn elastic_colliders(e: &ElasticDesc, dynamic: bool, root: &Path) -> Result<Vec<ColliderBuilder>> {
    let mut builders = Vec::new();
    match &e.colliders {
        None => {
            if dynamic {
                bail!(
                    "elastic object {}: a dynamic body needs primitive `colliders`",
                    e.name
                );
            }
            let mesh_path = root.join(&e.mesh);
            let mesh = modal_bake::mesh::read_mesh(&mesh_path)
                .with_context(|| format!("reading mesh {}", mesh_path.display()))?;
            let (_, tris) = modal_bake::bake::extract_surface(&mesh);
            let verts: Vec<Vector> = mesh.nodes.iter().map(|p| v3(*p)).collect();
            let idx_tris: Vec<[u32; 3]> = tris
                .iter()
                .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32])
                .collect();
            let b = ColliderBuilder::trimesh_with_flags(
                verts.clone(),
                idx_tris.clone(),
                TriMeshFlags::FIX_INTERNAL_EDGES,
            )
            .or_else(|_| ColliderBuilder::trimesh(verts, idx_tris))
            .map_err(|err| anyhow::anyhow!("trimesh of {}: {err:?}", e.name))?;
            builders.push(b);
        }
        Some(cs) => {
            let vol: f64 = cs.iter().map(collider_volume).sum::<Result<f64>>()?;
            let density = match &e.body {
                BodyKind::Dynamic { mass } => mass / vol,
                BodyKind::Static => 1.0,
            };
            for c in cs {
                builders.push(
                    shape_builder(&c.shape)?
                        .position(pose_from_desc(&c.offset))
                        .density(density),
                );
            }
        }
    }
    Ok(builders)
}

/// The frame prop `p` is placed in: the pose of the elastic object it is `relative_to`, or
/// the world frame.
fn prop_frame(desc: &SceneDesc, p: &PropDesc) -> Result<Pose> {
    Ok(match &p.relative_to {
        None => Pose::IDENTITY,
        Some(name) => {
            let e = desc.elastic.iter().find(|e| &e.name == name);
            let Some(e) = e else {
                bail!(
                    "prop {}: relative_to names no elastic object {name}",
                    p.name
                )
            };
            pose_from_desc(&e.pose)
        }
    })
}
