// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/linear/convergence.h"
#include "solver/linear/solver.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

/// n patches of unit area, each seeing the other n-1 equally: F_ij = 1/(n-1), exactly
/// representable in float when n-1 is a power of two, so rows sum to exactly 1 (a furnace
/// whose discrete solution is exactly E/(1-rho)). `scale` > 1 makes rows sum above 1.
struct SyntheticEnclosure {
    std::vector<Patch> patches;
    FormFactorMatrix F;
    SyntheticEnclosure(std::size_t n, double rho, double e, double scale = 1.0)
        : F(FormFactorMatrix::from_values(n, [&] {
              std::vector<float> v(n * n, float(scale / double(n - 1)));
              for (std::size_t i = 0; i < n; ++i) v[i * n + i] = 0.0f;
              return v;
          }())) {
        for (std::size_t i = 0; i < n; ++i) {
            Patch p;
            p.vertex_count = 4;
            p.area = 1.0;
            p.normal = {0, 0, 1};
            p.reflectance = Rgb::gray(rho);
            p.emission = Rgb::gray(e);
            patches.push_back(p);
        }
    }
};

struct Solved {
    SolveResult result;
};

SolveResult run(const std::string& solver, const std::vector<Patch>& P, const FormFactorMatrix& F, SolverOptions o,
                const char* method = "synthetic") {
    const MatrixFormFactor rows(F, method);
    return make_solver(solver, {P, &rows, &F}, o)->solve();
}

double max_relative(const std::vector<Rgb>& a, const std::vector<Rgb>& b) {
    double worst = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c)
            if (b[i][c] != 0) worst = std::max(worst, std::abs(a[i][c] - b[i][c]) / std::abs(b[i][c]));
    return worst;
}

}  // namespace

