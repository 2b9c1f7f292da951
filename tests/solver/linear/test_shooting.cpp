// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/contact_cuts.h"
#include "mesh/cornell_box.h"
#include "mesh/patch_mesh.h"
#include "mesh/validation_scenes.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/open_parts.h"
#include "solver/linear/shooting_solver.h"
#include "solver/linear/solver.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

TEST(ShootingSolver, FurnaceGivesEOverOneMinusRho) {
    for (double rho : {0.5, 0.9}) {
        MeshingOptions o;
        o.max_edge = 0.25;
        const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(rho), Rgb(1, 2, 3)}), o);
        const auto vis = make_cgal_visibility(mesh.patches());
        const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
        ShootingOptions so;
        so.tolerance = 1e-9;
        so.max_iterations = 1000000;
        const SolveResult r = ShootingSolver(mesh.patches(), *ff, so).solve();
        ASSERT_TRUE(r.converged);
        double worst = 0;
        for (const auto& b : r.radiosity)
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(b[c] / ((c + 1) / (1 - rho)) - 1));
        std::printf("furnace rho %.2f: %zu patches, %zu shots, worst relative error %.3g\n", rho, mesh.size(), r.steps,
                    worst);
        // Row-sum errors are amplified by 1/(1-rho); measured 3.2e-5 (0.5) and 1.4e-4 (0.9).
        EXPECT_LT(worst, rho == 0.5 ? 1e-4 : 5e-4);
    }
}

TEST(ShootingSolver, EnergyBalanceHoldsToRounding) {
    MeshingOptions o;
    o.target_patches = 400;
    const PatchMesh mesh(make_cornell_box(), o);
    const auto vis = make_cgal_visibility(mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
    ShootingOptions so;
    so.tolerance = 1e-2;
    const SolveResult r = ShootingSolver(mesh.patches(), *ff, so).solve();
    EXPECT_TRUE(r.converged);
    EXPECT_LT(r.unshot_fraction, 1e-2);
    for (int c = 0; c < 3; ++c) {
        const double sum = r.absorbed_power[c] + r.escaped_power[c] + r.unshot_power[c];
        EXPECT_NEAR(sum / r.emitted_power[c], 1.0, 1e-9);
        // The box is open at the front: some light escapes, none is created.
        EXPECT_GT(r.escaped_power[c], 0.0);
        EXPECT_LT(r.escaped_power[c], r.emitted_power[c]);
    }
    // The unshot fraction reported is the unshot power held, over the emitted power.
    EXPECT_NEAR(r.unshot_fraction, r.unshot_power.sum() / r.emitted_power.sum(), 1e-12);
}

TEST(ShootingSolver, StopsAtMaxShotsAndSaysItDidNotConverge) {
    const PatchMesh mesh(make_cornell_box(), MeshingOptions{.target_patches = 200});
    const auto vis = make_cgal_visibility(mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
    ShootingOptions so;
    so.max_iterations = 5;
    const SolveResult r = ShootingSolver(mesh.patches(), *ff, so).solve();
    EXPECT_EQ(r.steps, 5u);
    EXPECT_FALSE(r.converged);
    EXPECT_GT(r.unshot_fraction, 1e-3);
}

TEST(ShootingSolver, ASceneWithoutLightIsRefused) {
    const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb()}), MeshingOptions{.subdivide = false});
    const auto ff = make_form_factor_estimator("analytic", mesh.patches(), nullptr, {});
    EXPECT_THROW(ShootingSolver(mesh.patches(), *ff, {}).solve(), std::invalid_argument);
}

