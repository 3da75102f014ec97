//! [`DcrSolverHooks`]: the `PhysicsHooks` of the in-solver application path.

use std::sync::atomic::{AtomicBool, Ordering};

use super::contact_id::collider_pair_key;
use super::rapier::math::Vector;
use super::rapier::prelude::{ColliderHandle, ContactModificationContext, PhysicsHooks};

/// One collider pair whose contacts replay responses this step.
#[derive(Debug)]
pub(super) struct PairMark {
    /// `collider_pair_key` of the pair.
    pub key: u64,
    /// The elastic object's collider (the other one belongs to the receiving body).
    pub elastic: ColliderHandle,
    /// Lateral kick: the tangential velocity (m/s, world frame) the receiving body's contact
    /// points should have relative to the elastic surface at the end of the step (their
    /// velocity before the step plus the kick's Δv); zero when the kick is off.
    pub kick: Vector,
    /// Whether the hook saw the pair during the step.
    pub seen: AtomicBool,
}

/// The in-solver path's `PhysicsHooks` (see [`super::ApplyMode::InSolver`]): for each contact
/// manifold of a collider pair that carries a response this step it sets the manifold's
/// restitution to 1 and, with a lateral kick, the solver contacts' `tangent_velocity`.
///
/// Why restitution (rapier 0.36, `dynamics/solver/contact_constraint/`): a contact's normal row
/// gets `rhs = max(dist, 0)/dt + clamp(dist·erp/dt, −max_corrective_velocity, 0)` in
/// `ContactWith{Twist,Coulomb}FrictionBuilder::update`; the negative (pushing) part is the ERP
/// bias, which `update_rhs_wo_bias` strips in the relax pass, so lowering `dist` in the hook
/// moves a resting body (a position push of about |Δdist|) but leaves it without velocity. A
/// normal component of `tangent_velocity` only shifts body 1's surface inside `update` (again
/// through `dist`). The one velocity-level term that survives the relax pass is the
/// end-of-step restitution pass (`apply_restitution`, after all substeps), which drives each
/// bouncy point's normal velocity to `−restitution × (its approach velocity at constraint
/// generation)`; a point already loaded in the previous step is bouncy only with restitution
/// ≥ 1 (`geometry::is_bouncy`). A body at rest approaches at ≈ 0, so [`super::DcrRapier`]
/// first gives it the reverse of its response (approach at Δv) and this hook makes the
/// manifold reflect it (restitution 1).
///
/// The hook only reads data fixed before the step, so it is `Sync` and allocation-free. To
/// combine it with hooks of your own, call [`DcrSolverHooks::modify`] from your
/// `modify_solver_contacts` (bevy_rapier: from a `BevyPhysicsHooks` implementation).
/// Enabling `ActiveHooks::MODIFY_SOLVER_CONTACTS` on a collider disables rapier's contact
/// recycling for its pairs ([`super::DcrRapier::add_object`] does it on the elastic objects'
/// colliders in this mode only).
#[derive(Debug, Default)]
pub struct DcrSolverHooks {
    /// Sorted by `key`.
    pub(super) marks: Vec<PairMark>,
}

impl DcrSolverHooks {
    /// Applies this step's responses to one manifold (no-op for pairs without responses).
    pub fn modify(&self, ctx: &mut ContactModificationContext) {
        if self.marks.is_empty() {
            return;
        }
        let key = collider_pair_key(ctx.collider1, ctx.collider2);
        let Ok(i) = self.marks.binary_search_by_key(&key, |m| m.key) else {
            return;
        };
        let mark = &self.marks[i];
        mark.seen.store(true, Ordering::Relaxed);
        let elastic_is_1 = ctx.collider1 == mark.elastic;
        let Some(m) = ctx.rigid_mut() else {
            return;
        };
        *m.restitution = 1.0;
        if mark.kick != Vector::ZERO {
            // Body 2's tangential velocity is driven to body 1's plus `tangent_velocity`
            // (rapier: "an additional movement of the first body's surface").
            let n = *m.normal;
            let kick = mark.kick - n * mark.kick.dot(n);
            let tv = if elastic_is_1 { kick } else { -kick };
            for sc in m.solver_contacts.iter_mut() {
                sc.tangent_velocity = tv;
            }
        }
    }

    /// Number of collider pairs carrying responses in the coming step.
    pub fn num_marked_pairs(&self) -> usize {
        self.marks.len()
    }
}

impl PhysicsHooks for DcrSolverHooks {
    fn modify_solver_contacts(&self, ctx: &mut ContactModificationContext) {
        self.modify(ctx);
    }
}
