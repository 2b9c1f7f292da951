// SPDX-License-Identifier: MIT
// Issue 6: the speed-ups (Embree, threads, reciprocity borrowing) must not change answers.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include <tbb/global_control.h>
#include <glm/geometric.hpp>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/patch_sampling.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/linear/shooting_solver.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

/// As the CLI loads it, but without contact cuts: the constructed rays below assume surfaces
/// without holes, and a hole's outline lies on another object's edge (a block's foot), where
/// whether a ray through the seam is blocked is a matter of rounding, exact in CGAL and float in
/// Embree. No patch sees through such a seam: only the inside of a block lies behind it.
PatchMesh cornell(std::size_t target) {
    MeshingOptions o;
    o.target_patches = target;
    o.cut_contacts = false;
    return PatchMesh(load_scene("cornell"), o);
}

struct Ray {
    glm::dvec3 a, b;
    int expect = -1;  // 1 blocked, 0 open, -1 no constructed answer
    const char* kind = "";
};

/// Rays with known answers at the places single precision could slip: through edges and
/// vertices shared by neighbouring patches, grazing the surfaces at a thousandth of a radian,
/// skimming parallel just above them, and ending one offset short of a wall; plus random rays
/// through the box and the solver's own kind (between lifted points on two patches).
std::vector<Ray> ray_set(const std::vector<Patch>& P, double eps) {
    std::vector<Ray> rays;
    std::map<std::pair<std::array<double, 3>, std::array<double, 3>>, std::size_t> edges;
    auto key = [](const glm::dvec3& v) { return std::array<double, 3>{v.x, v.y, v.z}; };
    // Patches of one surface around each vertex: 4 or more means the vertex is inside it.
    std::map<std::pair<int, std::array<double, 3>>, int> around;
    for (const auto& p : P)
        for (int k = 0; k < p.vertex_count; ++k) ++around[{p.surface, key(p.vertices[k])}];
    for (std::size_t i = 0; i < P.size(); ++i) {
        const Patch& p = P[i];
        const double size = std::sqrt(p.area);
        for (int k = 0; k < p.vertex_count; ++k) {
            const glm::dvec3 &u = p.vertices[k], &v = p.vertices[(k + 1) % p.vertex_count];
            const auto ku = key(u), kv = key(v);
            const auto e = ku < kv ? std::pair(ku, kv) : std::pair(kv, ku);
            if (auto it = edges.find(e); it != edges.end() && P[it->second].surface == p.surface) {
                // Shared edge: straight through its midpoint, and through one end (a shared vertex).
                const glm::dvec3 m = 0.5 * (u + v);
                rays.push_back({m + 0.5 * size * p.normal, m - 0.5 * size * p.normal, 1, "through a shared edge"});
                if (around[{p.surface, key(u)}] >= 4) {
                    const glm::dvec3 tilt = 1e-3 * size * glm::normalize(v - u);
                    rays.push_back({u + 0.5 * size * p.normal + tilt, u - 0.5 * size * p.normal - tilt, 1,
                                    "through a shared vertex"});
                }
                // Across the shared edge from centre to centre, skimming ten offsets above it
                // (open, unless a block stands on the floor there).
                const Patch& q = P[it->second];
                rays.push_back(
                    {p.centre + 10 * eps * p.normal, q.centre + 10 * eps * p.normal, -1, "skimming a shared edge"});
            } else {
                edges.emplace(e, i);
            }
        }
        // The blocks stand on the floor and may cover part of a floor patch: no constructed
        // answers there.
        // The light hangs 0.1 below the ceiling: no constructed answers there either.
        const int known = std::abs(p.normal.y) > 0.5 ? -1 : 1;
        if (i % 7 == 0) {
            // Grazing: descend at 1e-3 rad onto the patch's centre and through it; then the
            // mirror image, which climbs away and misses.
            const glm::dvec3 t = glm::normalize(p.vertices[1] - p.vertices[0]);
            const double run = 0.45 * size, drop = 1e-3 * run;
            rays.push_back(
                {p.centre - run * t + drop * p.normal, p.centre + run * t - drop * p.normal, known, "grazing hit"});
            rays.push_back({p.centre - run * t + 2 * drop * p.normal, p.centre + run * t + 4 * drop * p.normal,
                            known < 0 ? -1 : 0, "grazing miss"});
            // Ending one offset in front of the surface, like every solver ray.
            rays.push_back({p.centre + 0.3 * size * p.normal, p.centre + eps * p.normal, known < 0 ? -1 : 0,
                            "ending an offset short"});
        }
    }
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const auto& p : P)
        for (int k = 0; k < p.vertex_count; ++k) lo = glm::min(lo, p.vertices[k]), hi = glm::max(hi, p.vertices[k]);
    for (int r = 0; r < 20000; ++r) {
        auto in_box = [&] { return lo + glm::dvec3(U(rng), U(rng), U(rng)) * (hi - lo); };
        rays.push_back({in_box(), in_box(), -1, "random in the box"});
        const Patch& p = P[rng() % P.size()];
        const Patch& q = P[rng() % P.size()];
        rays.push_back({patch_point(p, U(rng), U(rng)) + eps * p.normal,
                        patch_point(q, U(rng), U(rng)) + eps * q.normal, -1, "patch to patch"});
    }
    return rays;
}

}  // namespace

