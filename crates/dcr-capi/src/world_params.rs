//! [`DcrWorldParams`], [`DcrClassifyParams`], [`DcrElasticObjectDesc`] and [`DcrPose`]: the
//! set-up data of a world, with their documented defaults.

use dcr_runtime::world::ClassifyParams;
use dcr_runtime::{Pose, WorldParams};

use crate::guard::guard;
use crate::model::DcrModel;
use crate::ptr::{check_struct_size, write_out};
use crate::response_params::DcrResponseParams;
use crate::status::{DcrStatus, Failure};

/// An elastic object of a world: a slot index (low 32 bits) and the slot's generation (high 32
/// bits). While nothing is removed, the k-th object added has handle k. `dcr_world_remove_object`
/// bumps the slot's generation: the removed object's handle is stale for ever (every call with
/// it returns `DCR_STATUS_INVALID_HANDLE`), even after the slot is reused by a later object.
pub type DcrElasticHandle = u64;

/// A rigid transform from an object's frame (the frame of the mesh its base was baked from) to
/// the world frame: `x_world = R(rotation) x_object + translation`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcrPose {
    /// Unit quaternion `[x, y, z, w]` (Hamilton convention; the storage order of rapier, glam,
    /// Eigen's `coeffs()`, Unity). Normalised by the library; a zero or non-finite quaternion
    /// is the identity.
    pub rotation: [f64; 4],
    /// Position of the object frame's origin in the world (m).
    pub translation: [f64; 3],
}

/// Largest |translation| component a pose may have (m): beyond it an f64 position resolves
/// less than 0.1 µm, and products with it overflow sooner.
pub const DCR_MAX_TRANSLATION: f64 = 1e9;

impl DcrPose {
    /// The runtime's pose, or `DCR_STATUS_INVALID_ARGUMENT` for a translation component that is
    /// not finite or beyond `DCR_MAX_TRANSLATION` (a non-finite or zero quaternion is the
    /// identity rotation, documented on the field).
    pub(crate) fn checked(&self, name: &str) -> Result<Pose, crate::status::Failure> {
        for (k, &t) in self.translation.iter().enumerate() {
            if !(t.abs() <= DCR_MAX_TRANSLATION) {
                return Err(crate::status::Failure::invalid(format!(
                    "`{name}.translation[{k}]` is {t} m (must be finite and within ±{DCR_MAX_TRANSLATION:e} m)"
                )));
            }
        }
        Ok(Pose::new(self.rotation, self.translation))
    }
}

impl From<DcrPose> for Pose {
    fn from(p: DcrPose) -> Pose {
        Pose::new(p.rotation, p.translation)
    }
}

impl From<Pose> for DcrPose {
    fn from(p: Pose) -> DcrPose {
        DcrPose {
            rotation: p.rotation,
            translation: p.translation,
        }
    }
}

/// How a world tells impacts from resting contacts. All counts are rigid-body steps; the
/// defaults suit engines that create contacts one step before they carry an impulse (rapier's
/// predictive contacts).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcrClassifyParams {
    /// Ages rule: a contact can be an impact while its age (steps since it appeared, or last
    /// had zero impulse) is at most this, and it has not been an impact on that object since.
    /// Default 2.
    pub fresh_steps: u64,
    /// The contacts of the first `settle_steps` steps (the initial resting set) are never
    /// impacts. Default 3.
    pub settle_steps: u64,
    /// Ages rule: a contact id absent for at least this many consecutive steps is new when it
    /// comes back (a bounce). Default 1.
    pub new_after_missing_steps: u64,
    /// true: the engine's newness rule instead of ages: an impact is a report with
    /// `DcrContactReport.is_new`, impulse > 0 and ≥ the object's threshold, after the settle
    /// window (no age table). For callers that report contacts only on some steps and pass the
    /// others with `dcr_world_advance`. Default false (ages).
    pub engine_newness: bool,
    /// Smallest approach speed of an impact (m/s, ≥ 0): the normal speed at which the two
    /// bodies closed at the point before its impulse, `k λ − u⁺` from the reported body
    /// states; a fresh contact that closed slower is resting, under either rule. For engines
    /// that re-create the points of sliding contacts (Bullet): 2 g h leaves out the new points
    /// of a resting weight. Per point. Default 0 (no minimum).
    pub min_approach_speed: f64,
}

/// Settings of a world (`dcr_world_create`). Fill with `dcr_world_params_default`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcrWorldParams {
    /// `sizeof(DcrWorldParams)`, set by `dcr_world_params_default`.
    pub struct_size: u32,
    /// Rigid-body time step h (s, > 0), the same every step; every object's response uses it.
    /// Default 0.01.
    pub h: f64,
    /// Impact / resting classification.
    pub classify: DcrClassifyParams,
    /// true (default): bound the kinetic energy each object's responses inject per step by
    /// `energy_eta` × the energy its impacts dissipated (plus what chained impulses gave its
    /// body); its impulses are scaled down uniformly when over. false: no bound.
    pub energy_bound: bool,
    /// η ∈ [0, 1] of the energy bound. Default 1 (passive: a response never adds more energy
    /// than its impacts lost).
    pub energy_eta: f64,
    /// Longest chain of responses through dynamic elastic objects in one step (an impulse on
    /// an elastic object's body becomes an impact on it); 0 disables chains. Default 4.
    pub max_chain_depth: u32,
    /// Gravity (m/s², world frame) for the support compensation: a body a response lifts off
    /// (Δv ≥ g·h along the normal) also gets, at its centre of mass, the normal velocity
    /// gravity takes off over the step in which it leaves (its own event, `delta_v` 0), so
    /// that it ends that step with Δv. Default **unset** (NaN), which `dcr_world_create`
    /// refuses (`DCR_STATUS_INVALID_ARGUMENT`): set it to the engine's gravity, e.g.
    /// `{0, -9.81, 0}` for a y-up engine — also when the engine replays the events in its
    /// contact solver as a bounce or a velocity target, after which gravity acts over the
    /// body's first free step just the same — or to `{0, 0, 0}` for no compensation (a body a
    /// response lifts off then loses g·h of its push).
    pub gravity: [f64; 3],
}

