// SPDX-License-Identifier: MIT
// The checks every form-factor matrix must pass: rows sum to 1 in a closed scene, and
// A_i F_ij = A_j F_ji (reciprocity). `bounce form-factors --check` and `bounce info
// --row-sums` print them; the Python module returns them.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "mesh/meshing/patch.h"
#include "solver/form_factors/form_factor_matrix.h"

namespace bounce {

class FormFactorEstimator;
class ShaftCuller;

struct FormFactorCheck {
    std::vector<double> row_sums;  // sum_j F_ij, per patch, in double
    double row_sum_min = 0, row_sum_mean = 0, row_sum_max = 0;
    double deviation_min = 0, deviation_mean = 0, deviation_max = 0;  // |sum_j F_ij - 1| (closed scenes)
    double reciprocity_max = 0;       // max |A_i F_ij - A_j F_ji| / (A_i F_ij) over F_ij >= 1e-3
    double reciprocity_overall = 0;   // sum |A_i F_ij - A_j F_ji| / sum A_i F_ij
    bool reciprocity_checked = true;  // false when rows were streamed (check_row_sums)

    // Where the deviation comes from (with a ShaftCuller): a pair is partially visible when a
    // candidate blocker lies in its shaft. Unoccluded pairs are computed to a relative 1e-6,
    // so rows without partially visible pairs show the unoccluded factor's error; the excess in
    // the other rows is visibility error.
    bool split_by_visibility = false;
    std::size_t partial_pairs = 0;      // unordered pairs with F > 0 and a candidate blocker
    std::size_t rows_with_partial = 0;  // rows holding at least one of them
    double partial_share = 0;           // mean over rows of sum_j F_ij over partially visible j
    double deviation_mean_partial = 0, deviation_max_partial = 0;  // rows with partially visible pairs
    double deviation_mean_clear = 0, deviation_max_clear = 0;      // rows without
};

/// Row sums and reciprocity of F over these patches (F.size() == patches.size()); with a
/// culler over the same patches, the deviation split by partial visibility.
FormFactorCheck check_form_factors(const std::vector<Patch>& patches, const FormFactorMatrix& F,
                                   const ShaftCuller* culler = nullptr);

/// Row sums only, one row at a time (memory O(N), twice the work of a reciprocal matrix):
/// for scenes whose matrix would not fit. `progress(done, total)` is called per row; a set
/// `cancel` stops early (the result then covers the rows done).
FormFactorCheck check_row_sums(const std::vector<Patch>& patches, const FormFactorEstimator& ff,
                               const ShaftCuller* culler,
                               const std::function<void(std::size_t, std::size_t)>& progress = {},
                               const std::atomic<bool>* cancel = nullptr);

/// The report's lines, as `form-factors --check` and `info --row-sums` print them.
std::string row_sum_report(const FormFactorCheck& check);

}  // namespace bounce
