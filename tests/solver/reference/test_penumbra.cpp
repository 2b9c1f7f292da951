// SPDX-License-Identifier: MIT
// A blocker's penumbra on a floor, where the exact answer is known: a unit square lamp over a
// plane, a black square half-way between (0.6 on a side), nothing else that reflects. At a
// point x = (u, 0.5, 0) of the plane the blocker's shadow, scaled by 2 about the point onto
// the lamp's plane, covers the lamp but for the strip [1.6 - u, 1] x [0, 1], so
// B(x) = rho E F(dA_x -> strip) (Lambert's formula for the strip) across the penumbra
// 0.6 < u < 1.6. The default run and --adaptive must both follow it in their point data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/gather/hierarchical_point_values.h"
#include "solver/gather/patch_display_refinement.h"
#include "solver/gather/point_values.h"
#include "solver/linear/shooting_solver.h"
#include "solver/reference/probe_score.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

Scene blocked_lamp() {
    Scene s = lamp_over_plane();  // plane [-2,3]^2 (rho 0.5), lamp [0,1]^2 at z = 1, E = (3, 2, 1)
    s.surfaces.push_back(
        {{{0.2, 0.2, 0.5}, {0.2, 0.8, 0.5}, {0.8, 0.8, 0.5}, {0.8, 0.2, 0.5}}, 2, "blocker", {"test", 0}});
    return s;
}

MeshingOptions about_300_patches() {
    MeshingOptions coarse;
    coarse.target_patches = 300;
    return coarse;
}

/// The blocked lamp cut into about 300 patches and solved by shooting, not yet gathered: the
/// penumbra (1 wide) spans three or four patches.
struct CoarseBlockedLamp {
    PatchMesh mesh{blocked_lamp(), about_300_patches()};
    std::unique_ptr<Visibility> visibility = make_visibility("embree", mesh.patches());
    SolveResult solved =
        ShootingSolver(mesh.patches(), *make_form_factor_estimator("raycast", mesh.patches(), visibility.get(), {}),
                       SolverOptions{})
            .solve();
};

/// Exact radiosity at probes across the penumbra, where at least a tenth of the lamp shows
/// (nearer the umbra the value falls to nothing and any relative error grows without bound).
std::vector<ReferencePoint> exact_penumbra() {
    std::vector<ReferencePoint> out;
    for (double u = 0.72; u < 1.6; u += 0.08) {
        const V x(u, 0.5, 0.0), n(0, 0, 1);
        const double lo = std::max(0.0, 1.6 - u);
        const std::vector<V> strip = {{lo, 0, 1}, {1, 0, 1}, {1, 1, 1}, {lo, 1, 1}};
        const double f = point_polygon_form_factor(x, n, strip);
        ReferencePoint p;
        p.position = x;
        p.normal = n;
        p.radiosity = Rgb(3, 2, 1) * (0.5 * f);
        p.standard_error = Rgb();
        p.paths = 1;
        p.surface = "plane";
        p.status = "converged";
        p.has_value = true;
        out.push_back(p);
    }
    return out;
}

/// The blocked lamp solved by hierarchical radiosity from about 30 patches (what `bounce solve
/// --adaptive` starts from) at `power_epsilon`, its point data gathered with `display`:
/// the score across the exact penumbra, and the cells it ends with.
ProbeScore adaptive_on_blocked_lamp(double power_epsilon, const DisplayRefinement& display, std::size_t& cell_count) {
    MeshingOptions coarse;
    coarse.target_patches = 30;
    const PatchMesh mesh(blocked_lamp(), coarse);
    const auto visibility = make_visibility("embree", mesh.patches());
    HierarchicalOptions h;
    h.power_epsilon = power_epsilon;
    HierarchicalSolution sol = solve_hierarchical(mesh.patches(), *visibility, h);
    PatchMesh cells = sol.tree.conforming_mesh(sol.leaves);
    SolveResult res = sol.result;
    EXPECT_EQ(gather_hierarchical_point_values(sol, cells, *visibility, res, "vertices", display),
              GatherOutcome::gathered);
    cell_count = cells.size();
    return score_at_probes(cells, res.radiosity, exact_penumbra(), res.point_radiosity);
}

}  // namespace

TEST(Penumbra, TheDefaultRunsPointDataFollowsABlockersPenumbra) {
    const Scene scene = blocked_lamp();
    const PatchMesh mesh(scene, MeshingOptions{});
    const auto visibility = make_visibility("embree", mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), visibility.get(), {});
    SolveResult res = ShootingSolver(mesh.patches(), *ff, SolverOptions{}).solve();
    ASSERT_EQ(gather_point_values(mesh, *visibility, res, "vertices"), GatherOutcome::gathered);
    const auto reference = exact_penumbra();
    const ProbeScore s = score_at_probes(mesh, res.radiosity, reference, res.point_radiosity);
    std::cout << mesh.size() << " patches: point data " << s.rms_smooth << " RMS, " << s.max_smooth
              << " worst; patch values " << s.rms_patch << " RMS, " << s.max_patch << " worst\n";
    ASSERT_EQ(s.scored, reference.size());
    EXPECT_LE(s.max_smooth, 0.03);
}

