// SPDX-License-Identifier: MIT
// The solve pipeline: requests refused in each front end's words, the names of the enums,
// the hierarchical solver's coarse roots, and the warnings the command line prints being the
// pipeline's own.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "mesh/readers/json_scene.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/errors.h"
#include "scene_as_obj.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/gather/point_values.h"
#include "solver/linear/solver.h"
#include "solver/pipeline/solve_scene.h"
#include "solver/reference/path_tracer.h"
#include "solver/reference/probe_classes.h"
#include "solver/reference/probe_score.h"
#include "solver/reference/reference_csv.h"
#include "test_util.h"

using namespace bounce;

namespace {

/// The message validate() throws ("" when it accepts the request).
std::string refusal(const SolveRequest& r, const OptionNames& names = {}) {
    try {
        r.validate(names);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// A closed box of reflectance 0.9 that glows (the furnace): every row of exact form factors
/// sums to 1, so a coarse hemicube's rows above 1 show as energy gained.
const char* kFurnace = R"({"name": "furnace", "materials": {"glow": {"reflectance": 0.9, "emission": 1}},
    "objects": [{"type": "box", "material": "glow", "inward": true, "transform": {"scale": [2, 1.5, 1]}}]})";

/// The lines of `text` that start with `prefix`, the prefix cut off.
std::vector<std::string> lines_after(const std::string& text, const std::string& prefix) {
    std::vector<std::string> lines;
    for (std::size_t at = 0; at < text.size();) {
        const std::size_t end = std::min(text.find('\n', at), text.size());
        const std::string line = text.substr(at, end - at);
        if (line.rfind(prefix, 0) == 0) lines.push_back(line.substr(prefix.size()));
        at = end + 1;
    }
    return lines;
}

/// Every face of a closed 2 m box and of a block floating in it emits 1 and reflects 0.9.
Scene furnace_with_a_block() {
    test::TempDir tmp;
    const auto path = tmp.write("furnace.json", R"({"name": "furnace with a block",
      "materials": {"glow": {"reflectance": 0.9, "emission": 1}},
      "objects": [
        {"type": "box", "material": "glow", "inward": true, "transform": {"scale": 2, "translate": [1, 1, 1]}},
        {"type": "box", "material": "glow", "transform": {"scale": 0.8, "translate": [1, 1, 0.9]}}]})");
    return load_scene(path.string());
}

}  // namespace

TEST(SolveRequest, EnumNamesAreTheFactoriesNames) {
    std::vector<std::string> solvers = solver_names();
    solvers.push_back("hierarchical");
    EXPECT_EQ(solver_kind_names(), solvers);
    auto methods = form_factor_method_names(), known = form_factor_methods();
    std::sort(methods.begin(), methods.end());
    std::sort(known.begin(), known.end());
    EXPECT_EQ(methods, known);
    EXPECT_EQ(gather_mode_names(), gather_modes());
    for (const auto& name : solver_kind_names()) EXPECT_EQ(to_string(parse_solver_kind(name)), name);
    EXPECT_EQ(parse_gather_mode("centres"), GatherMode::centres);
}

