//! [`DcrStatus`]: what the plugin did with the physics steps, and why it refused some.

use bevy::prelude::Resource;

/// Why the plugin did not run the response on a fixed update (each reason is also logged once
/// as an error, with how to fix it).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum DcrRefusal {
    /// bevy_rapier's `TimestepMode` is not `Fixed { dt, substeps: 1 }`: a variable or
    /// interpolated step, or substeps, would step rapier by something else than one fixed
    /// step per fixed update.
    TimestepMode {
        /// The mode found (its `Debug` text).
        found: String,
        /// The world's step (s).
        h: f64,
    },
    /// rapier stepped by `dt` (s) and the world cannot follow: a response cannot be
    /// re-derived for it (a transfer table baked for the world's `h` under
    /// `TablePolicy::Refuse`), so the world keeps `h` (s).
    StepLength {
        /// rapier's dt (s).
        dt: f64,
        /// The world's step (s).
        h: f64,
    },
    /// bevy_rapier's context was not stepped between the plugin's two systems of this fixed
    /// update: bevy_rapier runs in another schedule (add it with
    /// `RapierPhysicsPlugin::default().in_fixed_schedule()`), or its step systems are not
    /// between [`crate::DcrSet::BeforeStep`] and [`crate::DcrSet::AfterStep`].
    NotStepped,
    /// No bevy_rapier context with `DefaultRapierContext` (bevy_rapier's plugin is missing or
    /// set up without its default context).
    NoContext,
}

impl std::fmt::Display for DcrRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DcrRefusal::TimestepMode { found, h } => write!(
                f,
                "bevy_rapier's TimestepMode is {found}; the response needs exactly one rapier \
                 step of the world's h = {h} s per fixed update: insert \
                 `TimestepMode::Fixed {{ dt: {h}, substeps: 1 }}` (DcrPlugin does at build), \
                 or build DcrPlugin with the h you want"
            ),
            DcrRefusal::StepLength { dt, h } => write!(
                f,
                "rapier stepped by dt = {dt} s but the world's responses cannot be re-derived \
                 for it (a transfer table baked for h = {h} s): set \
                 `TimestepMode::Fixed {{ dt: {h}, substeps: 1 }}`"
            ),
            DcrRefusal::NotStepped => write!(
                f,
                "bevy_rapier did not step between DcrSet::BeforeStep and DcrSet::AfterStep in \
                 FixedUpdate: add `RapierPhysicsPlugin::<NoUserData>::default().in_fixed_schedule()`"
            ),
            DcrRefusal::NoContext => write!(
                f,
                "no bevy_rapier context (DefaultRapierContext) found: add RapierPhysicsPlugin \
                 with its default context"
            ),
        }
    }
}

/// What the plugin did with the fixed updates so far.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct DcrStatus {
    /// Fixed updates on which the response ran after rapier's step (the adapter's counters:
    /// [`crate::DcrContext::step_info`]).
    pub steps: u64,
    /// Fixed updates on which the plugin refused to run the response (see `last_refusal`).
    pub refused_steps: u64,
    /// Fixed updates skipped because bevy_rapier's pipeline is paused
    /// (`RapierConfiguration::physics_pipeline_active` false): no step, no response.
    pub paused_steps: u64,
    /// The last reason for a refusal.
    pub last_refusal: Option<DcrRefusal>,
    /// Response impulses applied so far (or measured, under `ApplyMode::MeasureOnly`).
    pub total_events: u64,
}
