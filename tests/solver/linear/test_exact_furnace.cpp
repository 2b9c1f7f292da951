// SPDX-License-Identifier: MIT
// Closed scenes with the exact and the default form factors: the furnace answers E / (1 - rho) with every
// solver, and rows sum to 1 even across T-junctions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "mesh/geometry/contact_cuts.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/exact_form_factor.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/linear/solver.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

/// Solves a furnace (every patch the same rho and E) on the matrix F with each of `solvers`, at
/// tight tolerances and large budgets, and checks every B against `expected`: either the solver
/// converged, and then to within `tol` relative, or it says it did not (a failure too).
void expect_furnace(const std::vector<Patch>& P, const FormFactorMatrix& F, const std::string& label,
                    std::initializer_list<const char*> solvers, double expected, double tol) {
    const MatrixFormFactor rows(F, label);
    for (const char* name : solvers) {
        SolverOptions so;
        so.tolerance = std::string(name) == "shooting" ? 1e-7 : 1e-9;
        so.max_iterations = std::string(name) == "shooting" ? 4000000 : 5000;
        const SolveResult r = make_solver(name, {P, &rows, &F}, so)->solve();
        double worst = 0;
        for (const auto& b : r.radiosity) worst = std::max(worst, std::abs(b.g / expected - 1.0));
        std::printf("furnace %s: %-12s %zu steps, %s, worst |B/%g - 1| = %.2g\n", label.c_str(), name, r.steps,
                    r.converged ? "converged" : r.status.c_str(), expected, worst);
        if (r.converged)
            EXPECT_LT(worst, tol) << label << " " << name;
        else
            ADD_FAILURE() << label << " " << name << " did not converge within its budget: " << r.status;
    }
}

/// Unit cube, each face cut 12 x 12 (864 patches), rho 0.99, E 1: B = E / (1 - rho) = 100
/// everywhere. A row-sum surplus s is amplified to about s / (1 - rho) = 100 s in B: the
/// one-point ray-cast rows (up to +2.7e-3) answered 116-127; rows within 1e-6 must give 100
/// within 1e-4 relative with every solver.
void rho099_cube_gives_100(const std::string& method) {
    MeshingOptions o;
    o.max_edge = 1.0 / 12 * (1 + 1e-9);
    const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.99), Rgb::gray(1.0)}), o);
    const auto& P = mesh.patches();
    ASSERT_EQ(P.size(), 864u);
    const auto vis = make_visibility("embree", P);
    const auto ff = make_form_factor_estimator(method, P, vis.get(), {});
    const auto F = FormFactorMatrix::build(*ff, P.size(), std::size_t(1) << 30);
    expect_furnace(P, F, "rho 0.99, 12x12 cube, " + method, {"direct", "jacobi", "gauss-seidel", "shooting"}, 100.0,
                   1e-4);
}

/// The built-in Cornell box closed by a front wall (z = 0, facing in), without its lamp (a
/// thin one-sided quad 0.1 below the ceiling would leave a slit), the blocks inside; every
/// surface rho and E given. Contact cuts leave out the floor under the blocks.
Scene closed_cornell_box(double rho, double e) {
    Scene s = make_cornell_box();
    std::erase_if(s.surfaces, [&](const Surface& f) { return f.object == "light"; });
    s.surfaces.push_back({{{0, 0, 0}, {552.8, 0, 0}, {556, 548.8, 0}, {0, 548.8, 0}}, 0, "front wall", {"test", 0}});
    for (auto& m : s.materials) {
        m.reflectance = Rgb::gray(rho);
        m.emission = Rgb::gray(e);
    }
    s.covered = find_covered_regions(s);
    return s;
}

/// sum_j F_ij for every i, each unordered pair computed once in double (pair() is reciprocal).
template <class FF>
std::vector<double> row_sums(const FF& ff, const std::vector<Patch>& P) {
    std::vector<double> sums(P.size(), 0.0);
    for (std::size_t i = 0; i < P.size(); ++i)
        for (std::size_t j = i + 1; j < P.size(); ++j) {
            const double fij = ff.pair(i, j);
            sums[i] += fij;
            sums[j] += fij * P[i].area / P[j].area;
        }
    return sums;
}