TEST(SolveRequest, RefusesInEachFrontEndsWords) {
    SolveRequest r;
    EXPECT_EQ(refusal(r), "");
    r.solver = SolverKind::gauss_seidel;
    r.adaptive = true;
    EXPECT_EQ(refusal(r), "--adaptive is the hierarchical solver: it takes no other (got --solver gauss-seidel)");
    r = SolveRequest{};
    r.solver = SolverKind::hierarchical;
    r.sor = 1.2;
    EXPECT_EQ(refusal(r), "--sor applies to the patch solvers, not to --adaptive or hierarchical");
    EXPECT_EQ(refusal(r, OptionNames::python()), "sor applies to the patch solvers, not to adaptive or hierarchical");
    r = SolveRequest{};
    r.display_tolerance = 0.0025;
    r.series = 5;
    EXPECT_EQ(refusal(r), "--display-tolerance does not combine with --elements or --series");
    r.series.reset();
    r.solver = SolverKind::hierarchical;
    r.gather = GatherMode::none;
    EXPECT_EQ(refusal(r, OptionNames::python()),
              "display_tolerance refines the point data gathered at the vertices: it needs gather vertices (got none)");
    r = SolveRequest{};
    r.form_factors.visibility_rays = 5000;
    EXPECT_EQ(refusal(r, OptionNames::python()), "rays: out of range, got 5000 (expected 1 to 4096)");
    r = SolveRequest{};
    r.retired.push_back("target-error");
    EXPECT_EQ(refusal(r),
              "--target-error belonged to the receiver-only refinement --adaptive ran before, now retired: "
              "--adaptive is the hierarchical solver refining on power; set --power-epsilon (with --adaptive 1e-05 "
              "unless given)");
    r = SolveRequest{};
    r.element_split = 2;
    r.method = FormFactorMethod::exact;
    EXPECT_EQ(refusal(r), "--elements needs the shooting solver and raycast or analytic form factors");
    try {
        parse_solver_kind("newton", OptionNames::python());
        FAIL() << "newton parsed";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "solver: unknown, got 'newton' (expected one of shooting, gauss-seidel, jacobi, direct, "
                  "hierarchical)");
    }
}

TEST(SolveScene, HierarchicalStartsFromCoarseRootsUnlessTheMeshingIsGiven) {
    // The default meshing (2000 patches) would be the roots of thousands of quadtrees: the
    // hierarchical solver cuts kCoarseTargetPatches roots instead (90 on the box, whose
    // contact cuts split some faces), and a given patch count as asked.
    const Scene scene = load_scene("cornell");
    SolveRequest r;
    r.solver = SolverKind::hierarchical;
    r.max_level = 1;
    r.gather = GatherMode::none;
    const SolvedScene coarse = solve_scene(scene, r);
    EXPECT_EQ(coarse.patches, 90u);
    ASSERT_TRUE(coarse.hierarchy);
    EXPECT_EQ(coarse.mesh->size(), coarse.hierarchy->leaves);
    EXPECT_GT(coarse.hierarchy->leaves, coarse.patches);
    r.meshing.target_patches = 200;
    const SolvedScene given = solve_scene(scene, r);
    MeshingOptions m;
    m.target_patches = 200;
    EXPECT_EQ(given.patches, PatchMesh(scene, m).size());
    EXPECT_GT(given.patches, 150u);
    EXPECT_EQ(
        given.settings.rfind("patches=" + std::to_string(given.patches) + " rays=4 seed=1 solver=hierarchical", 0), 0u)
        << given.settings;
}

TEST(SolveScene, ShotRowsAboveOneWarnAsTheCommandLinePrints) {
    // A 16-pixel hemicube overshoots each row by about 2e-3: on whole patches the pipeline
    // warns, and the command line prints exactly its warnings, each after "warning: ". On open
    // parts (the default) every closed row is scaled to send exactly what it has: no surplus.
    test::TempDir dir;
    const auto path = dir.write("furnace.json", kFurnace);
    SolveRequest r;
    r.open_parts = false;
    r.meshing.target_patches = 216;
    r.method = FormFactorMethod::hemicube;
    r.form_factors.hemicube_resolution = 16;
    r.gather = GatherMode::none;
    const SolvedScene solved = solve_scene(load_scene(path.string()), r);
    ASSERT_EQ(solved.warnings.size(), 1u);
    const std::string prefix = "the form-factor rows of the shots sum to 1 + ";
    ASSERT_EQ(solved.warnings[0].rfind(prefix, 0), 0u) << solved.warnings[0];
    const double surplus = std::stod(solved.warnings[0].substr(prefix.size()));
    std::printf("shot rows sum to 1 + %.3g\n", surplus);
    EXPECT_GT(surplus, 1e-3);
    EXPECT_LT(surplus, 1e-2);
    const auto cli = test::run(std::string(BOUNCE_EXE) + " solve " + path.string() +
                               " --patches 216 --form-factors hemicube --hemicube-res 16 --gather none "
                               "--whole-patches -o " +
                               (dir / "f.vtu").string());
    ASSERT_EQ(cli.exit_code, 0) << cli.err;
    EXPECT_EQ(lines_after(cli.err, "warning: "), solved.warnings) << cli.err;
    // Open parts: no surplus, nothing escapes or is gained.
    r.open_parts = true;
    const SolvedScene open = solve_scene(load_scene(path.string()), r);
    EXPECT_TRUE(open.warnings.empty());
    for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(open.result.escaped_power[c]) / open.result.emitted_power[c], 1e-9);
    // Exact rows: no warning from either.
    r.open_parts = false;
    r.method = FormFactorMethod::exact;
    EXPECT_TRUE(solve_scene(load_scene(path.string()), r).warnings.empty());
}

