//! [`ElasticObjectDesc`]: the definition of an elastic object added to a [`crate::DcrWorld`].

use std::sync::Arc;

use super::Pose;
use crate::model::ModalModel;
use crate::response::ResponseParams;

/// How to build an elastic object ([`crate::DcrWorld::add_object`]): its base, its response
/// parameters and the engine body it is attached to.
///
/// Start from [`ElasticObjectDesc::new`] (the documented defaults) and change fields:
///
/// ```
/// use std::sync::Arc;
/// use dcr_runtime::{testing, ElasticObjectDesc, ModalModel};
///
/// let model = Arc::new(ModalModel::from_base(testing::plate_base())?);
/// let mut desc = ElasticObjectDesc::new(model, 42);
/// desc.response.impact_threshold = 0.5; // N·s
/// desc.gain = 2.0;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct ElasticObjectDesc {
    /// The baked base, shared by every object that uses it.
    pub model: Arc<ModalModel>,
    /// Response parameters (method, damping, impact threshold in N·s, lateral kick, …).
    /// `response.h` is replaced by [`crate::WorldParams::h`]: an object steps with its world.
    /// `response.impact_threshold` is also the impact classification threshold. Default
    /// [`ResponseParams::default`].
    pub response: ResponseParams,
    /// Engine id of the rigid body carrying the object (its collision shapes' body).
    pub body: u64,
    /// `true`: the body moves (a fridge on a floor): set its pose every step with
    /// [`crate::DcrWorld::set_pose`], and responses of other objects that push it become
    /// impacts on it in the same step (chains). `false` (default): static, its pose is
    /// `pose` for ever.
    pub dynamic: bool,
    /// Scale of the velocity changes this object's responses ask for (dimensionless, ≥ 0).
    /// Default 1 (the paper's response).
    pub gain: f64,
    /// The object's pose (object frame → world). Default [`Pose::IDENTITY`].
    pub pose: Pose,
}

impl ElasticObjectDesc {
    /// A static object on engine body `body` with the default response parameters, gain 1 and
    /// the identity pose.
    pub fn new(model: Arc<ModalModel>, body: u64) -> ElasticObjectDesc {
        ElasticObjectDesc {
            model,
            response: ResponseParams::default(),
            body,
            dynamic: false,
            gain: 1.0,
            pose: Pose::IDENTITY,
        }
    }
}
