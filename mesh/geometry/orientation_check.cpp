// SPDX-License-Identifier: MIT
#include "mesh/geometry/orientation_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "mesh/geometry/surface_tree.h"
#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using V = glm::dvec3;

constexpr int kPoints = 8;            // sample points per group
constexpr int kRays = 8;              // cosine-weighted rays per point and side (2 x 4 strata)
constexpr double kMinShare = 1e-3;    // groups with less of the scene's area are not looked at
constexpr std::size_t kGroups = 512;  // at most this many groups, the largest
constexpr double kFrontAtMost = 0.2;  // reversed: the front sees at most this much front ...
constexpr double kBackAtLeast = 0.5;  // ... and the back at least this much

struct Keyed {
    std::array<long long, 6> key;  // object, material, plane (normal and offset, quantized)
    int surface;
};

struct Group {
    std::vector<int> surfaces;
    double area = 0.0;
    V normal{0.0};
};

/// Point k of kPoints on group g: a surface by area (stratified over the group), a triangle of
/// it by area, a point in it; into s and x. False when the surface has no triangle.
bool sample_point(const Scene& scene, const Group& g, const std::vector<double>& area, int k, std::mt19937_64& rng,
                  std::uniform_real_distribution<double>& uni, std::size_t& s, V& x) {
    double u = (k + uni(rng)) / kPoints * g.area;
    std::size_t pick = 0;
    while (pick + 1 < g.surfaces.size() && u > area[std::size_t(g.surfaces[pick])]) {
        u -= area[std::size_t(g.surfaces[pick])];
        ++pick;
    }
    s = std::size_t(g.surfaces[pick]);
    const auto& poly = scene.surfaces[s].vertices;
    const auto tris = triangulate_polygon(poly);
    if (tris.empty()) return false;
    double t_area = 0.0;
    for (const auto& t : tris)
        t_area += 0.5 * glm::length(glm::cross(poly[t[1]] - poly[t[0]], poly[t[2]] - poly[t[0]]));
    double w = uni(rng) * t_area;
    std::size_t ti = 0;
    for (; ti + 1 < tris.size(); ++ti) {
        const auto& t = tris[ti];
        const double a = 0.5 * glm::length(glm::cross(poly[t[1]] - poly[t[0]], poly[t[2]] - poly[t[0]]));
        if (w <= a) break;
        w -= a;
    }
    const auto& t = tris[ti];
    double r1 = uni(rng), r2 = uni(rng);
    if (r1 + r2 > 1) {
        r1 = 1 - r1;
        r2 = 1 - r2;
    }
    x = poly[t[0]] + r1 * (poly[t[1]] - poly[t[0]]) + r2 * (poly[t[2]] - poly[t[0]]);
    return true;
}

}  // namespace

std::vector<ReversedSurface> find_reversed_surfaces(const Scene& scene) {
    if (scene.surfaces.size() < 2) return {};
    return find_reversed_surfaces(scene, SurfaceTree(scene));
}

