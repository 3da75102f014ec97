/*
 * bullet_dinner: dinner is served (paper Fig. 1) in the Bullet physics engine, with dcr through
 * its C ABI. A 5 kg pot is dropped on a table laid with six plates; the table carries the modal
 * base baked from data/scenes/table.msh (20 modes, feet fixed; see docs/engine-integration.md,
 * "A released C++ engine: Bullet"). The scene is the one of the Bevy example (crates/dcr-bevy/examples/
 * dinner.rs), so the two engines can be compared on the same base.
 *
 *   bullet_dinner TABLE.modes [--steps N] [--frame-dt S] [--fixed-dt S]
 *                 [--table-origin Y [--ignore-origin]] [--moving-table V] [--min-approach S] [--remove-at N]
 *                 [--installed-callback] [--trace] [--no-support]
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
 * less. --trace prints each step's events on stderr, the spin of each plate that leaves (about a
 * horizontal axis: the response's events push it at its contact points, off its centre) and
 * the table's contact impulse on a plate still rising: a spinning plate whose rim comes back down
 * on the table before its centre's apex is carried by it (about a fifth of its weight, as a
 * rocking disc) and rises higher than free flight. --no-support runs without the
 * support compensation (the world's gravity set to zero), to see what it does.
 * Exit status: 0 on success, 1 on an error (message on stderr), 2 on a usage error.
 *
 * The integration is crates/dcr-capi/integrations/bullet/dcr_bullet.hpp (header-only, over the
 * C ABI): dcr_bullet::World reports every manifold point of the table after each internal
 * Bullet step, steps the dcr world and applies its impulse events; its gravity is Bullet's
 * (the support compensation: a plate lifted off keeps the velocity the response gave it through
 * its first free step). This program calls World::tick from its own internal tick callback,
 * which then measures the plates. --frame-dt S steps Bullet as a game does,
 * stepSimulation(S, 16, 0.01) (substeps of 10 ms inside frames of S), instead of one
 * stepSimulation(0.01, 0) per step: the same internal steps, so the same outcome. --fixed-dt S
 * makes Bullet's internal step S instead of the world's h = 0.01 s: dcr_bullet re-derives the
 * responses for it (h_changes in the output). --table-origin Y puts the table's body frame Y m
 * above the mesh's (its shapes shifted down by as much, as a body whose frame is its centre of
 * mass has them) and tells dcr_bullet where the mesh's frame is in it; --ignore-origin does not,
 * to see what a base in the wrong frame does (its contacts are not mapped: "unmapped").
 * --moving-table V makes the table a 30 kg dynamic body on a frictionless floor, and it, the
 * plates and the falling pot start moving along +x at V m/s (V = 0: dynamic, at rest): a
 * dynamic elastic object whose pose dcr_bullet follows every step (table_moved_m: how far it
 * went; use a base baked without --fixed, a free object). --min-approach S sets the world's
 * classify.min_approach_speed (m/s; default dcr_bullet's 2 g h = 0.196 m/s; 1e-9 for
 * practically none), the closing speed below which a new contact point is not an impact.
 * --remove-at N removes the table's elastic object at step N (dcr_bullet::World::remove; a
 * second removal must find nothing: "removed" in the output); no response follows.
 * --installed-callback lets dcr_bullet install Bullet's tick callback itself (its default) and
 * measures after each stepSimulation(0.01, 0) call instead: the same outcome.
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
#include "dcr_bullet.hpp"

namespace {

constexpr double H = 0.01;           // s: the dcr world's h, and Bullet's step unless --fixed-dt
constexpr double GRAVITY = 9.81;     // m/s^2, along -y
constexpr double PLATE_Y = 0.758;    // m: plate centres at rest (table top 0.75 + half height)
constexpr double PLATE_MASS = 0.5;   // kg
constexpr double POT_MASS = 5.0;     // kg
constexpr double TABLE_MASS = 30.0;  // kg, when the table moves (--moving-table)
constexpr double MARGIN = 0.002;     // m: Bullet's collision margin, embedded in the shapes
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
    bool rising = true;  // its centre not yet past its apex (--trace)
};

struct Outcome {
    double lift_mm = 0.0;
    uint64_t events = 0;
    uint64_t plate_events = 0;
    double injected_j = 0.0;
    double dissipated_j = 0.0;
    uint64_t unmapped = 0;
    uint64_t h_changes = 0;
    double table_moved_m = 0.0;
    bool removed = false;
    std::vector<Launch> launches;
};

/* The rise of free flight from the end of a step with upward velocity v, as Bullet integrates
   it (semi-implicit Euler: velocity, then position, every step of h). A body that is to end
   its first free step with velocity u leaves with v = u + g h. */
