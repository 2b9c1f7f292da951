// SPDX-License-Identifier: MIT
// The path tracer's estimate of the irradiance that mirrors and glass bring to a diffuse point:
// the witness for a caustic photon map.
#include <algorithm>
#include <array>

#include <glm/geometric.hpp>

#include "solver/reference/path_tracer.h"
#include "solver/reference/path_tracer_paths.h"
#include "solver/reference/path_tracer_sampling.h"
#include "solver/reference/path_tracer_scene.h"

namespace bounce {

using path_tracing::BatchStatistics;
using path_tracing::cosine_direction;
using path_tracing::follow_specular;
using path_tracing::kBatch;
using path_tracing::kStrataSide;
using path_tracing::Random;
using path_tracing::reflected;

IrradianceEstimate PathTracer::specular_irradiance(const SurfacePoint& x, std::uint64_t paths, bool emitted_only,
                                                   std::uint64_t seed, std::uint64_t index) const {
    const Impl& im = *m_impl;
    Random rng(seed, index);
    BatchStatistics stats;
    auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };
    auto uniform = [&] { return rng.uniform(); };
    const glm::dvec3 n = glm::normalize(x.normal);
    const glm::dvec3 origin = x.position + im.epsilon * n;
    std::array<int, kBatch> strata{};
    const std::uint64_t batches = std::max<std::uint64_t>(1, (paths + kBatch - 1) / kBatch);
    for (std::uint64_t b = 0; b < batches; ++b) {
        for (int k = 0; k < kBatch; ++k) strata[std::size_t(k)] = k;
        std::shuffle(strata.begin(), strata.end(), rng.engine());
        Rgb batch_sum;
        for (int path = 0; path < kBatch; ++path) {
            const int stratum = strata[std::size_t(path)];
            const double u1 = (double(stratum % kStrataSide) + rng.uniform()) / kStrataSide;
            const double u2 = (double(stratum / kStrataSide) + rng.uniform()) / kStrataSide;
            Rgb throughput = Rgb::gray(1.0);
            const auto a = follow_specular(im, m_scene, origin, cosine_direction(n, u1, u2), throughput, uniform);
            // Only what a mirror or glass sent: light straight from a diffuse surface is not
            // the caustic.
            if (a.surface < 0 || !a.through_specular) continue;
            const auto& sh = im.surfaces[std::size_t(a.surface)];
            Rgb b = sh.emission;
            if (!emitted_only)
                b += reflected(im, m_scene, a.position, sh.normal, a.surface, sh.reflectance, rng, random_pair,
                               [&] { return random_pair(0); });
            // E = integral of L cos over the hemisphere = pi E_cos[L], and L = B / pi.
            batch_sum += throughput * b;
        }
        stats.add(batch_sum * (1.0 / kBatch));
    }
    m_paths.fetch_add(batches * kBatch, std::memory_order_relaxed);
    return {Rgb(stats.mean[0], stats.mean[1], stats.mean[2]),
            Rgb(stats.standard_error(0), stats.standard_error(1), stats.standard_error(2)), batches * kBatch};
}

}  // namespace bounce
