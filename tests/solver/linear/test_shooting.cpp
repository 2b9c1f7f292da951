// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "mesh/cornell_box.h"
#include "mesh/patch_mesh.h"
#include "mesh/validation_scenes.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/linear/shooting_solver.h"
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
