// SPDX-License-Identifier: MIT
#include "solver/form_factors/open_parts.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "mesh/scene/errors.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/patch_sampling.h"
#include "solver/visibility/visibility.h"

namespace bounce {
namespace {

constexpr int kIntoCover = -100;  // a ray into the gap under a cover: absorbed, as by a back side

struct RayCounts {
    int open_points = 0, points = 0;
    long front = 0, back = 0, other = 0;  // rays from the open points: fronts, back sides, nothing or mirrors
};

/// Cosine-distributed direction about n from unit-square coordinates (Malley's method).
glm::dvec3 cosine_direction(const glm::dvec3& n, double u, double v) {
    const glm::dvec3 t =
        glm::normalize(std::abs(n.x) > 0.5 ? glm::cross(n, glm::dvec3(0, 1, 0)) : glm::cross(n, glm::dvec3(1, 0, 0)));
    const glm::dvec3 b = glm::cross(n, t);
    const double r = std::sqrt(u), phi = 2.0 * M_PI * v;
    return r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0, 1.0 - u)) * n;
}

/// The covered regions (convex) with their planes' normals (Newell's, unnormalised), found once.
struct Covers {
    explicit Covers(std::span<const CoveredRegion> covered) : regions(covered) {
        for (const CoveredRegion& c : regions) {
            glm::dvec3 n(0.0);
            for (std::size_t k = 0; k < c.polygon.size(); ++k)
                n += glm::cross(c.polygon[k], c.polygon[(k + 1) % c.polygon.size()]);
            normals.push_back(n);
        }
    }
    /// True when the ray x + t d (t > 0) passes through one of the regions.
    bool crossed_by(const glm::dvec3& x, const glm::dvec3& d) const {
        for (std::size_t r = 0; r < regions.size(); ++r) {
            const auto& poly = regions[r].polygon;
            const glm::dvec3& n = normals[r];
            if (poly.size() < 3) continue;
            const double dn = glm::dot(n, d);
            if (dn == 0.0) continue;
            const double t = glm::dot(n, poly[0] - x) / dn;
            if (!(t > 0.0)) continue;
            const glm::dvec3 y = x + t * d;
            bool inside = true;
            for (std::size_t k = 0; k < poly.size() && inside; ++k)
                inside = glm::dot(glm::cross(poly[(k + 1) % poly.size()] - poly[k], y - poly[k]), n) >= 0.0;
            if (inside) return true;
        }
        return false;
    }
    std::span<const CoveredRegion> regions;
    std::vector<glm::dvec3> normals;
};

/// Traces `side` x `side` points of polygon p, a part of the scene's patch `own` (which its
/// rays do not count as met), `rays` each, and adds what they meet to `c`. `patches` are what
/// the visibility indexes.
void trace_points(const std::vector<Patch>& patches, const Visibility& vis, const Covers& covers, const Patch& p,
                  std::size_t own, int side, int rays, double reach, SplitMix64& rng, RayCounts& c) {
    const int ray_side = std::max(1, int(std::lround(std::sqrt(double(rays)))));
    std::vector<int> hits(std::size_t(ray_side * ray_side));
    for (int a = 0; a < side; ++a)
        for (int b = 0; b < side; ++b) {
            const glm::dvec3 x =
                patch_point(p, (a + rng.uniform()) / side, (b + rng.uniform()) / side) + vis.offset() * p.normal;
            int open = 0;
            for (int k = 0; k < ray_side * ray_side; ++k) {
                const glm::dvec3 d = cosine_direction(p.normal, (k % ray_side + rng.uniform()) / ray_side,
                                                      (k / ray_side + rng.uniform()) / ray_side);
                int q = vis.first_patch(x, x + reach * d);
                if (q == Visibility::kNothing && covers.crossed_by(x, d)) q = kIntoCover;
                // 0: nothing or a mirror, 1: a front, 2: a back side
                hits[std::size_t(k)] = q == kIntoCover                                   ? 2
                                       : q < 0 || q == int(own)                          ? 0
                                       : glm::dot(patches[std::size_t(q)].normal, d) < 0 ? 1
                                                                                         : 2;
                if (hits[std::size_t(k)] != 2) ++open;
            }
            ++c.points;
            if (4 * open < ray_side * ray_side) continue;  // buried: most rays meet a back side first
            ++c.open_points;
            for (const int h : hits) (h == 1 ? c.front : h == 2 ? c.back : c.other) += 1;
        }
}

}  // namespace