impl DcrWorldParams {
    /// The documented defaults.
    pub fn defaults() -> DcrWorldParams {
        let w = WorldParams::default();
        DcrWorldParams {
            struct_size: std::mem::size_of::<DcrWorldParams>() as u32,
            h: w.h,
            classify: DcrClassifyParams {
                fresh_steps: w.classify.fresh_steps,
                settle_steps: w.classify.settle_steps,
                new_after_missing_steps: w.classify.new_after_missing_steps,
                engine_newness: w.classify.engine_newness,
                min_approach_speed: w.classify.min_approach_speed,
            },
            energy_bound: w.energy_eta.is_some(),
            energy_eta: w.energy_eta.unwrap_or(1.0),
            max_chain_depth: w.max_chain_depth,
            gravity: w.gravity,
        }
    }

    pub(crate) fn runtime_params(&self, name: &str) -> Result<WorldParams, Failure> {
        check_struct_size::<DcrWorldParams>(self.struct_size, name, "DcrWorldParams")?;
        Ok(WorldParams {
            h: self.h,
            classify: ClassifyParams {
                fresh_steps: self.classify.fresh_steps,
                settle_steps: self.classify.settle_steps,
                new_after_missing_steps: self.classify.new_after_missing_steps,
                engine_newness: self.classify.engine_newness,
                min_approach_speed: self.classify.min_approach_speed,
            },
            energy_eta: self.energy_bound.then_some(self.energy_eta),
            max_chain_depth: self.max_chain_depth,
            gravity: self.gravity,
        })
    }
}

/// How to build an elastic object (`dcr_world_add_object`). Fill with
/// `dcr_elastic_object_desc_default`, then set at least `model` and `body`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcrElasticObjectDesc {
    /// `sizeof(DcrElasticObjectDesc)`, set by `dcr_elastic_object_desc_default`.
    pub struct_size: u32,
    /// The object's base (borrowed for the call: the world keeps its own reference). Default
    /// NULL, which `dcr_world_add_object` refuses.
    pub model: *const DcrModel,
    /// Response parameters (method, damping, impact threshold in N·s, …); `response.h` is
    /// replaced by the world's h, `response.impact_threshold` is also the impact
    /// classification threshold. Default `dcr_response_params_default`.
    pub response: DcrResponseParams,
    /// Engine id of the rigid body carrying the object. Default 0.
    pub body: u64,
    /// true: the body moves (set its pose every step with `dcr_world_set_pose`), and
    /// responses of other objects that push it become impacts on it in the same step
    /// (chains). false (default): static, at `pose` for ever.
    pub dynamic: bool,
    /// Scale of the velocity changes its responses ask for (dimensionless, ≥ 0). Default 1.
    pub gain: f64,
    /// The object's pose (object frame → world). Default the identity.
    pub pose: DcrPose,
}

impl DcrElasticObjectDesc {
    /// The documented defaults (model NULL, body 0).
    pub fn defaults() -> DcrElasticObjectDesc {
        DcrElasticObjectDesc {
            struct_size: std::mem::size_of::<DcrElasticObjectDesc>() as u32,
            model: std::ptr::null(),
            response: DcrResponseParams::defaults(),
            body: 0,
            dynamic: false,
            gain: 1.0,
            pose: Pose::IDENTITY.into(),
        }
    }
}

/// Fills `out` with the documented world defaults (and `struct_size`).
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` when `out` is NULL.
///
/// # Safety
/// `out` must be NULL or valid for a write of a `DcrWorldParams`.
#[no_mangle]
pub unsafe extern "C" fn dcr_world_params_default(out: *mut DcrWorldParams) -> DcrStatus {
    guard("dcr_world_params_default", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, DcrWorldParams::defaults(), "out") }
    })
}

/// Fills `out` with the documented elastic-object defaults: no model, body 0, the default
/// response parameters, static, gain 1, identity pose (and both `struct_size` fields).
///
/// # Errors
/// `DCR_STATUS_NULL_POINTER` when `out` is NULL.
///
/// # Safety
/// `out` must be NULL or valid for a write of a `DcrElasticObjectDesc`.
#[no_mangle]
pub unsafe extern "C" fn dcr_elastic_object_desc_default(
    out: *mut DcrElasticObjectDesc,
) -> DcrStatus {
    guard("dcr_elastic_object_desc_default", || {
        // SAFETY: caller contract (NULL is checked).
        unsafe { write_out(out, DcrElasticObjectDesc::defaults(), "out") }
    })
}