TEST(SolveScene, ShootingRefusedItsBalancedMatrixShootsRowsAsSampledAndSaysSo) {
    // Shooting builds the whole matrix (n^2 floats) to balance its rows, so it asks the memory
    // check first, as the matrix solvers do. Allowed, it balances; refused, it shoots the rows
    // as sampled, bit for bit as balance false does, and warns with the check's reason. The
    // command line's check is --max-memory: 1000 patches' matrix (4 MB) is over 2 MB.
    test::TempDir dir;
    const Scene scene = load_scene(dir.write("furnace.json", kFurnace).string());
    SolveRequest r;
    r.meshing.target_patches = 216;
    r.gather = GatherMode::none;
    std::vector<std::pair<std::string, double>> asked;
    bool allow = true;
    SolveHooks hooks;
    hooks.check_memory = [&](const std::string& what, double bytes) {
        asked.emplace_back(what, bytes);
        if (!allow) throw ResourceLimitError(what + " is over the limit");
    };
    const SolvedScene balanced = solve_scene(scene, r, hooks);
    const std::string matrix = "the balanced form-factor matrix (" + std::to_string(balanced.patches) + " patches)";
    ASSERT_EQ(asked.size(), 1u);
    EXPECT_EQ(asked[0].first, matrix);
    EXPECT_EQ(asked[0].second, 4.0 * double(balanced.patches) * double(balanced.patches));
    EXPECT_NE(balanced.settings.find(" open_parts=1 balanced=1"), std::string::npos) << balanced.settings;
    EXPECT_TRUE(balanced.warnings.empty());
    allow = false;
    const SolvedScene refused = solve_scene(scene, r, hooks);
    EXPECT_TRUE(refused.result.converged);
    EXPECT_EQ(refused.settings.find("balanced="), std::string::npos) << refused.settings;
    EXPECT_EQ(refused.warnings,
              std::vector<std::string>{matrix + " is over the limit: shooting on rows as sampled, "
                                                "computed as it shoots, not balanced (as --no-balance)"});
    r.balance = false;
    const SolvedScene sampled = solve_scene(scene, r);
    EXPECT_EQ(refused.settings, sampled.settings);
    EXPECT_EQ(refused.result.radiosity, sampled.result.radiosity);
    EXPECT_NE(balanced.result.radiosity, sampled.result.radiosity);
    const auto cli = test::run(std::string(BOUNCE_EXE) + " solve --patches 1000 --max-memory 2 --gather none -o " +
                               (dir / "c.vtu").string());
    ASSERT_EQ(cli.exit_code, 0) << cli.err;
    const auto warnings = lines_after(cli.err, "warning: ");
    ASSERT_EQ(warnings.size(), 1u) << cli.err;
    EXPECT_EQ(warnings[0].rfind("the balanced form-factor matrix (", 0), 0u) << warnings[0];
    EXPECT_NE(warnings[0].find(" MB, over --max-memory 2 MB: shooting on rows as sampled"), std::string::npos)
        << warnings[0];
}

