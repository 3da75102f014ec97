/*
 * world: drives the dcr world API for a few rigid-body steps, as an engine integration would.
 *
 *   world BASE.modes [STEPS [UP]]
 *
 * One static elastic object (engine body 1) built from BASE, placed in the world rotated by
 * 90 degrees about +y and moved by (2, 0, 0) m, so object and world frames differ. UP is the
 * base's up axis in its own frame (the frame of the mesh it was baked from): x, y, z, -x, -y
 * or -z, default z; the scenes' table is y-up. A 1 kg box (body 7) rests on the object's top
 * face (the side of its bounding box along UP) near a corner, and a 0.5 kg ball (body 9) hits
 * the middle of that face with 2 N*s at step 5 (STEPS, default 10). After every step the
 * example prints what it reported and what the world returned, one record per line (%.17g):
 *
 *   pose   QX QY QZ QW TX TY TZ                      (once: the object's pose)
 *   body   ID INV_MASS I00..I22 CX CY CZ VX VY VZ WX WY WZ
 *   step   STEP NUM_CONTACTS NUM_EVENTS
 *   contact ID BODY1 BODY2 P1X P1Y P1Z P2X P2Y P2Z NX NY NZ IMPULSE IS_NEW
 *   event  BODY PX PY PZ JX JY JZ NX NY NZ DELTA_V OBJECT SERVED_BY CONTACT CHAINED
 *
 * and, at the end, the world's counters on stderr. Contacts farther than the response's
 * max_map_distance from the base's surface get no response: when the object's running totals
 * (dcr_world_object_totals) count any, a warning on stderr says so and names UP (a base whose
 * up axis is not UP puts the box beside the object, not on it). An engine would apply each
 * event with its apply-impulse-at-point (rapier: RigidBody::apply_impulse_at_point(impulse,
 * point, true)). Exit status: 0 on success, 1 on an error (message on stderr), 2 on a usage
 * error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dcr.h"

#define BOX_BODY 7u
#define BALL_BODY 9u
#define OBJECT_BODY 1u

/* x_world = R(q) x + t, with q = [x, y, z, w] (Hamilton), as DcrPose documents. */
static void rotate(const double q[4], const double v[3], double out[3]) {
    double x = q[0], y = q[1], z = q[2], w = q[3];
    /* t = 2 (q_v × v); v' = v + w t + q_v × t */
    double t0 = 2.0 * (y * v[2] - z * v[1]);
    double t1 = 2.0 * (z * v[0] - x * v[2]);
    double t2 = 2.0 * (x * v[1] - y * v[0]);
    out[0] = v[0] + w * t0 + (y * t2 - z * t1);
    out[1] = v[1] + w * t1 + (z * t0 - x * t2);
    out[2] = v[2] + w * t2 + (x * t1 - y * t0);
}

static void to_world(const DcrPose *pose, const double p[3], double out[3]) {
    rotate(pose->rotation, p, out);
    for (int k = 0; k < 3; ++k) {
        out[k] += pose->translation[k];
    }
}

static int fail(const char *what, DcrStatus st) {
    fprintf(stderr, "world: %s: %s (%s)\n", what, dcr_last_error(), dcr_status_name(st));
    return 1;
}

static void print_body(const DcrBodyState *b) {
    printf("body %llu %.17g", (unsigned long long)b->id, b->inv_mass);
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            printf(" %.17g", b->inv_inertia[i][j]);
        }
    }
    for (int k = 0; k < 3; ++k) printf(" %.17g", b->center_of_mass[k]);
    for (int k = 0; k < 3; ++k) printf(" %.17g", b->linvel[k]);
    for (int k = 0; k < 3; ++k) printf(" %.17g", b->angvel[k]);
    printf("\n");
}

static void print_contact(const DcrContactReport *c) {
    printf("contact %llu %llu %llu", (unsigned long long)c->id, (unsigned long long)c->body1,
           (unsigned long long)c->body2);
    for (int k = 0; k < 3; ++k) printf(" %.17g", c->point1[k]);
    for (int k = 0; k < 3; ++k) printf(" %.17g", c->point2[k]);
    for (int k = 0; k < 3; ++k) printf(" %.17g", c->normal[k]);
    printf(" %.17g %d\n", c->impulse, c->is_new ? 1 : 0);
}