std::vector<ReversedSurface> find_reversed_surfaces(const Scene& scene, const SurfaceTree& tree) {
    const std::size_t n = scene.surfaces.size();
    std::vector<ReversedSurface> out;
    if (n < 2) return out;
    V lo(std::numeric_limits<double>::infinity()), hi = -lo;
    std::vector<V> normal(n, V(0.0));
    std::vector<double> area(n, 0.0);
    double total = 0.0;
    for (std::size_t s = 0; s < n; ++s) {
        const auto& poly = scene.surfaces[s].vertices;
        for (const auto& v : poly) {
            lo = glm::min(lo, v);
            hi = glm::max(hi, v);
        }
        const V nn = newell_normal(poly);
        const double len = glm::length(nn);
        if (!(len > 0)) continue;
        normal[s] = nn / len;
        area[s] = 0.5 * len;
        total += area[s];
    }
    const double diag = glm::length(hi - lo);
    if (!(total > 0) || !(diag > 0)) return out;

    // Group the surfaces of one object and material that lie in one plane.
    std::unordered_map<std::string, long long> object_ids;
    std::vector<Keyed> keyed;
    keyed.reserve(n);
    for (std::size_t s = 0; s < n; ++s) {
        if (!(area[s] > 0)) continue;
        const Surface& f = scene.surfaces[s];
        const auto id = object_ids.emplace(f.where.file + '\n' + f.object, (long long)object_ids.size()).first->second;
        const V& m = normal[s];
        const double d = glm::dot(m, polygon_centroid(f.vertices)) / diag;
        keyed.push_back({{id, f.material, std::llround(m.x * 1e3), std::llround(m.y * 1e3), std::llround(m.z * 1e3),
                          std::llround(d * 1e4)},
                         int(s)});
    }
    std::sort(keyed.begin(), keyed.end(),
              [](const Keyed& a, const Keyed& b) { return a.key != b.key ? a.key < b.key : a.surface < b.surface; });
    std::vector<Group> groups;
    for (std::size_t k = 0; k < keyed.size(); ++k) {
        if (k == 0 || keyed[k].key != keyed[k - 1].key) groups.emplace_back();
        Group& g = groups.back();
        g.surfaces.push_back(keyed[k].surface);
        g.area += area[std::size_t(keyed[k].surface)];
    }
    std::erase_if(groups, [&](const Group& g) { return g.area < kMinShare * total; });
    std::sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) {
        return a.area != b.area ? a.area > b.area : a.surfaces.front() < b.surfaces.front();
    });
    if (groups.size() > kGroups) groups.resize(kGroups);
    if (groups.empty()) return out;

    if (tree.empty()) return out;
    const double lift = 1e-6 * diag;

    // Shares of the rays from each side that meet a front face, per group (in parallel; each
    // group draws from its own generator, so the answer does not depend on the threads).
    std::vector<std::array<double, 2>> sees(groups.size(), {0.0, 0.0});
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groups.size(), 4), [&](const auto& range) {
        for (std::size_t gi = range.begin(); gi != range.end(); ++gi) {
            const Group& g = groups[gi];
            std::mt19937_64 rng(0x0b5e55edULL + gi);
            std::uniform_real_distribution<double> uni(0.0, 1.0);
            std::array<int, 2> fronts{0, 0};
            for (int k = 0; k < kPoints; ++k) {
                std::size_t s = 0;
                V x(0.0);
                if (!sample_point(scene, g, area, k, rng, uni, s, x)) continue;
                const V& nm = normal[s];
                const V tx =
                    glm::normalize(std::abs(nm.x) < 0.9 ? glm::cross(nm, V(1, 0, 0)) : glm::cross(nm, V(0, 1, 0)));
                const V ty = glm::cross(nm, tx);
                for (int side = 0; side < 2; ++side) {
                    const V up = side == 0 ? nm : -nm;
                    const V from = x + lift * up;
                    for (int j = 0; j < kRays; ++j) {
                        const double a = (j % 2 + uni(rng)) / 2, b = (j / 2 + uni(rng)) / (kRays / 2);
                        const double r = std::sqrt(a), phi = 2 * std::numbers::pi * b;
                        const V d = r * std::cos(phi) * tx + r * std::sin(phi) * ty + std::sqrt(1 - a) * up;
                        const int hit = tree.first_hit(from, d);
                        if (hit >= 0 && glm::dot(normal[std::size_t(hit)], d) < 0) ++fronts[side];
                    }
                }
            }
            sees[gi] = {fronts[0] / double(kPoints * kRays), fronts[1] / double(kPoints * kRays)};
        }
    });
    for (std::size_t gi = 0; gi < groups.size(); ++gi)
        if (sees[gi][0] <= kFrontAtMost && sees[gi][1] >= kBackAtLeast)
            out.push_back({groups[gi].surfaces, sees[gi][0], sees[gi][1]});
    std::sort(out.begin(), out.end(), [](const ReversedSurface& a, const ReversedSurface& b) {
        return a.surfaces.front() < b.surfaces.front();
    });
    return out;
}

std::string reversed_surface_warning(const Scene& scene, const ReversedSurface& r) {
    const Surface& s = scene.surfaces[std::size_t(r.surfaces.front())];
    const auto percent = [](double x) { return std::to_string(int(std::lround(100 * x))) + "%"; };
    std::string msg = "orientation: " + describe(s.where, s.object);
    if (r.surfaces.size() > 1)
        msg += " and " + std::to_string(r.surfaces.size() - 1) + " more face" + (r.surfaces.size() > 2 ? "s" : "") +
               " in its plane";
    msg += " faces away from the scene: " + percent(r.front_sees) +
           " of the view from its front meets the front of a " + "surface, " + percent(r.back_sees) +
           " of the view from its back; it seems wound clockwise seen from " +
           "its front (that front stays dark, and what it should reflect escapes). ";
    if (s.where.file.find(".json") != std::string::npos)
        msg += "Set \"flip\": true on that object";
    else
        msg += "Reverse the order of its vertices (--flip turns every face, if all are reversed)";
    return msg;
}

}  // namespace bounce
