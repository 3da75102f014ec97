/*
 * dcr_bullet.hpp: dcr's distant collision response in a Bullet btDiscreteDynamicsWorld,
 * header-only, over dcr's C ABI (dcr.h). C++17; tested with Bullet 3.24 (float and double btScalar).
 *
 *   #include "dcr_bullet.hpp"   // with crates/dcr-capi/include on the include path
 *
 *   DcrWorldParams wp;
 *   dcr_world_params_default(&wp);
 *   wp.h = 1.0 / 120.0;                        // Bullet's fixedTimeStep (s)
 *   dcr_bullet::World dcr(dynamics, wp);       // gravity: Bullet's, as wp.gravity is unset
 *   DcrElasticObjectDesc desc;
 *   dcr_elastic_object_desc_default(&desc);
 *   desc.model = table_model;                  // a DcrModel from dcr_model_load
 *   dcr.add(table_body, desc);                 // the table's btRigidBody
 *   ...
 *   dynamics.stepSimulation(frame_dt, 8, 1.0 / 120.0);   // as before: dcr runs in every substep
 *   if (dcr.status() != DCR_STATUS_OK) log(dcr.error());
 *
 * dcr_bullet::World installs Bullet's internal tick callback, so the response runs after every
 * internal step — each substep of stepSimulation(dt, maxSubSteps, fixedTimeStep) — when that
 * step's contacts and impulses are in the manifolds: every manifold point between an elastic
 * object's body and another body becomes a DcrContactReport (Bullet's normal on B points from
 * B toward A and the solver's impulse pushes A along it, so body1 = B, body2 = A; the id is a
 * counter kept in the point's m_userPersistentData, which Bullet preserves while it tracks the
 * point), every non-static body of those manifolds a DcrBodyState, and each returned event is
 * applied with btRigidBody::applyImpulse at its point (waking the body). Engine body ids are the
 * bodies' addresses (dcr_bullet::body_id). The base's object frame is placed in the body's frame
 * (btCollisionObject::getWorldTransform, the centre-of-mass frame) by add()'s mesh_in_body; a
 * dynamic elastic object's pose is set every step.
 *
 * Bullet has one internal tick callback: a program with its own passes install_callback =
 * false and calls World::tick(timeStep) from it. m_userPersistentData of the elastic objects'
 * manifold points is used for the ids (a program that sets it itself, through
 * gContactAddedCallback, has its values used as ids). A step of another length than the world's
 * h re-derives the responses for it (dcr_world_set_h; counted by h_changes()). A failure inside
 * the callback cannot be returned: status() and error() keep the first one, and the response
 * stops. The buffers keep their capacity from step to step: once they have grown to the most
 * contacts seen, a step allocates nothing (tests/c/bullet_alloc.cpp counts operator new;
 * dcr_world_step is tested allocation-free in Rust). Tested by crates/dcr-capi/tests/bullet.rs
 * through examples/bullet_dinner.cpp and tests/c/bullet_alloc.cpp.
 */
#ifndef DCR_BULLET_HPP
#define DCR_BULLET_HPP

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "dcr.h"

namespace dcr_bullet {

/* The engine id of a Bullet body in dcr's reports and events: its address. */
inline uint64_t body_id(const btCollisionObject *body) {
    return uint64_t(reinterpret_cast<uintptr_t>(body));
}

/* The pose of an object frame placed at `mesh_in_body` in a body's frame (object frame ->
   world; quaternion [x, y, z, w], m). */
inline DcrPose pose_of(const btCollisionObject &body, const btTransform &mesh_in_body) {
    const btTransform t = body.getWorldTransform() * mesh_in_body;
    const btQuaternion q = t.getRotation();
    DcrPose p;
    p.rotation[0] = q.x();
    p.rotation[1] = q.y();
    p.rotation[2] = q.z();
    p.rotation[3] = q.w();
    p.translation[0] = t.getOrigin().x();
    p.translation[1] = t.getOrigin().y();
    p.translation[2] = t.getOrigin().z();
    return p;
}

class World {
  public:
    /* Attaches dcr to `dynamics` with `params` (params.h: Bullet's fixed step, s; an unset
       params.gravity, the default, becomes Bullet's gravity now; a zero
       params.classify.min_approach_speed, the default, becomes 2 g h: Bullet re-creates the
       manifold points of a sliding contact, and the new points of a resting weight, which
       close at about g h, are no impacts). Check status(). */
    World(btDiscreteDynamicsWorld &dynamics, DcrWorldParams params, bool install_callback = true)
        : dynamics_(dynamics), installed_(install_callback) {
        if (std::isnan(params.gravity[0]) || std::isnan(params.gravity[1]) || std::isnan(params.gravity[2])) {
            const btVector3 g = dynamics.getGravity();
            params.gravity[0] = g.x();
            params.gravity[1] = g.y();
            params.gravity[2] = g.z();
        }
        if (params.classify.min_approach_speed == 0.0) {
            const double g = std::sqrt(params.gravity[0] * params.gravity[0] + params.gravity[1] * params.gravity[1] +
                                       params.gravity[2] * params.gravity[2]);
            params.classify.min_approach_speed = 2.0 * g * params.h;
        }
        h_ = params.h;
        if (!check(dcr_world_create(&params, &world_), "dcr_world_create")) {
            world_ = nullptr;
            return;
        }
        if (installed_) {
            dynamics_.setInternalTickCallback(&World::on_tick, this, false);
        }
    }