TEST(Solvers, AllFourAgreeOnASmallClosedScene) {
    // A closed box with a lamp on the floor and coloured walls: a real raycast matrix.
    Scene s = closed_box({1, 1.3, 0.8}, {"white", Rgb(0.7, 0.6, 0.5), Rgb()});
    s.materials.push_back({"lamp", Rgb(0.2, 0.2, 0.2), Rgb(5, 4, 3)});
    s.materials.push_back({"red", Rgb(0.8, 0.1, 0.1), Rgb()});
    s.surfaces[0].material = 1;
    s.surfaces[2].material = 2;
    MeshingOptions mo;
    mo.max_edge = 0.3;
    const PatchMesh mesh(s, mo);
    const auto vis = make_cgal_visibility(mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
    const auto F = FormFactorMatrix::build(*ff, mesh.size(), std::size_t(1) << 30);
    SolverOptions o;
    o.tolerance = 1e-12;
    const SolveResult direct = run("direct", mesh.patches(), F, o);
    ASSERT_TRUE(direct.converged);
    EXPECT_LT(direct.residual, 1e-12);
    for (const char* name : {"jacobi", "gauss-seidel", "shooting"}) {
        const SolveResult r = run(name, mesh.patches(), F, o);
        EXPECT_TRUE(r.converged) << name;
        EXPECT_LT(max_relative(r.radiosity, direct.radiosity), 1e-6) << name;
    }
    // Over-relaxed Gauss-Seidel reaches the same solution.
    o.sor = 1.3;
    EXPECT_LT(max_relative(run("gauss-seidel", mesh.patches(), F, o).radiosity, direct.radiosity), 1e-6);
}

TEST(Solvers, FurnaceConvergesToEOverOneMinusRhoLikeRhoToTheK) {
    for (double rho : {0.5, 0.9, 0.99}) {
        const SyntheticEnclosure box(17, rho, 2.0);
        const double exact = 2.0 / (1 - rho);
        SolverOptions o;
        o.tolerance = 1e-8;
        o.max_iterations = 100000;
        // Jacobi from B = E: B_k = E (1 + rho + ... + rho^k), so its residual is E rho^(k+1)
        // and it stops after the first k with rho^k < tol (it returns one sweep further).
        const std::size_t bound = std::size_t(std::ceil(std::log(o.tolerance) / std::log(rho)));
        const SolveResult jacobi = run("jacobi", box.patches, box.F, o);
        const SolveResult gs = run("gauss-seidel", box.patches, box.F, o);
        o.tolerance = 1e-10;  // shooting stops on unshot power; its error is about unshot / (1 - rho)
        const SolveResult shooting = run("shooting", box.patches, box.F, o);
        for (const auto* r : {&jacobi, &gs, &shooting}) {
            ASSERT_TRUE(r->converged) << r->solver << " rho " << rho;
            for (const auto& b : r->radiosity) EXPECT_NEAR(b.g / exact, 1.0, 1e-6) << r->solver << " rho " << rho;
        }
        EXPECT_GE(jacobi.steps + 1, bound) << rho;
        EXPECT_LE(jacobi.steps, bound + 2) << rho;
        EXPECT_LE(gs.steps, jacobi.steps) << rho;
        // Shooting: each shot drains one patch, so about n shots per Jacobi sweep.
        EXPECT_LE(shooting.steps, 17 * (bound + 3)) << rho;
        std::printf("furnace rho %.2f: bound %zu, jacobi %zu sweeps, gauss-seidel %zu, shooting %zu shots\n", rho,
                    bound, jacobi.steps, gs.steps, shooting.steps);
    }
}

TEST(Solvers, ReflectanceOneInAClosedSceneIsRefusedOrStopsFinite) {
    const SyntheticEnclosure box(17, 1.0, 1.0);
    EXPECT_GE(contraction_bound(box.patches, box.F.row_sums()), 1.0);
    SolverOptions o;
    o.max_iterations = 300;
    EXPECT_THROW(run("direct", box.patches, box.F, o), SingularSystemError);
    for (const char* name : {"jacobi", "gauss-seidel", "shooting"}) {
        const SolveResult r = run(name, box.patches, box.F, o);
        EXPECT_FALSE(r.converged) << name;
        EXPECT_EQ(r.steps, 300u) << name;
        for (const auto& b : r.radiosity) EXPECT_TRUE(std::isfinite(b.sum())) << name;
    }
}

TEST(Solvers, RowSumsAboveOneAreReportedAsDivergence) {
    const SyntheticEnclosure box(17, 0.9, 1.0, 2.0);  // rho * row sum = 1.8
    SolverOptions o;
    o.max_iterations = 100000;
    for (const char* name : {"jacobi", "gauss-seidel"}) {
        const SolveResult r = run(name, box.patches, box.F, o);
        EXPECT_EQ(r.status, "diverged") << name;
        EXPECT_LT(r.steps, 1000u) << name;
        for (const auto& b : r.radiosity) EXPECT_TRUE(std::isfinite(b.sum())) << name;
    }
}

namespace {
struct CornellSystem {
    PatchMesh mesh;
    std::unique_ptr<Visibility> vis;
    std::unique_ptr<FormFactorEstimator> ff;
    FormFactorMatrix F;
    SolveResult direct;
};
const CornellSystem& cornell() {
    static const CornellSystem* c = [] {
        MeshingOptions mo;
        mo.target_patches = 500;
        PatchMesh mesh(make_cornell_box(), mo);
        auto vis = make_cgal_visibility(mesh.patches());
        auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
        auto F = FormFactorMatrix::build(*ff, mesh.size(), std::size_t(1) << 30);
        auto* sys = new CornellSystem{std::move(mesh), std::move(vis), std::move(ff), std::move(F), {}};
        sys->direct = run("direct", sys->mesh.patches(), sys->F, {});
        return sys;
    }();
    return *c;
}
}  // namespace

TEST(Solvers, GaussSeidelNeedsFewerSweepsThanJacobiOnTheCornellBox) {
    const auto& c = cornell();
    SolverOptions o;
    o.tolerance = 1e-8;
    const SolveResult j = run("jacobi", c.mesh.patches(), c.F, o);
    const SolveResult g = run("gauss-seidel", c.mesh.patches(), c.F, o);
    ASSERT_TRUE(j.converged && g.converged);
    std::printf("cornell %zu patches, to 1e-8 residual: jacobi %zu sweeps, gauss-seidel %zu\n", c.mesh.size(), j.steps,
                g.steps);
    EXPECT_LT(g.steps, j.steps);
    EXPECT_LT(max_relative(g.radiosity, c.direct.radiosity), 1e-6);
}

TEST(Solvers, ShootingReachesOnePercentInFarFewerShotsThanPatches) {
    const auto& c = cornell();
    SolverOptions o;
    o.tolerance = 1e-4;
    o.reference = &c.direct.radiosity;
    const SolveResult r = run("shooting", c.mesh.patches(), c.F, o, "raycast");
    std::size_t shots = 0, ambient_shots = 0;
    for (const auto& rec : r.log) {
        if (!shots && rec.rms_error >= 0 && rec.rms_error < 0.01) shots = rec.step;
        if (!ambient_shots && rec.ambient_rms_error >= 0 && rec.ambient_rms_error < 0.01) ambient_shots = rec.step;
    }
    std::printf("cornell %zu patches: shooting reaches 1%% RMS error after %zu shots, %zu with the ambient term\n",
                c.mesh.size(), shots, ambient_shots);
    ASSERT_GT(shots, 0u);
    ASSERT_GT(ambient_shots, 0u);
    // Measured at 537 patches: B itself needs 470 shots (0.88 N) for 1%, since the reflected
    // light must be shot on by most patches; B plus the ambient term needs 220 (0.41 N).
    EXPECT_LT(shots, c.mesh.size());
    EXPECT_LT(ambient_shots, c.mesh.size() / 2);
}

TEST(Solvers, UnknownSolverAndMissingMatrixAreRefused) {
    const SyntheticEnclosure box(5, 0.5, 1.0);
    EXPECT_THROW(make_solver("conjugate-gradient", {box.patches, nullptr, &box.F}, {}), std::invalid_argument);
    EXPECT_THROW(make_solver("jacobi", {box.patches, nullptr, nullptr}, {}), std::invalid_argument);
}

TEST(Solvers, OverShootingReachesTheSameSolutionInFewerShots) {
    const auto& c = cornell();
    SolverOptions o;
    o.tolerance = 1e-8;
    const SolveResult plain = run("shooting", c.mesh.patches(), c.F, o, "raycast");
    o.overshoot = true;
    const SolveResult over = run("shooting", c.mesh.patches(), c.F, o, "raycast");
    ASSERT_TRUE(plain.converged && over.converged);
    std::printf("cornell %zu patches to 1e-8 unshot: %zu shots, %zu over-shooting\n", c.mesh.size(), plain.steps,
                over.steps);
    EXPECT_LT(over.steps, plain.steps);
    EXPECT_LT(max_relative(over.radiosity, c.direct.radiosity), 1e-6);
    EXPECT_LT(max_relative(plain.radiosity, c.direct.radiosity), 1e-6);
    // Energy still balances with negative unshot radiosity about.
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR((over.absorbed_power[ch] + over.escaped_power[ch] + over.unshot_power[ch]) / over.emitted_power[ch],
                    1.0, 1e-9);
}
