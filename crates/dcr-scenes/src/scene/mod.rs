//! Scene descriptions (JSON) and the rapier world built from them.

mod scene_desc;
mod validate;
mod world_builder;

pub use scene_desc::{
    name_matches, AxisDesc, BodyKind, ColliderDesc, DriverDesc, ElasticDesc, FixedBelowDesc,
    JointDesc, MaterialDesc, MethodDesc, OutcomeDesc, PoseDesc, PropDesc, SceneDesc, ShapeDesc,
    TableOrderDesc, TransferDesc,
};
pub use validate::{
    is_plain_name, H_RANGE_S, MASS_RANGE_KG, MAX_BODIES, MAX_GRAVITY, MAX_POSITION_M, MAX_SIZE_M,
    MAX_SPEED, MAX_STEPS, MAX_STEP_BODIES, MIN_SIZE_M, OUTCOME_KINDS,
};
pub use world_builder::{build_world, pose_from_desc, BodyInfo, BuiltWorld};