static void print_event(const DcrImpulseEvent *e) {
    printf("event %llu", (unsigned long long)e->body);
    for (int k = 0; k < 3; ++k) printf(" %.17g", e->point[k]);
    for (int k = 0; k < 3; ++k) printf(" %.17g", e->impulse[k]);
    for (int k = 0; k < 3; ++k) printf(" %.17g", e->normal[k]);
    printf(" %.17g %u %u %llu %d\n", e->delta_v, (unsigned)e->object, (unsigned)e->served_by,
           (unsigned long long)e->contact, e->chained ? 1 : 0);
}

/* The up axis `arg` (x, y, z, optionally signed) as an axis index and a sign; 0 if invalid. */
static int parse_up(const char *arg, int *axis, double *sign) {
    *sign = 1.0;
    if (arg[0] == '-' || arg[0] == '+') {
        *sign = arg[0] == '-' ? -1.0 : 1.0;
        ++arg;
    }
    if ((arg[0] != 'x' && arg[0] != 'y' && arg[0] != 'z') || arg[1] != '\0') {
        return 0;
    }
    *axis = arg[0] - 'x';
    return 1;
}

int main(int argc, char **argv) {
    if (argc < 2 || argc > 4) {
        fprintf(stderr, "usage: %s BASE.modes [STEPS [UP]]   (UP: x, y, z, -x, -y, -z; default z)\n",
                argv[0]);
        return 2;
    }
    int up_axis = 2;
    double up_sign = 1.0;
    const char *up_name = argc == 4 ? argv[3] : "z";
    if (!parse_up(up_name, &up_axis, &up_sign)) {
        fprintf(stderr, "world: UP `%s` must be one of x, y, z, -x, -y, -z (the base's up axis)\n",
                up_name);
        return 2;
    }
    long steps = 10;
    if (argc >= 3) {
        char *end = NULL;
        steps = strtol(argv[2], &end, 10);
        if (end == argv[2] || *end != '\0' || steps < 1 || steps > 100000) {
            fprintf(stderr, "world: STEPS `%s` must be an integer in 1..100000\n", argv[2]);
            return 2;
        }
    }

    int rc = 1;
    DcrModel *model = NULL;
    DcrWorld *world = NULL;
    DcrStatus st = dcr_model_load(argv[1], &model);
    if (st != DCR_STATUS_OK) {
        rc = fail("cannot load the base", st);
        goto done;
    }
    DcrModelInfo info;
    dcr_model_info(model, &info);

    DcrWorldParams wp;
    dcr_world_params_default(&wp);
    wp.h = 0.01; /* s: the engine's fixed step */
    /* m/s^2, world: the engine's gravity for the support compensation (e.g. {0, -9.81, 0} for
       a y-up engine). The bodies here are not moved by an engine, so none: {0, 0, 0}. */
    wp.gravity[0] = wp.gravity[1] = wp.gravity[2] = 0.0;
    st = dcr_world_create(&wp, &world);
    if (st != DCR_STATUS_OK) {
        rc = fail("cannot create the world", st);
        goto done;
    }

    DcrElasticObjectDesc desc;
    dcr_elastic_object_desc_default(&desc);
    desc.model = model;
    desc.body = OBJECT_BODY;
    desc.response.method = DCR_METHOD_MODAL;
    desc.response.impact_threshold = 0.05; /* N*s: resting weight per step stays below */
    const double half = sqrt(0.5);
    desc.pose.rotation[0] = 0.0; /* 90 degrees about +y */
    desc.pose.rotation[1] = half;
    desc.pose.rotation[2] = 0.0;
    desc.pose.rotation[3] = half;
    desc.pose.translation[0] = 2.0;
    desc.pose.translation[1] = 0.0;
    desc.pose.translation[2] = 0.0;
    DcrElasticHandle handle;
    st = dcr_world_add_object(world, &desc, &handle);
    if (st != DCR_STATUS_OK) {
        rc = fail("cannot add the elastic object", st);
        goto done;
    }
    /* The model can go now: the world holds its own reference. */
    dcr_model_free(model);
    model = NULL;
    printf("pose %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", desc.pose.rotation[0],
           desc.pose.rotation[1], desc.pose.rotation[2], desc.pose.rotation[3],
           desc.pose.translation[0], desc.pose.translation[1], desc.pose.translation[2]);

    /* Points on the object's top face (object frame), then in the world frame: the bounding
       box's side along UP, 80 % and 50 % across the other two axes. */
    const double *lo = info.bounding_box_min, *hi = info.bounding_box_max;
    double rest_obj[3], hit_obj[3], up_obj[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; ++k) {
        rest_obj[k] = lo[k] + 0.8 * (hi[k] - lo[k]);
        hit_obj[k] = 0.5 * (lo[k] + hi[k]);
    }
    rest_obj[up_axis] = hit_obj[up_axis] = up_sign > 0.0 ? hi[up_axis] : lo[up_axis];
    up_obj[up_axis] = up_sign;
    double rest_w[3], hit_w[3], up_w[3];
    const double zero[3] = {0.0, 0.0, 0.0};
    DcrPose identity_rot = desc.pose;
    for (int k = 0; k < 3; ++k) identity_rot.translation[k] = zero[k];
    to_world(&desc.pose, rest_obj, rest_w);
    to_world(&desc.pose, hit_obj, hit_w);
    to_world(&identity_rot, up_obj, up_w);

    /* Bodies after each step: the box at rest on the face, the ball leaving it at rest
       (a plastic hit: its 2 N*s stopped it). */
    DcrBodyState bodies[2] = {{0}, {0}};
    bodies[0].id = BOX_BODY;
    bodies[0].inv_mass = 1.0;
    for (int k = 0; k < 3; ++k) bodies[0].center_of_mass[k] = rest_w[k] + 0.05 * up_w[k];
    bodies[1].id = BALL_BODY;
    bodies[1].inv_mass = 2.0;
    for (int k = 0; k < 3; ++k) bodies[1].center_of_mass[k] = hit_w[k] + 0.03 * up_w[k];
    print_body(&bodies[0]);
    print_body(&bodies[1]);

    for (long s = 0; s < steps; ++s) {
        DcrContactReport contacts[2];
        size_t nc = 0;
        /* The box's weight over one step: m g h = 1 kg * 9.81 m/s^2 * 0.01 s. The object is
           body1, so the normal points from it toward the box: the face's outward normal. */
        DcrContactReport rest = {70, OBJECT_BODY, BOX_BODY, {0}, {0}, {0}, 0.0981, false};
        for (int k = 0; k < 3; ++k) {
            rest.point1[k] = rest.point2[k] = rest_w[k];
            rest.normal[k] = up_w[k];
        }
        contacts[nc++] = rest;
        if (s == 5) {
            /* The ball is body1 here: the normal points from the ball into the object. */
            DcrContactReport hit = {90, BALL_BODY, OBJECT_BODY, {0}, {0}, {0}, 2.0, true};
            for (int k = 0; k < 3; ++k) {
                hit.point1[k] = hit.point2[k] = hit_w[k];
                hit.normal[k] = -up_w[k];
            }
            contacts[nc++] = hit;
        }
        const DcrImpulseEvent *events = NULL;
        size_t ne = 0;
        st = dcr_world_step(world, contacts, nc, bodies, 2, &events, &ne);
        if (st != DCR_STATUS_OK) {
            rc = fail("step", st);
            goto done;
        }
        printf("step %ld %zu %zu\n", s, nc, ne);
        for (size_t i = 0; i < nc; ++i) print_contact(&contacts[i]);
        for (size_t i = 0; i < ne; ++i) print_event(&events[i]);
    }

    DcrObjectStepInfo oi;
    DcrWorldStepInfo wi;
    DcrObjectTotals totals;
    dcr_world_object_info(world, handle, &oi);
    dcr_world_step_info(world, &wi);
    dcr_world_object_totals(world, handle, &totals);
    if (totals.contacts_unmapped > 0 || totals.impacts_unmapped > 0) {
        /* NaN: automatic, 5 % of the base's bounding-box diagonal. */
        double max_map = isnan(desc.response.max_map_distance)
                             ? 0.05 * info.bounding_box_diagonal_m
                             : desc.response.max_map_distance;
        fprintf(stderr,
                "world: warning: %llu resting contacts and %llu impacts were not mapped onto the "
                "base (farther than max_map_distance = %g m from its surface) and got no "
                "response: is the base's up axis `%s`? Pass it as UP (x, y, z, -x, -y, -z)\n",
                (unsigned long long)totals.contacts_unmapped,
                (unsigned long long)totals.impacts_unmapped, max_map, up_name);
    }
    fprintf(stderr,
            "world: %ld steps; last step: %u contacts, %u impacts, %u resting, %u events; "
            "object %u injected %.3g J in all, its impacts dissipated %.3g J\n",
            steps, wi.contacts, wi.impacts, wi.resting, wi.events, (unsigned)handle,
            oi.energy.total_injected, oi.energy.total_dissipated);
    rc = 0;

done:
    dcr_world_free(world);
    dcr_model_free(model);
    return rc;
}
