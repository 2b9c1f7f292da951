// SPDX-License-Identifier: MIT
#include "solver/form_factors/form_factor_matrix.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <span>
#include <vector>

#include <tbb/parallel_for.h>

namespace bounce {

FormFactorMatrix FormFactorMatrix::build(const FormFactorEstimator& estimator, std::size_t n, std::size_t max_bytes,
                                         const std::function<void(std::size_t, std::size_t)>& progress,
                                         const std::atomic<bool>* cancel) {
    const std::size_t need = bytes_for(n);
    if (n != 0 && (need / n / sizeof(float) != n || need > max_bytes))
        throw ResourceLimitError("form-factor matrix of " + std::to_string(n) + " patches needs " +
                                 std::to_string((need + (1u << 20) - 1) >> 20) + " MB, over the limit of " +
                                 std::to_string(max_bytes >> 20) + " MB (--max-matrix-mb)");
    const auto start = std::chrono::steady_clock::now();
    FormFactorMatrix m;
    m.m_n = n;
    m.m_f.resize(n * n);
    std::atomic<std::size_t> done{0};
    // A reciprocal estimator computes the upper triangle only; the lower one follows from
    // A_i F_ij = A_j F_ji. known[j] marks the columns row i leaves alone (j <= i).
    const bool upper_only = estimator.reciprocal();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            if (cancel && cancel->load()) return;
            const std::span<float> row(m.m_f.data() + i * n, n);
            if (upper_only) {
                // Per row, not thread_local: compute_row runs nested parallel loops, and a worker
                // waiting in one may start another row on this thread.
                std::vector<std::uint8_t> known(n, 0);
                std::fill(known.begin(), known.begin() + std::ptrdiff_t(i + 1), 1);
                estimator.compute_row(i, row, known);
            } else {
                estimator.compute_row(i, row);
            }
        }
        const std::size_t d = done += range.size();
        if (progress) progress(d, n);
    });
    if (cancel && cancel->load()) throw Interrupted("interrupted while computing form factors");
    if (upper_only) {
        std::vector<double> area(n);  // once, not a virtual call per entry
        for (std::size_t i = 0; i < n; ++i) area[i] = estimator.patch_area(i);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const auto& range) {
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
                const double ai = area[i];
                for (std::size_t j = 0; j < i; ++j) m.m_f[i * n + j] = float(double(m.m_f[j * n + i]) * area[j] / ai);
                m.m_f[i * n + i] = 0.0f;
            }
        });
    }
    m.m_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return m;
}

FormFactorMatrix FormFactorMatrix::from_values(std::size_t n, std::vector<float> values) {
    if (values.size() != n * n) throw std::invalid_argument("form-factor matrix: need n*n values");
    FormFactorMatrix m;
    m.m_n = n;
    m.m_f = std::move(values);
    return m;
}

std::vector<double> FormFactorMatrix::row_sums() const {
    std::vector<double> s(m_n, 0.0);
    for (std::size_t i = 0; i < m_n; ++i)
        for (std::size_t j = 0; j < m_n; ++j) s[i] += m_f[i * m_n + j];
    return s;
}

MatrixFormFactor::MatrixFormFactor(const FormFactorMatrix& matrix, std::string method)
    : m_matrix(matrix), m_method(std::move(method)) {}

void MatrixFormFactor::compute_row(std::size_t i, std::span<float> row) const {
    const float* r = m_matrix.row(i);
    std::copy(r, r + m_matrix.size(), row.begin());
}

}  // namespace bounce
