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

/// One Jacobi sweep from `old` into B (over-relaxed by w); returns the squared area-weighted
/// residual of `old`, sum_i A_i |E_i + rho_i sum_j F_ij old_j - old_i|^2.
double jacobi_sweep(const std::vector<Patch>& P, const FormFactorMatrix& F, double w, const std::vector<Rgb>& old,
                    std::vector<Rgb>& B) {
    const std::size_t n = P.size();
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, 16), 0.0,
        [&](const auto& range, double acc) {
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
                const float* row = F.row(i);
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
}

/// One Gauss-Seidel sweep over B in place (over-relaxed by w), each row using the rows before
/// it from this sweep; returns the squared area-weighted residual of `old`, B before the sweep.
double gauss_seidel_sweep(const std::vector<Patch>& P, const FormFactorMatrix& F, double w, const std::vector<Rgb>& old,
                          std::vector<Rgb>& B) {
    const std::size_t n = P.size();
    double r2 = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const float* row = F.row(i);
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
    return r2;
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
    res.status = SolveStatus::max_iterations;

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
        snap.status = SolveStatus::running;
        snap.steps = step;
        snap.residual = residual;
        snap.radiosity = b;
        matrix_energy_account(P, m_F, snap, m_options.open_parts);
        snap.seconds = seconds_since(t0);
        m_options.snapshot(snap);
    };
    if (snapshots) snapshot(0, B, -1.0);
    std::vector<Rgb> old(n);
    for (std::size_t sweep = 1; sweep <= max_sweeps; ++sweep) {
        // One pass over F gives the update and the residual of the iterate before it.
        old = B;
        const double r2 = m_gauss_seidel ? gauss_seidel_sweep(P, m_F, w, old, B) : jacobi_sweep(P, m_F, w, old, B);
        const double residual = std::sqrt(r2) / e_norm;
        log(sweep - 1, residual, old);
        if (snapshots && sweep % m_options.snapshot_every == 0) snapshot(sweep, B, -1.0);
        res.steps = sweep;
        res.residual = residual;
        if (first < 0) first = residual;
        if (!std::isfinite(residual) || residual > 1e8 * std::max(first, 1e-300)) {
            // Diverging (row sums above 1 with high reflectance): keep the last finite iterate.
            B = old;
            res.status = SolveStatus::diverged;
            break;
        }
        if (residual < m_options.tolerance) {
            res.status = SolveStatus::converged;
            res.converged = true;
            break;
        }
        if (m_options.max_seconds > 0 && seconds_since(t0) > m_options.max_seconds) {
            res.status = SolveStatus::max_seconds;
            break;
        }
        if (m_options.cancel && m_options.cancel->load()) {
            res.status = SolveStatus::interrupted;
            break;
        }
    }
    res.radiosity = B;
    res.seconds = seconds_since(t0);
    matrix_energy_account(P, m_F, res, m_options.open_parts);
    return res;
}

}  // namespace bounce
