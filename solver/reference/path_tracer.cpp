// SPDX-License-Identifier: MIT
// The path tracer's construction, point location and the estimate of B at surface points; its
// pictures are in path_tracer_image.cpp, probe placement and classification in
// path_tracer_probes.cpp.
#include "solver/reference/path_tracer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/reference/path_tracer_paths.h"
#include "solver/reference/path_tracer_sampling.h"
#include "solver/reference/path_tracer_scene.h"

namespace bounce {

using path_tracing::BatchStatistics;
using path_tracing::kBatch;
using path_tracing::kStrataSide;
using path_tracing::kStratifiedEmitters;
using path_tracing::Random;
using path_tracing::reflected;

std::string to_string(EstimateStatus s) {
    switch (s) {
        case EstimateStatus::converged:
            return "converged";
        case EstimateStatus::budget:
            return "budget";
        case EstimateStatus::interrupted:
            return "interrupted";
    }
    return "?";
}

PathTracer::PathTracer(const Scene& scene) : m_scene(scene), m_impl(std::make_unique<Impl>(scene)) {
    m_diagonal = m_impl->diagonal;
}

PathTracer::~PathTracer() = default;

std::string PathTracer::surface_name(int surface) const {
    const std::size_t n = m_scene.surfaces.size();
    const auto& s = std::size_t(surface) < n ? m_scene.surfaces.at(std::size_t(surface))
                                             : m_scene.specular_surfaces.at(std::size_t(surface) - n);
    return s.object.empty() ? "surface " + std::to_string(surface) : s.object;
}

std::optional<SurfacePoint> PathTracer::locate(const glm::dvec3& p, const glm::dvec3& n_in) const {
    const Impl& im = *m_impl;
    const double len = glm::length(n_in);
    if (!(len > 0) || !std::isfinite(len)) return std::nullopt;
    const glm::dvec3 n = n_in / len;
    const double snap = snap_distance();
    // Walk every crossing of the segment p + n*snap -> p - n*snap and keep the facing one
    // nearest to p.
    const glm::dvec3 o = p + snap * n;
    double tnear = 0;
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 64; ++k) {
        const auto hit = im.trace(o, -n, tnear, 2 * snap);
        if (hit.surface < 0) break;
        const auto& sd = im.surfaces[std::size_t(hit.surface)];
        if (sd.kind == MaterialKind::diffuse && glm::dot(sd.normal, n) > 0) {
            // Exact distance along n to the surface's plane, in double precision.
            const double t = glm::dot(sd.origin - p, sd.normal) / glm::dot(n, sd.normal);
            if (std::abs(t) < best_distance) {
                best_distance = std::abs(t);
                best = hit.surface;
            }
        }
        tnear = hit.t + 1e-7 * m_diagonal;
    }
    if (best < 0 || best_distance > snap) return std::nullopt;
    const auto& sd = im.surfaces[std::size_t(best)];
    const double t = glm::dot(sd.origin - p, sd.normal) / glm::dot(n, sd.normal);
    return SurfacePoint{p + t * n, sd.normal, best};
}