TEST(SolveScene, GatheringSolverWarnsWhenRowsSumAboveOne) {
    // With the whole matrix the rows are summed before solving: the same hemicube's rows
    // exceed 1 by more than 1e-3 somewhere, unless balanced (every part of the closed box is
    // closed, so every balanced row sums to one).
    test::TempDir dir;
    const auto path = dir.write("furnace.json", kFurnace);
    SolveRequest r;
    r.meshing.target_patches = 216;
    r.solver = SolverKind::gauss_seidel;
    r.method = FormFactorMethod::hemicube;
    r.form_factors.hemicube_resolution = 16;
    r.gather = GatherMode::none;
    r.balance = false;
    const Scene scene = load_scene(path.string());
    const SolvedScene solved = solve_scene(scene, r);
    ASSERT_FALSE(solved.warnings.empty());
    EXPECT_EQ(solved.warnings[0].rfind("form-factor rows sum to up to 1 + ", 0), 0u) << solved.warnings[0];
    EXPECT_GT(solved.form_factor_seconds, 0.0);
    r.balance = true;
    const SolvedScene balanced = solve_scene(scene, r);
    for (const auto& w : balanced.warnings) EXPECT_EQ(w.find("form-factor rows sum"), std::string::npos) << w;
}

TEST(SolveScene, CancelledBeforeTheSolveReturnsTheStartingState) {
    // A set flag stops the shooting at its first check: status interrupted, no point gather.
    std::atomic<bool> cancel{true};
    SolveHooks hooks;
    hooks.cancel = &cancel;
    SolveRequest r;
    r.meshing.target_patches = 100;
    const SolvedScene solved = solve_scene(load_scene("cornell"), r, hooks);
    EXPECT_EQ(to_string(solved.result.status), "interrupted");
    EXPECT_FALSE(solved.gathered);
    EXPECT_TRUE(solved.result.point_radiosity.empty());
}

TEST(SolveScene, AClosedRoomWithBoxesThatTouchAndCrossLosesNoLight) {
    // A closed 6 x 3 x 6 room lit by a one-sided lamp hung 10 cm below its ceiling, with boxes
    // that rest on the floor, touch each other, cross each other in the air, and pass through
    // the floor and a wall. Nothing can leave a closed room: what the lamp's black back
    // absorbs is absorbed, not escaped. Default request (open parts), shooting and
    // Gauss-Seidel; whole patches lose what their rows miss.
    test::TempDir tmp;
    const auto path = tmp.write("room.json", R"({"name": "room", "materials": {
        "wall": {"reflectance": 0.7}, "grey": {"reflectance": [0.5, 0.4, 0.3]},
        "lamp": {"reflectance": 0, "emission": 10}},
      "objects": [
        {"type": "box", "material": "wall", "inward": true, "transform": {"scale": [6, 3, 6], "translate": [0, 1.5, 0]}},
        {"type": "quad", "material": "lamp",
         "transform": {"scale": 1, "rotate": {"axis": [1, 0, 0], "degrees": 90}, "translate": [0, 2.9, 0]}},
        {"type": "box", "material": "grey", "transform": {"scale": 1, "translate": [-2, 0.5, -2]}},
        {"type": "box", "material": "grey", "transform": {"scale": [1, 0.6, 1], "translate": [-1, 0.3, -2]}},
        {"type": "box", "material": "grey", "transform": {"scale": [1.2, 1, 0.8], "translate": [1.5, 0.3, 1.5]}},
        {"type": "box", "material": "grey", "transform": {"scale": [0.8, 2, 0.8],
         "rotate": {"axis": [0, 1, 0], "degrees": 30}, "translate": [1.8, 0.8, 1.2]}},
        {"type": "box", "material": "grey", "transform": {"scale": 1, "translate": [2.8, 1.2, -1.5]}},
        {"type": "box", "material": "grey", "transform": {"scale": 0.7,
         "rotate": {"axis": [1, 1, 0], "degrees": 40}, "translate": [-1.5, 1.6, 1.5]}},
        {"type": "box", "material": "grey", "transform": {"scale": 0.5,
         "rotate": {"axis": [0, 0, 1], "degrees": 20}, "translate": [-1.3, 1.8, 1.7]}},
        {"type": "box", "material": "grey", "transform": {"scale": [0.6, 0.3, 0.6],
         "rotate": {"axis": [1, 0, 1], "degrees": 35}, "translate": [0.4, 2.3, -0.6]}},
        {"type": "box", "material": "grey", "transform": {"scale": [0.5, 0.8, 0.4],
         "rotate": {"axis": [0, 1, 1], "degrees": 50}, "translate": [0.7, 2.2, -0.4]}}]})");
    const Scene scene = load_scene(path.string());
    // The escaped share of the emitted power, per channel the largest and the smallest
    // (negative: light made).
    struct Escape {
        double most = -1.0, least = 1.0;
        double worst() const { return std::max(std::abs(most), std::abs(least)); }
    };
    const auto loss = [&](SolverKind solver, bool open, bool adaptive = false) {
        SolveRequest r;
        r.solver = solver;
        r.open_parts = open;
        r.adaptive = adaptive;
        r.gather = GatherMode::none;
        const SolveResult res = solve_scene(scene, r).result;
        Escape x;
        for (int c = 0; c < 3; ++c) {
            const double e = res.emitted_power[c];
            EXPECT_NEAR((res.absorbed_power[c] + res.escaped_power[c] + res.unshot_power[c]) / e, 1.0, 1e-9);
            x.most = std::max(x.most, res.escaped_power[c] / e);
            x.least = std::min(x.least, res.escaped_power[c] / e);
        }
        return x;
    };
    const Escape shooting = loss(SolverKind::shooting, true), gathering = loss(SolverKind::gauss_seidel, true),
                 whole = loss(SolverKind::shooting, false), adaptive = loss(SolverKind::hierarchical, true, true),
                 whole_elements = loss(SolverKind::hierarchical, false, true);
    std::printf(
        "closed room with boxes: escaped share %.2e (shooting), %.2e (gauss-seidel), %.2e to %.2e (adaptive); "
        "whole patches %.2e, whole elements %.2e\n",
        shooting.worst(), gathering.worst(), adaptive.least, adaptive.most, whole.most, whole_elements.most);
    EXPECT_LE(shooting.worst(), 1e-3);
    EXPECT_LE(gathering.worst(), 1e-3);
    // The hierarchy's elements on their open parts lose nothing either. (A link hands every
    // leaf under it its end's mean form factor, so where a leaf's radiosity varies over the
    // linked element the hierarchy can make light: the issue tracks that, and
    // ElementOpenShares.AFurnaceWithACabinetIsFlatAndKeepsItsLight bounds it in a furnace.)
    EXPECT_LE(adaptive.most, 1e-3);
    EXPECT_GT(whole.most, 1e-3);
    EXPECT_GT(whole_elements.most, 1e-3);
}

