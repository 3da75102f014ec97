// dcr.h from C++17: compiles with -Wall -Wextra -Werror -pedantic, links, and runs a query
// through RAII owners (tests/c_programs.rs, `header_compiles_and_runs_as_cpp17`).
//
//   cxx_smoke BASE.modes
#include <cstdio>
#include <memory>
#include <vector>

#include "dcr.h"

namespace {

struct ModelFree {
    void operator()(DcrModel *m) const { dcr_model_free(m); }
};
struct ResponseFree {
    void operator()(DcrResponse *r) const { dcr_response_free(r); }
};
using ModelPtr = std::unique_ptr<DcrModel, ModelFree>;
using ResponsePtr = std::unique_ptr<DcrResponse, ResponseFree>;

int fail(const char *what, DcrStatus st) {
    std::fprintf(stderr, "cxx_smoke: %s: %s (%s)\n", what, dcr_last_error(), dcr_status_name(st));
    return 1;
}

}  // namespace

int main(int argc, char **argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s BASE.modes\n", argv[0]);
        return 2;
    }
    DcrVersion v{};
    if (dcr_version(&v) != DCR_STATUS_OK || v.abi != DCR_ABI_VERSION) {
        std::fprintf(stderr, "cxx_smoke: header ABI %d, library ABI %u\n", DCR_ABI_VERSION, v.abi);
        return 1;
    }
    DcrModel *raw = nullptr;
    DcrStatus st = dcr_model_load(argv[1], &raw);
    if (st != DCR_STATUS_OK) return fail("load", st);
    ModelPtr model(raw);

    DcrResponseParams params{};
    dcr_response_params_default(&params);
    params.method = DCR_METHOD_MODAL;
    DcrResponse *rraw = nullptr;
    st = dcr_response_create(model.get(), &params, &rraw);
    if (st != DCR_STATUS_OK) return fail("create", st);
    ResponsePtr response(rraw);

    const DcrImpact hit{{0.5, 0.5, 1.0}, {0.0, 0.0, -1.0}, 1.0};
    const std::vector<DcrRestingContact> resting{{1, {0.2, 0.3, 1.0}}, {2, {0.9, 0.9, 1.0}}};
    std::vector<DcrContactResponse> out(1);
    size_t count = 0;
    st = dcr_response_step(response.get(), &hit, 1, resting.data(), resting.size(), out.data(),
                           out.size(), &count);
    if (st != DCR_STATUS_BUFFER_TOO_SMALL || count != resting.size()) return fail("size query", st);
    out.resize(count);
    st = dcr_response_step(response.get(), &hit, 1, resting.data(), resting.size(), out.data(),
                           out.size(), &count);
    if (st != DCR_STATUS_OK) return fail("step", st);
    for (const DcrContactResponse &c : out) {
        if (!c.mapped || !(c.delta_v > 0.0)) return fail("response", st);
        std::printf("%llu %.17g\n", static_cast<unsigned long long>(c.id), c.delta_v);
    }
    return 0;
}
