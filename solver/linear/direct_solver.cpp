// SPDX-License-Identifier: MIT
#include "solver/linear/direct_solver.h"

#include <chrono>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "solver/linear/convergence.h"

namespace bounce {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Solves A x = b in place, A n x n row-major (overwritten by its LU factors), b in x: LU with
/// partial pivoting (Doolittle, right-looking), the row updates of each step in parallel,
/// then back substitution. Returns false, leaving x unsolved, when `cancel` is set.
bool lu_solve(std::vector<double>& A, std::vector<double>& x, std::size_t n, const std::atomic<bool>* cancel) {
    for (std::size_t k = 0; k < n; ++k) {
        // A step costs O((n - k)^2): polling here answers a signal within milliseconds even
        // when the whole factorisation takes a minute.
        if (cancel && cancel->load()) return false;
        std::size_t piv = k;
        double best = std::abs(A[k * n + k]);
        for (std::size_t i = k + 1; i < n; ++i)
            if (std::abs(A[i * n + k]) > best) {
                best = std::abs(A[i * n + k]);
                piv = i;
            }
        if (!(best > 1e-12))
            throw SingularSystemError("the radiosity system is singular (pivot " + std::to_string(best) + " at patch " +
                                      std::to_string(k) + "): reflectance 1 in a closed scene has no steady state");
        if (piv != k) {
            std::swap_ranges(A.begin() + k * n, A.begin() + (k + 1) * n, A.begin() + piv * n);
            std::swap(x[k], x[piv]);
        }
        const double* pk = A.data() + k * n;
        const double inv = 1.0 / pk[k];
        tbb::parallel_for(tbb::blocked_range<std::size_t>(k + 1, n, 64), [&](const auto& range) {
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
                double* pi = A.data() + i * n;
                const double l = pi[k] * inv;
                if (l == 0.0) continue;
                pi[k] = 0.0;
                for (std::size_t j = k + 1; j < n; ++j) pi[j] -= l * pk[j];
                x[i] -= l * x[k];
            }
        });
    }
    for (std::size_t k = n; k-- > 0;) {
        double s = x[k];
        const double* pk = A.data() + k * n;
        for (std::size_t j = k + 1; j < n; ++j) s -= pk[j] * x[j];
        x[k] = s / pk[k];
    }
    return true;
}

}  // namespace

DirectSolver::DirectSolver(const RadiositySystem& system, const SolverOptions& options)
    : m_patches(system.patches), m_F(*system.matrix), m_options(options) {}

SolveResult DirectSolver::solve() {
    const auto t0 = std::chrono::steady_clock::now();
    const auto& P = m_patches;
    const std::size_t n = P.size();
    const std::size_t bytes = n * n * sizeof(double);
    if (bytes > (m_options.max_matrix_mb << 20))
        throw ResourceLimitError("direct solver: " + std::to_string(n) + " patches need " +
                                 std::to_string(bytes >> 20) + " MB, over the limit of " +
                                 std::to_string(m_options.max_matrix_mb) + " MB");
    SolveResult res;
    res.solver = name();
    res.radiosity.assign(n, Rgb());
    std::vector<double> A(n * n);
    std::vector<double> x(n);
    bool interrupted = false;
    for (int c = 0; c < 3; ++c) {
        // A = I - diag(rho_c) F, row-major; b = E_c.
        tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
            const float* row = m_F.row(i);
            const double rho = P[i].reflectance[c];
            double* a = A.data() + i * n;
            for (std::size_t j = 0; j < n; ++j) a[j] = -rho * row[j];
            a[i] += 1.0;
        });
        for (std::size_t i = 0; i < n; ++i) x[i] = P[i].emission[c];
        if (!lu_solve(A, x, n, m_options.cancel)) {
            interrupted = true;
            break;
        }
        double top = 0.0;
        for (std::size_t i = 0; i < n; ++i) top = std::max(top, std::abs(x[i]));
        for (std::size_t i = 0; i < n; ++i) {
            // Radiosity cannot be negative: a negative solution means rho F has spectral radius
            // above 1 (reflectance 1 in a closed scene with rows summing a little above 1).
            if (!(x[i] >= -1e-9 * top))
                throw SingularSystemError(
                    "the radiosity system has no physical solution (negative radiosity at patch " + std::to_string(i) +
                    "): reflectance at or near 1 in a closed scene");
            res.radiosity[i][c] = x[i];
        }
    }
    if (interrupted) {
        // No partial LU is a solution; what there is so far is the zeroth iterate, B = E,
        // written as such: status "interrupted", not converged.
        for (std::size_t i = 0; i < n; ++i) res.radiosity[i] = P[i].emission;
        res.steps = 0;
        res.residual = relative_residual(P, m_F, res.radiosity);
        res.converged = false;
        res.status = SolveStatus::interrupted;
        res.seconds = seconds_since(t0);
        ConvergenceRecord r;
        r.seconds = res.seconds;
        r.residual = res.residual;
        res.log.push_back(r);
        matrix_energy_account(P, m_F, res, m_options.open_parts);
        return res;
    }
    res.steps = 1;
    res.residual = relative_residual(P, m_F, res.radiosity);
    res.converged = std::isfinite(res.residual);
    res.status = res.converged ? SolveStatus::converged : SolveStatus::diverged;
    res.seconds = seconds_since(t0);
    ConvergenceRecord r;
    r.step = 1;
    r.seconds = res.seconds;
    r.residual = res.residual;
    if (m_options.reference) reference_errors(res.radiosity, *m_options.reference, r.rms_error, r.max_error);
    res.log.push_back(r);
    matrix_energy_account(P, m_F, res, m_options.open_parts);
    return res;
}

}  // namespace bounce
