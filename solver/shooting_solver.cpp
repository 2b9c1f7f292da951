// SPDX-License-Identifier: MIT
#include "solver/shooting_solver.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace bounce {

ShootingSolver::ShootingSolver(const std::vector<Patch>& patches, const FormFactorEstimator& form_factors,
                               const ShootingOptions& options)
    : m_patches(patches), m_ff(form_factors), m_options(options) {}

SolveResult ShootingSolver::solve() {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t n = m_patches.size();
    SolveResult res;
    res.solver = "shooting";
    res.form_factors = m_ff.name();
    res.radiosity.resize(n);
    res.irradiance.assign(n, Rgb());
    res.unshot.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        res.radiosity[i] = m_patches[i].emission;
        res.unshot[i] = m_patches[i].emission;
        res.emitted_power += m_patches[i].emission * m_patches[i].area;
    }
    const double emitted = res.emitted_power.sum();
    if (!(emitted > 0.0)) throw std::invalid_argument("the scene emits no light: no surface has emission > 0");

    // Rows of shooters are kept (float) while the cache budget allows: a bright patch shoots
    // many times and its row does not change.
    const std::size_t row_bytes = n * sizeof(float);
    std::size_t cache_rows = row_bytes ? (m_options.cache_mb << 20) / row_bytes : 0;
    std::vector<std::unique_ptr<float[]>> cache(n);
    std::vector<float> scratch(n);

    const std::size_t max_shots = m_options.max_shots ? m_options.max_shots : 100 * n;
    double unshot_total = emitted;
    auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    while (true) {
        // Recompute the sum now and then: the running update drifts by rounding.
        if (res.steps % 256 == 0) {
            unshot_total = 0.0;
            for (std::size_t i = 0; i < n; ++i) unshot_total += res.unshot[i].sum() * m_patches[i].area;
        }
        res.unshot_fraction = unshot_total / emitted;
        if (res.unshot_fraction < m_options.tolerance) { res.converged = true; break; }
        if (res.steps >= max_shots) break;

        std::size_t shooter = 0;
        double best = -1.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double p = res.unshot[i].sum() * m_patches[i].area;
            if (p > best) { best = p; shooter = i; }
        }
        const float* row;
        if (cache[shooter]) {
            row = cache[shooter].get();
        } else {
            m_ff.compute_row(shooter, scratch);
            if (cache_rows > 0) {
                --cache_rows;
                cache[shooter].reset(new float[n]);
                std::copy(scratch.begin(), scratch.end(), cache[shooter].get());
                row = cache[shooter].get();
            } else {
                row = scratch.data();
            }
        }
        const Rgb shot = res.unshot[shooter];
        const double ai = m_patches[shooter].area;
        res.unshot[shooter] = Rgb();
        unshot_total -= shot.sum() * ai;
        double row_sum = 0.0;
        for (std::size_t j = 0; j < n; ++j) {
            const double f = row[j];
            if (f == 0.0) continue;
            row_sum += f;
            const Patch& pj = m_patches[j];
            const Rgb arriving = shot * (f * ai);          // power arriving at j
            const Rgb dh = arriving * (1.0 / pj.area);      // irradiance increment
            const Rgb reflected = pj.reflectance * dh;      // radiosity increment
            res.irradiance[j] += dh;
            res.radiosity[j] += reflected;
            res.unshot[j] += reflected;
            res.absorbed_power += arriving - pj.reflectance * arriving;
            unshot_total += reflected.sum() * pj.area;
        }
        res.escaped_power += shot * (ai * (1.0 - row_sum));
        ++res.steps;
        if (m_options.progress) {
            res.unshot_fraction = unshot_total / emitted;
            m_options.progress({res.steps, max_shots, res.unshot_fraction, m_options.tolerance, seconds()});
        }
    }
    for (std::size_t i = 0; i < n; ++i) res.unshot_power += res.unshot[i] * m_patches[i].area;
    res.seconds = seconds();
    return res;
}

}  // namespace bounce