double ballistic_rise(double v, double h) {
    double y = 0.0, best = 0.0;
    for (int k = 0; k < 100000 && v > 0.0; ++k) {
        v -= GRAVITY * h;
        y += v * h;
        best = std::max(best, y);
    }
    return best;
}

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
    btRigidBody *table = nullptr;
    btRigidBody *plates[NUM_PLATES] = {};

    /* The table's body at (0, table_origin, 0) m, its shapes shifted down by as much (a body
       frame other than the mesh's, as a centre-of-mass frame is). speed < 0: the table is
       static; else a 30 kg dynamic body on a frictionless floor, and it and everything on or
       above it start moving along +x at `speed` m/s. */
    Scene(double table_origin, double speed) {
        /* Several points per convex pair from the first contact (a plate resting flat). */
        config.setConvexConvexMultipointIterations();
        world.setGravity(btVector3(0, btScalar(-GRAVITY), 0));

        /* The table in the mesh's frame (y up): its top and four legs, static. */
        auto table = std::make_unique<btCompoundShape>();
        const btScalar dy = btScalar(-table_origin);
        auto top = box(0.8, 0.02, 0.45);
        table->addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(0, 0.73f + dy, 0)), top);
        const double legs[4][2] = {{-0.7, -0.35}, {0.7, -0.35}, {-0.7, 0.35}, {0.7, 0.35}};
        for (const auto &l : legs) {
            table->addChildShape(
                btTransform(btQuaternion::getIdentity(), btVector3(btScalar(l[0]), 0.355f + dy, btScalar(l[1]))),
                box(0.03, 0.355, 0.03));
        }
        const bool moving = speed >= 0.0;
        this->table =
            add(std::move(table), moving ? TABLE_MASS : 0.0, btVector3(0, btScalar(table_origin), 0), 1.0, 1.0);
        if (moving) {
            /* The floor, top at y = 0, frictionless (Bullet multiplies the pair's frictions). */
            add(std::unique_ptr<btCollisionShape>(box_shape(50.0, 0.05, 5.0)), 0.0, btVector3(0, -0.05f, 0), 0.0,
                1.0);
        }

        for (int i = 0; i < NUM_PLATES; ++i) {
            auto shape = std::make_unique<btCylinderShape>(btVector3(0.11f, 0.008f, 0.11f));
            shape->setMargin(MARGIN);
            plates[i] = add(std::move(shape), PLATE_MASS,
                            btVector3(btScalar(PLATES[i][0]), btScalar(PLATE_Y), btScalar(PLATES[i][1])),
                            0.55, 0.15);
        }
        /* The pot, falling on the bare table between the plates. */
        auto pot_shape = std::make_unique<btCylinderShape>(btVector3(0.13f, 0.1f, 0.13f));
        pot_shape->setMargin(MARGIN);
        btRigidBody *pot = add(std::move(pot_shape), POT_MASS, btVector3(0.05f, 1.25f, 0), 0.55, 0.15);
        pot->setLinearVelocity(btVector3(0, -1, 0));
        if (moving) {
            for (auto &b : bodies) {
                if (!b->isStaticObject()) b->setLinearVelocity(b->getLinearVelocity() + btVector3(btScalar(speed), 0, 0));
            }
        }
    }

    ~Scene() {
        for (auto &b : bodies) world.removeRigidBody(b.get());
    }

    /* A box shape owned by the caller (half extents, m). */
    static btBoxShape *box_shape(double x, double y, double z) {
        auto *b = new btBoxShape(btVector3(btScalar(x), btScalar(y), btScalar(z)));
        b->setMargin(MARGIN);
        return b;
    }

    /* A box shape owned by the scene (a child of a compound). */
    btBoxShape *box(double x, double y, double z) {
        shapes.emplace_back(box_shape(x, y, z));
        return static_cast<btBoxShape *>(shapes.back().get());
    }

    btRigidBody *add(std::unique_ptr<btCollisionShape> shape, double mass, const btVector3 &at, double friction,
                     double restitution) {
        btVector3 inertia(0, 0, 0);
        if (mass > 0.0) shape->calculateLocalInertia(btScalar(mass), inertia);
        auto motion = std::make_unique<btDefaultMotionState>(btTransform(btQuaternion::getIdentity(), at));
        btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), motion.get(), shape.get(), inertia);
        info.m_friction = btScalar(friction);
        info.m_restitution = btScalar(restitution);
        auto body = std::make_unique<btRigidBody>(info);
        body->setActivationState(DISABLE_DEACTIVATION);
        world.addRigidBody(body.get());
        btRigidBody *raw = body.get();
        shapes.push_back(std::move(shape));
        motions.push_back(std::move(motion));
        bodies.push_back(std::move(body));
        return raw;
    }
};

