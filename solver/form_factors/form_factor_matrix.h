// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh/scene/errors.h"  // Interrupted, ResourceLimitError
#include "solver/form_factors/form_factor_estimator.h"

namespace bounce {

/// The full form-factor matrix, dense, float storage (row-major, F(i, j) = F_ij). For the
/// gathering solvers (Jacobi, Gauss-Seidel), which need every row every sweep.
class FormFactorMatrix {
public:
    /// Bytes a matrix of n patches needs (n^2 floats).
    static std::size_t bytes_for(std::size_t n) { return n * n * sizeof(float); }

    /// Builds every row, in parallel over rows on all cores. Checks the memory first: throws
    /// ResourceLimitError naming the size, before allocating, when it exceeds max_bytes.
    /// `progress(rows_done, n)` is called from worker threads (it must be thread-safe).
    /// When `cancel` becomes true the build stops and throws Interrupted.
    static FormFactorMatrix build(const FormFactorEstimator& estimator, std::size_t n, std::size_t max_bytes,
                                  const std::function<void(std::size_t, std::size_t)>& progress = {},
                                  const std::atomic<bool>* cancel = nullptr);

    /// A matrix from given values (row-major n x n), e.g. an exactly stochastic test system.
    static FormFactorMatrix from_values(std::size_t n, std::vector<float> values);

    std::size_t size() const { return m_n; }
    /// sum_j F_ij, accumulated in double.
    std::vector<double> row_sums() const;
    float operator()(std::size_t i, std::size_t j) const { return m_f[i * m_n + j]; }
    const float* row(std::size_t i) const { return m_f.data() + i * m_n; }
    /// Row i to rewrite in place (balance_form_factors).
    float* mutable_row(std::size_t i) { return m_f.data() + i * m_n; }
    double seconds() const { return m_seconds; }  // time to build

private:
    std::size_t m_n = 0;
    std::vector<float> m_f;
    double m_seconds = 0.0;
};

/// Rows read from a built matrix, so shooting and the gathering solvers work on the very
/// same F when they are compared.
class MatrixFormFactor final : public FormFactorEstimator {
public:
    MatrixFormFactor(const FormFactorMatrix& matrix, std::string method);
    std::string name() const override { return m_method; }
    void compute_row(std::size_t i, std::span<float> row) const override;

private:
    const FormFactorMatrix& m_matrix;
    std::string m_method;
};

}  // namespace bounce