namespace {

/// An axis-aligned rectangle facing `normal`: the corners ordered so that it does.
Surface rectangle(std::vector<glm::dvec3> corners, glm::dvec3 normal, int material) {
    if (glm::dot(glm::cross(corners[1] - corners[0], corners[2] - corners[0]), normal) < 0)
        std::reverse(corners.begin(), corners.end());
    return {corners, material, "corridor", {"test", 0}};
}

/// A closed L-shaped corridor 1 high: a leg x in [0,4], y in [0,1], turning at its end into a
/// leg x in [3,4], y in [1,4]. The lamp is the ceiling over x in [0,0.5] of the first leg; the
/// second leg beyond y = 1.5 sees none of it, lit only by inter-reflection (rho 0.8 walls).
Scene l_corridor() {
    Scene s;
    s.name = "L corridor";
    s.materials = {{"wall", Rgb::gray(0.8), Rgb()}, {"lamp", Rgb(), Rgb(3, 2, 1)}};
    const glm::dvec3 up(0, 0, 1), down(0, 0, -1);
    auto floor_and_ceiling = [&](double x0, double x1, double y0, double y1, int ceiling_material) {
        s.surfaces.push_back(rectangle({{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}}, up, 0));
        s.surfaces.push_back(rectangle({{x0, y0, 1}, {x1, y0, 1}, {x1, y1, 1}, {x0, y1, 1}}, down, ceiling_material));
    };
    floor_and_ceiling(0, 0.5, 0, 1, 1);
    floor_and_ceiling(0.5, 3, 0, 1, 0);
    floor_and_ceiling(3, 4, 0, 1, 0);
    floor_and_ceiling(3, 4, 1, 4, 0);
    auto wall_x = [&](double x, double y0, double y1, double facing) {  // in the plane x
        s.surfaces.push_back(rectangle({{x, y0, 0}, {x, y1, 0}, {x, y1, 1}, {x, y0, 1}}, {facing, 0, 0}, 0));
    };
    auto wall_y = [&](double y, double x0, double x1, double facing) {  // in the plane y
        s.surfaces.push_back(rectangle({{x0, y, 0}, {x1, y, 0}, {x1, y, 1}, {x0, y, 1}}, {0, facing, 0}, 0));
    };
    wall_x(0, 0, 1, 1);
    wall_x(4, 0, 1, -1);
    wall_x(4, 1, 4, -1);
    wall_x(3, 1, 4, 1);
    wall_y(0, 0, 3, 1);
    wall_y(0, 3, 4, 1);
    wall_y(1, 0, 3, -1);
    wall_y(4, 3, 4, -1);
    return s;
}

/// Largest |B_i - R_i| / R_i over patches (channel sums).
double worst_relative(const std::vector<Rgb>& b, const std::vector<Rgb>& r) {
    double worst = 0;
    for (std::size_t i = 0; i < b.size(); ++i)
        if (r[i].sum() > 0) worst = std::max(worst, std::abs(b[i].sum() / r[i].sum() - 1));
    return worst;
}

}  // namespace

// Issue 34: a closed box at rho 0.97 stopped at the old cap of 100 N shots. With no cap by
// default, a rho 0.99 furnace converges, and the error it leaves is what its tolerance (1e-3)
// asks for: every patch within 1e-3 of E / (1 - rho), give or take the estimate's own error
// (measured 1.01e-3 at rho 0.97, 0.995e-3 at 0.99; empty-box rows are within ~1e-11 of the truth).
TEST(ShootingSolver, DefaultsConvergeOnABrightFurnaceWithinTheirTolerance) {
    for (double rho : {0.97, 0.99}) {
        MeshingOptions o;
        o.max_edge = 0.25;
        const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(rho), Rgb(1, 2, 3)}), o);
        const auto vis = make_cgal_visibility(mesh.patches());
        const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
        const SolveResult r = ShootingSolver(mesh.patches(), *ff, ShootingOptions{}).solve();
        ASSERT_TRUE(r.converged) << r.status;
        EXPECT_EQ(r.status, "converged");
        EXPECT_LT(r.error_estimate, 1e-3);
        double worst = 0;
        for (const auto& b : r.radiosity)
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(b[c] / ((c + 1) / (1 - rho)) - 1));
        std::printf(
            "furnace rho %.2f, defaults: %zu patches, %zu shots (%.0f N), unshot %.3g, estimated error %.3g, "
            "worst relative error %.3g\n",
            rho, mesh.size(), r.steps, double(r.steps) / double(mesh.size()), r.unshot_fraction, r.error_estimate,
            worst);
        EXPECT_LT(worst, 1.1e-3) << rho;
        EXPECT_GT(worst, 0.5e-3) << rho << ": no more shots than the tolerance needs";
        EXPECT_GT(r.steps, 100 * mesh.size()) << "the old cap would have stopped it";
    }
}