TEST(VisibilityBackends, EmbreeAndCgalAgreeOnEveryRayIncludingGrazingAndSharedEdges) {
    const PatchMesh mesh = cornell(2000);
    const auto cgal = make_visibility("cgal", mesh.patches());
    const auto embree = make_visibility("embree", mesh.patches());
    ASSERT_EQ(cgal->offset(), embree->offset());
    const auto rays = ray_set(mesh.patches(), cgal->offset());
    std::map<std::string, int> count, blocked;
    std::vector<Visibility::Segment> segments;
    for (const auto& r : rays) {
        const bool c = cgal->occluded(r.a, r.b), e = embree->occluded(r.a, r.b);
        ++count[r.kind];
        blocked[r.kind] += c;
        ASSERT_EQ(c, e) << r.kind << " ray (" << r.a.x << "," << r.a.y << "," << r.a.z << ") -> (" << r.b.x << ","
                        << r.b.y << "," << r.b.z << ")";
        if (r.expect >= 0) {
            EXPECT_EQ(int(c), r.expect) << r.kind;
        }
        segments.push_back({r.a, r.b});
    }
    // The packet path gives the single-ray answers.
    std::vector<std::uint8_t> packet(segments.size());
    embree->occluded(segments, packet);
    for (std::size_t k = 0; k < rays.size(); ++k) ASSERT_EQ(bool(packet[k]), cgal->occluded(rays[k].a, rays[k].b));
    for (const auto& [kind, n] : count) std::printf("%-24s %6d rays, %6d blocked\n", kind.c_str(), n, blocked[kind]);
    EXPECT_GT(count["through a shared edge"], 1000);
    EXPECT_GT(count["through a shared vertex"], 500);
    EXPECT_GT(count["grazing hit"], 100);
    EXPECT_LT(blocked["skimming a shared edge"], count["skimming a shared edge"] / 10);
    // Random rays through a box with two blocks: both answers occur often.
    EXPECT_GT(blocked["random in the box"], 2000);
    EXPECT_LT(blocked["random in the box"], 18000);
}

TEST(VisibilityBackends, CornellSolutionAgreesWithEitherBackend) {
    const PatchMesh mesh = cornell(600);
    const auto& P = mesh.patches();
    std::vector<std::vector<Rgb>> b;
    for (const std::string& backend : visibility_backends()) {
        const auto vis = make_visibility(backend, P);
        const auto ff = make_form_factor_estimator("raycast", P, vis.get(), {});
        b.push_back(ShootingSolver(P, *ff, {}).solve().radiosity);
    }
    ASSERT_EQ(b.size(), 2u);
    // The published red wall is not planar: it is two exact triangles folded by 0.2% along the
    // diagonal, and rays leaving one triangle at grazing angles meet the other. Exact (CGAL) and
    // float (Embree) intersection decide a few of those differently, so the solutions agree to a
    // few 1e-4, not to the bit (measured 1.7e-4); the ray-level test above stays exact.
    double worst = 0;
    for (std::size_t i = 0; i < P.size(); ++i)
        for (int c = 0; c < 3; ++c)
            if (b[0][i][c] > 0) worst = std::max(worst, std::abs(b[1][i][c] / b[0][i][c] - 1));
    EXPECT_LT(worst, 1e-3);
}

TEST(VisibilityBackends, UnknownBackendIsRefusedWithTheValidNames) {
    try {
        make_visibility("optix", {});
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("embree"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("cgal"), std::string::npos);
    }
}

TEST(Threads, ShootingAndMatrixAreBitIdenticalOnOneAndTwoThreads) {
    const PatchMesh mesh = cornell(600);
    const auto& P = mesh.patches();
    const auto vis = make_visibility("embree", P);
    for (const std::string method : {"raycast", "hemicube"}) {
        const auto ff = make_form_factor_estimator(method, P, vis.get(), {});
        std::vector<std::vector<Rgb>> b;
        std::vector<std::vector<float>> rows;
        for (const std::size_t threads : {1u, 2u}) {
            const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
            b.push_back(ShootingSolver(P, *ff, {}).solve().radiosity);
            const auto F = FormFactorMatrix::build(*ff, P.size(), std::size_t(1) << 30);
            rows.emplace_back(F.row(17), F.row(17) + P.size());
            rows.emplace_back(F.row(P.size() - 3), F.row(P.size() - 3) + P.size());
        }
        for (std::size_t i = 0; i < P.size(); ++i)
            for (int c = 0; c < 3; ++c) ASSERT_EQ(b[0][i][c], b[1][i][c]) << method << " patch " << i;
        EXPECT_EQ(rows[0], rows[2]) << method;
        EXPECT_EQ(rows[1], rows[3]) << method;
    }
}

