/*
 * bullet_alloc: dcr_bullet::World::tick allocates nothing once its buffers have grown.
 *
 *   bullet_alloc TABLE.modes
 *
 * A static table (the dinner table's top and legs) carries TABLE.modes; six boxes rest on it
 * and a 5 kg ball is dropped on it, then, every 40 steps, dropped again from the same height
 * (the same contacts each time). The global operator new counts the allocations made inside
 * World::tick; the first drop is the warm-up (the buffers grow to the most contacts), and every
 * tick after it must allocate nothing (dcr_world_step itself is tested allocation-free in
 * Rust). Prints "ticks N, responses R, allocations after warm-up A" and exits 0 when A is 0
 * and R > 0, 1 otherwise, 2 on a usage or set-up error.
 */
#include <btBulletDynamicsCommon.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>

#include "dcr.h"
#include "dcr_bullet.hpp"

namespace {
bool counting = false;
unsigned long allocations = 0;
} // namespace

void *operator new(std::size_t n) {
    if (counting) ++allocations;
    if (void *p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void operator delete(void *p) noexcept { std::free(p); }
void operator delete(void *p, std::size_t) noexcept { std::free(p); }

namespace {
struct Tick {
    dcr_bullet::World *dcr;
    long step = 0;
    long warm_up = 45;
    unsigned long responses = 0;
};

void on_tick(btDynamicsWorld *w, btScalar time_step) {
    Tick &t = *static_cast<Tick *>(w->getWorldUserInfo());
    counting = t.step++ >= t.warm_up;
    t.dcr->tick(time_step);
    counting = false;
    t.responses += t.dcr->events().size();
}
} // namespace

int main(int argc, char **argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s TABLE.modes\n", argv[0]);
        return 2;
    }
    DcrModel *model = nullptr;
    if (dcr_model_load(argv[1], &model) != DCR_STATUS_OK) {
        std::fprintf(stderr, "bullet_alloc: %s\n", dcr_last_error());
        return 2;
    }
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    world.setGravity(btVector3(0, -9.81f, 0));
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btRigidBody>> bodies;
    auto body = [&](btCollisionShape *shape, double mass, const btVector3 &at) {
        shapes.emplace_back(shape);
        btVector3 inertia(0, 0, 0);
        if (mass > 0) shape->calculateLocalInertia(btScalar(mass), inertia);
        btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), nullptr, shape, inertia);
        info.m_startWorldTransform.setOrigin(at);
        bodies.emplace_back(new btRigidBody(info));
        bodies.back()->setActivationState(DISABLE_DEACTIVATION);
        world.addRigidBody(bodies.back().get());
        return bodies.back().get();
    };
    auto *table_shape = new btCompoundShape();
    auto *top = new btBoxShape(btVector3(0.8f, 0.02f, 0.45f));
    shapes.emplace_back(top);
    table_shape->addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(0, 0.73f, 0)), top);
    btRigidBody *table = body(table_shape, 0.0, btVector3(0, 0, 0));
    for (int i = 0; i < 6; ++i) {
        body(new btBoxShape(btVector3(0.05f, 0.02f, 0.05f)), 0.5, btVector3(-0.6f + 0.24f * float(i), 0.77f, 0.3f));
    }
    btRigidBody *ball = body(new btSphereShape(0.1f), 5.0, btVector3(0, 1.1f, 0));

    DcrWorldParams wp;
    dcr_world_params_default(&wp);
    wp.h = 0.01;
    dcr_bullet::World dcr(world, wp, false);
    DcrElasticObjectDesc desc;
    dcr_elastic_object_desc_default(&desc);
    desc.model = model;
    desc.response.impact_threshold = 0.5;
    desc.response.max_map_distance = 0.1;
    if (dcr.status() != DCR_STATUS_OK || dcr.add(table, desc) != DCR_STATUS_OK) {
        std::fprintf(stderr, "bullet_alloc: %s\n", dcr.error().empty() ? dcr_last_error() : dcr.error().c_str());
        dcr_model_free(model);
        return 2;
    }
    Tick t{&dcr};
    world.setInternalTickCallback(on_tick, &t, false);
    for (int s = 0; s < 200; ++s) {
        if (s > 0 && s % 40 == 0) {
            /* The ball again from the same height, at rest. */
            btTransform start(btQuaternion::getIdentity(), btVector3(0, 1.1f, 0));
            ball->setWorldTransform(start);
            ball->setLinearVelocity(btVector3(0, 0, 0));
            ball->setAngularVelocity(btVector3(0, 0, 0));
        }
        world.stepSimulation(0.01f, 0);
    }
    for (auto &b : bodies) world.removeRigidBody(b.get());
    dcr_model_free(model);
    std::printf("ticks %ld, responses %lu, allocations after warm-up %lu\n", t.step, t.responses, allocations);
    return allocations == 0 && t.responses > 0 && dcr.status() == DCR_STATUS_OK ? 0 : 1;
}
