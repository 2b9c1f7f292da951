// SPDX-License-Identifier: MIT
// Where the path tracer's probes go and what classifies them: points spread over the
// non-emitting surfaces by area, the unblocked share of direct light at a point, and its
// clearance to the nearest surface.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <glm/geometric.hpp>

#include "solver/reference/path_tracer.h"
#include "solver/reference/path_tracer_sampling.h"
#include "solver/reference/path_tracer_scene.h"

namespace bounce {
namespace {

double point_segment_distance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double s = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + s * ab));
}

}  // namespace

using path_tracing::cosine_direction;
using path_tracing::Random;
using path_tracing::SurfaceData;

std::vector<SurfacePoint> PathTracer::probes(std::size_t n, std::uint64_t seed) const {
    const Impl& im = *m_impl;
    std::vector<int> candidates;
    std::vector<double> cumulative;
    double total = 0;
    for (std::size_t s = 0; s < im.surfaces.size(); ++s) {
        const auto& sd = im.surfaces[s];
        if (sd.area > 0 && !(sd.emission.max() > 0) && sd.kind == MaterialKind::diffuse) {
            total += sd.area;
            candidates.push_back(int(s));
            cumulative.push_back(total);
        }
    }
    std::vector<SurfacePoint> out;
    if (candidates.empty() || n == 0) return out;
    Random rng(seed, 0xB0B0u);

    // Whether x lies open to the scene: at least 4 of 16 cosine rays leave without meeting a
    // back face first. A floor under a block is enclosed; so is a ceiling deep behind a lamp
    // hung just below it, which light reaches only through the gap and no viewer sees.
    auto reachable = [&](const glm::dvec3& x, const glm::dvec3& normal) {
        int open = 0;
        for (int k = 0; k < 16; ++k) {
            const glm::dvec3 d = cosine_direction(normal, (k % 4 + rng.uniform()) / 4, (k / 4 + rng.uniform()) / 4);
            const auto hit = im.trace_all(x + im.epsilon * normal, d, 0.0, std::numeric_limits<float>::infinity());
            if (hit.surface < 0 || glm::dot(im.surfaces[std::size_t(hit.surface)].normal, d) < 0) ++open;
            if (open >= 4) return true;
        }
        return false;
    };
    auto away_from_edges = [&](int s, const glm::dvec3& x) {
        const auto& poly = m_scene.surfaces[std::size_t(s)].vertices;
        const double margin = 0.02 * im.surfaces[std::size_t(s)].size;
        for (std::size_t k = 0; k < poly.size(); ++k)
            if (point_segment_distance(x, poly[k], poly[(k + 1) % poly.size()]) < margin) return false;
        return true;
    };
    auto try_point = [&](double area_position) -> std::optional<SurfacePoint> {
        std::size_t c =
            std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), area_position) - cumulative.begin());
        c = std::min(c, candidates.size() - 1);
        const int s = candidates[c];
        const glm::dvec3 x = im.sample_surface(m_scene, s, rng.uniform(), rng.uniform());
        const glm::dvec3 normal = im.surfaces[std::size_t(s)].normal;
        if (!away_from_edges(s, x) || !reachable(x, normal)) return std::nullopt;
        return SurfacePoint{x, normal, s};
    };
    for (std::size_t k = 0; k < n; ++k) {
        std::optional<SurfacePoint> p;
        // First within the k-th stratum of area, then (a stratum wholly enclosed) anywhere.
        for (int attempt = 0; attempt < 200 && !p; ++attempt)
            p = try_point((double(k) + rng.uniform()) / double(n) * total);
        for (int attempt = 0; attempt < 2000 && !p; ++attempt) p = try_point(rng.uniform() * total);
        if (p) out.push_back(*p);
    }
    return out;
}

double PathTracer::direct_light_share(const SurfacePoint& x, int samples, std::uint64_t seed) const {
    const Impl& im = *m_impl;
    Random rng(seed, 0xD1EC7u);
    const int side = std::max(1, int(std::lround(std::sqrt(double(std::max(samples, 1))))));
    const glm::dvec3 xo = x.position + im.epsilon * x.normal;
    double total = 0.0, open = 0.0;
    for (const int e : im.emitters) {
        if (e == x.surface) continue;
        const SurfaceData& ed = im.surfaces[std::size_t(e)];
        for (int k = 0; k < side * side; ++k) {
            const double u1 = (k % side + rng.uniform()) / side, u2 = (k / side + rng.uniform()) / side;
            const glm::dvec3 y = im.sample_surface(m_scene, e, u1, u2);
            const glm::dvec3 w = y - x.position;
            const double r2 = glm::dot(w, w);
            if (!(r2 > 0)) continue;
            const double cos_x = glm::dot(x.normal, w), cos_y = -glm::dot(ed.normal, w);
            if (cos_x <= 0 || cos_y <= 0) continue;
            const double kernel = ed.emission.luminance() * ed.area * cos_x * cos_y / (r2 * r2);
            total += kernel;
            if (!im.occluded(xo, y + im.epsilon * ed.normal)) open += kernel;
        }
    }
    return total > 0 ? open / total : -1.0;
}

double PathTracer::clearance(const SurfacePoint& x, int rays, std::uint64_t seed) const {
    const Impl& im = *m_impl;
    Random rng(seed, 0xC1EAu);
    const int side = std::max(1, int(std::lround(std::sqrt(double(std::max(rays, 1))))));
    double nearest = std::numeric_limits<double>::infinity();
    for (int k = 0; k < side * side; ++k) {
        const glm::dvec3 d =
            cosine_direction(x.normal, (k % side + rng.uniform()) / side, (k / side + rng.uniform()) / side);
        const auto hit =
            im.trace_all(x.position + im.epsilon * x.normal, d, 0.0, std::numeric_limits<float>::infinity());
        if (!hit.missed()) nearest = std::min(nearest, hit.t);
    }
    return nearest;
}
}  // namespace bounce
