/*
 * bullet_dinner: dinner is served (paper Fig. 1) in the Bullet physics engine, with dcr through
 * its C ABI. A 5 kg pot is dropped on a table laid with six plates; the table carries the modal
 * base baked from data/scenes/table.msh (20 modes, feet fixed; see docs/engine-integration.md,
 * "A real engine: Bullet"). The scene is the one of the Bevy example (crates/dcr-bevy/examples/
 * dinner.rs), so the two engines can be compared on the same base.
 *
 *   bullet_dinner TABLE.modes [--steps N] [--trace] [--no-support]
 *
 * The scene runs twice in the same process, with the response and without it, and prints one
 * JSON object on stdout:
 *
 *   {"engine": "Bullet 3.24 (float)", "h_s": 0.01, "steps": 150,
 *    "on": {"lift_mm": ..., "events": ..., "plate_events": ..., "launches": [...], ...},
 *    "off": {"lift_mm": ..., ...}}
 *
 * lift_mm is the largest rise of a plate's centre above its start (mm). A launch is a step in
 * which response impulses leave a plate rising: asked_mps is the upward velocity of its centre
 * that the response's contact events give it (its velocity before them included; m/s),
 * support_mps what the support-compensation events add (g h when it leaves), v_up_mps its
 * velocity after both, rise_mm the rise of its centre over the free flight that follows (until
 * it comes down or is pushed again) and ballistic_mm the rise of a free flight under gravity that
 * ends its first step with asked_mps, as Bullet integrates it: what the response asked for. A
 * plate that scrapes the table on the way, or loses g h to gravity in the step it leaves, rises
 * less. --trace prints each step's contacts and events on stderr. --no-support runs without the
 * support compensation (the world's gravity set to zero), to see what it does.
 * Exit status: 0 on success, 1 on an error (message on stderr), 2 on a usage error.
 *
 * The integration is what an engine team writes (about 100 lines, marked "dcr:" below):
 *   - after each btDiscreteDynamicsWorld::stepSimulation, every manifold point between the
 *     table and another body becomes a DcrContactReport: Bullet's normal on B points from B
 *     toward A and the solver's impulse pushes A along it, so body1 = B, body2 = A; the id is a
 *     counter stored in the point's m_userPersistentData, which Bullet keeps while it tracks
 *     the point (replaceContactPoint preserves it);
 *   - each dynamic body touching the table becomes a DcrBodyState (inverse mass, world inverse
 *     inertia, centre of mass, velocities);
 *   - dcr_world_step returns impulse events, applied with btRigidBody::applyImpulse at the
 *     event's point (waking the body);
 *   - the world's gravity is Bullet's, for the support compensation (a plate lifted off keeps
 *     the velocity the response gave it through its first free step).
 */
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dcr.h"

