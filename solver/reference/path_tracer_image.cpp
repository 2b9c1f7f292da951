// SPDX-License-Identifier: MIT
// The path tracer's radiance along eye rays: one direction, a pixel's stratified mean, and single
// pixel samples for progressive pictures.
#include <algorithm>
#include <array>

#include <glm/geometric.hpp>

#include "solver/reference/path_tracer.h"
#include "solver/reference/path_tracer_paths.h"
#include "solver/reference/path_tracer_sampling.h"
#include "solver/reference/path_tracer_scene.h"

namespace bounce {

using path_tracing::BatchStatistics;
using path_tracing::follow_specular;
using path_tracing::kBatch;
using path_tracing::kPi;
using path_tracing::kStrataSide;
using path_tracing::Random;
using path_tracing::reflected;

RadianceEstimate PathTracer::radiance(const glm::dvec3& origin, const glm::dvec3& direction, std::uint64_t paths,
                                      std::uint64_t seed, std::uint64_t index) const {
    return pixel_radiance(origin, direction, glm::dvec3(0.0), glm::dvec3(0.0), paths, seed, index);
}

RadianceEstimate PathTracer::pixel_radiance(const glm::dvec3& origin, const glm::dvec3& corner, const glm::dvec3& du,
                                            const glm::dvec3& dv, std::uint64_t paths, std::uint64_t seed,
                                            std::uint64_t index) const {
    const Impl& im = *m_impl;
    Random rng(seed, index);
    BatchStatistics stats;
    auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };
    const bool area = glm::length(du) > 0 || glm::length(dv) > 0;
    std::array<int, kBatch> strata{};
    const std::uint64_t batches = std::max<std::uint64_t>(2, (paths + kBatch - 1) / kBatch);
    for (std::uint64_t b = 0; b < batches; ++b) {
        Rgb batch_sum;
        if (area) {
            for (int k = 0; k < kBatch; ++k) strata[std::size_t(k)] = k;
            std::shuffle(strata.begin(), strata.end(), rng.engine());
        }
        for (int path = 0; path < kBatch; ++path) {
            glm::dvec3 d = corner;
            if (area) {
                const int stratum = strata[std::size_t(path)];
                const double u = (double(stratum % kStrataSide) + rng.uniform()) / kStrataSide;
                const double v = (double(stratum / kStrataSide) + rng.uniform()) / kStrataSide;
                d += u * du + v * dv;
            }
            d = glm::normalize(d);
            Rgb throughput = Rgb::gray(1.0);
            const auto a = follow_specular(im, m_scene, origin, d, throughput, [&] { return rng.uniform(); });
            if (a.surface < 0) continue;
            const auto& sh = im.surfaces[std::size_t(a.surface)];
            const Rgb b_sample = sh.emission + reflected(im, m_scene, a.position, sh.normal, a.surface, sh.reflectance,
                                                         rng, random_pair, [&] { return random_pair(0); });
            batch_sum += throughput * b_sample * (1.0 / kPi);
        }
        stats.add(batch_sum * (1.0 / kBatch));
    }
    m_paths.fetch_add(batches * kBatch, std::memory_order_relaxed);
    return {Rgb(stats.mean[0], stats.mean[1], stats.mean[2]),
            Rgb(stats.standard_error(0), stats.standard_error(1), stats.standard_error(2)), batches * kBatch};
}

PixelSample PathTracer::pixel_sample(const glm::dvec3& origin, const glm::dvec3& corner, const glm::dvec3& du,
                                     const glm::dvec3& dv, std::uint64_t seed, std::uint64_t index) const {
    const Impl& im = *m_impl;
    Random rng(seed, index);
    auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };
    const double u = rng.uniform(), v = rng.uniform();
    Rgb throughput = Rgb::gray(1.0);
    const auto a = follow_specular(im, m_scene, origin, glm::normalize(corner + u * du + v * dv), throughput,
                                   [&] { return rng.uniform(); });
    m_paths.fetch_add(1, std::memory_order_relaxed);
    if (a.surface < 0) return {};
    const auto& sh = im.surfaces[std::size_t(a.surface)];
    const Rgb b = sh.emission + reflected(im, m_scene, a.position, sh.normal, a.surface, sh.reflectance, rng,
                                          random_pair, [&] { return random_pair(0); });
    return {throughput * b * (1.0 / kPi), a.surface};
}
}  // namespace bounce