TEST(Penumbra, AdaptivePointDataFollowsABlockersPenumbra) {
    std::size_t cells = 0;
    const ProbeScore s = adaptive_on_blocked_lamp(adaptive_power_epsilon(0.0),
                                                  DisplayRefinement{adaptive_display_tolerance(std::nullopt)}, cells);
    std::cout << cells << " cells: point data " << s.rms_smooth << " RMS, " << s.max_smooth << " worst; patch values "
              << s.rms_patch << " RMS, " << s.max_patch << " worst\n";
    ASSERT_EQ(s.scored, exact_penumbra().size());
    EXPECT_LE(s.max_smooth, 0.03);
}

TEST(Penumbra, DisplayRefinementFollowsThePenumbraOnCoarsePatches) {
    // About 300 patches: the penumbra (1 wide) spans three or four of them, and linear
    // interpolation between their vertices misses its curve; display cells gathered at their
    // own vertices follow it, and so do the cells' values, which share their patch's light
    // (each patch's power stays the solve's). (What is left is the gather's: 16 rays to each
    // of the lamp's dozen patches.)
    const CoarseBlockedLamp lamp;
    const PatchMesh& mesh = lamp.mesh;
    const Visibility* visibility = lamp.visibility.get();
    const SolveResult& solved = lamp.solved;
    const auto reference = exact_penumbra();
    SolveResult plain = solved;
    ASSERT_EQ(gather_point_values(mesh, *visibility, plain, "vertices"), GatherOutcome::gathered);
    const ProbeScore before = score_at_probes(mesh, plain.radiosity, reference, plain.point_radiosity);
    PatchMesh cells = mesh;
    SolveResult refined = solved;
    ASSERT_EQ(gather_point_values(cells, *visibility, refined, "vertices", PatchDisplayRefinement{0.02}),
              GatherOutcome::gathered);
    const ProbeScore after = score_at_probes(cells, refined.radiosity, reference, refined.point_radiosity);
    std::cout << mesh.size() << " patches: point data " << before.rms_smooth << " RMS, " << before.max_smooth
              << " worst; " << cells.size() << " display cells: " << after.rms_smooth << " RMS, " << after.max_smooth
              << " worst; cell values " << before.rms_patch << " -> " << after.rms_patch << " RMS\n";
    ASSERT_EQ(after.scored, reference.size());
    EXPECT_GT(before.max_smooth, 0.2);
    EXPECT_LE(after.max_smooth, 0.05);
    EXPECT_LE(after.rms_smooth, 0.02);
    // The cells share their patch's light by the point data: their own values follow it too.
    EXPECT_LT(after.rms_patch, 0.7 * before.rms_patch);
    EXPECT_GT(cells.size(), mesh.size());
    ASSERT_EQ(refined.radiosity.size(), cells.size());
    ASSERT_EQ(refined.point_radiosity.size(), cells.mesh().n_vertices());
    // The cells tile the patches and carry their radiosity: area and power as solved.
    double area = 0, cell_area = 0;
    Rgb power, cell_power;
    for (std::size_t i = 0; i < mesh.size(); ++i) {
        area += mesh.patches()[i].area;
        power += solved.radiosity[i] * mesh.patches()[i].area;
    }
    for (std::size_t i = 0; i < cells.size(); ++i) {
        cell_area += cells.patches()[i].area;
        cell_power += refined.radiosity[i] * cells.patches()[i].area;
    }
    EXPECT_NEAR(cell_area, area, 1e-12 * area);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(cell_power[c], power[c], 1e-12 * power[c]);
}