namespace {

constexpr double H = 0.01;           // s: Bullet's fixed step, the dcr world's h
constexpr double GRAVITY = 9.81;     // m/s^2, along -y
constexpr double PLATE_Y = 0.758;    // m: plate centres at rest (table top 0.75 + half height)
constexpr double PLATE_MASS = 0.5;   // kg
constexpr double POT_MASS = 5.0;     // kg
constexpr double MARGIN = 0.002;     // m: Bullet's collision margin, embedded in the shapes
constexpr uint64_t TABLE_ID = 1;     // engine ids (btCollisionObject user index)
constexpr uint64_t PLATE_ID0 = 10;
constexpr uint64_t POT_ID = 20;
constexpr int NUM_PLATES = 6;
constexpr double PLATES[NUM_PLATES][2] = {{-0.6, -0.25}, {-0.6, 0.25}, {0.6, -0.25},
                                          {0.6, 0.25},   {-0.25, -0.3}, {0.3, 0.3}};

struct Launch {
    int plate;
    long step;
    double asked;        // m/s: the centre's upward velocity before the impulses + what the
                         // response's contact events give it (sum of J_y / m, delta_v > 0)
    double support;      // m/s: what the support-compensation events give it (delta_v == 0)
    double v_up;         // m/s: the centre's upward velocity after all the step's impulses
    double y0;           // m: the centre's height at launch
    double rise = 0.0;   // m: measured
    bool open = true;    // still in flight
};

struct Outcome {
    double lift_mm = 0.0;
    uint64_t events = 0;
    uint64_t plate_events = 0;
    double injected_j = 0.0;
    double dissipated_j = 0.0;
    uint64_t unmapped = 0;
    std::vector<Launch> launches;
};

/* The rise of free flight from the end of a step with upward velocity v, as Bullet integrates
   it (semi-implicit Euler: velocity, then position, every step of H). A body that is to end
   its first free step with velocity u leaves with v = u + g H. */
double ballistic_rise(double v) {
    double y = 0.0, best = 0.0;
    for (int k = 0; k < 100000 && v > 0.0; ++k) {
        v -= GRAVITY * H;
        y += v * H;
        best = std::max(best, y);
    }
    return best;
}

void set3(double out[3], const btVector3 &v) {
    out[0] = v.x();
    out[1] = v.y();
    out[2] = v.z();
}

btVector3 vec(const double v[3]) { return btVector3(btScalar(v[0]), btScalar(v[1]), btScalar(v[2])); }

int fail(const char *what, DcrStatus st) {
    std::fprintf(stderr, "bullet_dinner: %s: %s (%s)\n", what, dcr_last_error(), dcr_status_name(st));
    return 1;
}

/* One Bullet world holding the dinner scene. Bullet combines friction and restitution of a
   pair by product: the table's are 1, so a pair gets the prop's own (0.55 and 0.15, the
   averages rapier takes of the Bevy example's values). */
struct Scene {
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher{&config};
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btDefaultMotionState>> motions;
    std::vector<std::unique_ptr<btRigidBody>> bodies;
    btRigidBody *plates[NUM_PLATES] = {};

    Scene() {
        /* Several points per convex pair from the first contact (a plate resting flat). */
        config.setConvexConvexMultipointIterations();
        world.setGravity(btVector3(0, btScalar(-GRAVITY), 0));

        /* The table in the mesh's frame (y up): its top and four legs, static. */
        auto table = std::make_unique<btCompoundShape>();
        auto top = box(0.8, 0.02, 0.45);
        table->addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(0, 0.73f, 0)), top);
        const double legs[4][2] = {{-0.7, -0.35}, {0.7, -0.35}, {-0.7, 0.35}, {0.7, 0.35}};
        for (const auto &l : legs) {
            table->addChildShape(
                btTransform(btQuaternion::getIdentity(), btVector3(btScalar(l[0]), 0.355f, btScalar(l[1]))),
                box(0.03, 0.355, 0.03));
        }
        add(std::move(table), 0.0, btVector3(0, 0, 0), TABLE_ID, 1.0, 1.0);

