// SPDX-License-Identifier: MIT
// A link's ends send and take by where they see each other (solver/refinement/seen_ends.h,
// HierarchicalOptions::weighted_ends), in the L-shaped corridor lit from one end
// (examples/scenes/corridor.obj): its far leg, round the corner, is lit only by light that has
// run the length of the near leg, bounce by bounce. A coarse element's mean hands what lies
// down the gradient its bright side's light, and that excess compounds over every bounce.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/refinement/link_refiner.h"
#include "solver/refinement/seen_ends.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

/// Per input patch, its leaves' radiosity luminance, the mean over their open area.
std::vector<double> patch_means(const HierarchicalSolution& sol) {
    const auto& tree = sol.tree;
    std::vector<double> power(tree.root_count(), 0.0), area(tree.root_count(), 0.0);
    for (std::size_t k = 0; k < sol.leaves.size(); ++k) {
        const std::uint32_t r = tree.node(sol.leaves[k]).root;
        const double a = tree.geometry()[sol.leaves[k]].area * sol.sending_share(sol.leaves[k]);
        power[r] += sol.result.radiosity[k].luminance() * a;
        area[r] += a;
    }
    for (std::size_t r = 0; r < power.size(); ++r) power[r] /= area[r];
    return power;
}

/// The largest relative difference of `a` from `b` over the input patches.
double worst_difference(const std::vector<double>& a, const std::vector<double>& b) {
    double worst = 0.0;
    for (std::size_t r = 0; r < a.size(); ++r) worst = std::max(worst, std::abs(a[r] / b[r] - 1));
    return worst;
}

}  // namespace

// `--adaptive`'s power epsilon leaves the far leg's links coarse (its light is a thousandth of
// the near leg's); a power epsilon a hundred times smaller refines them all. Each input patch's
// mean radiosity must agree with that finer solve.
TEST(SeenEnds, TheCorridorsFarLegAgreesWithAFinerSolve) {
    MeshingOptions m;
    m.target_patches = 30;  // the roots `bounce solve --adaptive` starts from
    const PatchMesh mesh(load_scene(std::string(BOUNCE_SOURCE_DIR) + "/examples/scenes/corridor.obj"), m);
    const auto visibility = make_visibility("embree", mesh.patches());
    HierarchicalOptions o;
    o.power_epsilon = adaptive_power_epsilon(0.0);
    const HierarchicalSolution adaptive = solve_hierarchical(mesh.patches(), *visibility, o);
    o.weighted_ends = false;
    const HierarchicalSolution means = solve_hierarchical(mesh.patches(), *visibility, o);
    HierarchicalOptions fine;
    fine.power_epsilon = adaptive_power_epsilon(0.0) / 100;
    const HierarchicalSolution finer = solve_hierarchical(mesh.patches(), *visibility, fine);
    const std::vector<double> truth = patch_means(finer);
    const double weighted = worst_difference(patch_means(adaptive), truth);
    const double mean_ends = worst_difference(patch_means(means), truth);
    std::printf(
        "input patches' mean radiosity against power epsilon %g (%zu elements): worst %.2f%% with weighted "
        "ends (%zu elements), %.2f%% with the ends' means\n",
        fine.power_epsilon, finer.leaves.size(), 100 * weighted, adaptive.leaves.size(), 100 * mean_ends);
    ASSERT_GT(finer.leaves.size(), adaptive.leaves.size());
    EXPECT_LT(weighted, 0.02);
    EXPECT_GT(mean_ends, 2 * weighted);  // what the test tells apart
}

// Every list's weights sum to one, and no node takes more than a point can: what it takes per
// unit of its open area, F times its take, is at most the source's radiosity (F <= 1). Where a
// few rays' kernel put a coarse end's weight on one small leaf, the iteration diverged.
TEST(SeenEnds, EveryListSumsToOneAndNoNodeTakesMoreThanAPointCan) {
    MeshingOptions m;
    m.target_patches = 30;
    const PatchMesh mesh(load_scene(std::string(BOUNCE_SOURCE_DIR) + "/examples/scenes/corridor.obj"), m);
    const auto visibility = make_visibility("embree", mesh.patches());
    HierarchicalOptions o;
    o.power_epsilon = adaptive_power_epsilon(0.0);
    const HierarchicalSolution sol = solve_hierarchical(mesh.patches(), *visibility, o);
    const auto& G = sol.tree.geometry();
    const RaycastFormFactor ff(G, visibility.get(), with_rays_only(with_default_rays(o.form_factors, kRefinementRays)));
    const ElementOpenness open{sol.open_share, {}, sol.open_share.empty()};
    const hierarchical::SeenEnds ends =
        hierarchical::seen_ends(sol.tree, sol.links, ff, hierarchical::kPartialVisibilityRays, &open);
    ASSERT_EQ(ends.first.size(), sol.links.size() + 1);
    ASSERT_EQ(ends.middle.size(), sol.links.size());
    ASSERT_EQ(ends.take.size(), ends.node.size());
    ASSERT_EQ(ends.weight.size(), ends.node.size());
    std::size_t lists = 0, partly = 0;
    for (std::size_t k = 0; k < sol.links.size(); ++k) {
        const HierarchicalLink& l = sol.links[k];
        if (!l.between_elements()) {
            EXPECT_EQ(ends.first[k], ends.first[k + 1]);  // a cluster end sends its mean
            continue;
        }
        const double factor[2] = {double(l.fab), double(l.fab) * G[l.a].area / G[l.b].area};
        const std::uint32_t bounds[3] = {ends.first[k], ends.middle[k], ends.first[k + 1]};
        for (int end = 0; end < 2; ++end) {
            if (bounds[end] == bounds[end + 1]) continue;
            ++lists;
            partly += l.visible > 0.0f && l.visible < 1.0f;
            double sum = 0.0;
            for (std::uint32_t e = bounds[end]; e < bounds[end + 1]; ++e) {
                sum += ends.weight[e];
                const std::uint32_t node = ends.node[e];
                const double open_share = node < sol.open_share.size() ? sol.open_share[node] : 1.0;
                EXPECT_LE(factor[end] * ends.take[e] / open_share, 1.0 + 1e-5) << "link " << k << " node " << node;
            }
            EXPECT_NEAR(sum, 1.0, 1e-5) << "link " << k;
        }
    }
    std::printf("%zu lists over %zu links, %zu of them on partly visible links\n", lists, sol.links.size(), partly);
    EXPECT_GT(partly, 0u);
    EXPECT_GT(lists, sol.links.size() / 10);
}
