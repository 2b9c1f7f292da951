// SPDX-License-Identifier: MIT
#include "solver/linear/gathering_solver.h"

#include <chrono>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "solver/linear/convergence.h"

namespace bounce {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Fills the energy account of a gathering solution from B: H = F^T-weighted arrivals.
void account(const std::vector<Patch>& P, const FormFactorMatrix& F, SolveResult& res) {
    const std::size_t n = P.size();
    res.irradiance.assign(n, Rgb());
    res.unshot.assign(n, Rgb());
    res.emitted_power = res.absorbed_power = res.escaped_power = res.unshot_power = Rgb();
    std::vector<double> sums = F.row_sums();
    for (std::size_t i = 0; i < n; ++i) {
        res.emitted_power += P[i].emission * P[i].area;
        // Power leaving i: B_i A_i; the part not landing on any patch escapes.
        res.escaped_power += res.radiosity[i] * (P[i].area * (1.0 - sums[i]));
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const auto& range) {
        for (std::size_t j = range.begin(); j != range.end(); ++j) {
            // H_j A_j = sum_i B_i A_i F_ij (power arriving at j).
            Rgb h;
            for (std::size_t i = 0; i < n; ++i) h += res.radiosity[i] * (P[i].area * double(F(i, j)));
            res.irradiance[j] = h * (1.0 / P[j].area);
        }
    });
    for (std::size_t j = 0; j < n; ++j) {
        const Rgb arriving = res.irradiance[j] * P[j].area;
        res.absorbed_power += arriving - P[j].reflectance * arriving;
    }
    // Not yet in balance: B differs from E + rho H by the residual; that difference is
    // the "unshot" power a gathering solver still owes.
    for (std::size_t j = 0; j < n; ++j) {
        const Rgb owed = P[j].emission + P[j].reflectance * res.irradiance[j] - res.radiosity[j];
        res.unshot_power += owed * P[j].area;
    }
    res.unshot_fraction = res.emitted_power.sum() > 0 ? res.unshot_power.sum() / res.emitted_power.sum() : 0.0;
}

}  // namespace

GatheringSolver::GatheringSolver(bool gauss_seidel, const RadiositySystem& system, const SolverOptions& options)
    : m_gauss_seidel(gauss_seidel), m_patches(system.patches), m_F(*system.matrix), m_options(options) {
    if (!(options.sor > 0.0 && options.sor < 2.0)) throw std::invalid_argument("--sor must be in (0, 2)");
}