    ~World() {
        if (installed_ && dynamics_.getWorldUserInfo() == this) {
            dynamics_.setInternalTickCallback(nullptr, nullptr, false);
        }
        dcr_world_free(world_);
    }

    World(const World &) = delete;
    World &operator=(const World &) = delete;

    /* DCR_STATUS_OK, or the first failure (creation, a step); error() says what. */
    DcrStatus status() const { return status_; }
    const std::string &error() const { return error_; }

    /* Makes `body` an elastic object: desc.body, desc.dynamic (a body that is not static) and
       desc.pose are set from it; the rest of `desc` (model, response, gain) is the caller's.
       `mesh_in_body` places the base's object frame (the frame of the mesh it was baked from)
       in the body's frame: Bullet's body frame is its centre of mass, so a body whose shapes
       were shifted by -c to put the centre of mass at its origin passes a translation by -c
       (the identity when the body's frame is the mesh's). */
    DcrStatus add(btRigidBody *body, DcrElasticObjectDesc desc,
                  const btTransform &mesh_in_body = btTransform::getIdentity(), DcrElasticHandle *out = nullptr) {
        if (!world_) return status_;
        desc.body = body_id(body);
        desc.dynamic = !body->isStaticObject();
        desc.pose = pose_of(*body, mesh_in_body);
        DcrElasticHandle h = 0;
        DcrStatus st = dcr_world_add_object(world_, &desc, &h);
        if (st != DCR_STATUS_OK) return st;
        objects_.push_back({body, h, mesh_in_body});
        if (out) *out = h;
        return st;
    }

    /* Removes `body`'s elastic object (DCR_STATUS_NOT_FOUND when it has none). */
    DcrStatus remove(const btRigidBody *body) {
        auto it = std::find_if(objects_.begin(), objects_.end(),
                               [body](const Object &o) { return o.body == body; });
        if (it == objects_.end() || !world_) return DCR_STATUS_NOT_FOUND;
        DcrStatus st = dcr_world_remove_object(world_, it->handle);
        objects_.erase(it);
        return st;
    }

    /* One internal Bullet step of `time_step` s has ended: report its contacts, step the dcr
       world and apply its events. Called by the installed callback, or by the program's own. */
    void tick(btScalar time_step) {
        if (!world_ || status_ != DCR_STATUS_OK) return;
        const double ts = double(time_step);
        if (std::fabs(ts - h_) > 1e-6 * h_) {
            if (!check(dcr_world_set_h(world_, ts), "dcr_world_set_h")) return;
            h_ = ts;
            ++h_changes_;
        }
        for (const Object &o : objects_) {
            if (!o.body->isStaticObject()) {
                const DcrPose p = pose_of(*o.body, o.mesh_in_body);
                dcr_world_set_pose(world_, o.handle, &p);
            }
        }
        contacts_.clear();
        states_.clear();
        bodies_.clear();
        btDispatcher *d = dynamics_.getDispatcher();
        for (int m = 0; m < d->getNumManifolds(); ++m) {
            btPersistentManifold *pm = d->getManifoldByIndexInternal(m);
            const btCollisionObject *a = pm->getBody0();
            const btCollisionObject *b = pm->getBody1();
            if (pm->getNumContacts() == 0 || (!elastic(a) && !elastic(b))) continue;
            touching(a);
            touching(b);
            for (int j = 0; j < pm->getNumContacts(); ++j) {
                btManifoldPoint &pt = pm->getContactPoint(j);
                if (!pt.m_userPersistentData) {
                    pt.m_userPersistentData = reinterpret_cast<void *>(next_id_++);
                }
                DcrContactReport c{};
                c.id = uint64_t(reinterpret_cast<uintptr_t>(pt.m_userPersistentData));
                c.body1 = body_id(b);
                c.body2 = body_id(a);
                set3(c.point1, pt.getPositionWorldOnB());
                set3(c.point2, pt.getPositionWorldOnA());
                set3(c.normal, pt.m_normalWorldOnB);
                c.impulse = std::max(0.0, double(pt.m_appliedImpulse));
                c.is_new = false;
                contacts_.push_back(c);
            }
        }
        /* Each touching body once, ordered by address (its id): a state per body, and an
           event's body found by binary search. */
        std::sort(bodies_.begin(), bodies_.end());
        bodies_.erase(std::unique(bodies_.begin(), bodies_.end()), bodies_.end());
        for (const btRigidBody *b : bodies_) states_.push_back(state_of(*b));
        const DcrImpulseEvent *events = nullptr;
        size_t n = 0;
        if (!check(dcr_world_step(world_, contacts_.data(), contacts_.size(), states_.data(), states_.size(),
                                  &events, &n),
                   "dcr_world_step")) {
            return;
        }
        events_.assign(events, events + n);
        for (const DcrImpulseEvent &e : events_) {
            btRigidBody *body = rigid(e.body);
            if (!body) continue;
            body->applyImpulse(vec(e.impulse), vec(e.point) - body->getCenterOfMassPosition());
            body->activate(true);
        }
        ++steps_;
    }