/* One run: the scene, dcr attached to it (or not), what is measured after each internal step. */
struct Run {
    Scene &scene;
    dcr_bullet::World *dcr;
    Outcome &out;
    long steps;
    bool trace;
    long remove_at; /* the step at which the table stops being elastic (-1: never) */
    long step = 0;
};

/* The sum of the table's contact impulses on `body` in the last step (N*s). */
double table_impulse(Scene &scene, const btRigidBody *body) {
    double sum = 0.0;
    btDispatcher *d = scene.world.getDispatcher();
    for (int m = 0; m < d->getNumManifolds(); ++m) {
        const btPersistentManifold *pm = d->getManifoldByIndexInternal(m);
        if (!((pm->getBody0() == body && pm->getBody1() == scene.table) ||
              (pm->getBody1() == body && pm->getBody0() == scene.table)))
            continue;
        for (int j = 0; j < pm->getNumContacts(); ++j) sum += pm->getContactPoint(j).m_appliedImpulse;
    }
    return sum;
}

/* Bullet's internal tick callback of a run: dcr's step (dcr_bullet::World::tick), then the
   measurements, for the first `steps` internal steps. */
/* After internal step `s` of `time_step` s and dcr's response to it: counts the events, records
   the plates that leave and their heights. `before` holds each plate's upward velocity before
   the step's events (m/s). */
void measure(Run &r, long s, double time_step, const double before[NUM_PLATES]) {
    Scene &scene = r.scene;
    Outcome &out = r.out;
    if (r.dcr) {
        double plate_asked[NUM_PLATES], plate_support[NUM_PLATES] = {};
        bool pushed[NUM_PLATES] = {};
        std::copy(before, before + NUM_PLATES, plate_asked);
        for (const DcrImpulseEvent &e : r.dcr->events()) {
            ++out.events;
            for (int p = 0; p < NUM_PLATES; ++p) {
                if (e.body != dcr_bullet::body_id(scene.plates[p])) continue;
                ++out.plate_events;
                pushed[p] = true;
                (e.delta_v > 0.0 ? plate_asked[p] : plate_support[p]) += e.impulse[1] / PLATE_MASS;
            }
            if (r.trace) {
                std::fprintf(stderr, "step %ld event J (%.4g %.4g %.4g) dv %.4g\n", s, e.impulse[0], e.impulse[1],
                             e.impulse[2], e.delta_v);
            }
        }
        for (int p = 0; p < NUM_PLATES; ++p) {
            if (!pushed[p]) continue;
            for (auto &l : out.launches)
                if (l.plate == p) l.open = false; /* another push ends a flight */
            double v = scene.plates[p]->getLinearVelocity().y();
            if (v > GRAVITY * time_step) {
                out.launches.push_back(
                    Launch{p, s, plate_asked[p], plate_support[p], v, scene.plates[p]->getCenterOfMassPosition().y()});
                if (r.trace) {
                    const btVector3 w = scene.plates[p]->getAngularVelocity();
                    std::fprintf(stderr, "step %ld plate %d leaves: v_up %.4g m/s, spin %.4g rad/s\n", s, p, v,
                                 std::hypot(double(w.x()), double(w.z())));
                }
            }
        }
    }
    for (int p = 0; p < NUM_PLATES; ++p) {
        double y = scene.plates[p]->getCenterOfMassPosition().y();
        out.lift_mm = std::max(out.lift_mm, (y - PLATE_Y) * 1e3);
        for (auto &l : out.launches) {
            if (l.plate != p || !l.open || l.step == s) continue;
            if (r.trace && l.rising) {
                const double j = table_impulse(scene, scene.plates[p]), v = scene.plates[p]->getLinearVelocity().y();
                if (j > 0.0) {
                    std::fprintf(stderr, "step %ld plate %d rising: the table's contact impulse %.4g N*s, v_up %.4g m/s\n",
                                 s, p, j, v);
                }
                l.rising = v > 0.0;
            }
            l.rise = std::max(l.rise, y - l.y0);
            if (y < l.y0) l.open = false; /* came down */
        }
    }
}

