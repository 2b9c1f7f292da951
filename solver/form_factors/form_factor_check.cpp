// SPDX-License-Identifier: MIT
#include "solver/form_factors/form_factor_check.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <sstream>

#include <tbb/parallel_for.h>

#include "solver/form_factors/form_factor_estimator.h"
#include "solver/visibility/shaft_culler.h"

namespace bounce {
namespace {

/// Summaries of the row sums; `partial[i]` (when given) is row i's sum over partially
/// visible pairs and `has_partial[i]` whether it has any.
void summarize(FormFactorCheck& c, const std::vector<double>* partial, const std::vector<std::uint8_t>* has_partial) {
    const std::size_t n = c.row_sums.size();
    double lo = 1e300, hi = -1e300, mean = 0;
    // In a closed scene every row sums to 1; |sum - 1| is the error a furnace amplifies by
    // 1 / (1 - rho). (Entries are stored as float: about 1e-7 of each row is rounding.)
    double dlo = 1e300, dhi = 0, dmean = 0;
    std::size_t with = 0;
    double share = 0, dp_sum = 0, dp_max = 0, dc_sum = 0, dc_max = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double s = c.row_sums[i], d = std::abs(s - 1.0);
        lo = std::min(lo, s);
        hi = std::max(hi, s);
        mean += s / double(n);
        dlo = std::min(dlo, d);
        dhi = std::max(dhi, d);
        dmean += d / double(n);
        if (!partial) continue;
        share += (*partial)[i] / double(n);
        if ((*has_partial)[i]) {
            ++with;
            dp_sum += d;
            dp_max = std::max(dp_max, d);
        } else {
            dc_sum += d;
            dc_max = std::max(dc_max, d);
        }
    }
    c.row_sum_min = n ? lo : 0;
    c.row_sum_mean = mean;
    c.row_sum_max = n ? hi : 0;
    c.deviation_min = n ? dlo : 0;
    c.deviation_mean = dmean;
    c.deviation_max = dhi;
    if (!partial) return;
    c.split_by_visibility = true;
    c.rows_with_partial = with;
    c.partial_share = share;
    c.deviation_mean_partial = with ? dp_sum / double(with) : 0;
    c.deviation_max_partial = dp_max;
    c.deviation_mean_clear = n > with ? dc_sum / double(n - with) : 0;
    c.deviation_max_clear = dc_max;
}

bool partially_visible(const ShaftCuller& culler, std::size_t i, std::size_t j) {
    thread_local std::vector<std::uint32_t> blockers;
    culler.candidates(std::min(i, j), std::max(i, j), blockers);
    return !blockers.empty();
}

}  // namespace

FormFactorCheck check_form_factors(const std::vector<Patch>& P, const FormFactorMatrix& F, const ShaftCuller* culler) {
    const std::size_t n = F.size();
    FormFactorCheck c;
    c.row_sums.assign(n, 0.0);
    std::vector<double> partial(n, 0.0);
    std::vector<std::uint8_t> has_partial(n, 0);
    std::vector<double> diff(n, 0.0), total(n, 0.0), recip(n, 0.0);
    std::vector<std::size_t> pairs(n, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
            for (std::size_t j = 0; j < n; ++j) {
                const double f = F(i, j);
                c.row_sums[i] += f;
                const double aij = P[i].area * f, aji = P[j].area * F(j, i);
                diff[i] += std::abs(aij - aji);
                total[i] += aij;
                if (f >= 1e-3) recip[i] = std::max(recip[i], std::abs(aij - aji) / aij);
                if (culler && (f > 0 || F(j, i) > 0) && partially_visible(*culler, i, j)) {
                    partial[i] += f;
                    has_partial[i] |= f > 0;
                    pairs[i] += j > i;  // each pair once
                }
            }
    });
    double d = 0, t = 0;
    for (std::size_t i = 0; i < n; ++i) {
        d += diff[i];
        t += total[i];
        c.reciprocity_max = std::max(c.reciprocity_max, recip[i]);
        c.partial_pairs += pairs[i];
    }
    c.reciprocity_overall = t > 0 ? d / t : 0.0;
    summarize(c, culler ? &partial : nullptr, culler ? &has_partial : nullptr);
    return c;
}

FormFactorCheck check_row_sums(const std::vector<Patch>& P, const FormFactorEstimator& ff, const ShaftCuller* culler,
                               const std::function<void(std::size_t, std::size_t)>& progress,
                               const std::atomic<bool>* cancel) {
    const std::size_t n = P.size();
    FormFactorCheck c;
    c.reciprocity_checked = false;
    c.row_sums.assign(n, 0.0);
    std::vector<double> partial(n, 0.0);
    std::vector<std::uint8_t> has_partial(n, 0);
    std::vector<float> row(n);
    std::vector<std::uint8_t> flag(n, 0);
    std::size_t done = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (cancel && cancel->load()) break;
        ff.compute_row(i, row);
        if (culler)
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64), [&](const auto& r) {
                for (std::size_t j = r.begin(); j != r.end(); ++j)
                    flag[j] = row[j] > 0 && partially_visible(*culler, i, j);
            });
        double s = 0;
        for (std::size_t j = 0; j < n; ++j) {
            s += row[j];
            // Pairs counted once, from their lower index.
            if (culler && flag[j]) {
                partial[i] += row[j];
                has_partial[i] = 1;
                if (j > i) ++c.partial_pairs;
            }
        }
        c.row_sums[i] = s;
        ++done;
        if (progress) progress(done, n);
    }
    c.row_sums.resize(done);
    partial.resize(done);
    has_partial.resize(done);
    summarize(c, culler ? &partial : nullptr, culler ? &has_partial : nullptr);
    return c;
}

std::string row_sum_report(const FormFactorCheck& c) {
    std::ostringstream s;
    s << "row sums: min " << c.row_sum_min << ", mean " << c.row_sum_mean << ", max " << c.row_sum_max << "\n"
      << "row-sum deviation |sum_j F_ij - 1| (closed scenes): min " << c.deviation_min << ", mean " << c.deviation_mean
      << ", max " << c.deviation_max << "\n";
    if (c.split_by_visibility)
        s << "partially visible pairs (a candidate blocker in the shaft): " << c.partial_pairs << ", in "
          << c.rows_with_partial << " of " << c.row_sums.size() << " rows, carrying " << c.partial_share
          << " of the mean row; deviation in those rows: mean " << c.deviation_mean_partial << ", max "
          << c.deviation_max_partial << "; in the others: mean " << c.deviation_mean_clear << ", max "
          << c.deviation_max_clear << "\n";
    if (c.reciprocity_checked)
        s << "reciprocity |A_i F_ij - A_j F_ji| / (A_i F_ij): max " << c.reciprocity_max
          << " (over F_ij >= 1e-3); overall sum|A_i F_ij - A_j F_ji| / sum A_i F_ij = " << c.reciprocity_overall
          << "\n";
    return s.str();
}

}  // namespace bounce