        for (int i = 0; i < NUM_PLATES; ++i) {
            auto shape = std::make_unique<btCylinderShape>(btVector3(0.11f, 0.008f, 0.11f));
            shape->setMargin(MARGIN);
            plates[i] = add(std::move(shape), PLATE_MASS,
                            btVector3(btScalar(PLATES[i][0]), btScalar(PLATE_Y), btScalar(PLATES[i][1])),
                            PLATE_ID0 + uint64_t(i), 0.55, 0.15);
        }
        /* The pot, falling on the bare table between the plates. */
        auto pot_shape = std::make_unique<btCylinderShape>(btVector3(0.13f, 0.1f, 0.13f));
        pot_shape->setMargin(MARGIN);
        btRigidBody *pot = add(std::move(pot_shape), POT_MASS, btVector3(0.05f, 1.25f, 0), POT_ID, 0.55, 0.15);
        pot->setLinearVelocity(btVector3(0, -1, 0));
    }

    ~Scene() {
        for (auto &b : bodies) world.removeRigidBody(b.get());
    }

    btBoxShape *box(double x, double y, double z) {
        auto b = std::make_unique<btBoxShape>(btVector3(btScalar(x), btScalar(y), btScalar(z)));
        b->setMargin(MARGIN);
        btBoxShape *raw = b.get();
        shapes.push_back(std::move(b));
        return raw;
    }

    btRigidBody *add(std::unique_ptr<btCollisionShape> shape, double mass, const btVector3 &at, uint64_t id,
                     double friction, double restitution) {
        btVector3 inertia(0, 0, 0);
        if (mass > 0.0) shape->calculateLocalInertia(btScalar(mass), inertia);
        auto motion = std::make_unique<btDefaultMotionState>(btTransform(btQuaternion::getIdentity(), at));
        btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), motion.get(), shape.get(), inertia);
        info.m_friction = btScalar(friction);
        info.m_restitution = btScalar(restitution);
        auto body = std::make_unique<btRigidBody>(info);
        body->setUserIndex(int(id));
        body->setActivationState(DISABLE_DEACTIVATION);
        world.addRigidBody(body.get());
        btRigidBody *raw = body.get();
        shapes.push_back(std::move(shape));
        motions.push_back(std::move(motion));
        bodies.push_back(std::move(body));
        return raw;
    }

    btRigidBody *find(uint64_t id) {
        for (auto &b : bodies)
            if (uint64_t(b->getUserIndex()) == id) return b.get();
        return nullptr;
    }
};

/* dcr: the engine body's state as dcr reads it (world frame). */
DcrBodyState body_state(const btRigidBody &b) {
    DcrBodyState s{};
    s.id = uint64_t(b.getUserIndex());
    s.inv_mass = b.getInvMass();
    const btMatrix3x3 &ii = b.getInvInertiaTensorWorld();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) s.inv_inertia[i][j] = ii[i][j];
    set3(s.center_of_mass, b.getCenterOfMassPosition());
    set3(s.linvel, b.getLinearVelocity());
    set3(s.angvel, b.getAngularVelocity());
    return s;
}

