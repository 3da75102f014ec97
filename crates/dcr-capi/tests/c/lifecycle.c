/*
 * lifecycle: an elastic object's life through the C ABI, as an engine would drive it.
 *
 *   lifecycle BASE.modes      (a base whose +z side of the bounding box is a flat face: the
 *                              unit cube of the tests)
 *
 * A static object (engine body 1) carries a 1 kg box (body 7) resting near a corner of its top
 * face; a 0.5 kg ball (body 9) hits the middle of the face with 2 N*s on chosen steps. Checked,
 * in order (each hit is a new contact id on a world that was quiet since the last one):
 *   1. a hit pushes the box: one event, Delta-v dv1 > 0, along +z;
 *   2. disabled: a hit gives no event, the disabled steps are counted in the totals;
 *   3. enabled again (filters restart at rest) with gain 2: a hit gives exactly 2 dv1;
 *   4. threshold 3 N*s (above the 2 N*s hit): no event; back to 0.5: events again;
 *   5. removed: every call with the handle is DCR_STATUS_INVALID_HANDLE with a message naming
 *      the removal; a step reporting the same contacts succeeds with no event;
 *   6. a new object on the same body reuses the slot with the next generation: the old handle
 *      stays stale, the new one answers a hit with dv1 (a fresh object at gain 1);
 *   7. bad values (negative gain, NaN threshold) are refused and change nothing.
 * Prints "ok" and exits 0; on a failed check prints the check and exits 1. The tests run it
 * under AddressSanitizer with leak detection.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dcr.h"

#define OBJECT_BODY 1u
#define BOX_BODY 7u
#define BALL_BODY 9u

static int failures = 0;

#define CHECK(cond)                                                                     \
    do {                                                                                \
        if (!(cond)) {                                                                  \
            fprintf(stderr, "lifecycle.c:%d: check failed: %s (last error: %s)\n",     \
                    __LINE__, #cond, dcr_last_error());                                 \
            ++failures;                                                                 \
        }                                                                               \
    } while (0)

static double rest_point[3], hit_point[3];
static DcrBodyState bodies[2];
static uint64_t next_hit_id = 100;

/* One step: the box's resting contact, and (when `hit`) the ball's 2 N*s impact. Returns the
   number of events; the Delta-v of the first event on the box goes to *dv (0 if none). */
static size_t step(DcrWorld *world, int hit, double *dv) {
    DcrContactReport c[2];
    size_t n = 0;
    DcrContactReport rest = {70, OBJECT_BODY, BOX_BODY, {0}, {0}, {0, 0, 1}, 0.0981, false};
    memcpy(rest.point1, rest_point, sizeof rest_point);
    memcpy(rest.point2, rest_point, sizeof rest_point);
    c[n++] = rest;
    if (hit) {
        DcrContactReport h = {next_hit_id++, BALL_BODY, OBJECT_BODY, {0}, {0}, {0, 0, -1},
                              2.0, true};
        memcpy(h.point1, hit_point, sizeof hit_point);
        memcpy(h.point2, hit_point, sizeof hit_point);
        c[n++] = h;
    }
    const DcrImpulseEvent *events = NULL;
    size_t ne = 0;
    DcrStatus st = dcr_world_step(world, c, n, bodies, 2, &events, &ne);
    CHECK(st == DCR_STATUS_OK);
    if (dv != NULL) {
        *dv = 0.0;
        for (size_t i = 0; i < ne; ++i) {
            if (events[i].body == BOX_BODY) {
                *dv = events[i].delta_v;
                CHECK(fabs(events[i].normal[2] - 1.0) < 1e-12);
                break;
            }
        }
    }
    return ne;
}

/* Quiet steps (the box resting) until the previous hit stops ringing. */
static void settle(DcrWorld *world) {
    for (int s = 0; s < 200; ++s) {
        step(world, 0, NULL);
    }
}