double worst_deviation(const std::vector<double>& sums) {
    double worst = 0;
    for (const double s : sums) worst = std::max(worst, std::abs(s - 1));
    return worst;
}

/// A 1 x 1 x 1 box whose floor is cut into 3 strips and whose ceiling into 2 (and the walls
/// into 3 x 2 uneven cells), so patch edges meet mid-edge (T-junctions).
Scene t_junction_box() {
    Scene s;
    s.name = "t-junction box";
    s.materials = {{"w", Rgb::gray(0.5), Rgb()}};
    const auto quad = [&](glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
        s.surfaces.push_back({{a, b, c, d}, 0, "wall", {"test", 0}});
    };
    for (int k = 0; k < 3; ++k) {  // floor z = 0 facing +z, 3 strips along x
        const double x0 = k / 3.0, x1 = (k + 1) / 3.0;
        quad({x0, 0, 0}, {x1, 0, 0}, {x1, 1, 0}, {x0, 1, 0});
    }
    for (int k = 0; k < 2; ++k) {  // ceiling z = 1 facing -z, 2 strips along x
        const double x0 = k / 2.0, x1 = (k + 1) / 2.0;
        quad({x0, 0, 1}, {x0, 1, 1}, {x1, 1, 1}, {x1, 0, 1});
    }
    // x = 0 facing +x: two cells along y; x = 1 facing -x: three cells along y.
    for (int k = 0; k < 2; ++k) {
        const double y0 = k / 2.0, y1 = (k + 1) / 2.0;
        quad({0, y0, 0}, {0, y1, 0}, {0, y1, 1}, {0, y0, 1});
    }
    for (int k = 0; k < 3; ++k) {
        const double y0 = k / 3.0, y1 = (k + 1) / 3.0;
        quad({1, y0, 0}, {1, y0, 1}, {1, y1, 1}, {1, y1, 0});
    }
    // y = 0 facing +y and y = 1 facing -y, each cut into a 3 x 2 grid (x thirds, z halves).
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 2; ++b) {
            const double x0 = a / 3.0, x1 = (a + 1) / 3.0, z0 = b / 2.0, z1 = (b + 1) / 2.0;
            quad({x0, 0, z0}, {x0, 0, z1}, {x1, 0, z1}, {x1, 0, z0});
            quad({x0, 1, z0}, {x1, 1, z0}, {x1, 1, z1}, {x0, 1, z1});
        }
    return s;
}

}  // namespace

TEST(ExactFurnace, Rho099CubeGives100WithEverySolver) { rho099_cube_gives_100("exact"); }

TEST(ExactFurnace, TJunctionBoxRowsSumToOne) {
    // Rows still sum to 1 across the T-junctions.
    const Scene s = t_junction_box();
    const PatchMesh mesh(s, MeshingOptions{.subdivide = false});
    const auto& P = mesh.patches();
    ASSERT_EQ(P.size(), 22u);
    const ExactFormFactor ff(P, true, {});
    const double worst = worst_deviation(row_sums(ff, P));
    std::printf("t-junction box: worst |row sum - 1| %.3g\n", worst);
    EXPECT_LT(worst, 1e-9);
    EXPECT_EQ(ff.tally().partial + ff.tally().hidden, 0u);
}

TEST(ClosedScenes, DefaultMethodRho099CubeGives100WithEverySolver) {
    // The default method's unoccluded factors are within 1e-6 relative: B within about 1e-4.
    rho099_cube_gives_100("raycast");
}

