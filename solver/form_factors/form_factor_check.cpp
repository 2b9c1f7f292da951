// SPDX-License-Identifier: MIT
#include "solver/form_factors/form_factor_check.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace bounce {

FormFactorCheck check_form_factors(const std::vector<Patch>& P, const FormFactorMatrix& F) {
    const std::size_t n = F.size();
    FormFactorCheck c;
    c.row_sums.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) c.row_sums[i] += F(i, j);
    double lo = 1e300, hi = -1e300, mean = 0, recip = 0, diff = 0, total = 0;
    for (std::size_t i = 0; i < n; ++i) {
        lo = std::min(lo, c.row_sums[i]);
        hi = std::max(hi, c.row_sums[i]);
        mean += c.row_sums[i] / double(n);
        for (std::size_t j = 0; j < n; ++j) {
            const double aij = P[i].area * F(i, j), aji = P[j].area * F(j, i);
            diff += std::abs(aij - aji);
            total += aij;
            if (F(i, j) >= 1e-3) recip = std::max(recip, std::abs(aij - aji) / aij);
        }
    }
    // In a closed scene every row sums to 1; |sum - 1| is the error a furnace amplifies by
    // 1 / (1 - rho). (Entries are stored as float: about 1e-7 of each row is rounding.)
    double dlo = 1e300, dhi = 0, dmean = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double d = std::abs(c.row_sums[i] - 1.0);
        dlo = std::min(dlo, d);
        dhi = std::max(dhi, d);
        dmean += d / double(std::max<std::size_t>(n, 1));
    }
    c.row_sum_min = lo;
    c.row_sum_mean = mean;
    c.row_sum_max = hi;
    c.deviation_min = dlo;
    c.deviation_mean = dmean;
    c.deviation_max = dhi;
    c.reciprocity_max = recip;
    c.reciprocity_overall = total > 0 ? diff / total : 0.0;
    return c;
}

}  // namespace bounce
