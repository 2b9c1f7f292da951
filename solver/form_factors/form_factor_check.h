// SPDX-License-Identifier: MIT
// The checks every form-factor matrix must pass: rows sum to 1 in a closed scene, and
// A_i F_ij = A_j F_ji (reciprocity). `bounce form-factors --check` prints them; the Python
// module returns them.
#pragma once

#include <vector>

#include "mesh/patch.h"
#include "solver/form_factors/form_factor_matrix.h"

namespace bounce {

struct FormFactorCheck {
    std::vector<double> row_sums;  // sum_j F_ij, per patch, in double
    double row_sum_min = 0, row_sum_mean = 0, row_sum_max = 0;
    double deviation_min = 0, deviation_mean = 0, deviation_max = 0;  // |sum_j F_ij - 1| (closed scenes)
    double reciprocity_max = 0;      // max |A_i F_ij - A_j F_ji| / (A_i F_ij) over F_ij >= 1e-3
    double reciprocity_overall = 0;  // sum |A_i F_ij - A_j F_ji| / sum A_i F_ij
};

/// Row sums and reciprocity of F over these patches (F.size() == patches.size()).
FormFactorCheck check_form_factors(const std::vector<Patch>& patches, const FormFactorMatrix& F);

}  // namespace bounce