TEST(SolveScene, ABrightClosedBoxWithALampUnderItsCeilingConvergesAndKeepsItsLight) {
    // Walls at rho 0.99, a block resting on the floor, a lamp hung 1 cm below the ceiling: the
    // contact cuts leave the ceiling behind the lamp out, and rays that graze into the gap pass
    // where it was. That light is absorbed there (between the ceiling and the lamp's black
    // back), not escaped; 1 / (1 - rho) = 100 amplifies any leak. The defaults converge.
    test::TempDir tmp;
    const auto path = tmp.write("bright.json", R"({"name": "bright box", "materials": {
        "w": {"reflectance": 0.99}, "lamp": {"reflectance": 0, "emission": 10}},
      "objects": [{"type": "box", "material": "w", "inward": true, "transform": {"scale": 2}},
        {"type": "box", "material": "w", "transform": {"scale": 0.5, "translate": [0.3, -0.75, 0.2]}},
        {"type": "quad", "material": "lamp",
         "transform": {"scale": 0.5, "rotate": {"axis": [1, 0, 0], "degrees": 90}, "translate": [0, 0.99, 0]}}]})");
    const Scene scene = load_scene(path.string());
    ASSERT_FALSE(scene.covered.empty());
    SolveRequest r;
    r.gather = GatherMode::none;
    const SolveResult res = solve_scene(scene, r).result;
    EXPECT_TRUE(res.converged) << to_string(res.status);
    for (int c = 0; c < 3; ++c) {
        const double e = res.emitted_power[c];
        EXPECT_NEAR((res.absorbed_power[c] + res.escaped_power[c] + res.unshot_power[c]) / e, 1.0, 1e-9);
        EXPECT_LT(std::abs(res.escaped_power[c]) / e, 1e-3) << "channel " << c;
    }
    std::printf("bright closed box, rho 0.99: %zu shots, escaped %.2e, absorbed by back sides %.3f of the emitted\n",
                res.steps, res.escaped_power[0] / res.emitted_power[0],
                res.back_absorbed_power[0] / res.emitted_power[0]);
}