double OpenPart::shot_scale(double row_sum) const {
    if (!(row_sum > 0.0)) return 1.0;
    if (closed) return area_share / row_sum;
    return std::min(1.0, area_share / row_sum);
}

namespace {

/// open_parts and element_open_parts: polygon i of `sampled` lies on patches[owner(i)].
template <class Owner>
std::vector<OpenPart> open_parts_of(const std::vector<Patch>& sampled, const Owner& owner,
                                    const std::vector<Patch>& patches, const Visibility& visibility, int points,
                                    int rays, std::uint64_t seed, const std::atomic<bool>* cancel,
                                    std::span<const CoveredRegion> covered) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const auto& p : patches)
        for (int k = 0; k < p.vertex_count; ++k) {
            lo = glm::min(lo, p.vertices[k]);
            hi = glm::max(hi, p.vertices[k]);
        }
    const double reach = 2.0 * glm::length(hi - lo) + 1.0;  // past every patch
    const Covers covers(covered);
    std::vector<OpenPart> out(sampled.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sampled.size(), 16), [&](const auto& range) {
        if (cancel && cancel->load()) return;
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            SplitMix64 rng{seed * 0x9E3779B97F4A7C15ull + i};
            RayCounts c;
            trace_points(patches, visibility, covers, sampled[i], owner(i), points, rays, reach, rng, c);
            // Points that disagree: the patch straddles a cover's edge; its open share is
            // worth a finer look (it scales the patch's irradiance).
            if (c.open_points > 0 && c.open_points < c.points) {
                c = RayCounts{};
                trace_points(patches, visibility, covers, sampled[i], owner(i), 2 * points, rays, reach, rng, c);
            }
            OpenPart& o = out[i];
            o.area_share = double(c.open_points) / double(c.points);
            o.closed = c.open_points > 0 && c.back == 0 && c.other == 0;
            // A buried patch sends nothing: what reaches it stays there (absorbed, as by a back side).
            o.back_share = c.open_points == 0     ? 1.0
                           : c.back + c.other > 0 ? double(c.back) / double(c.back + c.other)
                                                  : 0.0;
        }
    });
    if (cancel && cancel->load()) throw Interrupted("interrupted while finding the patches' open parts");
    return out;
}

}  // namespace

std::vector<OpenPart> open_parts(const std::vector<Patch>& patches, const Visibility& visibility, int points, int rays,
                                 std::uint64_t seed, const std::atomic<bool>* cancel,
                                 std::span<const CoveredRegion> covered) {
    return open_parts_of(
        patches, [](std::size_t i) { return i; }, patches, visibility, points, rays, seed, cancel, covered);
}

std::vector<OpenPart> element_open_parts(const std::vector<Patch>& elements, std::span<const std::uint32_t> patch_of,
                                         const std::vector<Patch>& patches, const Visibility& visibility, int points,
                                         int rays, std::uint64_t seed, const std::atomic<bool>* cancel,
                                         std::span<const CoveredRegion> covered) {
    if (patch_of.size() != elements.size()) throw std::invalid_argument("element open parts: one patch per element");
    return open_parts_of(
        elements, [&](std::size_t i) { return std::size_t(patch_of[i]); }, patches, visibility, points, rays, seed,
        cancel, covered);
}

std::vector<Patch> open_part_patches(const std::vector<Patch>& patches, const std::vector<OpenPart>& open) {
    std::vector<Patch> out = patches;
    for (std::size_t i = 0; i < out.size(); ++i) out[i].area *= open[i].receiving_share();
    return out;
}

FormFactorMatrix open_part_matrix(const FormFactorMatrix& whole, const std::vector<OpenPart>& open) {
    const std::size_t n = whole.size();
    const std::vector<double> sums = whole.row_sums();
    std::vector<double> send(n);
    for (std::size_t j = 0; j < n; ++j) send[j] = open[j].shot_scale(sums[j]);
    std::vector<float> values(n * n, 0.0f);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const double receive = 1.0 / open[i].receiving_share();
            const float* row = whole.row(i);
            for (std::size_t j = 0; j < n; ++j) values[i * n + j] = float(double(row[j]) * send[j] * receive);
        }
    });
    return FormFactorMatrix::from_values(n, std::move(values));
}

}  // namespace bounce