// The error the default stop leaves where the light arrives last: the far leg of a corridor,
// lit only by inter-reflection, against a run converged to 1e-9. Stopping at 1e-3 unshot
// power left it 2.9% low (issue 34); the rule promises each patch within about its tolerance
// (measured: estimated 0.999e-3, worst 0.968e-3, 480 patches).
TEST(ShootingSolver, DefaultStopLeavesItsToleranceWhereOnlyInterreflectionLights) {
    MeshingOptions o;
    o.max_edge = 0.25;
    const PatchMesh mesh(l_corridor(), o);
    const auto vis = make_cgal_visibility(mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
    const SolveResult r = ShootingSolver(mesh.patches(), *ff, ShootingOptions{}).solve();
    ASSERT_TRUE(r.converged) << r.status;
    ShootingOptions tight;
    tight.tolerance = 1e-9;
    const SolveResult exact = ShootingSolver(mesh.patches(), *ff, tight).solve();
    ASSERT_TRUE(exact.converged) << exact.status;
    // The far leg: patches beyond y = 2.
    std::vector<Rgb> far_b, far_exact;
    double far_mean = 0, area = 0, mean = 0;
    for (std::size_t i = 0; i < mesh.size(); ++i) {
        mean += exact.radiosity[i].sum() * mesh.patches()[i].area;
        area += mesh.patches()[i].area;
        if (mesh.patches()[i].centre.y > 2) {
            far_b.push_back(r.radiosity[i]);
            far_exact.push_back(exact.radiosity[i]);
            far_mean += exact.radiosity[i].sum();
        }
    }
    far_mean /= double(far_exact.size());
    mean /= area;
    const double worst = worst_relative(r.radiosity, exact.radiosity);
    const double far = worst_relative(far_b, far_exact);
    std::printf(
        "L corridor: %zu patches (%zu in the far leg, %.3g of the mean radiosity), default %zu shots, "
        "unshot %.3g, estimated error %.3g; worst relative error %.3g (far leg %.3g); 1e-9: %zu shots\n",
        mesh.size(), far_b.size(), far_mean / mean, r.steps, r.unshot_fraction, r.error_estimate, worst, far,
        exact.steps);
    EXPECT_LT(far_mean, 0.2 * mean) << "the far leg is dim: lit by inter-reflection only";
    EXPECT_LT(r.error_estimate, 1e-3);
    EXPECT_LT(worst, 1.1e-3);
    EXPECT_LT(far, 1.1e-3);
    EXPECT_GT(far, 0.3e-3) << "the far leg is where the error is left";
}

TEST(ShootingSolver, AClosedFurnaceWithCrossingBoxesKeepsItsLight) {
    // A closed 4 x 3 x 4 room, every face emitting 1 and reflecting 0.9, with a box pushed
    // through the floor, one through a wall and two crossing each other in the air: a closed
    // scene, so no power escapes and the mean radiosity is 10. Without the solid cuts the
    // hidden parts of the straddling patches shoot into the backs of the boxes and lose it.
    Scene s = closed_box({4, 3, 4}, {"w", Rgb::gray(0.9), Rgb::gray(1)});
    const auto add_box = [&](glm::dvec3 lo, glm::dvec3 hi, const std::string& name) {
        const std::vector<std::vector<glm::dvec3>> faces = {
            {{lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}},  // +z
            {{lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, lo.y, lo.z}},  // -z
            {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}},  // -y
            {{lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}},  // +y
            {{lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}},  // -x
            {{hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}},  // +x
        };
        for (const auto& f : faces) s.surfaces.push_back({f, 0, name, {"test", 0}});
    };
    add_box({0.7, 0.6, -0.35}, {1.6, 1.5, 0.45}, "through the floor");  // closed_box: z is up
    add_box({3.45, 1.1, 1.2}, {4.35, 2.0, 2.1}, "through a wall");
    add_box({1.5, 2.0, 1.0}, {2.7, 2.6, 1.9}, "crossed");
    add_box({2.2, 2.3, 1.3}, {3.0, 3.2, 2.3}, "crossing");
    s.covered = find_covered_regions(s);
    double loss[2] = {0, 0};
    for (const bool cut : {false, true}) {
        MeshingOptions o;
        o.max_edge = 0.25 * (1 + 1e-9);
        o.cut_contacts = cut;
        const PatchMesh mesh(s, o);
        const auto vis = make_visibility("embree", mesh.patches());
        FormFactorOptions fo;
        fo.visibility_rays = 8;  // the 2 of the default leave +-0.15% of row-sum noise
        const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), fo);
        ShootingOptions so;
        so.tolerance = 1e-6;
        const SolveResult r = ShootingSolver(mesh.patches(), *ff, so).solve();
        ASSERT_TRUE(r.converged);
        double area = 0, power = 0;
        for (std::size_t i = 0; i < mesh.size(); ++i) {
            area += mesh.patches()[i].area;
            power += mesh.patches()[i].area * r.radiosity[i][0];
        }
        loss[cut] = r.escaped_power[0] / r.emitted_power[0];
        std::printf("crossing boxes, cuts %s: %zu patches, escaped %.4f%%, mean B %.4f\n", cut ? "on" : "off",
                    mesh.size(), 100 * loss[cut], power / area);
        if (cut) {
            EXPECT_LT(std::abs(loss[cut]), 5e-4);
            EXPECT_NEAR(power / area, 10.0, 0.01);
        }
    }
    EXPECT_GT(loss[0], 10 * std::abs(loss[1]));
}

