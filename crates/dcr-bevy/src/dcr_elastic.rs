//! [`DcrElastic`]: the component that makes a rigid body an elastic object, and the components
//! the plugin adds in return ([`DcrObject`], [`DcrElasticFailed`]).

use bevy::prelude::{Component, Handle};
use dcr_rapier::{ElasticHandle, ResponseParams};

use crate::ModesAsset;

/// Gives the rigid body of this entity (a bevy_rapier `RigidBody::Fixed` or `Dynamic` with its
/// colliders on the entity or its children) a baked modal base: impacts on its colliders push
/// the bodies resting elsewhere on it.
///
/// The base's object frame is the body's local frame: place the entity where the mesh the
/// base was baked from should be, and give it the collision shapes in the mesh's frame. The
/// plugin adds the object once the base has loaded and bevy_rapier has created the body
/// (the object's pose is then the body's pose; a dynamic body's pose is read every step), and
/// inserts [`DcrObject`] (or [`DcrElasticFailed`]). Kinematic bodies are refused by the
/// world's rules (they never respond).
///
/// At run time, from the next physics step on: changing `enabled`, `gain` or
/// `response.impact_threshold` changes the object (a disabled object ignores its contacts and
/// issues no response; enabled again, its filters restart at rest); removing the component or
/// despawning the entity removes the object from the world (its [`DcrObject`] handle goes
/// stale; inserting a `DcrElastic` again adds a new object). The other fields (`base`, the rest
/// of `response`) are read once, when the object is added.
///
/// ```
/// # use bevy::prelude::*;
/// # use dcr_bevy::{DcrElastic, ModesAsset};
/// # fn spawn(mut commands: Commands, assets: Res<AssetServer>) {
/// let mut table = DcrElastic::new(assets.load::<ModesAsset>("table.modes"));
/// table.response.impact_threshold = 0.5; // N·s
/// table.response.max_map_distance = 0.1; // m
/// # let _ = table;
/// # }
/// ```
#[derive(Component, Clone, Debug)]
pub struct DcrElastic {
    /// The base (`.modes` asset).
    pub base: Handle<ModesAsset>,
    /// Response parameters (method, damping, impact threshold in N·s, contact mapping distance
    /// in m, lateral kick, …); `h` is replaced by the plugin's step. Default
    /// [`ResponseParams::default`].
    pub response: ResponseParams,
    /// Scale of the velocity changes the responses ask for (dimensionless, ≥ 0). Default 1 (the
    /// paper's response).
    pub gain: f64,
    /// Whether the object responds (default true); false keeps it in the world, silent.
    pub enabled: bool,
}

impl DcrElastic {
    /// An enabled elastic object with base `base`, the default response parameters and gain 1.
    pub fn new(base: Handle<ModesAsset>) -> DcrElastic {
        DcrElastic {
            base,
            response: ResponseParams::default(),
            gain: 1.0,
            enabled: true,
        }
    }
}

/// Inserted by the plugin on a [`DcrElastic`] entity once its object is in the world: its
/// handle in [`crate::DcrContext::world`] (counters: `world().object_info(handle)`). Removed
/// by the plugin with the object when the entity's [`DcrElastic`] is removed.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct DcrObject(pub ElasticHandle);

/// Inserted by the plugin on a [`DcrElastic`] entity that could not become an elastic object
/// (its base failed to load, the body has no collider, or the world refused the parameters);
/// the reason is also logged once as an error. Remove it (and fix the cause) to retry.
#[derive(Component, Clone, Debug, PartialEq, Eq)]
pub struct DcrElasticFailed {
    /// Why, with the asset path or the parameter at fault.
    pub reason: String,
}
