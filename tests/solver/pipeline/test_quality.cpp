// SPDX-License-Identifier: MIT
// The quality presets (quality.h): their names, what each sets and what it yields to, the
// standard one changing nothing, and a coarse preset being further from a closed form than a
// fine one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mesh/readers/scene_loader.h"
#include "mesh/scene/errors.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/gather/patch_display_refinement.h"
#include "solver/pipeline/quality.h"
#include "solver/pipeline/solve_scene.h"
#include "test_util.h"

using namespace bounce;

namespace {

/// A 2 x 2 floor (rho 0.5) under a 0.5 x 0.5 lamp (E 1, rho 0) facing it 0.5 above, in the
/// open: light reaches the floor only straight from the lamp, and the floor's light returns to
/// the black lamp only. The floor's radiosity is then rho E F(x -> lamp), Lambert's formula.
const char* kLampOverFloor = R"({"name": "lamp over a floor",
    "materials": {"grey": {"reflectance": 0.5}, "lamp": {"reflectance": 0, "emission": 1}},
    "objects": [
      {"type": "quad", "material": "grey", "transform": {"scale": 2}},
      {"type": "quad", "material": "lamp",
       "transform": {"scale": 0.5, "rotate": {"axis": [1, 0, 0], "degrees": 180}, "translate": [0, 0, 0.5]}}]})";

/// The message `f` throws as InputError ("" when it throws none).
template <class F>
std::string refusal(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// RMS relative error of the point data, interpolated at each floor cell's centre as a viewer
/// shows it (the mean of the cell's corners), against rho E F(centre -> lamp).
double floor_point_data_error(const SolvedScene& s) {
    const std::vector<glm::dvec3> lamp = {
        {-0.25, 0.25, 0.5}, {0.25, 0.25, 0.5}, {0.25, -0.25, 0.5}, {-0.25, -0.25, 0.5}};
    double sum = 0.0;
    int cells = 0;
    for (std::size_t p = 0; p < s.mesh->size(); ++p) {
        const Patch& cell = s.mesh->patches()[p];
        if (cell.normal.z < 0.5) continue;  // the lamp's cells face down
        double shown = 0.0;
        const std::vector<int> corners = s.mesh->patch_vertex_indices(p);
        for (const int v : corners) shown += s.result.point_radiosity[std::size_t(v)].r / double(corners.size());
        const double exact = 0.5 * point_polygon_form_factor(cell.centre, cell.normal, lamp);
        sum += std::pow(shown / exact - 1.0, 2);
        ++cells;
    }
    return std::sqrt(sum / cells);
}

}  // namespace

TEST(Quality, NamesRoundTripAndAnUnknownOneListsTheValidOnes) {
    EXPECT_EQ(quality_names(), (std::vector<std::string>{"draft", "default", "fine"}));
    for (const auto& name : quality_names()) EXPECT_EQ(to_string(parse_quality(name)), name);
    EXPECT_EQ(refusal([] { parse_quality("best"); }),
              "--quality: unknown, got 'best' (expected one of draft, default, fine)");
    EXPECT_EQ(refusal([] { parse_quality("Fine", OptionNames::python()); }),
              "quality: unknown, got 'Fine' (expected one of draft, default, fine)");
}

TEST(Quality, TheDefaultPresetLeavesTheRequestAsItIs) {
    SolveRequest r;
    r.quality = Quality::standard;
    apply_quality(r, false);
    EXPECT_TRUE(same_meshing(r.meshing, SolveRequest{}.meshing));
    EXPECT_FALSE(r.display_tolerance);
    EXPECT_DOUBLE_EQ(r.patch_display_tolerance(), kPatchDisplayTolerance);
    EXPECT_EQ(quality_preset(Quality::standard).flags, "");
    // It combines with every solver, as no preset does.
    r.adaptive = true;
    EXPECT_EQ(refusal([&] { r.validate(); }), "");
}

