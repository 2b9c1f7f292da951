// SPDX-License-Identifier: MIT
// The default run (`bounce solve` on the built-in Cornell box: uniform meshing to about 2000
// patches with contact cuts, ray-cast form factors, shooting to 1e-3 unshot, point data gathered
// at the vertices) scored against the shipped path-traced reference, 128 probes at 0.5%
// (examples/reference/cornell_probes_128.csv, written by `bounce reference --probes 128`).
// Issue 16's goal for that run: point data within 2% RMS and 10% at the worst probe, patch
// values within 5% RMS, in relative luminance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/gather/point_values.h"
#include "solver/linear/shooting_solver.h"
#include "solver/reference/path_tracer.h"
#include "solver/reference/probe_classes.h"
#include "solver/reference/probe_score.h"
#include "solver/reference/reference_csv.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

TEST(DefaultCornell, MeetsTheGoalAgainstThePathTracedReference) {
    const auto reference =
        read_reference(std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples/reference/cornell_probes_128.csv");
    ASSERT_EQ(reference.size(), 128u);
    const Scene scene = load_scene("cornell");
    const PatchMesh mesh(scene, MeshingOptions{});
    ASSERT_EQ(mesh.size(), 2186u);  // what `bounce solve` prints for the default run
    const auto visibility = make_visibility("embree", mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), visibility.get(), {});
    SolveResult res = ShootingSolver(mesh.patches(), *ff, SolverOptions{}).solve();
    ASSERT_TRUE(res.converged);
    ASSERT_EQ(gather_point_values(mesh, *visibility, res, "vertices"), GatherOutcome::gathered);
    const ProbeScore s = score_at_probes(mesh, res.radiosity, reference, res.point_radiosity);
    std::cout << "scored " << s.scored << " of 128 probes (noise " << s.reference_noise << "): patch values "
              << s.rms_patch << " RMS, " << s.max_patch << " max; point data " << s.rms_smooth << " RMS, "
              << s.max_smooth << " max\n";
    // Every probe is scored: the probes avoid edges and the floor under the blocks, so each lies
    // on a patch and is lit.
    EXPECT_EQ(s.scored, 128u);
    EXPECT_LE(s.rms_smooth, 0.02);
    EXPECT_LE(s.max_smooth, 0.10);
    EXPECT_LE(s.rms_patch, 0.05);
}

namespace {

/// The default run with its display cells, scored at a shipped class-balanced reference (192
/// probes path-traced to 0.5%, a quarter each lit, penumbra, unlit, contact), per class as
/// `bounce compare` scores it.
std::array<ClassScore, 4> default_run_by_class(const std::string& scene_name, const std::string& reference_csv,
                                               ProbeScore& all, std::uint64_t seed = 1,
                                               PatchDisplayRefinement cells = {kPatchDisplayTolerance}) {
    const auto reference = read_reference(std::filesystem::path(BOUNCE_SOURCE_DIR) / reference_csv);
    const Scene scene = load_scene(scene_name);
    PatchMesh mesh(scene, MeshingOptions{});
    const auto visibility = make_visibility("embree", mesh.patches());
    FormFactorOptions rays;
    rays.seed = seed;
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), visibility.get(), rays);
    SolveResult res = ShootingSolver(mesh.patches(), *ff, SolverOptions{}).solve();
    EXPECT_TRUE(res.converged);
    const std::size_t patches = mesh.size();
    EXPECT_EQ(gather_point_values(mesh, *visibility, res, "vertices", cells), GatherOutcome::gathered);
    EXPECT_GT(mesh.size(), patches) << "no display cells";
    all = score_at_probes(mesh, res.radiosity, reference, res.point_radiosity);
    const PathTracer tracer(scene);
    std::vector<ProbeClass> classes(reference.size(), ProbeClass::lit);
    for (std::size_t k = 0; k < reference.size(); ++k)
        if (const auto x = tracer.locate(reference[k].position, reference[k].normal))
            classes[k] = classify_probe(tracer, *x, k);
    const auto by_class = score_by_class(all, classes);
    std::cout << scene_name << ": " << patches << " patches, " << mesh.size() << " cells; point data " << all.rms_smooth
              << " RMS, " << all.max_smooth << " worst; cell values " << all.rms_patch << " RMS";
    for (std::size_t c = 0; c < 4; ++c)
        std::cout << "; " << to_string(kProbeClasses[c]) << " " << by_class[c].rms_smooth << " / "
                  << by_class[c].max_smooth << " (" << by_class[c].scored << ")";
    std::cout << "\n";
    return by_class;
}

}  // namespace

// Issue 34's goals where it is hard: point data within 1.5% RMS and 5% at the worst probe,
// penumbra probes within 3% RMS, the cells' values within 5% RMS.
// Where a block stands on the floor, the penumbra of its edge narrows to nothing at its foot: a
// step in the light that a 30 mm patch's cells, split twice (7.5 mm), straddle, so a probe a
// millimetre or two beside the line takes the other side's light from a corner across it, and
// a cell's value averages both sides. The cells a step still crosses are split on (step_depth)
// down to 2 mm along the lines; stopped at two splits, the cells' values are off by more.
TEST(DefaultCornell, DisplayCellsMeetThePointDataGoalsWhereItIsHard) {
    ProbeScore all, stopped;
    const auto by_class = default_run_by_class("cornell", "examples/reference/cornell_classes_192.csv", all);
    EXPECT_GE(all.scored, 180u);
    EXPECT_LE(all.rms_smooth, 0.015);
    EXPECT_LE(by_class[1].rms_smooth, 0.03);  // penumbra
    EXPECT_GE(by_class[1].scored, 40u);
    EXPECT_LE(all.rms_patch, 0.05);
    EXPECT_LE(all.max_smooth, 0.05);
    PatchDisplayRefinement two_splits{kPatchDisplayTolerance};
    two_splits.step_depth = 0;
    default_run_by_class("cornell", "examples/reference/cornell_classes_192.csv", stopped, 1, two_splits);
    EXPECT_GT(stopped.rms_patch, 0.08);
    EXPECT_LT(all.rms_smooth, stopped.rms_smooth);
}