SolveResult GatheringSolver::solve() {
    const auto t0 = std::chrono::steady_clock::now();
    const auto& P = m_patches;
    const std::size_t n = P.size();
    SolveResult res;
    res.solver = name();
    double e_norm2 = 0.0;
    for (const auto& p : P)
        for (int c = 0; c < 3; ++c) e_norm2 += p.area * p.emission[c] * p.emission[c];
    if (!(e_norm2 > 0)) throw std::invalid_argument("the scene emits no light: no surface has emission > 0");
    const double e_norm = std::sqrt(e_norm2);
    std::vector<Rgb> B(n), next(n);
    for (std::size_t i = 0; i < n; ++i) B[i] = P[i].emission;
    const std::size_t max_sweeps = m_options.max_iterations ? m_options.max_iterations : 10000;
    const double w = m_options.sor;
    double first = -1.0;
    res.status = "max iterations";

    auto log = [&](std::size_t step, double residual, const std::vector<Rgb>& b) {
        ConvergenceRecord r;
        r.step = step;
        r.seconds = seconds_since(t0);
        r.residual = residual;
        if (m_options.reference) reference_errors(b, *m_options.reference, r.rms_error, r.max_error);
        res.log.push_back(r);
        if (m_options.progress) m_options.progress({step, max_sweeps, residual, m_options.tolerance, r.seconds});
    };

    // A snapshot carries its own energy account (O(N^2), like a sweep) and the seconds so far.
    const bool snapshots = m_options.snapshot && m_options.snapshot_every;
    auto snapshot = [&](std::size_t step, const std::vector<Rgb>& b, double residual) {
        SolveResult snap;
        snap.solver = res.solver;
        snap.status = "running";
        snap.steps = step;
        snap.residual = residual;
        snap.radiosity = b;
        account(P, m_F, snap);
        snap.seconds = seconds_since(t0);
        m_options.snapshot(snap);
    };
    if (snapshots) snapshot(0, B, -1.0);
    std::vector<Rgb> old(n);
    for (std::size_t sweep = 1; sweep <= max_sweeps; ++sweep) {
        // One pass over F gives the update and the residual of the iterate before it.
        old = B;
        double r2 = 0.0;
        if (!m_gauss_seidel) {
            r2 = tbb::parallel_reduce(
                tbb::blocked_range<std::size_t>(0, n, 16), 0.0,
                [&](const auto& range, double acc) {
                    for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const float* row = m_F.row(i);
                        double g0 = 0, g1 = 0, g2 = 0;
                        for (std::size_t j = 0; j < n; ++j) {
                            const double f = row[j];
                            g0 += f * old[j].r;
                            g1 += f * old[j].g;
                            g2 += f * old[j].b;
                        }
                        const Rgb r = P[i].emission + P[i].reflectance * Rgb(g0, g1, g2) - old[i];
                        B[i] = old[i] + w * r;
                        acc += P[i].area * (r.r * r.r + r.g * r.g + r.b * r.b);
                    }
                    return acc;
                },
                std::plus<double>());
        } else {
            for (std::size_t i = 0; i < n; ++i) {
                const float* row = m_F.row(i);
                double an[3] = {0, 0, 0}, ao[3] = {0, 0, 0}, rest[3] = {0, 0, 0};
                for (std::size_t j = 0; j < i; ++j) {
                    const double f = row[j];
                    an[0] += f * B[j].r;
                    an[1] += f * B[j].g;
                    an[2] += f * B[j].b;
                    ao[0] += f * old[j].r;
                    ao[1] += f * old[j].g;
                    ao[2] += f * old[j].b;
                }
                for (std::size_t j = i; j < n; ++j) {
                    const double f = row[j];
                    rest[0] += f * B[j].r;
                    rest[1] += f * B[j].g;
                    rest[2] += f * B[j].b;
                }
                const Rgb& rho = P[i].reflectance;
                const Rgb r_old = P[i].emission + rho * Rgb(ao[0] + rest[0], ao[1] + rest[1], ao[2] + rest[2]) - old[i];
                const Rgb gathered = P[i].emission + rho * Rgb(an[0] + rest[0], an[1] + rest[1], an[2] + rest[2]);
                B[i] += w * (gathered - B[i]);
                r2 += P[i].area * (r_old.r * r_old.r + r_old.g * r_old.g + r_old.b * r_old.b);
            }
        }
        const double residual = std::sqrt(r2) / e_norm;
        log(sweep - 1, residual, old);
        if (snapshots && sweep % m_options.snapshot_every == 0) snapshot(sweep, B, -1.0);
        res.steps = sweep;
        res.residual = residual;
        if (first < 0) first = residual;
        if (!std::isfinite(residual) || residual > 1e8 * std::max(first, 1e-300)) {
            // Diverging (row sums above 1 with high reflectance): keep the last finite iterate.
            B = old;
            res.status = "diverged";
            break;
        }
        if (residual < m_options.tolerance) {
            res.status = "converged";
            res.converged = true;
            break;
        }
        if (m_options.max_seconds > 0 && seconds_since(t0) > m_options.max_seconds) {
            res.status = "max seconds";
            break;
        }
        if (m_options.cancel && m_options.cancel->load()) {
            res.status = "interrupted";
            break;
        }
    }
    res.radiosity = B;
    res.seconds = seconds_since(t0);
    account(P, m_F, res);
    return res;
}

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
    std::vector<std::size_t> perm(n);
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
        // LU with partial pivoting (Doolittle, right-looking); the row updates of each step in
        // parallel.
        for (std::size_t k = 0; k < n; ++k) {
            // A step costs O((n - k)^2): polling here answers a signal within milliseconds,
            // where polling per channel left Ctrl-C waiting for the whole factorisation
            // (58 s at 4000 patches).
            if (m_options.cancel && m_options.cancel->load()) {
                interrupted = true;
                break;
            }
            std::size_t piv = k;
            double best = std::abs(A[k * n + k]);
            for (std::size_t i = k + 1; i < n; ++i)
                if (std::abs(A[i * n + k]) > best) {
                    best = std::abs(A[i * n + k]);
                    piv = i;
                }
            if (!(best > 1e-12))
                throw SingularSystemError("the radiosity system is singular (pivot " + std::to_string(best) +
                                          " at patch " + std::to_string(k) +
                                          "): reflectance 1 in a closed scene has no steady state");
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
        if (interrupted) break;
        for (std::size_t k = n; k-- > 0;) {
            double s = x[k];
            const double* pk = A.data() + k * n;
            for (std::size_t j = k + 1; j < n; ++j) s -= pk[j] * x[j];
            x[k] = s / pk[k];
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
        res.status = "interrupted";
        res.seconds = seconds_since(t0);
        ConvergenceRecord r;
        r.seconds = res.seconds;
        r.residual = res.residual;
        res.log.push_back(r);
        account(P, m_F, res);
        return res;
    }
    res.steps = 1;
    res.residual = relative_residual(P, m_F, res.radiosity);
    res.converged = std::isfinite(res.residual);
    res.status = res.converged ? "converged" : "diverged";
    res.seconds = seconds_since(t0);
    ConvergenceRecord r;
    r.step = 1;
    r.seconds = res.seconds;
    r.residual = res.residual;
    if (m_options.reference) reference_errors(res.radiosity, *m_options.reference, r.rms_error, r.max_error);
    res.log.push_back(r);
    account(P, m_F, res);
    return res;
}

}  // namespace bounce
