// SPDX-License-Identifier: MIT
// Hierarchical radiosity with the power bound on the built-in Cornell box, its point data
// scored against the shipped path-traced reference (128 probes to 0.1%,
// examples/reference/cornell_probes_128_fine.csv). Links accepted for the little power they
// could misplace hand a whole coarse element one irradiance: the links' ends send and take by
// where they see each other (HierarchicalOptions::weighted_ends), the point gather first
// re-gathers every leaf at its centre (solver/gather/hierarchical_point_values.h), and the
// vertices gather from those values.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "solver/gather/hierarchical_point_values.h"
#include "solver/reference/probe_score.h"
#include "solver/reference/reference_csv.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

// The box at power epsilon 3e-6 from the coarse patches `bounce solve --solver hierarchical`
// starts from, solved once (per number of refinement rounds) for the tests below.
struct PowerBoundBox {
    std::vector<ReferencePoint> reference;
    std::unique_ptr<HierarchicalSolution> solution;
    std::unique_ptr<PatchMesh> elements;
    std::unique_ptr<Visibility> element_visibility;
};

std::unique_ptr<PowerBoundBox> solve_box(int refine_rounds, bool weighted_ends = true) {
    auto b = std::make_unique<PowerBoundBox>();
    b->reference =
        read_reference(std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples/reference/cornell_probes_128_fine.csv");
    MeshingOptions o;
    o.target_patches = 30;  // what `bounce solve --solver hierarchical` starts from
    const PatchMesh mesh(load_scene("cornell"), o);
    const auto visibility = make_visibility("embree", mesh.patches());
    HierarchicalOptions h;
    h.power_epsilon = 3e-6;
    h.refine_rounds = refine_rounds;
    h.weighted_ends = weighted_ends;
    b->solution = std::make_unique<HierarchicalSolution>(solve_hierarchical(mesh.patches(), *visibility, h));
    b->elements = std::make_unique<PatchMesh>(b->solution->tree.conforming_mesh(b->solution->leaves));
    b->element_visibility = make_visibility("embree", b->elements->patches());
    return b;
}

// With the default refinement (one round).
const PowerBoundBox& power_bound_box() {
    static const std::unique_ptr<PowerBoundBox> box = solve_box(HierarchicalOptions{}.refine_rounds);
    return *box;
}

// With the links' ends sending and taking their means (HierarchicalOptions::weighted_ends off).
const PowerBoundBox& mean_ends_box() {
    static const std::unique_ptr<PowerBoundBox> box = solve_box(HierarchicalOptions{}.refine_rounds, false);
    return *box;
}

// With three refinement rounds, each refining with the last one's solution (multigridding).
const PowerBoundBox& three_round_box() {
    static const std::unique_ptr<PowerBoundBox> box = solve_box(3);
    return *box;
}

// The point data gathered from `solution` (the box's, or a variant of it with the same
// leaves), scored at the probes.
ProbeScore point_data_score(const HierarchicalSolution& solution, const PowerBoundBox& box = power_bound_box()) {
    SolveResult res = solution.result;
    EXPECT_EQ(gather_hierarchical_point_values(solution, *box.elements, *box.element_visibility, res, "vertices"),
              GatherOutcome::gathered);
    return score_at_probes(*box.elements, res.radiosity, box.reference, res.point_radiosity);
}

}  // namespace

TEST(HierarchicalCornell, WeightedEndsAndTheRegatherCutThePowerBoundsPointErrorAtTheProbes) {
    const PowerBoundBox& box = power_bound_box();
    ASSERT_EQ(box.reference.size(), 128u);
    const HierarchicalSolution& sol = *box.solution;
    ASSERT_EQ(sol.power_epsilon, 3e-6);
    const ProbeScore regathered = point_data_score(sol);
    // The links as power refinement alone leaves them: ends send and take their means, and
    // the vertices gather from the solve's leaves.
    const PowerBoundBox& means = mean_ends_box();
    HierarchicalSolution plain = *means.solution;
    plain.power_epsilon = 0.0;
    const ProbeScore direct = point_data_score(plain, means);
    std::cout << sol.leaves.size() << " elements, " << sol.links.size() << " links; point data "
              << regathered.rms_smooth << " RMS (" << regathered.max_smooth << " max) with weighted ends and the "
              << "leaves re-gathered, " << direct.rms_smooth << " (" << direct.max_smooth << ") with neither; "
              << "patch values " << regathered.rms_patch << "\n";
    EXPECT_EQ(regathered.scored, 128u);
    EXPECT_EQ(plain.leaves, sol.leaves);  // the same refinement
    EXPECT_LE(regathered.rms_smooth, 0.012);
    EXPECT_LE(regathered.rms_smooth, 0.8 * direct.rms_smooth);
    EXPECT_LE(regathered.max_smooth, 0.06);
}