/* Runs the scene for `steps` steps; with `table_model`, the table is dcr's elastic object. */
int run(const DcrModel *table_model, long steps, bool trace, bool support, Outcome &out) {
    Scene scene;
    DcrWorld *world = nullptr;
    DcrElasticHandle handle = 0;
    if (table_model) {
        /* dcr: a world stepping with Bullet's step and gravity, and the table as a static
           elastic object at the identity pose (the mesh's frame is the world's). */
        DcrWorldParams wp;
        dcr_world_params_default(&wp);
        wp.h = H;
        wp.gravity[0] = 0.0;
        wp.gravity[1] = support ? -GRAVITY : 0.0; /* m/s^2: Bullet's, or none */
        wp.gravity[2] = 0.0;
        DcrStatus st = dcr_world_create(&wp, &world);
        if (st != DCR_STATUS_OK) return fail("cannot create the world", st);
        DcrElasticObjectDesc desc;
        dcr_elastic_object_desc_default(&desc);
        desc.model = table_model;
        desc.body = TABLE_ID;
        desc.response.impact_threshold = 0.5; /* N*s: a plate's weight per step stays below */
        desc.response.max_map_distance = 0.1; /* m */
        st = dcr_world_add_object(world, &desc, &handle);
        if (st != DCR_STATUS_OK) {
            dcr_world_free(world);
            return fail("cannot add the table", st);
        }
    }
    std::unique_ptr<DcrWorld, void (*)(DcrWorld *)> guard(world, dcr_world_free);

    uintptr_t next_contact_id = 1;
    std::vector<DcrContactReport> contacts;
    std::vector<DcrBodyState> states;
    for (long s = 0; s < steps; ++s) {
        scene.world.stepSimulation(btScalar(H), 0); /* one step of exactly H */

        if (world) {
            /* dcr: every manifold point between the table and another body. */
            contacts.clear();
            states.clear();
            btDispatcher *d = scene.world.getDispatcher();
            for (int m = 0; m < d->getNumManifolds(); ++m) {
                btPersistentManifold *pm = d->getManifoldByIndexInternal(m);
                const btCollisionObject *a = pm->getBody0();
                const btCollisionObject *b = pm->getBody1();
                uint64_t ida = uint64_t(a->getUserIndex()), idb = uint64_t(b->getUserIndex());
                if (ida != TABLE_ID && idb != TABLE_ID) continue;
                const btCollisionObject *other = ida == TABLE_ID ? b : a;
                bool listed = false;
                for (const auto &st : states) listed = listed || st.id == uint64_t(other->getUserIndex());
                if (!listed) states.push_back(body_state(*btRigidBody::upcast(other)));
                for (int j = 0; j < pm->getNumContacts(); ++j) {
                    btManifoldPoint &pt = pm->getContactPoint(j);
                    if (!pt.m_userPersistentData) {
                        pt.m_userPersistentData = reinterpret_cast<void *>(next_contact_id++);
                    }
                    DcrContactReport c{};
                    c.id = uint64_t(reinterpret_cast<uintptr_t>(pt.m_userPersistentData));
                    c.body1 = idb; /* Bullet's normal on B points from B toward A */
                    c.body2 = ida;
                    set3(c.point1, pt.getPositionWorldOnB());
                    set3(c.point2, pt.getPositionWorldOnA());
                    set3(c.normal, pt.m_normalWorldOnB);
                    c.impulse = std::max(0.0, double(pt.m_appliedImpulse));
                    c.is_new = false;
                    contacts.push_back(c);
                }
            }
            const DcrImpulseEvent *events = nullptr;
            size_t ne = 0;
            DcrStatus st = dcr_world_step(world, contacts.data(), contacts.size(), states.data(), states.size(),
                                          &events, &ne);
            if (st != DCR_STATUS_OK) return fail("dcr_world_step", st);
            /* dcr: apply each event at its point. */
            double plate_asked[NUM_PLATES] = {}, plate_support[NUM_PLATES] = {};
            bool pushed[NUM_PLATES] = {};
            for (int p = 0; p < NUM_PLATES; ++p) plate_asked[p] = scene.plates[p]->getLinearVelocity().y();
            for (size_t i = 0; i < ne; ++i) {
                const DcrImpulseEvent &e = events[i];
                btRigidBody *body = scene.find(e.body);
                if (!body) continue;
                body->applyImpulse(vec(e.impulse), vec(e.point) - body->getCenterOfMassPosition());
                body->activate(true);
                ++out.events;
                if (e.body >= PLATE_ID0 && e.body < PLATE_ID0 + NUM_PLATES) {
                    ++out.plate_events;
                    const size_t p = size_t(e.body - PLATE_ID0);
                    pushed[p] = true;
                    (e.delta_v > 0.0 ? plate_asked[p] : plate_support[p]) += e.impulse[1] / PLATE_MASS;
                }
                if (trace) {
                    std::fprintf(stderr, "step %ld event body %llu J (%.4g %.4g %.4g) dv %.4g\n", s,
                                 (unsigned long long)e.body, e.impulse[0], e.impulse[1], e.impulse[2], e.delta_v);
                }
            }
            if (trace && !contacts.empty()) {
                double pot = 0.0; /* N*s: the pot's contact impulse on the table this step */
                for (const auto &c : contacts)
                    if (c.body1 == POT_ID || c.body2 == POT_ID) pot += c.impulse;
                std::fprintf(stderr, "step %ld: %zu contacts (pot: %.4g N*s), %zu events\n", s, contacts.size(),
                             pot, ne);
            }
            for (int p = 0; p < NUM_PLATES; ++p) {
                if (!pushed[p]) continue;
                for (auto &l : out.launches)
                    if (l.plate == p) l.open = false; /* another push ends a flight */
                double v = scene.plates[p]->getLinearVelocity().y();
                if (v > GRAVITY * H) {
                    out.launches.push_back(Launch{p, s, plate_asked[p], plate_support[p], v,
                                                  scene.plates[p]->getCenterOfMassPosition().y()});
                }
            }
        }
        for (int p = 0; p < NUM_PLATES; ++p) {
            double y = scene.plates[p]->getCenterOfMassPosition().y();
            out.lift_mm = std::max(out.lift_mm, (y - PLATE_Y) * 1e3);
            for (auto &l : out.launches) {
                if (l.plate != p || !l.open || l.step == s) continue;
                l.rise = std::max(l.rise, y - l.y0);
                if (y < l.y0) l.open = false; /* came down */
            }
        }
    }
    if (world) {
        DcrObjectStepInfo oi;
        DcrObjectTotals totals;
        dcr_world_object_info(world, handle, &oi);
        dcr_world_object_totals(world, handle, &totals);
        out.injected_j = oi.energy.total_injected;
        out.dissipated_j = oi.energy.total_dissipated;
        out.unmapped = totals.contacts_unmapped + totals.impacts_unmapped;
    }
    return 0;
}