TEST(ClosedScenes, DefaultMethodCubeRowsSumToOneAndAreReciprocal) {
    // Each face cut n x n: rows within 1e-6 of 1 with the default method, reciprocity to rounding.
    for (const int n : {6, 12, 20}) {
        MeshingOptions o;
        o.max_edge = 1.0 / n * (1 + 1e-9);
        const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(0)}), o);
        const auto& P = mesh.patches();
        ASSERT_EQ(P.size(), std::size_t(6 * n * n));
        const auto vis = make_visibility("embree", P);
        const RaycastFormFactor ff(P, vis.get(), {});
        const double worst = worst_deviation(row_sums(ff, P));
        double worst_recip = 0;
        for (std::size_t i = 0; i < P.size(); i += 37)
            for (std::size_t j = 0; j < P.size(); ++j) {
                const double fij = ff.pair(i, j);
                if (fij > 0)
                    worst_recip = std::max(worst_recip,
                                           std::abs(P[i].area * fij - P[j].area * ff.pair(j, i)) / (P[i].area * fij));
            }
        std::printf("cube %dx%d, raycast: worst |row sum - 1| %.3g, reciprocity %.3g\n", n, n, worst, worst_recip);
        EXPECT_LT(worst, 1e-6) << n;
        EXPECT_LT(worst_recip, 1e-12) << n;
    }
}

TEST(ClosedScenes, DefaultMethodTJunctionBoxRowsSumToOne) {
    // Patches whose edges meet mid-edge: the near pairs go to the contour integral, exact.
    const Scene s = t_junction_box();
    MeshingOptions o;
    o.max_edge = 0.26;  // cut further, unevenly against the strips
    const PatchMesh mesh(s, o);
    const auto& P = mesh.patches();
    const auto vis = make_visibility("embree", P);
    const RaycastFormFactor ff(P, vis.get(), {});
    const double worst = worst_deviation(row_sums(ff, P));
    std::printf("t-junction box, %zu patches, raycast: worst |row sum - 1| %.3g\n", P.size(), worst);
    EXPECT_LT(worst, 1e-6);
}

TEST(ClosedScenes, ClosedCornellBoxRowsWithin1e4AndFurnaceWithin0Point1Percent) {
    // Blocks inside, so pairs are partly hidden. The exact method's rows, and the furnace (rho
    // 0.9, E 1 everywhere: E / (1 - rho) = 10). Each block is one convex solid
    // (ConvexBlockers), so a pair behind it clips one shadow per block, never the block's
    // patches one by one or rays; receivers start from 4 x 4 cells, so a narrow shadow at a
    // block's corner is not missed. Measured at visibility tolerance 1e-3: rows within 3.4e-5
    // (4.7e-3 with kernel-weighted rays, 5.7e-4 with solids from one cell), B within 2.9e-5
    // (0.42% with rays).
    MeshingOptions o;
    o.target_patches = 500;
    const PatchMesh mesh(closed_cornell_box(0.9, 1.0), o);
    const auto& P = mesh.patches();
    const auto vis = make_visibility("embree", P);
    FormFactorOptions fo;
    fo.visibility_tolerance = 1e-3;
    const ExactFormFactor exact(P, true, fo, vis.get());
    const auto F = FormFactorMatrix::build(exact, P.size(), std::size_t(1) << 30);
    const PairTally t = exact.tally();
    const double rows = worst_deviation(F.row_sums());
    std::printf(
        "closed cornell box, %zu patches, exact: worst |row sum - 1| %.3g (%llu unoccluded, %llu partial, "
        "%llu hidden pairs)\n",
        P.size(), rows, (unsigned long long)t.unoccluded, (unsigned long long)t.partial, (unsigned long long)t.hidden);
    EXPECT_LT(rows, 1e-4);
    EXPECT_GT(t.partial, 0u);
    expect_furnace(P, F, "closed cornell box, exact", {"gauss-seidel", "shooting"}, 10.0, 1e-3);

    // The default method on the same box: its partly hidden pairs take the unweighted fraction
    // of rays, so rows stray further; reported, and bounded loosely.
    const RaycastFormFactor raycast(P, vis.get(), {});
    const double dev = worst_deviation(row_sums(raycast, P));
    std::printf("closed cornell box, raycast: worst |row sum - 1| %.3g\n", dev);
    EXPECT_LT(dev, 0.05);
}
