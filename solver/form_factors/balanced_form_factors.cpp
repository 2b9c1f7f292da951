// SPDX-License-Identifier: MIT
#include "solver/form_factors/balanced_form_factors.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace bounce {

namespace {

// Float storage holds a row sum to about 1e-7; the sweeps stop there.
constexpr double kRowTolerance = 1e-7;
constexpr int kMaxSweeps = 500;

/// G_ij = A_i F_ij made symmetric in place: each unordered pair takes the mean of its two
/// estimates (equal to rounding for a reciprocal estimator).
void make_reciprocal(FormFactorMatrix& f, const std::vector<double>& area) {
    const std::size_t n = f.size();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            float* row = f.mutable_row(i);
            for (std::size_t j = i + 1; j < n; ++j) {
                float& back = f.mutable_row(j)[i];
                const double g = 0.5 * (area[i] * row[j] + area[j] * back);
                row[j] = float(g / area[i]);
                back = float(g / area[j]);
            }
        }
    });
}

/// The closed parts to balance and their targets t_i = a_i A_i - sum_{j not balanced} G_ij.
/// A part whose target is not positive, or that exchanges nothing with another balanced part,
/// leaves the set, which changes the others' targets: repeated until it holds.
std::vector<double> balance_targets(const FormFactorMatrix& f, const std::vector<double>& area,
                                    const std::vector<OpenPart>& open, std::vector<std::uint8_t>& in) {
    const std::size_t n = f.size();
    std::vector<double> target(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) in[i] = open[i].closed && open[i].area_share > 0.0;
    for (bool changed = true; changed;) {
        changed = false;
        for (std::size_t i = 0; i < n; ++i) {
            if (!in[i]) continue;
            const float* row = f.row(i);
            double outside = 0.0, inside = 0.0;
            for (std::size_t j = 0; j < n; ++j) (in[j] ? inside : outside) += row[j];
            target[i] = area[i] * (open[i].area_share - outside);
            if (!(target[i] > 0.0) || !(inside > 0.0)) {
                in[i] = 0;
                changed = true;
            }
        }
    }
    return target;
}

/// (G d)_i over the balanced set, G_ij = A_i F_ij.
std::vector<double> exchange_times(const FormFactorMatrix& f, const std::vector<double>& area,
                                   const std::vector<std::uint8_t>& in, const std::vector<double>& d) {
    const std::size_t n = f.size();
    std::vector<double> s(n, 0.0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            if (!in[i]) continue;
            const float* row = f.row(i);
            double sum = 0.0;
            for (std::size_t j = 0; j < n; ++j)
                if (in[j]) sum += row[j] * d[j];
            s[i] = area[i] * sum;
        }
    });
    return s;
}

}  // namespace

FormFactorMatrix balance_form_factors(FormFactorMatrix f, const std::vector<Patch>& patches,
                                      const std::vector<OpenPart>& open, BalanceReport* report) {
    const std::size_t n = f.size();
    if (patches.size() != n || open.size() != n)
        throw std::invalid_argument("balance_form_factors: one patch and one open part per row");
    std::vector<double> area(n);
    for (std::size_t i = 0; i < n; ++i) area[i] = patches[i].area;
    make_reciprocal(f, area);
    std::vector<std::uint8_t> in(n, 0);
    const std::vector<double> target = balance_targets(f, area, open, in);
    // Symmetric Sinkhorn: d_i <- sqrt(d_i t_i / (G d)_i); the square root keeps the update
    // symmetric in i and j, and it converges for a symmetric non-negative G with total support.
    std::vector<double> d(n, 1.0);
    BalanceReport r;
    for (std::size_t i = 0; i < n; ++i) r.balanced += in[i];
    for (; r.iterations < kMaxSweeps; ++r.iterations) {
        const std::vector<double> s = exchange_times(f, area, in, d);
        double worst = 0.0;
        for (std::size_t i = 0; i < n; ++i)
            if (in[i]) worst = std::max(worst, std::abs(d[i] * s[i] / target[i] - 1.0));
        if (worst < kRowTolerance) break;
        for (std::size_t i = 0; i < n; ++i)
            if (in[i]) d[i] = std::sqrt(d[i] * target[i] / s[i]);
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            if (!in[i]) continue;
            float* row = f.mutable_row(i);
            for (std::size_t j = 0; j < n; ++j)
                if (in[j]) row[j] = float(double(row[j]) * d[i] * d[j]);
        }
    });
    const std::vector<double> sums = f.row_sums();
    for (std::size_t i = 0; i < n; ++i)
        if (in[i]) r.worst_row_error = std::max(r.worst_row_error, std::abs(sums[i] / open[i].area_share - 1.0));
    if (report) *report = r;
    return f;
}

}  // namespace bounce
