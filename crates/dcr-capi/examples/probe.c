/*
 * probe: the distant response of a baked base to one impact, through the dcr C API.
 *
 *   probe BASE.modes IX IY IZ IMPULSE CX CY CZ [CX CY CZ]...
 *
 * Applies one impact of IMPULSE N*s at (IX, IY, IZ) (m, the base's object frame) along the
 * inward surface normal there, and prints one line per contact point (CX, CY, CZ):
 *
 *   INDEX DELTA_V_MPS PEAK_DISPLACEMENT_M
 *
 * (INDEX from 0 in the order given; %.17g). Same conventions as `modal-bake probe ... --json`
 * with its defaults (modal method, h = 0.01 s, the paper's sampling, the base's damping, no
 * impact threshold, points within 5% of the bounding-box diagonal of the surface), so the two
 * agree. Exit status: 0 on success, 1 on an error (message on stderr), 2 on a usage error.
 *
 * Build (see docs/engine-integration.md, "C and C++"):
 *   cc -std=c99 -I crates/dcr-capi/include crates/dcr-capi/examples/probe.c \
 *      target/release/libdcr_capi.a -lpthread -ldl -lm -o probe
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dcr.h"

static int usage(const char *argv0) {
    fprintf(stderr,
            "usage: %s BASE.modes IX IY IZ IMPULSE CX CY CZ [CX CY CZ]...\n"
            "  one impact of IMPULSE N*s (> 0) at (IX, IY, IZ) along the inward normal;\n"
            "  prints INDEX DELTA_V_MPS PEAK_DISPLACEMENT_M per contact (object frame, m)\n",
            argv0);
    return 2;
}

/* Parses a finite double; 0 on success. */
static int parse_double(const char *s, double *out) {
    char *end = NULL;
    double v = strtod(s, &end);
    if (end == s || *end != '\0' || !isfinite(v)) {
        return 1;
    }
    *out = v;
    return 0;
}

/* Prints "probe: WHAT: <library message>" and returns 1. */
static int fail(const char *what, DcrStatus st) {
    fprintf(stderr, "probe: %s: %s (%s)\n", what, dcr_last_error(), dcr_status_name(st));
    return 1;
}

int main(int argc, char **argv) {
    if (argc < 9 || (argc - 6) % 3 != 0) {
        return usage(argv[0]);
    }
    double impact[3];
    double impulse;
    for (int k = 0; k < 3; ++k) {
        if (parse_double(argv[2 + k], &impact[k]) != 0) {
            fprintf(stderr, "probe: impact coordinate `%s` is not a finite number\n", argv[2 + k]);
            return 2;
        }
    }
    if (parse_double(argv[5], &impulse) != 0 || !(impulse > 0.0)) {
        fprintf(stderr, "probe: IMPULSE `%s` must be a finite number > 0 (N*s)\n", argv[5]);
        return 2;
    }
    size_t n = (size_t)(argc - 6) / 3;

    int rc = 1;
    DcrModel *model = NULL;
    DcrResponse *response = NULL;
    DcrRestingContact *contacts = calloc(n, sizeof *contacts);
    DcrContactResponse *out = calloc(n, sizeof *out);
    if (contacts == NULL || out == NULL) {
        fprintf(stderr, "probe: out of memory\n");
        goto done;
    }
    for (size_t i = 0; i < n; ++i) {
        contacts[i].id = i;
        for (int k = 0; k < 3; ++k) {
            const char *arg = argv[6 + 3 * i + (size_t)k];
            if (parse_double(arg, &contacts[i].point[k]) != 0) {
                fprintf(stderr, "probe: contact %zu coordinate `%s` is not a finite number\n",
                        i, arg);
                rc = 2;
                goto done;
            }
        }
    }

    DcrStatus st = dcr_model_load(argv[1], &model);
    if (st != DCR_STATUS_OK) {
        rc = fail("cannot load the base", st);
        goto done;
    }
    DcrResponseParams params;
    dcr_response_params_default(&params);
    params.method = DCR_METHOD_MODAL;
    params.impact_threshold = 0.0;
    st = dcr_response_create(model, &params, &response);
    if (st != DCR_STATUS_OK) {
        rc = fail("cannot set up the response", st);
        goto done;
    }

    /* The inward normal at the impact: minus the outward normal of its surface point. */
    DcrSurfacePoint sp;
    st = dcr_model_project(model, impact, NAN, &sp);
    if (st != DCR_STATUS_OK) {
        rc = fail("impact point", st);
        goto done;
    }
    DcrImpact hit;
    for (int k = 0; k < 3; ++k) {
        hit.point[k] = impact[k];
        hit.direction[k] = -sp.normal[k];
    }
    hit.impulse = impulse;

    size_t count = 0;
    st = dcr_response_step(response, &hit, 1, contacts, n, out, n, &count);
    if (st != DCR_STATUS_OK) {
        rc = fail("query", st);
        goto done;
    }
    for (size_t i = 0; i < count; ++i) {
        if (!out[i].mapped) {
            DcrResponseInfo info;
            dcr_response_info(response, &info);
            fprintf(stderr,
                    "probe: contact %zu at (%g, %g, %g) is farther than %.4f m from the surface\n",
                    i, contacts[i].point[0], contacts[i].point[1], contacts[i].point[2],
                    info.max_map_distance);
            goto done;
        }
    }
    for (size_t i = 0; i < count; ++i) {
        printf("%zu %.17g %.17g\n", i, out[i].delta_v, out[i].peak_displacement);
    }
    rc = 0;

done:
    dcr_response_free(response);
    dcr_model_free(model);
    free(out);
    free(contacts);
    return rc;
}