// The display cells must not hang on the rays' luck: with other seeds a cell over the short
// block's foot, its mean matching its corners' mean by chance, went unsplit and carried the
// block corner's light 19 mm into the shadow beside it (50-60% off at a probe 5 mm above
// the floor). A patch whose corners disagree is tried split whatever its mean.
TEST(DefaultCornell, DisplayCellsHoldWithOtherRays) {
    for (const std::uint64_t seed : {2u, 4u}) {
        ProbeScore all;
        default_run_by_class("cornell", "examples/reference/cornell_classes_192.csv", all, seed);
        EXPECT_LE(all.rms_smooth, 0.02) << "seed " << seed;
        EXPECT_LE(all.max_smooth, 0.1) << "seed " << seed;
    }
}

TEST(DefaultStudy, DisplayCellsMeetThePointDataGoalsWhereItIsHard) {
    ProbeScore all;
    const auto by_class = default_run_by_class(std::string(BOUNCE_SOURCE_DIR) + "/examples/scenes/study.json",
                                               "examples/reference/study_classes_192.csv", all);
    EXPECT_GE(all.scored, 180u);
    EXPECT_LE(all.rms_smooth, 0.015);
    EXPECT_LE(by_class[1].rms_smooth, 0.03);
    EXPECT_GE(by_class[1].scored, 40u);
}

// The corridor's dark far leg, lit only by the walls, is path-traced to 1% per probe (the rest
// to 0.5%; the reference's own noise is 0.7% RMS over the probes): issue 34's goals of 1.5%
// RMS and 5% at the worst probe hold against it as they stand, with no allowance for noise.
TEST(DefaultCorridor, DisplayCellsMeetThePointDataGoalsWhereItIsHard) {
    ProbeScore all;
    const auto by_class = default_run_by_class(std::string(BOUNCE_SOURCE_DIR) + "/examples/scenes/corridor.obj",
                                               "examples/reference/corridor_classes_192.csv", all);
    EXPECT_GE(all.scored, 180u);
    EXPECT_LE(all.reference_noise, 0.01);
    EXPECT_LE(all.rms_smooth, 0.015);
    EXPECT_LE(all.max_smooth, 0.05);
    EXPECT_LE(by_class[1].rms_smooth, 0.03);
    EXPECT_GE(by_class[1].scored, 10u);  // its penumbrae are thin: 12 of its probes
}

// Where the short block stands on the floor, the block's side and the floor in front of it
// darken together towards their common edge, each by the dark strip of the other it sees most
// of: 34 points path-traced to 0.3% (examples/reference/cornell_block_foot.csv: 17 up the
// side at 0.3, 1, 2, ... 80 mm above the floor, then 17 out along the floor at the same
// distances from the side, written by `bounce reference cornell --points P.csv --target-error
// 0.003 --max-paths 4000000`). Gathered once from the 30 mm patches, each near patch sending its
// mean shaped by its corners, the point data was 31% (side) and 36% (floor) too bright 0.3 mm
// from the edge and 5% a centimetre up; the near field's passes over the display cells
// (PatchDisplayRefinement::near_field_passes) follow the darkening down to a millimetre from
// the edge. At 0.3 mm the side is still about 9% bright: its lowest vertex holds the value at
// the point it was first gathered at, a tenth of the way into the patches around it (3 mm).
TEST(DefaultCornell, PointDataFollowTheDarkeningIntoTheBlocksFoot) {
    const auto reference =
        read_reference(std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples/reference/cornell_block_foot.csv");
    ASSERT_EQ(reference.size(), 34u);
    const auto run = [&](int passes) {
        PatchMesh mesh(load_scene("cornell"), MeshingOptions{});
        const auto visibility = make_visibility("embree", mesh.patches());
        const auto ff = make_form_factor_estimator("raycast", mesh.patches(), visibility.get(), {});
        SolveResult res = ShootingSolver(mesh.patches(), *ff, SolverOptions{}).solve();
        PatchDisplayRefinement cells{kPatchDisplayTolerance};
        cells.near_field_passes = passes;
        EXPECT_EQ(gather_point_values(mesh, *visibility, res, "vertices", cells), GatherOutcome::gathered);
        return score_at_probes(mesh, res.radiosity, reference, res.point_radiosity);
    };
    const ProbeScore s = run(PatchDisplayRefinement{}.near_field_passes);
    std::cout << "block foot: point data " << s.rms_smooth << " RMS, " << s.max_smooth << " worst (noise "
              << s.reference_noise << ")\n";
    EXPECT_EQ(s.scored, 34u);
    EXPECT_LE(s.rms_smooth, 0.03);
    for (std::size_t k = 0; k < s.smooth_error.size(); ++k)
        if (k % 17 != 0) {  // a millimetre or more from the edge: issue 34's 5%
            EXPECT_LE(std::abs(s.smooth_error[k]), 0.05) << "point " << k;
        }
    const ProbeScore once = run(0);
    std::cout << "block foot, gathered once: point data " << once.rms_smooth << " RMS, " << once.max_smooth
              << " worst\n";
    EXPECT_GT(once.rms_smooth, 3 * s.rms_smooth);
    EXPECT_GT(once.max_smooth, 3 * s.max_smooth);
}
