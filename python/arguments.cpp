// SPDX-License-Identifier: MIT
#include "python/arguments.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "mesh/scene/input_error.h"

namespace bounce::python {

void check_range(const char* name, double x, double lo, double hi) {
    if (!(x >= lo && x <= hi)) {
        std::ostringstream v;
        v << x;
        throw InputError(std::string(name) + ": " + out_of_range_text(v.str(), lo, hi));
    }
}

void check_positive(const char* name, double x) {
    if (!(x > 0) || !std::isfinite(x)) {
        std::ostringstream v;
        v << x;
        throw InputError(std::string(name) + ": " + not_positive_text(v.str()));
    }
}

void check_member(const char* name, const std::string& value, const std::vector<std::string>& valid) {
    if (std::find(valid.begin(), valid.end(), value) != valid.end()) return;
    std::string list;
    for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
    throw InputError(std::string(name) + ": unknown, got '" + value + "' (expected one of " + list + ")");
}

FormFactorOptions form_factor_options(const std::string& method, std::optional<int> rays, int receiver_samples,
                                      int hemicube_res, bool hemicube_jitter, std::uint64_t seed) {
    check_member("method", method, form_factor_methods());
    if (rays) check_range("rays", *rays, 1, 4096);
    check_range("receiver_samples", receiver_samples, 0, 16);
    check_range("hemicube_res", hemicube_res, 2, 4096);
    FormFactorOptions f;
    f.visibility_rays = rays.value_or(0);  // None: the method's default (kPatchPairRays, kRefinementRays)
    f.receiver_samples = receiver_samples;
    f.hemicube_resolution = hemicube_res;
    f.hemicube_jitter = hemicube_jitter;
    f.seed = seed;
    return f;
}

}  // namespace bounce::python