RadiosityEstimate PathTracer::estimate(const SurfacePoint& x, const ReferenceOptions& options, std::uint64_t index,
                                       const std::atomic<bool>* stop) const {
    const Impl& im = *m_impl;
    const auto& sx = im.surfaces.at(std::size_t(x.surface));
    Random rng(options.seed, index);
    BatchStatistics stats;
    std::uint64_t paths = 0;
    RadiosityEstimate out;
    out.status = EstimateStatus::interrupted;

    const std::size_t stratified = std::min<std::size_t>(im.emitters.size(), kStratifiedEmitters);
    std::vector<std::array<int, kBatch>> emitter_strata(stratified);
    std::array<int, kBatch> direction_strata{};
    auto jittered = [&](int stratum) {
        return std::pair{(double(stratum % kStrataSide) + rng.uniform()) / kStrataSide,
                         (double(stratum / kStrataSide) + rng.uniform()) / kStrataSide};
    };
    auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };

    // One batch of kBatch paths; returns the mean reflected radiosity of its paths.
    auto run_batch = [&]() {
        // One batch: its first-vertex samples cover the 8x8 strata once each, in an order
        // drawn afresh so emitter and direction strata pair up at random.
        for (auto& strata : emitter_strata) {
            for (int k = 0; k < kBatch; ++k) strata[std::size_t(k)] = k;
            std::shuffle(strata.begin(), strata.end(), rng.engine());
        }
        for (int k = 0; k < kBatch; ++k) direction_strata[std::size_t(k)] = k;
        std::shuffle(direction_strata.begin(), direction_strata.end(), rng.engine());

        Rgb batch_sum;
        for (int path = 0; path < kBatch; ++path) {
            batch_sum += reflected(
                im, m_scene, x.position, sx.normal, x.surface, sx.reflectance, rng,
                [&](std::size_t e) {
                    return e < stratified ? jittered(emitter_strata[e][std::size_t(path)]) : random_pair(e);
                },
                [&] { return jittered(direction_strata[std::size_t(path)]); });
        }
        return batch_sum * (1.0 / kBatch);
    };
    // Paths (whole batches) that statistics s predict for the target, with 10% to spare.
    auto planned = [&](const BatchStatistics& s) -> std::uint64_t {
        const double goal = options.target_error * (sx.emission.luminance() + s.mean[3]);
        const double se = s.standard_error(3);
        if (!(goal > 0)) return se > 0 ? options.max_paths : options.min_paths;
        const double batches = 1.1 * double(s.count) * (se / goal) * (se / goal);
        return std::uint64_t(std::min(std::ceil(batches), double(options.max_paths))) * kBatch;
    };
    auto stopped = [&] { return stop && stop->load(std::memory_order_relaxed); };

    // Sequential stopping on the running estimate is biased (it stops more often on a high
    // draw). A pilot run, thrown away, plans the number of paths instead; the estimate is then
    // made from fresh paths, and re-planned only in the rare case the plan fell short.
    std::uint64_t plan = options.max_paths;
    if (options.target_error > 0) {
        BatchStatistics pilot;
        for (std::uint64_t k = 0; k < options.min_paths && !stopped(); k += kBatch) pilot.add(run_batch());
        m_paths.fetch_add(pilot.count * kBatch, std::memory_order_relaxed);
        if (stopped()) return out;
        plan = std::clamp(planned(pilot), options.min_paths, options.max_paths);
    }
    while (true) {
        while (paths < plan) {
            if (stopped()) break;
            stats.add(run_batch());
            paths += kBatch;
        }
        const double mean_lum = sx.emission.luminance() + stats.mean[3];
        if (paths > 0 && options.target_error > 0 && stats.standard_error(3) <= options.target_error * mean_lum) {
            out.status = EstimateStatus::converged;
            break;
        }
        if (stopped()) {
            out.status = EstimateStatus::interrupted;
            break;
        }
        if (paths >= options.max_paths) {
            out.status = EstimateStatus::budget;
            break;
        }
        plan = std::min(options.max_paths, std::max(paths + kBatch, planned(stats)));
    }
    out.paths = paths;
    out.radiosity = sx.emission + Rgb(stats.mean[0], stats.mean[1], stats.mean[2]);
    out.standard_error = Rgb(stats.standard_error(0), stats.standard_error(1), stats.standard_error(2));
    m_paths.fetch_add(paths, std::memory_order_relaxed);
    return out;
}
std::vector<RadiosityEstimate> PathTracer::estimate_all(std::span<const SurfacePoint> points,
                                                        const ReferenceOptions& options,
                                                        const std::function<void(std::size_t, std::size_t)>& progress,
                                                        const std::atomic<bool>* stop) const {
    std::vector<RadiosityEstimate> out(points.size());
    std::atomic<std::size_t> done{0};
    tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) {
        if (stop && stop->load(std::memory_order_relaxed)) return;  // left as interrupted, 0 paths
        out[i] = estimate(points[i], options, i, stop);
        const std::size_t d = ++done;
        if (progress) progress(d, points.size());
    });
    return out;
}
}  // namespace bounce