/* Removes the table's elastic object at step `s` when asked (a second removal must find
   nothing). */
void maybe_remove(Run &r, long s) {
    if (r.dcr && s == r.remove_at) {
        r.out.removed = r.dcr->remove(r.scene.table) == DCR_STATUS_OK &&
                        r.dcr->remove(r.scene.table) == DCR_STATUS_NOT_FOUND;
    }
}

/* The program's internal tick callback: dcr's step (dcr_bullet::World::tick), then the
   measurements, for the first `steps` internal steps. */
void on_tick(btDynamicsWorld *w, btScalar time_step) {
    Run &r = *static_cast<Run *>(w->getWorldUserInfo());
    if (r.step >= r.steps) return;
    const long s = r.step++;
    maybe_remove(r, s);
    double before[NUM_PLATES];
    for (int p = 0; p < NUM_PLATES; ++p) before[p] = r.scene.plates[p]->getLinearVelocity().y();
    if (r.dcr) r.dcr->tick(time_step); /* dcr: report, step, apply */
    measure(r, s, double(time_step), before);
}

/* Runs the scene for `steps` internal Bullet steps of `fixed_dt` (s); with `table_model`, the
   table is dcr's elastic object (the world's h is H: another fixed_dt is re-derived by
   dcr_bullet). frame_dt 0: stepSimulation(fixed_dt, 0), one step per call; else
   stepSimulation(frame_dt, 16, fixed_dt), as a game steps at its frame rate. */
