/*
 * The C API's error paths, run by tests/c_programs.rs under AddressSanitizer with leak
 * detection: every failing call returns its documented status, sets a message that names
 * what failed, leaves its out-handles NULL and leaks nothing; a too-small buffer reports the
 * required size and changes no state.
 *
 *   error_paths BASE.modes CORRUPT.modes MISSING.modes
 *
 * Prints "ok N checks" and exits 0, or names the first failed check and exits 1.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <stddef.h>
#include <string.h>

#include "dcr.h"

static int checks = 0;
static int failed = 0;

#define CHECK(cond)                                                                  \
    do {                                                                             \
        ++checks;                                                                    \
        if (!(cond)) {                                                               \
            fprintf(stderr, "error_paths.c:%d: check failed: %s (last error: %s)\n", \
                    __LINE__, #cond, dcr_last_error());                              \
            failed = 1;                                                              \
        }                                                                            \
    } while (0)

/* The last error message contains `needle`. */
static int last_error_has(const char *needle) {
    return strstr(dcr_last_error(), needle) != NULL;
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: %s BASE.modes CORRUPT.modes MISSING.modes\n", argv[0]);
        return 2;
    }
    const char *base = argv[1], *corrupt = argv[2], *missing = argv[3];

    /* Version and ABI. */
    DcrVersion v;
    CHECK(dcr_version(&v) == DCR_STATUS_OK);
    CHECK(v.abi == DCR_ABI_VERSION);
    CHECK(dcr_version(NULL) == DCR_STATUS_NULL_POINTER);
    CHECK(last_error_has("dcr_version") && last_error_has("`out` is NULL"));
    CHECK(strcmp(dcr_status_name(DCR_STATUS_BUFFER_TOO_SMALL), "DCR_STATUS_BUFFER_TOO_SMALL") == 0);

    /* Missing file: DCR_STATUS_IO, the message names the file; *out is NULL. */
    DcrModel *model = (DcrModel *)&checks; /* a non-NULL value the call must overwrite */
    CHECK(dcr_model_load(missing, &model) == DCR_STATUS_IO);
    CHECK(model == NULL);
    CHECK(last_error_has("dcr_model_load") && last_error_has(missing));

    /* Corrupt file: DCR_STATUS_INVALID_BASE naming the file. */
    CHECK(dcr_model_load(corrupt, &model) == DCR_STATUS_INVALID_BASE);
    CHECK(model == NULL && last_error_has(corrupt));

    /* Corrupt bytes: named <memory>. */
    const unsigned char junk[] = "PK\003\004 not really a zip archive";
    CHECK(dcr_model_load_bytes(junk, sizeof junk, &model) == DCR_STATUS_INVALID_BASE);
    CHECK(model == NULL && last_error_has("<memory>"));
    CHECK(dcr_model_load_bytes(NULL, 10, &model) == DCR_STATUS_NULL_POINTER);
    CHECK(last_error_has("`data` is NULL"));

    /* NULL arguments. */
    CHECK(dcr_model_load(NULL, &model) == DCR_STATUS_NULL_POINTER);
    CHECK(last_error_has("`path` is NULL"));
    CHECK(dcr_model_load(base, NULL) == DCR_STATUS_NULL_POINTER);

    /* The real base, loaded from bytes too. */
    CHECK(dcr_model_load(base, &model) == DCR_STATUS_OK && model != NULL);
    if (model == NULL) {
        return 1;
    }
    FILE *f = fopen(base, "rb");
    CHECK(f != NULL);
    if (f != NULL) {
        fseek(f, 0, SEEK_END);
        long len = ftell(f);
        fseek(f, 0, SEEK_SET);
        unsigned char *bytes = malloc((size_t)len);
        CHECK(bytes != NULL && fread(bytes, 1, (size_t)len, f) == (size_t)len);
        fclose(f);
        DcrModel *from_bytes = NULL;
        CHECK(dcr_model_load_bytes(bytes, (size_t)len, &from_bytes) == DCR_STATUS_OK);
        free(bytes); /* the model copied what it needs */
        /* A truncated base is refused. */
        DcrModel *cut = NULL;
        CHECK(dcr_model_load_bytes(junk, 3, &cut) == DCR_STATUS_INVALID_BASE && cut == NULL);
        DcrModelInfo a, b;
        CHECK(dcr_model_info(model, &a) == DCR_STATUS_OK);
        CHECK(dcr_model_info(from_bytes, &b) == DCR_STATUS_OK);
        CHECK(a.num_modes == b.num_modes && a.num_surface_vertices == b.num_surface_vertices);
        dcr_model_free(from_bytes);
    }

    /* Frequencies: size query, too-small buffer, then the real call. */
    DcrModelInfo info;
    CHECK(dcr_model_info(model, &info) == DCR_STATUS_OK);
    CHECK(dcr_model_info(model, NULL) == DCR_STATUS_NULL_POINTER);
    size_t m = 0;
    CHECK(dcr_model_frequencies(model, NULL, 0, &m) == DCR_STATUS_BUFFER_TOO_SMALL);
    CHECK(m == info.num_modes && m > 1);
    double *freq = calloc(m, sizeof *freq);
    CHECK(dcr_model_frequencies(model, freq, m - 1, &m) == DCR_STATUS_BUFFER_TOO_SMALL);
    CHECK(freq[0] == 0.0); /* nothing written */
    CHECK(dcr_model_frequencies(model, freq, m, &m) == DCR_STATUS_OK);
    for (size_t j = 1; j < m; ++j) {
        CHECK(freq[j] >= freq[j - 1] && freq[0] > 0.0);
    }
    CHECK(dcr_model_frequencies(model, freq, m, NULL) == DCR_STATUS_NULL_POINTER);
    free(freq);

    /* Projection: a far point is NOT_FOUND; a negative distance is invalid. */
    double far[3] = {1e3, 1e3, 1e3};
    DcrSurfacePoint sp;
    CHECK(dcr_model_project(model, far, NAN, &sp) == DCR_STATUS_NOT_FOUND);
    CHECK(dcr_model_project(model, far, -1.0, &sp) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(dcr_model_project(model, NULL, NAN, &sp) == DCR_STATUS_NULL_POINTER);

    /* Response parameters: wrong struct_size, unknown codes, out-of-range values. */
    DcrResponseParams p;
    CHECK(dcr_response_params_default(&p) == DCR_STATUS_OK);
    CHECK(p.struct_size == sizeof p && p.h == 0.01 && p.method == DCR_METHOD_TRANSFER);
    CHECK(isnan(p.max_map_distance) && p.impact_threshold == 1e-3);
    DcrResponse *resp = (DcrResponse *)&checks;
    DcrResponseParams bad = p;
    bad.struct_size = 0;
    CHECK(dcr_response_create(model, &bad, &resp) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(resp == NULL && last_error_has("struct_size"));
    bad = p;
    bad.method = 99;
    CHECK(dcr_response_create(model, &bad, &resp) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(last_error_has("method") && last_error_has("99"));
    bad = p;
    bad.h = -1.0;
    CHECK(dcr_response_create(model, &bad, &resp) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(last_error_has("invalid h") && last_error_has("-1"));
    bad = p;
    bad.table_policy = DCR_TABLE_POLICY_REFUSE; /* this base has no table */
    CHECK(dcr_response_create(model, &bad, &resp) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(last_error_has("transfer table"));
    bad = p;
    bad.method = DCR_METHOD_ATTENUATION;
    bad.attenuation.amplitude = DCR_AMPLITUDE_MEAN_OVER; /* with no vertices */
    CHECK(dcr_response_create(model, &bad, &resp) == DCR_STATUS_INVALID_ARGUMENT);
    bad = p;
    memset(&bad.carry_over, 5, 1); /* uninitialised memory: not a bool */
    CHECK(dcr_response_create(model, &bad, &resp) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(last_error_has("params.carry_over") && last_error_has("holds 5"));
    CHECK(dcr_response_create(NULL, &p, &resp) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_response_create(model, NULL, &resp) == DCR_STATUS_NULL_POINTER);

    /* A working response; the step's buffer errors. */
    CHECK(dcr_response_create(model, &p, &resp) == DCR_STATUS_OK && resp != NULL);
    DcrImpact hit = {{0.5, 0.5, 1.0}, {0.0, 0.0, -1.0}, 2.0};
    DcrRestingContact rest[3] = {{1, {0.2, 0.3, 1.0}}, {2, {0.8, 0.8, 1.0}}, {3, {0.0, 0.5, 0.5}}};
    DcrContactResponse out[3];
    memset(out, 0, sizeof out);
    size_t count = 0;
    CHECK(dcr_response_step(resp, &hit, 1, rest, 3, out, 2, &count) == DCR_STATUS_BUFFER_TOO_SMALL);
    CHECK(count == 3 && out[0].id == 0 && last_error_has("did not run"));
    DcrStepInfo si;
    CHECK(dcr_response_step_info(resp, &si) == DCR_STATUS_OK);
    CHECK(si.impacts_applied == 0 && si.contacts_mapped_now == 0); /* no state changed */
    DcrResponseInfo ri;
    CHECK(dcr_response_info(resp, &ri) == DCR_STATUS_OK && ri.cached_contacts == 0);
    CHECK(dcr_response_step(resp, &hit, 1, rest, 3, NULL, 3, &count) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_response_step(resp, NULL, 1, rest, 3, out, 3, &count) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_response_step(resp, &hit, 1, rest, 3, out, 3, NULL) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_response_step(NULL, &hit, 1, rest, 3, out, 3, &count) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_response_step(resp, (const DcrImpact *)((const char *)&hit + 1), 1, rest, 3, out, 3,
                            &count) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(last_error_has("aligned"));
    CHECK(dcr_response_step(resp, &hit, 1, rest, 3, out, 3, &count) == DCR_STATUS_OK);
    CHECK(count == 3 && out[0].id == 1 && out[2].id == 3);
    CHECK(out[0].mapped && out[0].delta_v > 0.0 && out[0].served_by == DCR_SERVED_BY_MODAL);
    CHECK(fabs(out[0].delta_v * p.h - out[0].peak_displacement) <= 1e-15 * out[0].delta_v);
    CHECK(dcr_response_step_info(resp, &si) == DCR_STATUS_OK && si.impacts_applied == 1);
    /* Empty step with NULL arrays is fine. */
    CHECK(dcr_response_step(resp, NULL, 0, NULL, 0, NULL, 0, &count) == DCR_STATUS_OK && count == 0);
    bool needs = true;
    CHECK(dcr_response_needs_step(resp, &needs) == DCR_STATUS_OK && !needs);
    CHECK(dcr_response_skip_steps(resp, 5) == DCR_STATUS_OK);
    CHECK(dcr_response_skip_steps(NULL, 5) == DCR_STATUS_NULL_POINTER);

    /* Eq. 17-18 helpers. */
    const double inv_inertia[9] = {0};
    const double r[3] = {0.0, 0.0, 0.0}, n[3] = {0.0, 0.0, 1.0};
    double m_eff = 0.0, j[3] = {0.0, 0.0, 0.0};
    CHECK(dcr_effective_mass(0.5, inv_inertia, r, n, &m_eff) == DCR_STATUS_OK && m_eff == 2.0);
    CHECK(dcr_effective_mass(-1.0, inv_inertia, r, n, &m_eff) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(dcr_effective_mass(0.5, NULL, r, n, &m_eff) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_response_impulse(2.0, 0.25, n, j) == DCR_STATUS_OK && j[2] == 0.5 && j[0] == 0.0);
    CHECK(dcr_response_impulse(2.0, 0.25, n, NULL) == DCR_STATUS_NULL_POINTER);

    /* World: bad parameters, handles, bodies. */
    DcrWorldParams wp;
    CHECK(dcr_world_params_default(&wp) == DCR_STATUS_OK);
    CHECK(wp.h == 0.01 && wp.energy_bound && wp.energy_eta == 1.0 && wp.max_chain_depth == 4);
    DcrWorld *world = (DcrWorld *)&checks;
    /* The gravity is unset by default: the caller must give the engine's (or zero). */
    CHECK(isnan(wp.gravity[0]) && isnan(wp.gravity[1]) && isnan(wp.gravity[2]));
    CHECK(dcr_world_create(&wp, &world) == DCR_STATUS_INVALID_ARGUMENT && world == NULL);
    CHECK(last_error_has("gravity") && last_error_has("is not set"));
    wp.gravity[0] = wp.gravity[1] = wp.gravity[2] = 0.0;
    DcrWorldParams wbad = wp;
    wbad.energy_eta = 2.0;
    CHECK(dcr_world_create(&wbad, &world) == DCR_STATUS_INVALID_ARGUMENT && world == NULL);
    CHECK(last_error_has("energy_eta"));
    wbad = wp;
    wbad.struct_size = (uint32_t)sizeof wp + 8u;
    CHECK(dcr_world_create(&wbad, &world) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(dcr_world_create(&wp, &world) == DCR_STATUS_OK && world != NULL);
    DcrElasticObjectDesc desc;
    CHECK(dcr_elastic_object_desc_default(&desc) == DCR_STATUS_OK);
    DcrElasticHandle h = 77;
    CHECK(dcr_world_add_object(world, &desc, &h) == DCR_STATUS_NULL_POINTER); /* no model */
    CHECK(last_error_has("desc.model"));
    desc.model = model;
    desc.body = 1;
    desc.gain = -1.0;
    CHECK(dcr_world_add_object(world, &desc, &h) == DCR_STATUS_INVALID_ARGUMENT);
    desc.gain = 1.0;
    desc.response.struct_size = 1;
    CHECK(dcr_world_add_object(world, &desc, &h) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(last_error_has("desc.response.struct_size"));
    desc.response.struct_size = (uint32_t)sizeof desc.response;
    CHECK(dcr_world_add_object(world, &desc, &h) == DCR_STATUS_OK && h == 0);
    CHECK(dcr_world_add_object(world, &desc, &h) == DCR_STATUS_INVALID_ARGUMENT); /* same body */
    CHECK(last_error_has("body 1"));
    DcrPose pose = desc.pose;
    CHECK(dcr_world_set_pose(world, 5, &pose) == DCR_STATUS_INVALID_HANDLE);
    CHECK(last_error_has("elastic object 5"));
    CHECK(dcr_world_get_pose(world, 0, &pose) == DCR_STATUS_OK && pose.rotation[3] == 1.0);
    DcrElasticHandle found = 9;
    CHECK(dcr_world_object_of_body(world, 1, &found) == DCR_STATUS_OK && found == 0);
    CHECK(dcr_world_object_of_body(world, 2, &found) == DCR_STATUS_NOT_FOUND);
    size_t nobj = 0;
    CHECK(dcr_world_num_objects(world, &nobj) == DCR_STATUS_OK && nobj == 1);
    DcrObjectStepInfo oi;
    CHECK(dcr_world_object_info(world, 1, &oi) == DCR_STATUS_INVALID_HANDLE);
    CHECK(dcr_world_object_response_info(world, 0, &ri) == DCR_STATUS_OK);
    CHECK(ri.table_status == DCR_TABLE_STATUS_NO_TABLE);
    const DcrImpulseEvent *events = (const DcrImpulseEvent *)&checks;
    size_t ne = 7;
    CHECK(dcr_world_step(world, NULL, 2, NULL, 0, &events, &ne) == DCR_STATUS_NULL_POINTER);
    CHECK(events == NULL && ne == 0);
    CHECK(dcr_world_step(world, NULL, 0, NULL, 0, NULL, &ne) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_world_step(world, NULL, 0, NULL, 0, &events, &ne) == DCR_STATUS_OK && ne == 0);
    DcrContactReport reports[2];
    memset(reports, 0, sizeof reports);
    memset((unsigned char *)&reports[1] + offsetof(DcrContactReport, is_new), 9, 1);
    CHECK(dcr_world_step(world, reports, 2, NULL, 0, &events, &ne) == DCR_STATUS_INVALID_ARGUMENT);
    CHECK(last_error_has("contacts[1].is_new") && last_error_has("holds 9"));
    CHECK(dcr_world_events(world, &events, &ne) == DCR_STATUS_OK && events == NULL && ne == 0);
    DcrWorldStepInfo wi;
    CHECK(dcr_world_step_info(world, &wi) == DCR_STATUS_OK && wi.step == 0);
    bool ring = true;
    CHECK(dcr_world_needs_step(world, &ring) == DCR_STATUS_OK && !ring);
    CHECK(dcr_world_needs_step(world, NULL) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_world_advance(world, 3) == DCR_STATUS_OK);
    CHECK(dcr_world_advance(NULL, 3) == DCR_STATUS_NULL_POINTER);
    CHECK(dcr_world_step(world, NULL, 0, NULL, 0, &events, &ne) == DCR_STATUS_OK);
    CHECK(dcr_world_step_info(world, &wi) == DCR_STATUS_OK && wi.step == 4); /* 0, 1-3, 4 */

    /* The last error through a caller buffer: size query, truncation, whole. */
    CHECK(dcr_world_set_pose(world, 3, &pose) == DCR_STATUS_INVALID_HANDLE);
    size_t need = 0;
    CHECK(dcr_last_error_message(NULL, 0, &need) == DCR_STATUS_BUFFER_TOO_SMALL);
    CHECK(need == strlen(dcr_last_error()) + 1);
    char small[8];
    CHECK(dcr_last_error_message(small, sizeof small, &need) == DCR_STATUS_BUFFER_TOO_SMALL);
    CHECK(strlen(small) == sizeof small - 1 && strncmp(small, "dcr_wor", 7) == 0);
    char *whole = malloc(need);
    CHECK(dcr_last_error_message(whole, need, NULL) == DCR_STATUS_OK);
    CHECK(strcmp(whole, dcr_last_error()) == 0 && strstr(whole, "dcr_world_set_pose") != NULL);
    free(whole);
    CHECK(dcr_last_error_message(NULL, 4, NULL) == DCR_STATUS_NULL_POINTER);

    /* Freeing in any order; NULL is a no-op. */
    dcr_model_free(model); /* the response and world keep their own reference */
    CHECK(dcr_response_step(resp, &hit, 1, rest, 3, out, 3, &count) == DCR_STATUS_OK);
    dcr_response_free(resp);
    dcr_world_free(world);
    dcr_model_free(NULL);
    dcr_response_free(NULL);
    dcr_world_free(NULL);

    if (failed) {
        return 1;
    }
    printf("ok %d checks\n", checks);
    return 0;
}