static int same(double a, double b) { return fabs(a - b) <= 1e-12 * fabs(b); }

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s BASE.modes\n", argv[0]);
        return 2;
    }
    DcrModel *model = NULL;
    if (dcr_model_load(argv[1], &model) != DCR_STATUS_OK) {
        fprintf(stderr, "lifecycle: %s\n", dcr_last_error());
        return 1;
    }
    DcrModelInfo info;
    CHECK(dcr_model_info(model, &info) == DCR_STATUS_OK);
    const double *lo = info.bounding_box_min, *hi = info.bounding_box_max;
    for (int k = 0; k < 3; ++k) {
        rest_point[k] = lo[k] + 0.8 * (hi[k] - lo[k]);
        hit_point[k] = 0.5 * (lo[k] + hi[k]);
    }
    rest_point[2] = hit_point[2] = hi[2];
    memset(bodies, 0, sizeof bodies);
    bodies[0].id = BOX_BODY;
    bodies[0].inv_mass = 1.0;
    memcpy(bodies[0].center_of_mass, rest_point, sizeof rest_point);
    bodies[0].center_of_mass[2] += 0.05;
    bodies[1].id = BALL_BODY;
    bodies[1].inv_mass = 2.0;
    memcpy(bodies[1].center_of_mass, hit_point, sizeof hit_point);
    bodies[1].center_of_mass[2] += 0.03;

    DcrWorldParams wp;
    dcr_world_params_default(&wp);
    wp.energy_bound = false; /* Delta-v exactly linear in the gain */
    wp.gravity[0] = wp.gravity[1] = wp.gravity[2] = 0.0; /* no support compensation */
    DcrWorld *world = NULL;
    CHECK(dcr_world_create(&wp, &world) == DCR_STATUS_OK);
    DcrElasticObjectDesc desc;
    dcr_elastic_object_desc_default(&desc);
    desc.model = model;
    desc.body = OBJECT_BODY;
    desc.response.impact_threshold = 0.5; /* N*s: the box's weight per step (0.0981) is below */
    DcrElasticHandle obj = 0;
    CHECK(dcr_world_add_object(world, &desc, &obj) == DCR_STATUS_OK);

    /* 1. A hit pushes the box. */
    settle(world);
    double dv1 = 0.0, dv = 0.0;
    CHECK(step(world, 1, &dv1) == 1);
    CHECK(dv1 > 0.0);
    settle(world);

    /* 2. Disabled: no event, steps counted. */
    DcrObjectTotals t0, t1;
    CHECK(dcr_world_object_totals(world, obj, &t0) == DCR_STATUS_OK);
    CHECK(dcr_world_set_object_enabled(world, obj, false) == DCR_STATUS_OK);
    CHECK(step(world, 1, &dv) == 0);
    settle(world);
    CHECK(dcr_world_object_totals(world, obj, &t1) == DCR_STATUS_OK);
    CHECK(t1.disabled_steps == t0.disabled_steps + 201);
    CHECK(t1.impacts == t0.impacts);
    CHECK(t1.events == t0.events);

    /* 3. Enabled again, gain 2: twice the first push, filters at rest. */
    CHECK(dcr_world_set_object_enabled(world, obj, true) == DCR_STATUS_OK);
    CHECK(dcr_world_set_object_gain(world, obj, 2.0) == DCR_STATUS_OK);
    settle(world);
    CHECK(step(world, 1, &dv) == 1);
    CHECK(same(dv, 2.0 * dv1));
    settle(world);

    /* 4. Threshold above the hit: ignored; back below: answered. */
    CHECK(dcr_world_set_object_gain(world, obj, 1.0) == DCR_STATUS_OK);
    CHECK(dcr_world_set_object_threshold(world, obj, 3.0) == DCR_STATUS_OK);
    CHECK(step(world, 1, &dv) == 0);
    settle(world);
    CHECK(dcr_world_set_object_threshold(world, obj, 0.5) == DCR_STATUS_OK);
    CHECK(step(world, 1, &dv) == 1);
    CHECK(dv > 0.0);
    settle(world);

    /* 7. Bad values are refused and change nothing. */
    CHECK(dcr_world_set_object_gain(world, obj, -1.0) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(strstr(dcr_last_error(), "gain") != NULL);
    CHECK(dcr_world_set_object_threshold(world, obj, NAN) == DCR_STATUS_INVALID_ARGUMENT);

    /* 5. Removed: the handle is stale everywhere; the body's contacts are harmless. */
    CHECK(dcr_world_remove_object(world, obj) == DCR_STATUS_OK);
    DcrPose pose = desc.pose;
    DcrObjectStepInfo oi;
    DcrObjectTotals t;
    CHECK(dcr_world_remove_object(world, obj) == DCR_STATUS_INVALID_HANDLE);
    CHECK(strstr(dcr_last_error(), "removed") != NULL);
    CHECK(dcr_world_set_object_enabled(world, obj, true) == DCR_STATUS_INVALID_HANDLE);
    CHECK(dcr_world_set_object_gain(world, obj, 1.0) == DCR_STATUS_INVALID_HANDLE);
    CHECK(dcr_world_set_object_threshold(world, obj, 0.1) == DCR_STATUS_INVALID_HANDLE);
    CHECK(dcr_world_set_pose(world, obj, &pose) == DCR_STATUS_INVALID_HANDLE);
    CHECK(dcr_world_get_pose(world, obj, &pose) == DCR_STATUS_INVALID_HANDLE);
    CHECK(dcr_world_object_info(world, obj, &oi) == DCR_STATUS_INVALID_HANDLE);
    CHECK(dcr_world_object_totals(world, obj, &t) == DCR_STATUS_INVALID_HANDLE);
    CHECK(step(world, 1, &dv) == 0);
    size_t n = 99;
    CHECK(dcr_world_num_objects(world, &n) == DCR_STATUS_OK);
    CHECK(n == 0);

    /* 6. A new object on the same body: same slot, next generation, a fresh response. */
    DcrElasticHandle obj2 = 0;
    CHECK(dcr_world_add_object(world, &desc, &obj2) == DCR_STATUS_OK);
    CHECK(obj2 != obj);
    CHECK((uint32_t)obj2 == (uint32_t)obj);
    CHECK(dcr_world_set_object_gain(world, obj, 1.0) == DCR_STATUS_INVALID_HANDLE);
    CHECK(dcr_world_object_totals(world, obj2, &t) == DCR_STATUS_OK);
    CHECK(t.impacts == 0 && t.events == 0);
    settle(world);
    CHECK(step(world, 1, &dv) == 1);
    CHECK(same(dv, dv1));
    CHECK(dcr_world_object_totals(world, obj2, &t) == DCR_STATUS_OK);
    CHECK(t.impacts == 1 && t.events == 1);

    dcr_world_free(world);
    dcr_model_free(model);
    if (failures != 0) {
        fprintf(stderr, "lifecycle: %d checks failed\n", failures);
        return 1;
    }
    printf("ok\n");
    return 0;
}