int run(const DcrModel *table_model, long steps, double fixed_dt, double frame_dt, double table_origin,
        bool pass_origin, double speed, double min_approach, long remove_at, bool installed, bool trace,
        bool support, Outcome &out) {
    Scene scene(table_origin, speed);
    const double table_x0 = scene.table->getCenterOfMassPosition().x();
    std::unique_ptr<dcr_bullet::World> dcr;
    DcrElasticHandle handle = 0;
    if (table_model) {
        /* dcr: a world stepping with Bullet's step and gravity (unset: dcr_bullet takes
           Bullet's), and the table as a static elastic object (the mesh's frame is the body's). */
        DcrWorldParams wp;
        dcr_world_params_default(&wp);
        wp.h = H;
        if (!support) wp.gravity[0] = wp.gravity[1] = wp.gravity[2] = 0.0;
        wp.classify.min_approach_speed = min_approach; /* 0: dcr_bullet's 2 g h */
        dcr = std::make_unique<dcr_bullet::World>(scene.world, wp, installed);
        DcrElasticObjectDesc desc;
        dcr_elastic_object_desc_default(&desc);
        desc.model = table_model;
        desc.response.impact_threshold = 0.5; /* N*s: a plate's weight per step stays below */
        desc.response.max_map_distance = 0.1; /* m */
        DcrStatus st = dcr->status();
        /* The mesh's frame in the table body's frame. */
        const btTransform mesh_in_body(btQuaternion::getIdentity(),
                                       btVector3(0, btScalar(pass_origin ? -table_origin : 0.0), 0));
        if (st == DCR_STATUS_OK) st = dcr->add(scene.table, desc, mesh_in_body, &handle);
        if (st != DCR_STATUS_OK) {
            std::fprintf(stderr, "bullet_dinner: cannot add the table: %s\n",
                         dcr->error().empty() ? dcr_last_error() : dcr->error().c_str());
            return 1;
        }
    }
    Run r{scene, dcr.get(), out, steps, trace, remove_at};
    if (installed) {
        /* dcr_bullet's own callback; the measurements after each stepSimulation call, with the
           plates' velocities before the events taken back out of the events. */
        while (r.step < steps) {
            const long s = r.step++;
            maybe_remove(r, s);
            scene.world.stepSimulation(btScalar(fixed_dt), 0);
            static const std::vector<DcrImpulseEvent> none;
            const std::vector<DcrImpulseEvent> &events = dcr ? dcr->events() : none;
            double before[NUM_PLATES];
            for (int p = 0; p < NUM_PLATES; ++p) {
                before[p] = scene.plates[p]->getLinearVelocity().y();
                for (const DcrImpulseEvent &e : events)
                    if (e.body == dcr_bullet::body_id(scene.plates[p])) before[p] -= e.impulse[1] / PLATE_MASS;
            }
            measure(r, s, double(btScalar(fixed_dt)), before);
        }
    } else {
        scene.world.setInternalTickCallback(on_tick, &r, false);
    }
    while (r.step < steps) {
        if (frame_dt > 0.0) {
            scene.world.stepSimulation(btScalar(frame_dt), 16, btScalar(fixed_dt));
        } else {
            scene.world.stepSimulation(btScalar(fixed_dt), 0); /* one step of exactly fixed_dt */
        }
        if (dcr && dcr->status() != DCR_STATUS_OK) {
            std::fprintf(stderr, "bullet_dinner: %s\n", dcr->error().c_str());
            return 1;
        }
    }
    out.table_moved_m = scene.table->getCenterOfMassPosition().x() - table_x0;
    if (dcr) {
        /* The table's account (none once it was removed: its handle is stale). */
        DcrObjectStepInfo oi;
        DcrObjectTotals totals;
        if (dcr_world_object_info(dcr->raw(), handle, &oi) == DCR_STATUS_OK &&
            dcr_world_object_totals(dcr->raw(), handle, &totals) == DCR_STATUS_OK) {
            out.injected_j = oi.energy.total_injected;
            out.dissipated_j = oi.energy.total_dissipated;
            out.unmapped = totals.contacts_unmapped + totals.impacts_unmapped;
        }
        out.h_changes = dcr->h_changes();
    }
    return 0;
}

void print_outcome(const char *name, const Outcome &o, double fixed_dt, bool last) {
    std::printf("\"%s\": {\"lift_mm\": %.17g, \"events\": %llu, \"plate_events\": %llu, \"injected_J\": %.17g, "
                "\"dissipated_J\": %.17g, \"unmapped\": %llu, \"h_changes\": %llu, \"table_moved_m\": %.17g, "
                "\"removed\": %s, \"launches\": [",
                name, o.lift_mm, (unsigned long long)o.events, (unsigned long long)o.plate_events, o.injected_j,
                o.dissipated_j, (unsigned long long)o.unmapped, (unsigned long long)o.h_changes, o.table_moved_m, o.removed ? "true" : "false");
    for (size_t i = 0; i < o.launches.size(); ++i) {
        const Launch &l = o.launches[i];
        std::printf("%s{\"plate\": %d, \"step\": %ld, \"asked_mps\": %.17g, \"support_mps\": %.17g, "
                    "\"v_up_mps\": %.17g, \"rise_mm\": %.17g, \"ballistic_mm\": %.17g}",
                    i ? ", " : "", l.plate, l.step, l.asked, l.support, l.v_up, l.rise * 1e3,
                    ballistic_rise(l.asked + GRAVITY * fixed_dt, fixed_dt) * 1e3);
    }
    std::printf("]}%s", last ? "" : ", ");
}

} // namespace

/* The number `text` of option `name` into `out` when it lies in [lo, hi] (an integer when
   `integer`); otherwise says so on stderr and returns false. */
bool number(const char *name, const char *text, double lo, double hi, const char *unit, bool integer, double &out) {
    char *end = nullptr;
    const double v = std::strtod(text, &end);
    if (end != text && *end == '\0' && v >= lo && v <= hi && (!integer || v == std::floor(v))) {
        out = v;
        return true;
    }
    std::fprintf(stderr, "bullet_dinner: %s `%s` must be %s in [%g, %g]%s\n", name, text,
                 integer ? "an integer" : "a number", lo, hi, unit);
    return false;
}