void print_outcome(const char *name, const Outcome &o, bool last) {
    std::printf("\"%s\": {\"lift_mm\": %.6g, \"events\": %llu, \"plate_events\": %llu, \"injected_J\": %.6g, "
                "\"dissipated_J\": %.6g, \"unmapped\": %llu, \"launches\": [",
                name, o.lift_mm, (unsigned long long)o.events, (unsigned long long)o.plate_events, o.injected_j,
                o.dissipated_j, (unsigned long long)o.unmapped);
    for (size_t i = 0; i < o.launches.size(); ++i) {
        const Launch &l = o.launches[i];
        std::printf("%s{\"plate\": %d, \"step\": %ld, \"asked_mps\": %.6g, \"support_mps\": %.6g, "
                    "\"v_up_mps\": %.6g, \"rise_mm\": %.6g, \"ballistic_mm\": %.6g}",
                    i ? ", " : "", l.plate, l.step, l.asked, l.support, l.v_up, l.rise * 1e3,
                    ballistic_rise(l.asked + GRAVITY * H) * 1e3);
    }
    std::printf("]}%s", last ? "" : ", ");
}

} // namespace

int main(int argc, char **argv) {
    const char *base = nullptr;
    long steps = 150;
    bool trace = false, support = true;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--steps") == 0 && i + 1 < argc) {
            char *end = nullptr;
            steps = std::strtol(argv[++i], &end, 10);
            if (*end != '\0' || steps < 1 || steps > 1000000) {
                std::fprintf(stderr, "bullet_dinner: --steps `%s` must be an integer in 1..1000000\n", argv[i]);
                return 2;
            }
        } else if (std::strcmp(argv[i], "--trace") == 0) {
            trace = true;
        } else if (std::strcmp(argv[i], "--no-support") == 0) {
            support = false;
        } else if (argv[i][0] != '-' && !base) {
            base = argv[i];
        } else {
            std::fprintf(stderr, "usage: %s TABLE.modes [--steps N] [--trace] [--no-support]\n", argv[0]);
            return 2;
        }
    }
    if (!base) {
        std::fprintf(stderr, "usage: %s TABLE.modes [--steps N] [--trace] [--no-support]\n", argv[0]);
        return 2;
    }
    DcrModel *model = nullptr;
    DcrStatus st = dcr_model_load(base, &model);
    if (st != DCR_STATUS_OK) return fail("cannot load the table's base", st);
    std::unique_ptr<DcrModel, void (*)(DcrModel *)> model_guard(model, dcr_model_free);

    Outcome on, off;
    if (int rc = run(model, steps, trace, support, on)) return rc;
    if (int rc = run(nullptr, steps, false, support, off)) return rc;
    std::printf("{\"engine\": \"Bullet %d.%02d (%s)\", \"h_s\": %g, \"steps\": %ld, \"support\": %s, ",
                BT_BULLET_VERSION / 100, BT_BULLET_VERSION % 100, sizeof(btScalar) == 8 ? "double" : "float", H,
                steps, support ? "true" : "false");
    print_outcome("on", on, false);
    print_outcome("off", off, true);
    std::printf("}\n");
    return 0;
}