TEST(Reciprocity, RaycastMatrixIsReciprocalToRoundingAndBorrowingRowsChangesNothing) {
    const PatchMesh mesh = cornell(600);
    const auto& P = mesh.patches();
    const auto vis = make_visibility("embree", P);
    const auto ff = make_form_factor_estimator("raycast", P, vis.get(), {});
    ASSERT_TRUE(ff->reciprocal());
    const auto F = FormFactorMatrix::build(*ff, P.size(), std::size_t(1) << 30);
    double worst = 0.0;
    std::size_t compared = 0;
    for (std::size_t i = 0; i < P.size(); ++i)
        for (std::size_t j = i + 1; j < P.size(); ++j) {
            const double aij = P[i].area * F(i, j), aji = P[j].area * F(j, i);
            if (aij > 1e-9 * P[i].area) {
                worst = std::max(worst, std::abs(aij - aji) / aij);
                ++compared;
            }
        }
    EXPECT_GT(compared, P.size() * P.size() / 8);  // of the N^2/2 pairs, most see each other
    EXPECT_LT(worst, 1e-6);                        // float storage: a few ulps
    // A row computed whole equals the matrix row built from the upper triangle and mirrored.
    std::vector<float> row(P.size());
    for (const std::size_t i : {std::size_t(0), P.size() / 2, P.size() - 1}) {
        ff->compute_row(i, row);
        for (std::size_t j = 0; j < P.size(); ++j)
            EXPECT_NEAR(row[j], F(i, j), 1e-6 * std::max(1e-3f, row[j])) << i << "," << j;
    }
}

namespace {
double rms_relative(const std::vector<Rgb>& b, const std::vector<Rgb>& ref, const std::vector<Patch>& P) {
    double num = 0, den = 0;
    for (std::size_t i = 0; i < P.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            num += P[i].area * (b[i][c] - ref[i][c]) * (b[i][c] - ref[i][c]);
            den += P[i].area * ref[i][c] * ref[i][c];
        }
    return std::sqrt(num / den);
}
}  // namespace

TEST(ElementHierarchy, PatchesShootingToElementsApproachTheFineSolutionAndConserveEnergy) {
    const Scene scene = load_scene("cornell");
    MeshingOptions o;
    o.target_patches = 150;
    o.cut_contacts = false;  // elements tile uncut patches (PatchMesh::parents)
    const PatchMesh patches(scene, o);
    o.element_split = 3;
    const PatchMesh elements(scene, o);
    const auto& E = elements.patches();
    const auto vis = make_visibility("embree", E);
    SolverOptions so;
    so.tolerance = 1e-6;

    // Reference: the element mesh solved as ordinary patches (each element shoots).
    const auto fine_ff = make_form_factor_estimator("raycast", E, vis.get(), {});
    const SolveResult fine = ShootingSolver(E, *fine_ff, so).solve();
    // The coarse solution, each element taking its patch's radiosity.
    const auto coarse_ff = make_form_factor_estimator("raycast", patches.patches(), vis.get(), {});
    const SolveResult coarse = ShootingSolver(patches.patches(), *coarse_ff, so).solve();
    std::vector<Rgb> injected(E.size());
    for (std::size_t e = 0; e < E.size(); ++e) injected[e] = coarse.radiosity[elements.parents()[e]];
    // Patches shoot, elements receive.
    const PatchToElementFormFactor p2e(patches.patches(), E, vis.get(), {});
    const SolveResult hier =
        ShootingSolver(E, p2e, so, nullptr, ElementHierarchy{&patches.patches(), &elements.parents()}).solve();
    ASSERT_TRUE(hier.converged);

    const double err_coarse = rms_relative(injected, fine.radiosity, E);
    const double err_hier = rms_relative(hier.radiosity, fine.radiosity, E);
    std::printf("%zu patches, %zu elements: RMS vs element solution: coarse %.4f, patches->elements %.4f\n",
                patches.size(), E.size(), err_coarse, err_hier);
    // Measured: coarse 0.0169, patches->elements 0.0038 (what remains is the uniform-emitter
    // approximation of each shooting patch).
    EXPECT_LT(err_hier, 0.006);
    EXPECT_LT(err_hier, 0.35 * err_coarse);
    // Energy: emitted = absorbed + escaped + unshot, per channel.
    for (int c = 0; c < 3; ++c) {
        const double balance = hier.absorbed_power[c] + hier.escaped_power[c] + hier.unshot_power[c];
        EXPECT_NEAR(balance / hier.emitted_power[c], 1.0, 1e-9);
    }
}