TEST(SolveScene, AFurnaceWithAFloatingBlockIsFlat) {
    // Every face of a closed 2 m box and of a block floating in it emits 1 and reflects 0.9:
    // B = E / (1 - rho) = 10 on every patch, whatever blocks what. Sampled rows are off by the
    // rays' noise where the block hides part of a pair, and 1 / (1 - rho) = 10 amplifies it;
    // the default request balances the rows (reciprocal, closed rows summing to one), so every
    // patch is within 0.1%. Shooting and Gauss-Seidel; unbalanced rows are not.
    const Scene scene = furnace_with_a_block();
    const auto worst = [&](SolverKind solver, bool balance) {
        SolveRequest r;
        r.solver = solver;
        r.balance = balance;
        r.tolerance = 1e-7;
        r.gather = GatherMode::none;
        r.meshing.target_patches = 600;
        const SolvedScene s = solve_scene(scene, r);
        EXPECT_TRUE(s.result.converged);
        EXPECT_NE(s.settings.find(balance ? "balanced=1" : "open_parts=1"), std::string::npos) << s.settings;
        double off = 0;
        for (const auto& b : s.result.radiosity) off = std::max(off, std::abs(b[0] / 10 - 1));
        return off;
    };
    const double shooting = worst(SolverKind::shooting, true), gathering = worst(SolverKind::gauss_seidel, true),
                 sampled = worst(SolverKind::shooting, false);
    std::printf("furnace with a floating block: worst |B/10 - 1| %.2e shooting, %.2e gauss-seidel, %.2e unbalanced\n",
                shooting, gathering, sampled);
    EXPECT_LT(shooting, 1e-3);
    EXPECT_LT(gathering, 1e-3);
    EXPECT_GT(sampled, 1e-3);
}

TEST(SolveScene, AddedEmissionSolvesAgainOverTheSameFormFactors) {
    // The furnace with a floating block (rho 0.9, E = 1): B = E / (1 - rho) = 10. Asked again
    // with 1 more on every patch, the second solve gives 20 everywhere, and a third ask ends
    // it. Element solves and refining ones refuse the hook.
    const Scene scene = furnace_with_a_block();
    for (const SolverKind solver : {SolverKind::shooting, SolverKind::gauss_seidel}) {
        SolveRequest r;
        r.solver = solver;
        r.tolerance = 1e-7;
        r.gather = GatherMode::none;
        r.meshing.target_patches = 300;
        std::vector<double> worst;  // max |B / expected - 1| of each solve
        SolveHooks hooks;
        hooks.added_emission = [&](const SolveResult* so_far) -> std::optional<std::vector<Rgb>> {
            if (!so_far) return std::nullopt;
            const double expected = 10.0 * double(worst.size() + 1);
            double off = 0;
            for (const auto& b : so_far->radiosity) off = std::max(off, std::abs(b[1] / expected - 1));
            worst.push_back(off);
            if (worst.size() == 2) return std::nullopt;
            return std::vector<Rgb>(so_far->radiosity.size(), Rgb::gray(1.0));
        };
        const SolvedScene s = solve_scene(scene, r, hooks);
        ASSERT_EQ(worst.size(), 2u) << to_string(solver);
        std::printf("%s: worst |B/10 - 1| %.2e, then with E = 2 |B/20 - 1| %.2e\n", to_string(solver).c_str(), worst[0],
                    worst[1]);
        EXPECT_LT(worst[0], 1e-3);
        EXPECT_LT(worst[1], 1e-3);
        EXPECT_NEAR(s.result.radiosity.front()[0], 20.0, 0.02);
        r.element_split = 2;
        EXPECT_THROW(solve_scene(scene, r, hooks), std::invalid_argument);
        r.element_split = 1;
        r.solver = SolverKind::hierarchical;
        EXPECT_THROW(solve_scene(scene, r, hooks), std::invalid_argument);
    }
}

