// SPDX-License-Identifier: MIT
// Arguments refused before any work, in the command line's words (the keyword for the flag).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "solver/form_factors/form_factor_estimator.h"

namespace bounce::python {

void check_range(const char* name, double x, double lo, double hi);
void check_positive(const char* name, double x);
void check_member(const char* name, const std::string& value, const std::vector<std::string>& valid);
/// The form-factor keywords of form_factors() as options, checked.
FormFactorOptions form_factor_options(const std::string& method, std::optional<int> rays, int receiver_samples,
                                      int hemicube_res, bool hemicube_jitter, std::uint64_t seed);

}  // namespace bounce::python
