//! [`Pose`]: a rigid transform from an elastic object's frame to the world frame.

use crate::math::{add, dot};

/// A rigid transform from an object's frame (the frame of the mesh its base was baked from) to
/// the world frame: `x_world = R x_object + translation`.
///
/// `rotation` is a unit quaternion `[x, y, z, w]` (Hamilton convention, the storage order of
/// nalgebra, glam, rapier and Unity); it is normalised when the pose is set, so a quaternion off
/// unit length by rounding is fine. `translation` in m, world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Unit quaternion `[x, y, z, w]`: the object's orientation in the world.
    pub rotation: [f64; 4],
    /// Position of the object frame's origin in the world (m).
    pub translation: [f64; 3],
}

impl Pose {
    /// The identity: object frame = world frame.
    pub const IDENTITY: Pose = Pose {
        rotation: [0.0, 0.0, 0.0, 1.0],
        translation: [0.0; 3],
    };

    /// A pose from a rotation quaternion `[x, y, z, w]` and a translation (m).
    pub fn new(rotation: [f64; 4], translation: [f64; 3]) -> Pose {
        Pose {
            rotation,
            translation,
        }
    }

    /// A translation only (m).
    pub fn from_translation(translation: [f64; 3]) -> Pose {
        Pose {
            rotation: [0.0, 0.0, 0.0, 1.0],
            translation,
        }
    }

    /// A rotation by `angle` (rad) about unit `axis` (any non-zero length), then `translation`.
    pub fn from_axis_angle(axis: [f64; 3], angle: f64, translation: [f64; 3]) -> Pose {
        let n = dot(axis, axis).sqrt();
        let s = (0.5 * angle).sin() / if n > 0.0 { n } else { 1.0 };
        Pose {
            rotation: [axis[0] * s, axis[1] * s, axis[2] * s, (0.5 * angle).cos()],
            translation,
        }
    }

    /// The rotation matrix R (row-major) of the normalised quaternion; the identity for a zero
    /// or non-finite quaternion.
    pub fn rotation_matrix(&self) -> [[f64; 3]; 3] {
        let [x, y, z, w] = self.rotation;
        let n2 = x * x + y * y + z * z + w * w;
        if !(n2 > 0.0 && n2.is_finite()) {
            return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        }
        let s = 2.0 / n2;
        let (xx, yy, zz) = (x * x * s, y * y * s, z * z * s);
        let (xy, xz, yz) = (x * y * s, x * z * s, y * z * s);
        let (wx, wy, wz) = (w * x * s, w * y * s, w * z * s);
        [
            [1.0 - yy - zz, xy - wz, xz + wy],
            [xy + wz, 1.0 - xx - zz, yz - wx],
            [xz - wy, yz + wx, 1.0 - xx - yy],
        ]
    }

    /// `x_world = R x + translation` for a point `x` (m, object frame).
    pub fn transform_point(&self, x: [f64; 3]) -> [f64; 3] {
        add(rotate(&self.rotation_matrix(), x), self.translation)
    }
}

/// `R v`.
#[inline]
pub(crate) fn rotate(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}

/// `Rᵀ v`.
#[inline]
pub(crate) fn rotate_back(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
        r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
        r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2],
    ]
}