TEST(SolveScene, TheStudyAsJsonAndAsAnObjGivesOneAnswerWithEverySolver) {
    // Issue 34's goal: one scene written two ways agrees within 0.1% at every patch and every
    // vertex. The OBJ prints the JSON's transformed vertices to 15 digits (a few ulps off):
    // before the coordinate grid, the contact cuts under the table came out in another order
    // (other rays per patch: 4% apart at a probe) and the hierarchical refinement made other
    // elements.
    const std::string json = std::string(BOUNCE_SOURCE_DIR) + "/examples/scenes/study.json";
    test::TempDir dir;
    const auto obj = test::write_scene_as_obj(read_json_scene(json), dir, "study", 15);
    const Scene a = load_scene(json), b = load_scene(obj.string());
    for (const bool adaptive : {false, true}) {
        SolveRequest r;
        r.meshing.target_patches = 500;
        if (adaptive) {
            r.solver = SolverKind::hierarchical;
            r.adaptive = true;
        }
        const SolvedScene sa = solve_scene(a, r), sb = solve_scene(b, r);
        ASSERT_EQ(sa.mesh->size(), sb.mesh->size()) << adaptive;
        double worst = 0;
        for (std::size_t i = 0; i < sa.mesh->size(); ++i)
            for (int c = 0; c < 3; ++c) {
                const double x = sa.result.radiosity[i][c], y = sb.result.radiosity[i][c];
                worst = std::max(worst, std::abs(x - y) / std::max({std::abs(x), std::abs(y), 1e-12}));
            }
        ASSERT_EQ(sa.result.point_radiosity.size(), sb.result.point_radiosity.size()) << adaptive;
        for (std::size_t v = 0; v < sa.result.point_radiosity.size(); ++v)
            for (int c = 0; c < 3; ++c) {
                const double x = sa.result.point_radiosity[v][c], y = sb.result.point_radiosity[v][c];
                worst = std::max(worst, std::abs(x - y) / std::max({std::abs(x), std::abs(y), 1e-12}));
            }
        std::printf("%s: %zu cells, worst relative difference %.3g\n", adaptive ? "adaptive" : "default",
                    sa.mesh->size(), worst);
        EXPECT_LT(worst, 1e-3) << adaptive;
    }
}

TEST(SolveScene, AdaptiveRefinesEveryPenumbraOfDirectLightWhateverItsPower) {
    // The Cornell box with --adaptive, scored at the shipped path-traced probes classed as
    // penumbrae: a partly visible pair with an emitter at one end is refined on the relative
    // test alone, so faint penumbrae (beside the blocks, under their edges) are followed where
    // a power budget would leave them coarse (1.5% RMS then).
    const Scene scene = load_scene("cornell");
    SolveRequest r;
    r.adaptive = true;
    r.validate();
    const SolvedScene s = solve_scene(scene, r);
    ASSERT_TRUE(s.gathered);
    const auto reference =
        read_reference(std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples" / "reference" / "cornell_classes_192.csv");
    const PathTracer tracer(scene);
    std::vector<ProbeClass> classes(reference.size(), ProbeClass::lit);
    for (std::size_t k = 0; k < reference.size(); ++k)
        if (const auto x = tracer.locate(reference[k].position, reference[k].normal))
            classes[k] = classify_probe(tracer, *x, k);
    const ProbeScore score = score_at_probes(*s.mesh, s.result.radiosity, reference, s.result.point_radiosity);
    const ClassScore penumbra = score_by_class(score, classes)[1];
    std::printf("adaptive, %zu cells: penumbra point data %.4f RMS, %.4f worst over %zu probes\n", s.mesh->size(),
                penumbra.rms_smooth, penumbra.max_smooth, penumbra.scored);
    ASSERT_GE(penumbra.scored, 40u);
    EXPECT_LE(penumbra.rms_smooth, 0.01);
}