// One refinement round (the default), refined on emission plus the ambient term, against
// three, each refining with the last one's solution: the point data scores as well (the
// refinement's rays find the shadows, and the leaves are re-gathered), for half the solve.
TEST(HierarchicalCornell, OneRefinementRoundScoresAsWellAsThree) {
    ASSERT_EQ(HierarchicalOptions{}.refine_rounds, 1);
    const PowerBoundBox& three = three_round_box();
    const ProbeScore one_round = point_data_score(*power_bound_box().solution);
    const ProbeScore three_rounds = point_data_score(*three.solution, three);
    std::cout << "point data " << one_round.rms_smooth << " RMS (" << one_round.max_smooth << " max) after one round, "
              << three_rounds.rms_smooth << " (" << three_rounds.max_smooth << ") after three, whose later rounds "
              << "reused " << three.solution->reused_links << " form factors\n";
    // The probes' own noise is 0.1%, the gather's seeds move the RMS by about a tenth.
    EXPECT_GT(three.solution->reused_links, 0u);
    EXPECT_LE(one_round.rms_smooth, 1.15 * three_rounds.rms_smooth);
    EXPECT_LE(one_round.max_smooth, 1.3 * three_rounds.max_smooth);
}

// A link whose refinement rays were all blocked carries nothing in the solve, but a point of
// its element may still see part of the source: the vertex gathers through it with rays of its
// own. By the tall block, where its shadow falls on the red wall, vertices that skipped such
// links were several % dark after three refinement rounds. After one round (the default) the
// box gains nothing from it (five gather seeds: 0.68% RMS, 3.1% max through them, 0.67% and
// 2.5% without); under a blocker's penumbra it still does: without it the point data of
// HierarchicalPointValues.PartlyVisibleLinksRefineThePenumbra goes from 7.4% to 17% RMS.
TEST(HierarchicalCornell, VerticesGatherThroughLinksWhoseRaysWereAllBlocked) {
    const PowerBoundBox& three = three_round_box();
    const HierarchicalSolution& sol = *three.solution;
    HierarchicalSolution seen = sol;  // the same solution without its links of factor 0
    std::erase_if(seen.links, [](const HierarchicalLink& l) { return l.fab == 0.0f; });
    const std::size_t blocked = sol.links.size() - seen.links.size();
    const ProbeScore all = point_data_score(sol, three), without = point_data_score(seen, three);
    std::cout << blocked << " of " << sol.links.size() << " links blocked; point data " << all.rms_smooth << " RMS ("
              << all.max_smooth << " max) gathering through them, " << without.rms_smooth << " (" << without.max_smooth
              << ") without\n";
    EXPECT_GT(blocked, 0u);
    // Measured 0.66% against 0.68% RMS and 2.49% against 2.74% at the worst probe, with the
    // links' visibility from the 16 rays that judged them and the links a shaft test proves
    // unblocked gathered without rays (before that: 0.66% / 2.1% against 0.72% / 2.6%; 0.75%
    // against 1.02% RMS when 4 rays judged them: fewer links then stopped all their rays and
    // missed a source partly in view).
    EXPECT_LE(all.rms_smooth, without.rms_smooth);
    EXPECT_LE(all.max_smooth, 0.95 * without.max_smooth);
}

// Display refinement (DisplayRefinement): linear interpolation between the vertices misses
// where the light curves within an element (the tall block's penumbra on the back wall, the
// corners); splitting those elements for display and gathering their new vertices brings the
// point data closer to the probes, while the cells keep the solve's values and power.
TEST(HierarchicalCornell, DisplayRefinementBringsThePointDataCloserToTheProbes) {
    const PowerBoundBox& box = power_bound_box();
    const ProbeScore plain = point_data_score(*box.solution);
    HierarchicalSolution shown = *box.solution;
    PatchMesh cells = *box.elements;
    SolveResult res = shown.result;
    ASSERT_EQ(gather_hierarchical_point_values(shown, cells, *box.element_visibility, res, "vertices",
                                               DisplayRefinement{kSuggestedDisplayTolerance}),
              GatherOutcome::gathered);
    const ProbeScore refined = score_at_probes(cells, res.radiosity, box.reference, res.point_radiosity);
    const std::size_t added = shown.leaves.size() - box.solution->leaves.size();
    std::cout << "display refinement: " << added / 3 << " of " << box.solution->leaves.size()
              << " elements split, point data " << plain.rms_smooth << " RMS (" << plain.max_smooth << " max) -> "
              << refined.rms_smooth << " (" << refined.max_smooth << "); patch values " << plain.rms_patch << " -> "
              << refined.rms_patch << "\n";
    // Each split leaf becomes four that tile it with its radiosity: the cells' power and the
    // patch values at the probes are the solve's.
    EXPECT_EQ(added % 3, 0u);
    EXPECT_GT(added, 0u);
    ASSERT_EQ(cells.size(), shown.leaves.size());
    ASSERT_EQ(res.radiosity.size(), shown.leaves.size());
    ASSERT_EQ(shown.links.size(), box.solution->links.size());
    auto power = [](const PatchMesh& m, const std::vector<Rgb>& B) {
        double p = 0.0;
        for (std::size_t k = 0; k < m.size(); ++k) p += m.patches()[k].area * B[k].luminance();
        return p;
    };
    EXPECT_NEAR(power(cells, res.radiosity), power(*box.elements, box.solution->result.radiosity),
                1e-12 * power(*box.elements, box.solution->result.radiosity));
    EXPECT_NEAR(refined.rms_patch, plain.rms_patch, 1e-12);
    EXPECT_EQ(refined.scored, 128u);
    // Measured at power epsilon 3e-6 (2,239 of the 7,959 elements split): 0.69% -> 0.52% RMS,
    // 3.1% -> 2.1% at the worst probe; asserted at 15% less, beyond the gather's seed noise
    // (0.04 points at this epsilon).
    EXPECT_LE(refined.rms_smooth, 0.85 * plain.rms_smooth);
}
