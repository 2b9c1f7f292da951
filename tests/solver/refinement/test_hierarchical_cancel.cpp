// SPDX-License-Identifier: MIT
// Cancelling hierarchical radiosity (Ctrl-C in the command line and in Python) stops the
// stage that is running, not only the iteration after it: link refinement and the links'
// form factors can each take most of a large solve.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <string>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

std::vector<Patch> cornell(std::size_t target) {
    MeshingOptions o;
    o.target_patches = target;
    return PatchMesh(load_scene("cornell"), o).patches();
}

std::size_t computed(const HierarchicalSolution& s) {
    std::size_t n = 0;
    for (const auto& l : s.links) n += l.fab != 0.0f;
    return n;
}

HierarchicalOptions options() {
    HierarchicalOptions h;
    h.max_level = 2;
    return h;
}

/// Solves with cancel set when `stage` is first reported.
HierarchicalSolution cancelled_at(const std::vector<Patch>& P, const Visibility& vis, const std::string& stage) {
    std::atomic<bool> cancel{false};
    HierarchicalOptions h = options();
    h.cancel = &cancel;
    h.progress = [&](const std::string& s, std::size_t, std::size_t) {
        if (s == stage) cancel = true;
    };
    return solve_hierarchical(P, vis, h);
}

}  // namespace

TEST(HierarchicalCancel, StopsLinkRefinementAndTheLinksFormFactors) {
    const auto P = cornell(100);
    const auto vis = make_visibility("embree", P);
    const HierarchicalSolution full = solve_hierarchical(P, *vis, options());
    ASSERT_EQ(full.result.status, SolveStatus::converged);
    // Cancelled as refinement begins: no pair is judged, so no element is split and no link made.
    const HierarchicalSolution refining = cancelled_at(P, *vis, "round 1/1: refining links");
    // Cancelled at the first block of form factors: the other links keep theirs unset.
    const HierarchicalSolution factors = cancelled_at(P, *vis, "round 1/1: link form factors");
    std::printf(
        "uncancelled: %zu elements, %zu links with a form factor of %zu; cancelled refining: %zu elements, "
        "%zu links; cancelled at the form factors: %zu of %zu links with one\n",
        full.leaves.size(), computed(full), full.links.size(), refining.leaves.size(), refining.links.size(),
        computed(factors), factors.links.size());
    EXPECT_EQ(refining.result.status, SolveStatus::interrupted);
    EXPECT_EQ(refining.links.size(), 0u);
    EXPECT_EQ(refining.leaves.size(), P.size());
    EXPECT_EQ(refining.result.steps, 0u);
    EXPECT_EQ(factors.result.status, SolveStatus::interrupted);
    EXPECT_EQ(factors.links.size(), full.links.size());  // refinement had finished
    EXPECT_LT(computed(factors), computed(full) / 2);
    EXPECT_EQ(factors.result.steps, 0u);
    // What was done is still a whole solution over the elements (the command line writes it).
    EXPECT_EQ(factors.result.radiosity.size(), factors.leaves.size());
    EXPECT_EQ(factors.cluster_irradiance.size(), factors.leaves.size());
}