const char *const USAGE = "usage: %s TABLE.modes [--steps N] [--frame-dt S] [--fixed-dt S]\n"
                          "       [--table-origin Y [--ignore-origin]] [--moving-table V] [--min-approach S] [--remove-at N]\n"
                          "       [--installed-callback] [--trace] [--no-support]\n";

int main(int argc, char **argv) {
    const char *base = nullptr;
    double steps = 150;
    bool trace = false, support = true, pass_origin = true, installed = false;
    double frame_dt = 0.0, fixed_dt = H, table_origin = 0.0, speed = -1.0, min_approach = 0.0, remove_at = -1.0;
    /* Options with a value: name, range, unit, integer, where it goes. */
    struct Numeric {
        const char *name;
        double lo, hi;
        const char *unit;
        bool integer;
        double *out;
    };
    const Numeric numeric[] = {
        {"--steps", 1, 1e6, "", true, &steps},
        {"--frame-dt", 1e-4, 1.0, " s", false, &frame_dt},
        {"--fixed-dt", 1e-4, 0.05, " s", false, &fixed_dt},
        {"--table-origin", -10.0, 10.0, " m", false, &table_origin},
        {"--moving-table", 0.0, 10.0, " m/s", false, &speed},
        {"--min-approach", 1e-12, 100.0, " m/s", false, &min_approach},
        {"--remove-at", 0, 1e6, " (a step)", true, &remove_at},
    };
    for (int i = 1; i < argc; ++i) {
        const Numeric *opt = nullptr;
        for (const Numeric &n : numeric)
            if (std::strcmp(argv[i], n.name) == 0) opt = &n;
        if (opt && i + 1 < argc) {
            if (!number(opt->name, argv[i + 1], opt->lo, opt->hi, opt->unit, opt->integer, *opt->out)) return 2;
            ++i;
        } else if (std::strcmp(argv[i], "--installed-callback") == 0) {
            installed = true;
        } else if (std::strcmp(argv[i], "--ignore-origin") == 0) {
            pass_origin = false;
        } else if (std::strcmp(argv[i], "--trace") == 0) {
            trace = true;
        } else if (std::strcmp(argv[i], "--no-support") == 0) {
            support = false;
        } else if (argv[i][0] != '-' && !base) {
            base = argv[i];
        } else {
            std::fprintf(stderr, USAGE, argv[0]);
            return 2;
        }
    }
    if (!base) {
        std::fprintf(stderr, USAGE, argv[0]);
        return 2;
    }
    if (installed && frame_dt > 0.0) {
        std::fprintf(stderr, "bullet_dinner: --installed-callback measures after each stepSimulation call: "
                             "it steps one internal step per call (leave out --frame-dt)\n");
        return 2;
    }
    DcrModel *model = nullptr;
    DcrStatus st = dcr_model_load(base, &model);
    if (st != DCR_STATUS_OK) return fail("cannot load the table's base", st);
    std::unique_ptr<DcrModel, void (*)(DcrModel *)> model_guard(model, dcr_model_free);

    Outcome on, off;
    if (int rc = run(model, long(steps), fixed_dt, frame_dt, table_origin, pass_origin, speed, min_approach, long(remove_at), installed, trace, support, on)) return rc;
    if (int rc = run(nullptr, long(steps), fixed_dt, frame_dt, table_origin, pass_origin, speed, min_approach, long(remove_at), installed, false, support, off)) return rc;
    std::printf("{\"engine\": \"Bullet %d.%02d (%s)\", \"h_s\": %g, \"fixed_dt_s\": %g, \"steps\": %ld, "
                "\"frame_dt_s\": %g, \"support\": %s, ",
                BT_BULLET_VERSION / 100, BT_BULLET_VERSION % 100, sizeof(btScalar) == 8 ? "double" : "float", H,
                fixed_dt, long(steps), frame_dt, support ? "true" : "false");
    print_outcome("on", on, fixed_dt, false);
    print_outcome("off", off, fixed_dt, true);
    std::printf("}\n");
    return 0;
}