TEST(Quality, PresetsSetTheirPatchCountAndDisplayCellsUnlessGiven) {
    SolveRequest draft;
    draft.quality = Quality::draft;
    apply_quality(draft, false);
    EXPECT_EQ(draft.meshing.target_patches, 1000u);
    EXPECT_DOUBLE_EQ(draft.patch_display_tolerance(), 0.02);
    SolveRequest fine;
    fine.quality = Quality::fine;
    apply_quality(fine, false);
    EXPECT_EQ(fine.meshing.target_patches, 8000u);
    EXPECT_DOUBLE_EQ(fine.patch_display_tolerance(), 0.01);
    // Given options win: a meshing (patches, max_area or max_edge) and a display tolerance.
    SolveRequest given;
    given.quality = Quality::fine;
    given.meshing.target_patches = 300;
    given.display_tolerance = 0.05;
    apply_quality(given, true);
    EXPECT_EQ(given.meshing.target_patches, 300u);
    EXPECT_DOUBLE_EQ(*given.display_tolerance, 0.05);
    // Display cells stay off where they are off by default (elements, a series, no gather),
    // so the preset adds no refusal.
    for (auto set : {+[](SolveRequest& r) { r.element_split = 2; }, +[](SolveRequest& r) { r.series = 10; },
                     +[](SolveRequest& r) { r.gather = GatherMode::none; }}) {
        SolveRequest r;
        r.quality = Quality::fine;
        set(r);
        apply_quality(r, false);
        EXPECT_FALSE(r.display_tolerance);
        EXPECT_EQ(refusal([&] { r.validate(); }), "");
    }
    // The presets are patch-solver settings: with the element solvers they are refused.
    fine.solver = SolverKind::hierarchical;
    EXPECT_EQ(refusal([&] { fine.validate(); }),
              "--quality fine sets the patch solvers' patches and display cells: it does not combine with "
              "--adaptive or hierarchical");
}

TEST(Quality, TheDefaultPresetSolvesToTheSameBitsAsNone) {
    test::TempDir dir;
    const Scene scene = load_scene(dir.write("lamp.json", kLampOverFloor).string());
    SolveRequest none;
    SolveRequest standard;
    standard.quality = Quality::standard;
    apply_quality(standard, false);
    const SolvedScene a = solve_scene(scene, none), b = solve_scene(scene, standard);
    EXPECT_EQ(a.settings, b.settings);
    EXPECT_EQ(a.settings.find("quality"), std::string::npos) << a.settings;
    ASSERT_EQ(a.result.radiosity.size(), b.result.radiosity.size());
    for (std::size_t i = 0; i < a.result.radiosity.size(); ++i)
        ASSERT_EQ(a.result.radiosity[i], b.result.radiosity[i]) << "cell " << i;
    ASSERT_EQ(a.result.point_radiosity.size(), b.result.point_radiosity.size());
    for (std::size_t v = 0; v < a.result.point_radiosity.size(); ++v)
        ASSERT_EQ(a.result.point_radiosity[v], b.result.point_radiosity[v]) << "vertex " << v;
}

TEST(Quality, DraftIsFurtherFromLambertsFormulaThanFine) {
    // The floor's light falls off smoothly away from the lamp: the point data interpolated
    // inside a cell errs by about the curvature times the cell's size squared, so the draft's
    // larger cells must be further off than the fine preset's.
    test::TempDir dir;
    const Scene scene = load_scene(dir.write("lamp.json", kLampOverFloor).string());
    std::vector<double> errors;
    for (const Quality q : {Quality::draft, Quality::standard, Quality::fine}) {
        SolveRequest r;
        r.quality = q;
        apply_quality(r, false);
        const SolvedScene s = solve_scene(scene, r);
        MeshingOptions m;
        m.target_patches = quality_preset(q).patches;
        EXPECT_EQ(s.patches, PatchMesh(scene, m).size());
        if (q != Quality::standard) {
            EXPECT_NE(s.settings.find(" quality=" + to_string(q)), std::string::npos) << s.settings;
        }
        errors.push_back(floor_point_data_error(s));
        std::printf("%s: %zu patches, %zu cells, point data RMS %.3g%% at the floor cells' centres\n",
                    to_string(q).c_str(), s.patches, s.mesh->size(), 100 * errors.back());
    }
    EXPECT_GT(errors[0], 1.5 * errors[1]);
    EXPECT_GT(errors[1], 1.5 * errors[2]);
    EXPECT_LT(errors[0], 0.01);
}