TEST(Penumbra, APatchWhoseMeanMatchesItsCornersIsSplitWhereTheyDisagree) {
    // Each patch's value is set to the mean of its gathered corners, so the mean test finds
    // nothing to split: the patches the penumbra crosses (corners far apart) must be tried
    // all the same. With the corner test off (a spread above 1) nothing is split and the
    // interpolation misses the penumbra's curve by a third; the corner test alone brings the
    // worst probe under a tenth, the rest being the mean test's (the test above: both, 5%).
    const CoarseBlockedLamp lamp;
    const PatchMesh& mesh = lamp.mesh;
    const Visibility* visibility = lamp.visibility.get();
    SolveResult solved = lamp.solved;
    ASSERT_EQ(gather_point_values(mesh, *visibility, solved, "vertices"), GatherOutcome::gathered);
    for (std::size_t p = 0; p < mesh.size(); ++p) {
        Rgb mean;
        const std::vector<int> corners = mesh.patch_vertex_indices(p);
        for (const int v : corners) mean += solved.point_radiosity[std::size_t(v)] * (1.0 / double(corners.size()));
        solved.radiosity[p] = mean;
    }
    const auto reference = exact_penumbra();
    const auto refine = [&](double spread, std::size_t& added) {
        PatchMesh cells = mesh;
        SolveResult r = solved;
        PatchDisplayRefinement o{0.02};
        o.corner_spread = spread;
        added = refine_patch_display(cells, r, *visibility, o);
        return score_at_probes(cells, r.radiosity, reference, r.point_radiosity);
    };
    std::size_t with = 0, without = 0;
    const ProbeScore split = refine(PatchDisplayRefinement{}.corner_spread, with), kept = refine(2.0, without);
    std::cout << "means set to the corners': corner test on " << with << " cells added, worst " << split.max_smooth
              << "; off " << without << " added, worst " << kept.max_smooth << "\n";
    EXPECT_EQ(without, 0u);
    EXPECT_GT(with, 0u);
    EXPECT_GT(kept.max_smooth, 0.2);
    EXPECT_LE(split.max_smooth, 0.1);
}

TEST(Penumbra, AShortGatherBudgetSplitsTheCellsThatMissMost) {
    // A budget for 40 splits of the 314 patches (in a cluttered room most patches bend the
    // light and the budget runs out): the level that would pass it takes the patches whose
    // mean and corners disagree most, which the penumbra crosses, and is the last.
    const CoarseBlockedLamp lamp;
    const PatchMesh& mesh = lamp.mesh;
    SolveResult gathered = lamp.solved;
    ASSERT_EQ(gather_point_values(mesh, *lamp.visibility, gathered, "vertices"), GatherOutcome::gathered);
    const auto reference = exact_penumbra();
    const ProbeScore before = score_at_probes(mesh, gathered.radiosity, reference, gathered.point_radiosity);
    constexpr std::size_t kSplits = 40;
    PatchDisplayRefinement short_budget{0.02};
    short_budget.max_pairs = 5.0 * double(mesh.size()) * kSplits;
    PatchMesh cells = mesh;
    SolveResult refined = gathered;
    const std::size_t added = refine_patch_display(cells, refined, *lamp.visibility, short_budget);
    const ProbeScore after = score_at_probes(cells, refined.radiosity, reference, refined.point_radiosity);
    std::cout << mesh.size() << " patches, worst " << before.max_smooth << "; budget for " << kSplits
              << " splits: " << added << " cells added, worst " << after.max_smooth << ", RMS " << after.rms_smooth
              << "\n";
    ASSERT_EQ(after.scored, reference.size());
    EXPECT_GT(added, 0u);
    EXPECT_LE(added, 3 * kSplits);  // one level, at most kSplits splits of 4
    EXPECT_GT(before.max_smooth, 0.2);
    EXPECT_LE(after.max_smooth, 0.1);
}

TEST(Penumbra, AdaptiveDisplayPassesShareABudget) {
    // --adaptive's display passes share one budget (in a cluttered room most leaves miss at a
    // 0.25% tolerance, and every pass used to take up to the gather's whole budget): a pass
    // that would pass it splits the leaves that miss most first, and is the last. Coarse
    // leaves (power epsilon 1e-3) under a blocked lamp: a budget for a small share of the
    // passes adds a small share of their cells and still brings the penumbra's worst probe
    // closer to the exact light than no display cells do.
    const auto refine = [](double tolerance, double max_pairs, std::size_t& cell_count) {
        DisplayRefinement display{tolerance};
        display.max_pairs = max_pairs;
        return adaptive_on_blocked_lamp(1e-3, display, cell_count).max_smooth;
    };
    const double tolerance = adaptive_display_tolerance(std::nullopt);
    std::size_t plain_cells = 0, full_cells = 0, short_cells = 0;
    const double plain = refine(0.0, 0.0, plain_cells);
    const double full = refine(tolerance, 0.0, full_cells);
    const double short_budget = refine(tolerance, 1e5, short_cells);
    std::cout << "no display cells: " << plain_cells << " cells, worst " << plain << "; default budget " << full_cells
              << ", worst " << full << "; 1e5 pairs " << short_cells << ", worst " << short_budget << "\n";
    EXPECT_GT(full_cells, 2 * plain_cells);
    EXPECT_GT(short_cells, plain_cells);
    EXPECT_LT(short_cells - plain_cells, (full_cells - plain_cells) / 4);
    EXPECT_LT(short_budget, 0.75 * plain);
    EXPECT_LT(full, 0.5 * plain);
}