    /* The events of the last step (world frame), as applied. */
    const std::vector<DcrImpulseEvent> &events() const { return events_; }
    /* Steps run, and changes of h (Bullet's step other than the world's). */
    uint64_t steps() const { return steps_; }
    uint64_t h_changes() const { return h_changes_; }
    /* The dcr world, for its queries (dcr_world_object_info, dcr_world_object_totals, ...). */
    DcrWorld *raw() const { return world_; }

  private:
    struct Object {
        btRigidBody *body;
        DcrElasticHandle handle;
        btTransform mesh_in_body;
    };

    static void on_tick(btDynamicsWorld *w, btScalar time_step) {
        static_cast<World *>(w->getWorldUserInfo())->tick(time_step);
    }

    bool check(DcrStatus st, const char *what) {
        if (st == DCR_STATUS_OK) return true;
        if (status_ == DCR_STATUS_OK) {
            status_ = st;
            error_ = std::string("dcr_bullet: ") + what + ": " + dcr_last_error();
        }
        return false;
    }

    bool elastic(const btCollisionObject *o) const {
        for (const Object &e : objects_)
            if (e.body == o) return true;
        return false;
    }

    /* Notes a non-static rigid body of a manifold (duplicates are removed after the pass). */
    void touching(const btCollisionObject *o) {
        const btRigidBody *b = btRigidBody::upcast(o);
        if (b && !b->isStaticObject()) bodies_.push_back(const_cast<btRigidBody *>(b));
    }

    /* A body's state as dcr reads it (world frame). */
    static DcrBodyState state_of(const btRigidBody &b) {
        DcrBodyState s{};
        s.id = body_id(&b);
        s.inv_mass = b.getInvMass();
        const btMatrix3x3 &ii = b.getInvInertiaTensorWorld();
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) s.inv_inertia[i][j] = ii[i][j];
        set3(s.center_of_mass, b.getCenterOfMassPosition());
        set3(s.linvel, b.getLinearVelocity());
        set3(s.angvel, b.getAngularVelocity());
        return s;
    }

    /* The body of an event: one whose state this step reported (events go to no other);
       `bodies_` is sorted by address. */
    btRigidBody *rigid(uint64_t id) const {
        auto it = std::lower_bound(bodies_.begin(), bodies_.end(), id,
                                   [](const btRigidBody *b, uint64_t v) { return body_id(b) < v; });
        return it != bodies_.end() && body_id(*it) == id ? *it : nullptr;
    }

    static void set3(double out[3], const btVector3 &v) {
        out[0] = v.x();
        out[1] = v.y();
        out[2] = v.z();
    }

    static btVector3 vec(const double v[3]) { return btVector3(btScalar(v[0]), btScalar(v[1]), btScalar(v[2])); }

    btDiscreteDynamicsWorld &dynamics_;
    bool installed_;
    DcrWorld *world_ = nullptr;
    double h_ = 0.0;
    DcrStatus status_ = DCR_STATUS_OK;
    std::string error_;
    std::vector<Object> objects_;
    std::vector<DcrContactReport> contacts_;
    std::vector<DcrBodyState> states_;
    std::vector<btRigidBody *> bodies_;
    std::vector<DcrImpulseEvent> events_;
    uintptr_t next_id_ = 1;
    uint64_t steps_ = 0;
    uint64_t h_changes_ = 0;
};

} // namespace dcr_bullet

#endif
