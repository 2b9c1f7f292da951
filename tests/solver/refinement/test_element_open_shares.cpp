// SPDX-License-Identifier: MIT
// Open parts of elements (element_open_shares.h) and the hierarchical solve on them: an element
// under a cabinet with an open underside neither receives nor sends, and a closed furnace keeps
// its power, E / (1 - rho) on its open elements' mean.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/refinement/element_open_shares.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

/// The furnace of closed_box({2, 2, 2}) (rho 0.9, E 1: B = 10 everywhere open) with a cabinet
/// [0.6, 1.4]^2 x [0, 0.8] standing on its floor: five faces facing out, no bottom, so the
/// floor under it sees only the cabinet's inside (back sides). Surface 0 is the floor.
Scene furnace_with_cabinet() {
    Scene s = closed_box({2, 2, 2}, {"w", Rgb::gray(0.9), Rgb::gray(1)});
    const double lo = 0.6, hi = 1.4, top = 0.8;
    const std::vector<std::vector<glm::dvec3>> faces = {
        {{lo, lo, top}, {hi, lo, top}, {hi, hi, top}, {lo, hi, top}},  // +z
        {{lo, lo, 0}, {hi, lo, 0}, {hi, lo, top}, {lo, lo, top}},      // -y
        {{lo, hi, 0}, {lo, hi, top}, {hi, hi, top}, {hi, hi, 0}},      // +y
        {{lo, lo, 0}, {lo, lo, top}, {lo, hi, top}, {lo, hi, 0}},      // -x
        {{hi, lo, 0}, {hi, hi, 0}, {hi, hi, top}, {hi, lo, top}},      // +x
    };
    for (const auto& f : faces) s.surfaces.push_back({f, 0, "cabinet", {"test", 0}});
    return s;
}

/// One patch per face: the floor is one patch of 2 x 2 m, 0.64 m^2 of it under the cabinet.
PatchMesh whole_faces(const Scene& s) {
    MeshingOptions m;
    m.subdivide = false;
    return PatchMesh(s, m);
}

}  // namespace

TEST(ElementOpenShares, ElementsUnderACabinetAreBuriedAndTheirParentsKeepTheOpenArea) {
    const PatchMesh mesh = whole_faces(furnace_with_cabinet());
    const auto& P = mesh.patches();
    ASSERT_EQ(P[0].surface, 0);
    const auto vis = make_visibility("embree", P);
    ElementTree tree(P);
    // The floor in 4 x 4 elements of 0.5 m: the cabinet's footprint [0.6, 1.4]^2 covers the
    // four middle ones in part (0.16 m^2 of each 0.25).
    const std::size_t first = tree.split(0);
    for (int c = 0; c < 4; ++c) tree.split(first + std::size_t(c));
    ElementOpenShares shares(P, *vis, {}, nullptr);
    const ElementOpenness& o = shares.update(tree);
    double open_area = 0.0, worst_outside = 0.0;
    for (const std::uint32_t leaf : tree.leaves()) {
        if (tree.node(leaf).root != 0) {
            EXPECT_EQ(o.share[leaf], 1.0) << leaf;  // the walls and the cabinet: wholly open
            continue;
        }
        const Patch& e = tree.geometry()[leaf];
        open_area += e.area * o.share[leaf];
        const bool middle = std::abs(e.centre.x - 1.0) < 0.5 && std::abs(e.centre.y - 1.0) < 0.5;
        if (middle)
            EXPECT_NEAR(o.share[leaf], 1.0 - 0.16 / 0.25, 0.1) << leaf;  // 8 x 8 stratified points
        else
            worst_outside = std::max(worst_outside, 1.0 - o.share[leaf]);
    }
    std::printf("floor of 16 elements: open area %.4f m^2 (exact 3.36), worst outer element %.3f short\n", open_area,
                worst_outside);
    EXPECT_EQ(worst_outside, 0.0);
    // A parent's share is its children's area-weighted mean: the root's is the open area.
    EXPECT_NEAR(o.share[0] * P[0].area, open_area, 1e-12);
    EXPECT_NEAR(open_area, 4.0 - 0.64, 0.05);
    EXPECT_FALSE(o.all_open);
}

TEST(ElementOpenShares, AFurnaceWithACabinetIsFlatAndKeepsItsLight) {
    // Every open element of a closed furnace holds B = E / (1 - rho) = 10; the floor under the
    // cabinet, neither lit nor seen, holds its own E. On whole elements the floor's buried part
    // sends nothing that lands, so the light it should send is lost.
    const Scene scene = furnace_with_cabinet();
    const PatchMesh mesh = whole_faces(scene);
    const auto vis = make_visibility("embree", mesh.patches());
    HierarchicalOptions h;
    h.max_level = 3;
    const auto solve = [&](bool open) {
        h.open_parts = open;
        return solve_hierarchical(mesh.patches(), *vis, h);
    };
    const HierarchicalSolution s = solve(true), whole = solve(false);
    ASSERT_TRUE(s.result.converged);
    double worst = 0.0, mean = 0.0, area = 0.0;
    for (std::size_t k = 0; k < s.leaves.size(); ++k) {
        const std::uint32_t leaf = s.leaves[k];
        if (!(s.sending_share(leaf) > 0.0)) continue;
        const double b = s.result.radiosity[k].g, open_area = s.tree.geometry()[leaf].area * s.sending_share(leaf);
        worst = std::max(worst, std::abs(b - 10.0) / 10.0);
        mean += b * open_area;
        area += open_area;
    }
    const auto escaped = [](const HierarchicalSolution& x) {
        return x.result.escaped_power.g / x.result.emitted_power.g;
    };
    std::printf(
        "furnace with a cabinet: %zu elements, open ones' B from 10 by at most %.4f (mean %.5f), escaped "
        "%.2e (whole elements %.2e)\n",
        s.leaves.size(), worst, mean / area, escaped(s), escaped(whole));
    EXPECT_LT(std::abs(escaped(s)), 1e-3);
    EXPECT_GT(escaped(whole), 1e-3);
    // Conservation puts the mean over the open area at 10 (whole elements lose what the buried
    // parts send, above). Single elements straddling the cabinet's edge stray further, by their
    // partly blocked links' rays: printed, for the issue.
    EXPECT_NEAR(mean / area, 10.0, 0.01);
}
