//! Scene descriptions (JSON) and the rapier world built from them.

mod scene_desc;
mod world_builder;

pub use scene_desc::{
    name_matches, BodyKind, ColliderDesc, DriverDesc, ElasticDesc, JointDesc, MaterialDesc,
    MethodDesc, OutcomeDesc, PoseDesc, PropDesc, SceneDesc, ShapeDesc, TableOrderDesc,
    TransferDesc,
};
pub use world_builder::{build_world, pose_from_desc, BodyInfo, BuiltWorld};
