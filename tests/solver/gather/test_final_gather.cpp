// SPDX-License-Identifier: MIT
// Final gather against known answers: the furnace (sum of exact factors in a closed box is 1,
// no false occlusion at corners), direct light under a lamp (Lambert's formula), and a blocker
// that hides exactly half of the lamp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "mesh/patch_mesh.h"
#include "mesh/scene_loader.h"
#include "mesh/validation_scenes.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/gather/final_gather.h"

using namespace bounce;
using V = glm::dvec3;

TEST(FinalGather, FurnaceVerticesGatherExactlyEOverOneMinusRho) {
    const Scene box = closed_box({1.0, 1.5, 2.0}, {"furnace", Rgb::gray(0.5), Rgb::gray(1.0)});
    MeshingOptions o;
    o.target_patches = 200;
    const PatchMesh m(box, o);
    const auto vis = make_visibility("embree", m.patches());
    const std::vector<Rgb> B(m.size(), Rgb::gray(2.0));  // the exact solution
    const auto points = vertex_gather_points(m);
    const auto g = final_gather(m.patches(), B, *vis, points);
    for (std::size_t v = 0; v < g.size(); ++v)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(g[v][c], 2.0, 1e-9) << "vertex " << v;
    const auto centres = final_gather(m.patches(), B, *vis, centre_gather_points(m.patches()));
    for (const auto& b : centres) EXPECT_NEAR(b.g, 2.0, 1e-9);
}

TEST(FinalGather, DirectLightAtEveryVertexIsLambertsFormula) {
    const Scene s = lamp_over_plane();
    MeshingOptions o;
    o.max_edge = 0.25;
    const PatchMesh m(s, o);
    const auto vis = make_visibility("embree", m.patches());
    std::vector<Rgb> B;
    for (const auto& p : m.patches()) B.push_back(p.emission);  // nothing returns to the lamp
    const auto points = vertex_gather_points(m);
    const auto g = final_gather(m.patches(), B, *vis, points);
    std::size_t checked = 0;
    for (std::size_t v = 0; v < points.size(); ++v) {
        if (points[v].surface != 0) continue;
        const double F = point_polygon_form_factor(points[v].position, {0, 0, 1}, s.surfaces[1].vertices);
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(g[v][c], 0.5 * Rgb(3, 2, 1)[c] * F, 1e-12) << "vertex " << v;
        ++checked;
    }
    EXPECT_GT(checked, 300u);
}

TEST(FinalGather, KernelWeightedVisibilityUnderAHalfBlocker) {
    Scene s = lamp_over_plane();
    // Seen from (0.5, 0.5, 0) this black strip at z = 0.5 hides exactly the half x > 0.5 of the lamp.
    s.surfaces.push_back({{{0.5, -1, 0.5}, {1.0, -1, 0.5}, {1.0, 2, 0.5}, {0.5, 2, 0.5}}, 2, "blocker", {"test", 0}});
    MeshingOptions o;
    o.max_edge = 0.125;
    const PatchMesh m(s, o);
    const auto vis = make_visibility("embree", m.patches());
    std::vector<Rgb> B;
    for (const auto& p : m.patches()) B.push_back(p.emission);
    const GatherPoint x{{0.5, 0.5, 0}, {0, 0, 1}, 0, Rgb::gray(0.5), Rgb()};
    const auto g = final_gather(m.patches(), B, *vis, std::vector<GatherPoint>{x});
    const std::vector<V> visible = {{0, 0, 1}, {0, 1, 1}, {0.5, 1, 1}, {0.5, 0, 1}};
    const double exact = 0.5 * 2.0 * point_polygon_form_factor(x.position, x.normal, visible);
    // Lamp patches straddle the shadow line only at its edge x = 0.5, where the kernel-weighted
    // rays split them; the rest are wholly seen or wholly hidden.
    EXPECT_NEAR(g[0].g / exact, 1.0, 0.01);
}

// kernel_tolerance: far patches by the Gauss rule of the point-to-point kernel instead of
// Lambert's formula. With the same seed the rays are the same, so every vertex of the Cornell
// box (all its pairs: near, far, straddling the horizon) must stay within the tolerance of the
// exact gather, and the rule must actually be taken.
TEST(FinalGather, GaussRuleForFarPatchesWithinItsTolerance) {
    const Scene scene = load_scene("cornell");
    MeshingOptions o;
    o.target_patches = 500;
    const PatchMesh m(scene, o);
    const auto vis = make_visibility("embree", m.patches());
    std::vector<Rgb> B;
    for (std::size_t j = 0; j < m.size(); ++j) B.push_back(m.patches()[j].emission + Rgb(1, 2, 3) * double(1 + j % 7));
    const auto points = vertex_gather_points(m);
    const auto exact = final_gather(m.patches(), B, *vis, points);
    GatherOptions fast;
    fast.kernel_tolerance = 1e-4;
    const auto g = final_gather(m.patches(), B, *vis, points, fast);
    double worst = 0.0;
    for (std::size_t v = 0; v < g.size(); ++v)
        for (int c = 0; c < 3; ++c) {
            const double reflected = exact[v][c] - points[v].emission[c];  // the gathered part
            if (reflected > 0) worst = std::max(worst, std::abs(g[v][c] - exact[v][c]) / reflected);
        }
    std::cout << "largest relative change of a vertex's gathered light: " << worst << "\n";
    EXPECT_LE(worst, 1e-4);
    EXPECT_GT(worst, 1e-9);  // the rule was used
}

// The furnace with the rule: every factor within 1e-4 of Lambert's, so within 1e-4 of E/(1-rho).
TEST(FinalGather, FurnaceWithTheGaussRuleWithinItsTolerance) {
    const Scene box = closed_box({1.0, 1.5, 2.0}, {"furnace", Rgb::gray(0.5), Rgb::gray(1.0)});
    MeshingOptions o;
    o.target_patches = 200;
    const PatchMesh m(box, o);
    const auto vis = make_visibility("embree", m.patches());
    const std::vector<Rgb> B(m.size(), Rgb::gray(2.0));
    GatherOptions fast;
    fast.kernel_tolerance = 1e-4;
    const auto g = final_gather(m.patches(), B, *vis, vertex_gather_points(m), fast);
    double worst = 0.0;
    for (const Rgb& b : g) worst = std::max(worst, std::abs(b.g - 2.0));
    std::cout << "furnace: largest |B - 2| " << worst << "\n";
    EXPECT_LE(worst, 2.0 * 1e-4);
}
