//! [`DcrPlugin`] and its system sets.

use std::sync::Mutex;

use bevy::asset::{AssetApp, AssetPlugin};
use bevy::prelude::*;
use bevy_rapier3d::prelude::{PhysicsSet, TimestepMode};
use dcr_rapier::f32::{AdapterError, AdapterParams, ApplyMode};
use dcr_rapier::WorldParams;

use crate::systems::{dcr_after_step, dcr_before_step, StepGuard};
use crate::{DcrContext, DcrResponse, DcrStatus, ModesAsset, ModesLoader};

/// The plugin's two system sets in `FixedUpdate`, around bevy_rapier's step.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DcrSet {
    /// After `PhysicsSet::SyncBackend`, before `PhysicsSet::StepSimulation`: adds the elastic
    /// objects that are ready.
    BeforeStep,
    /// After `PhysicsSet::StepSimulation`, before `PhysicsSet::Writeback`: reads the step's
    /// contacts, steps the world, applies its impulses, writes the [`DcrResponse`] messages.
    /// Read the messages in a system after this set (or in `Update`).
    AfterStep,
}

/// Why a [`DcrPlugin`] could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DcrPluginError {
    /// The world refused its parameters (e.g. a step `h` that is not positive and finite).
    #[error(transparent)]
    World(#[from] AdapterError),
    /// `ApplyMode::InSolver` needs dcr's solver hooks in rapier's step, and bevy_rapier steps
    /// with its own hooks.
    #[error(
        "ApplyMode::InSolver is not supported by DcrPlugin (bevy_rapier runs rapier's step \
         with its own physics hooks): use ApplyMode::AfterStep"
    )]
    InSolver,
}

/// The distant collision response (Distant Collision Response in Rigid Body Simulations, CGF
/// 2020) for a bevy_rapier3d app: entities with a [`crate::DcrElastic`] component carry a
/// baked `.modes` base, and an impact on them pushes the bodies resting elsewhere on them.
///
/// Requirements, which the plugin sets or checks:
/// - bevy_rapier runs in `FixedUpdate`
///   (`RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule()`), one rapier step of
///   fixed length per fixed update: at build the plugin inserts
///   `TimestepMode::Fixed { dt: h, substeps: 1 }` and `Time::<Fixed>::from_seconds(h)`. A fixed
///   update on which rapier was not stepped between [`DcrSet::BeforeStep`] and
///   [`DcrSet::AfterStep`], or stepped with substeps or a variable step, is refused: no
///   response, an error logged once, counted in [`DcrStatus::refused_steps`] with the reason.
/// - The world follows bevy_rapier: every step its h becomes rapier's `dt` (another
///   `TimestepMode::Fixed { dt, substeps: 1 }` re-derives the responses for it, with a warning
///   once per change; a base whose transfer table cannot serve it is refused, as the world's
///   table policy says) and its gravity `RapierConfiguration::gravity` (the support of
///   impulses applied after the step).
/// - bevy's `AssetPlugin` (added at `finish` if missing) for the [`ModesAsset`] loader.
///
/// The impulses are applied in rapier's body set after the step and before bevy_rapier's
/// writeback, which copies them into the bodies' `Velocity` components.
///
/// ```no_run
/// use bevy::prelude::*;
/// use bevy_rapier3d::prelude::*;
/// use dcr_bevy::{dcr_rapier::WorldParams, DcrPlugin};
///
/// let dcr = DcrPlugin::new(WorldParams { h: 0.01, ..Default::default() }, Default::default())?;
/// App::new()
///     .add_plugins((
///         MinimalPlugins,
///         TransformPlugin,
///         AssetPlugin::default(),
///         RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule(),
///         dcr,
///     ))
///     .run();
/// # Ok::<(), dcr_bevy::DcrPluginError>(())
/// ```
pub struct DcrPlugin {
    h: f64,
    context: Mutex<Option<DcrContext>>,
}

impl DcrPlugin {
    /// A plugin whose world steps by `world.h` (s), with the adapter settings `adapter`
    /// (`ApplyMode::AfterStep` or `MeasureOnly`; the read gate).
    ///
    /// # Errors
    /// [`DcrPluginError::World`] for invalid world parameters, [`DcrPluginError::InSolver`].
    pub fn new(world: WorldParams, adapter: AdapterParams) -> Result<DcrPlugin, DcrPluginError> {
        if adapter.apply == ApplyMode::InSolver {
            return Err(DcrPluginError::InSolver);
        }
        let h = world.h;
        Ok(DcrPlugin {
            h,
            context: Mutex::new(Some(DcrContext::new(world, adapter)?)),
        })
    }

    /// The world's step at build (s): bevy_rapier's fixed `dt` and the fixed-update period the
    /// plugin inserts.
    pub fn h(&self) -> f64 {
        self.h
    }
}

impl Plugin for DcrPlugin {
    fn build(&self, app: &mut App) {
        let context = self.context.lock().ok().and_then(|mut c| c.take());
        let Some(context) = context else {
            log::error!("dcr-bevy: DcrPlugin built twice: the second build does nothing");
            return;
        };
        app.insert_resource(context)
            .init_resource::<StepGuard>()
            .init_resource::<DcrStatus>()
            .insert_resource(TimestepMode::Fixed {
                dt: self.h as f32,
                substeps: 1,
            })
            .insert_resource(Time::<Fixed>::from_seconds(self.h))
            .add_message::<DcrResponse>()
            .configure_sets(
                FixedUpdate,
                (
                    DcrSet::BeforeStep
                        .after(PhysicsSet::SyncBackend)
                        .before(PhysicsSet::StepSimulation),
                    DcrSet::AfterStep
                        .after(PhysicsSet::StepSimulation)
                        .before(PhysicsSet::Writeback),
                ),
            )
            .add_systems(
                FixedUpdate,
                (
                    dcr_before_step.in_set(DcrSet::BeforeStep),
                    dcr_after_step.in_set(DcrSet::AfterStep),
                ),
            );
        if app.is_plugin_added::<AssetPlugin>() {
            register_loader(app);
        }
    }

    fn finish(&self, app: &mut App) {
        if !app.is_plugin_added::<AssetPlugin>() {
            app.add_plugins(AssetPlugin::default());
        }
        register_loader(app);
    }
}

/// Registers [`ModesAsset`] and its loader once.
fn register_loader(app: &mut App) {
    if !app.world().contains_resource::<Assets<ModesAsset>>() {
        app.init_asset::<ModesAsset>()
            .register_asset_loader(ModesLoader);
    }
}
