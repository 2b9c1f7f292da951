// SPDX-License-Identifier: MIT
// SurfaceRays (Embree, single precision) answers the contact cuts' enclosure rays as the exact
// SurfaceTree does: the same surfaces at the first hit, within the cuts' slack.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/geometric.hpp>

#include "mesh/geometry/surface_rays.h"
#include "mesh/geometry/surface_tree.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/polygon.h"
#include "test_util.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

/// Rays as the enclosure test casts them: from points just in front of the surfaces (1e-6 of
/// the diagonal), in cosine-weighted directions about their normals; counts those whose first
/// hits differ between the two structures, and those that meet anything.
struct Agreement {
    int differ = 0, met = 0, rays = 0;
};

Agreement compare_rays(const Scene& scene, int per_surface, std::uint64_t seed) {
    const SurfaceTree tree(scene);
    const SurfaceRays rays(scene);
    V lo(1e300), hi(-1e300);
    for (const auto& s : scene.surfaces)
        for (const auto& v : s.vertices) {
            lo = glm::min(lo, v);
            hi = glm::max(hi, v);
        }
    const double diag = glm::length(hi - lo), slack = 5e-4 * diag;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Agreement a;
    for (const auto& s : scene.surfaces) {
        const V nn = newell_normal(s.vertices);
        if (!(glm::length(nn) > 0)) continue;
        const V n = glm::normalize(nn);
        const V t = glm::normalize(std::abs(n.x) < 0.9 ? glm::cross(n, V(1, 0, 0)) : glm::cross(n, V(0, 1, 0)));
        const V b = glm::cross(n, t);
        const auto tri = triangulate_polygon(s.vertices);
        for (int k = 0; k < per_surface; ++k) {
            // A point of the polygon's first triangle, uniform.
            double r1 = u(rng), r2 = u(rng);
            if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
            const auto& f = tri.front();
            const V x = s.vertices[std::size_t(f[0])] +
                        r1 * (s.vertices[std::size_t(f[1])] - s.vertices[std::size_t(f[0])]) +
                        r2 * (s.vertices[std::size_t(f[2])] - s.vertices[std::size_t(f[0])]);
            const double phi = 2 * M_PI * u(rng), sin_theta = std::sqrt(u(rng));
            const V d = std::cos(phi) * sin_theta * t + std::sin(phi) * sin_theta * b +
                        std::sqrt(1 - sin_theta * sin_theta) * n;
            const V from = x + 1e-6 * diag * n;
            const std::vector<int> exact = tree.first_hits(from, d, slack), fast = rays.first_hits(from, d, slack);
            a.differ += exact != fast;
            a.met += !exact.empty();
            ++a.rays;
        }
    }
    return a;
}

}  // namespace

TEST(SurfaceRays, TheCornellBoxsRaysMeetWhatTheExactTreeMeets) {
    // Blocks resting on the floor, a lamp 0.1 mm under the ceiling: rays from under the lamp
    // and along the blocks' feet meet surfaces a hair apart, which the slack must gather alike.
    const Scene scene = load_scene("cornell");
    const Agreement a = compare_rays(scene, 400, 7);
    std::printf("cornell: %d rays, %d met a surface, %d differ\n", a.rays, a.met, a.differ);
    EXPECT_GT(a.met, a.rays / 2);
    EXPECT_EQ(a.differ, 0);
}

TEST(SurfaceRays, ARoomOfCrossingBoxesMeetsWhatTheExactTreeMeets) {
    // Boxes resting on the floor, against a wall, crossing each other and the ceiling.
    test::TempDir tmp;
    const auto path = tmp.write("room.json", R"({"name": "crossing boxes",
      "materials": {"w": {"reflectance": 0.7}, "lamp": {"reflectance": 0, "emission": 5}},
      "objects": [{"type": "box", "material": "w", "inward": true, "transform": {"scale": [6, 3, 6], "translate": [0, 1.5, 0]}},
        {"type": "box", "material": "w", "transform": {"scale": [1, 0.8, 1], "translate": [0, 0.4, 0]}},
        {"type": "box", "material": "w", "transform": {"scale": [0.6, 1.2, 0.4], "translate": [2.7, 0.6, 1]}},
        {"type": "box", "material": "w", "transform": {"scale": [1.2, 0.5, 0.7], "rotate": {"axis": [0, 1, 0.3], "degrees": 35}, "translate": [0.3, 0.8, 0.2]}},
        {"type": "box", "material": "w", "transform": {"scale": [0.5, 0.5, 0.5], "translate": [-2, 2.9, -2]}},
        {"type": "quad", "material": "lamp", "transform": {"scale": 1, "rotate": {"axis": [1, 0, 0], "degrees": 90}, "translate": [0, 2.99, 1.5]}}]})");
    const Scene scene = load_scene(path.string());
    const Agreement a = compare_rays(scene, 400, 11);
    std::printf("crossing boxes: %d rays, %d met a surface, %d differ\n", a.rays, a.met, a.differ);
    EXPECT_GT(a.met, a.rays / 2);
    EXPECT_EQ(a.differ, 0);
}