TEST(ShootingSolver, FurnaceWithAFloatingBlockIsFlat) {
    // A closed 2 x 2 x 2 room with a block [0.6,1.4]^2 x [0.5,1.3] floating in it, every face
    // emitting 1 and reflecting 0.9: B = 10 everywhere, whatever blocks what. Where the pairs
    // the block partly hides take their visible share from too few rays, rows stop summing to
    // one and 1/(1-rho) amplifies it.
    const Scene s = floating_block_furnace();
    MeshingOptions o;
    o.max_edge = 0.2 * (1 + 1e-9);
    const PatchMesh mesh(s, o);
    const auto vis = make_visibility("embree", mesh.patches());
    double spread[2] = {0, 0};
    for (const int partial : {0, 16}) {
        FormFactorOptions fo;
        fo.partial_rays = partial;
        const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), fo);
        ShootingOptions so;
        so.tolerance = 1e-7;
        const SolveResult r = ShootingSolver(mesh.patches(), *ff, so).solve();
        ASSERT_TRUE(r.converged);
        double lo = 1e300, hi = 0;
        for (const auto& b : r.radiosity) {
            lo = std::min(lo, b[0]);
            hi = std::max(hi, b[0]);
        }
        std::printf("furnace with a floating block, %zu patches, partial rays %d: B from %.4f to %.4f\n", mesh.size(),
                    partial, lo, hi);
        spread[partial ? 1 : 0] = hi - lo;
        // Exact is 10 everywhere; what is left is the noise of 2 rays a pair (16 where partly
        // blocked). Issue 34 asks for 0.1%, which rays alone do not reach.
        EXPECT_LT(std::max(10 - lo, hi - 10), 0.12);
    }
    EXPECT_LT(spread[1], spread[0]);
}

TEST(ShootingSolver, FurnaceWithAFloatingBlockKeepsItsPowerOnOpenParts) {
    // The furnace above at the default 2 rays a pair, solved on open parts: every part is
    // closed, so every row sends all its light, nothing escapes, and the area-weighted mean
    // radiosity is exactly 10 (emitted = absorbed: sum E A = sum (1 - rho) H A, and B = E + rho H).
    // Each patch is still off by what its own row's sampling leaves (the rows a patch gathers
    // along are not scaled), about 1%: flatness per patch is not reached this way.
    // Shooting and Gauss-Seidel (the open parts' matrix).
    const Scene s = floating_block_furnace();
    MeshingOptions o;
    o.max_edge = 0.2 * (1 + 1e-9);
    const PatchMesh mesh(s, o);
    const auto vis = make_visibility("embree", mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
    const std::vector<OpenPart> open = open_parts(mesh.patches(), *vis);
    const auto mean_of = [&](const SolveResult& r) {
        double power = 0, area = 0;
        for (std::size_t i = 0; i < mesh.size(); ++i) {
            power += r.radiosity[i][0] * mesh.patches()[i].area * open[i].receiving_share();
            area += mesh.patches()[i].area * open[i].receiving_share();
        }
        return power / area;
    };
    ShootingOptions so;
    so.tolerance = 1e-7;
    const SolveResult whole = ShootingSolver(mesh.patches(), *ff, so).solve();
    so.open_parts = &open;
    const SolveResult shot = ShootingSolver(mesh.patches(), *ff, so).solve();
    ASSERT_TRUE(whole.converged && shot.converged);
    const FormFactorMatrix matrix =
        open_part_matrix(FormFactorMatrix::build(*ff, mesh.size(), std::size_t(1) << 30), open);
    const std::vector<Patch> parts = open_part_patches(mesh.patches(), open);
    SolverOptions go;
    go.tolerance = 1e-9;
    go.open_parts = &open;
    const SolveResult gathered = make_solver("gauss-seidel", {parts, nullptr, &matrix}, go)->solve();
    ASSERT_TRUE(gathered.converged);
    std::printf(
        "furnace with a floating block, 2 rays: mean B whole patches %.5f (escaped %.2e), open parts %.5f "
        "(shooting), %.5f (gauss-seidel)\n",
        mean_of(whole), whole.escaped_power[0] / whole.emitted_power[0], mean_of(shot), mean_of(gathered));
    EXPECT_LT(std::abs(mean_of(shot) - 10), 1e-4 * 10 + so.tolerance * 100);
    EXPECT_LT(std::abs(mean_of(gathered) - 10), 1e-4 * 10);
    EXPECT_GT(std::abs(mean_of(whole) - 10), 5e-4) << "whole patches lose what their rows miss";
    for (const SolveResult* r : {&shot, &gathered})
        for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(r->escaped_power[c]) / r->emitted_power[c], 1e-6);
}
