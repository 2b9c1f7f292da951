// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>

#include <glm/geometric.hpp>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/counting_visibility.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/patch_sampling.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/form_factors/reference_form_factors.h"
#include "solver/form_factors/surface_form_factor.h"
#include "solver/visibility/shaft_culler.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

double relative_error(double got, double want) { return std::abs(got - want) / want; }

}  // namespace

TEST(RaycastFormFactor, UnsubdividedQuadPairsMatchTheTablesAtDefaultSettings) {
    MeshingOptions whole;
    whole.subdivide = false;
    // Parallel table within 0.5%, perpendicular within 1% at the default receiver sampling.
    for (auto [a, b, c] : {std::tuple{1.0, 1.0, 1.0}, {2.0, 1.0, 1.0}, {1.0, 1.0, 0.5}, {1.0, 1.0, 2.0}}) {
        const PatchMesh mesh(parallel_pair(a, b, c), whole);
        const auto vis = make_cgal_visibility(mesh.patches());
        const RaycastFormFactor ff(mesh.patches(), vis.get(), {});
        const double f = ff.pair(0, 1);
        EXPECT_LT(relative_error(f, parallel_rectangles(a, b, c)), 5e-3) << a << " " << b << " " << c << ": " << f;
        EXPECT_EQ(ff.visible_fraction(0, 1), 1.0);
        // Reciprocity: identical rectangles, F_12 = F_21.
        EXPECT_LT(relative_error(ff.pair(1, 0), f), 5e-3);
    }
    for (auto [h, w, l] : {std::tuple{1.0, 1.0, 1.0}, {2.0, 1.0, 1.0}, {1.0, 2.0, 1.0}, {1.0, 1.0, 0.5}}) {
        const PatchMesh mesh(perpendicular_pair(h, w, l), whole);
        const auto vis = make_cgal_visibility(mesh.patches());
        const RaycastFormFactor ff(mesh.patches(), vis.get(), {});
        const double f = ff.pair(0, 1);
        EXPECT_LT(relative_error(f, perpendicular_rectangles(h, w, l)), 1e-2) << h << " " << w << " " << l << ": " << f;
        EXPECT_EQ(ff.visible_fraction(0, 1), 1.0) << "touching patches must not occlude each other";
    }
}

TEST(RaycastFormFactor, SubdividedSurfacesConvergeToTheTables) {
    MeshingOptions fine;
    fine.max_edge = 0.1;
    const PatchMesh par(parallel_pair(1, 1, 1), fine);
    const auto vis = make_cgal_visibility(par.patches());
    const auto ff = make_form_factor_estimator("raycast", par.patches(), vis.get(), {});
    // Far pairs use one receiver point (the centre): an O(h^2) error, measured 0.15% here.
    EXPECT_LT(relative_error(surface_form_factor(par.patches(), *ff, 0, 1), 0.199824896), 2e-3);
    const PatchMesh perp(perpendicular_pair(1, 1, 1), fine);
    const auto vis2 = make_cgal_visibility(perp.patches());
    const auto ff2 = make_form_factor_estimator("raycast", perp.patches(), vis2.get(), {});
    EXPECT_LT(relative_error(surface_form_factor(perp.patches(), *ff2, 0, 1), 0.200043776), 3e-3);
}

TEST(RaycastFormFactor, BlockerCoveringHalfTheViewHalvesTheFormFactor) {
    // Unit squares at distance 1; a large plate at z = 0.5 over x < 0.5 (the squares span
    // x in [0,1]). A ray from (x1, y1, 0) to (x2, y2, 1) is blocked when (x1 + x2)/2 < 0.5; the
    // reflection x -> 1 - x maps blocked pairs onto open ones, so exactly half of F remains.
    Scene s = parallel_pair(1, 1, 1);
    s.surfaces.push_back(
        {{{-10, -10, 0.5}, {0.5, -10, 0.5}, {0.5, 10, 0.5}, {-10, 10, 0.5}}, 0, "blocker", {"test", 0}});
    MeshingOptions o;
    o.max_edge = 1.0 / 8;
    const PatchMesh mesh(s, o);
    const auto vis = make_cgal_visibility(mesh.patches());
    FormFactorOptions fo;
    fo.visibility_rays = 16;
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), fo);
    const double f = surface_form_factor(mesh.patches(), *ff, 0, 1);
    EXPECT_LT(relative_error(f, 0.5 * 0.199824896), 1e-2) << f;
    // Without occlusion the same meshing gives the full value.
    const auto an = make_form_factor_estimator("analytic", mesh.patches(), nullptr, fo);
    EXPECT_LT(relative_error(surface_form_factor(mesh.patches(), *an, 0, 1), 0.199824896), 3e-3);
}

TEST(RaycastFormFactor, ClosedBoxRowsSumToOneAndAreReciprocal) {
    MeshingOptions o;
    o.max_edge = 0.25;
    const PatchMesh mesh(closed_box({1, 1.5, 2}, {"w", Rgb::gray(0.5), Rgb::gray(1)}), o);
    const auto& P = mesh.patches();
    const auto vis = make_cgal_visibility(P);
    const auto ff = make_form_factor_estimator("raycast", P, vis.get(), {});
    const std::size_t n = P.size();
    std::vector<float> F(n * n);
    for (std::size_t i = 0; i < n; ++i) ff->compute_row(i, std::span<float>(F.data() + i * n, n));
    double worst_sum = 0, worst_recip = 0;
    for (std::size_t i = 0; i < n; ++i) {
        double sum = 0;
        for (std::size_t j = 0; j < n; ++j) {
            sum += F[i * n + j];
            const double aij = P[i].area * F[i * n + j], aji = P[j].area * F[j * n + i];
            if (aij > 0) worst_recip = std::max(worst_recip, std::abs(aij - aji) / aij);
        }
        worst_sum = std::max(worst_sum, std::abs(sum - 1));
    }
    RecordProperty("worst_row_sum_error", std::to_string(worst_sum));
    RecordProperty("worst_reciprocity_error", std::to_string(worst_recip));
    std::printf("closed box: %zu patches, worst |row sum - 1| %.3g, worst reciprocity %.3g\n", n, worst_sum,
                worst_recip);
    // Measured: row sums 1 +- 2.5e-8 (float storage; 1 +- 0.0019 with the one-point receiver
    // rule this replaced). Each pair is computed once, so reciprocity holds to rounding
    // (1.6e-15); it was 2.7% when each way was integrated.
    EXPECT_LT(worst_sum, 1e-6);
    EXPECT_LT(worst_recip, 1e-12);
}

TEST(RaycastFormFactor, RowsDoNotDependOnTheThreadSchedule) {
    const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(1)}), MeshingOptions{.max_edge = 0.2});
    const auto vis = make_cgal_visibility(mesh.patches());
    const RaycastFormFactor ff(mesh.patches(), vis.get(), {});
    std::vector<float> row(mesh.size());
    ff.compute_row(7, row);
    for (std::size_t j = 0; j < mesh.size(); ++j) EXPECT_EQ(row[j], float(ff.pair(7, j)));
}

TEST(RaycastFormFactor, UnknownMethodIsRefusedWithTheValidNames) {
    try {
        make_form_factor_estimator("radiance", {}, nullptr, {});
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("raycast"), std::string::npos);
    }
}

namespace {

/// Unit squares z = 0 (facing +z) and z = 1 (facing -z) over [0,1]^2 with the square blocker
/// [0,0.5]^2 at z = 0.5 (shared/VALIDATION.md). A segment from (x1,y1,0) to (x2,y2,1) is blocked
/// when x1 + x2 < 1 and y1 + y2 < 1; the reflections x -> 1 - x, y -> 1 - y map the blocked set
/// onto the three open quarters with the same kernel, so exactly 3/4 of F remains, both
/// kernel-weighted and by unweighted ray fraction.
Scene symmetric_blocker_scene() {
    Scene s = parallel_pair(1, 1, 1);
    s.surfaces.push_back({{{0, 0, 0.5}, {0.5, 0, 0.5}, {0.5, 0.5, 0.5}, {0, 0.5, 0.5}}, 0, "blocker", {"test", 0}});
    return s;
}

}  // namespace

TEST(RaycastFormFactor, SymmetricBlockerIsUnbiasedForEveryRayCount) {
    // The strata were decoded with ceil(sqrt(m)) columns but only min(side^2, 64) cells:
    // --rays 256 sampled only v < 1/4 (F 35-42% low), --rays 2 always the same half, --rays 3
    // three cells of four. Now every ray count must be unbiased: the mean over seeds within
    // 3 standard errors of 3/4 of the unoccluded 0.199824896.
    const double exact = 0.75 * parallel_rectangles(1, 1, 1);  // 0.149868672
    EXPECT_NEAR(exact, 0.149868672, 1e-9);
    const PatchMesh mesh(symmetric_blocker_scene(), MeshingOptions{.subdivide = false});
    ASSERT_EQ(mesh.size(), 3u);
    const auto vis = make_embree_visibility(mesh.patches());
    for (const int rays : {2, 3, 16, 256}) {
        const int seeds = 256;
        double sum = 0, sum2 = 0;
        for (int seed = 1; seed <= seeds; ++seed) {
            FormFactorOptions o;
            o.visibility_rays = rays;
            o.seed = std::uint64_t(seed);
            o.clip_above = 0;  // the rays' own estimate, not the exact shadows
            const RaycastFormFactor ff(mesh.patches(), vis.get(), o);
            const double f = ff.pair(0, 1);
            sum += f;
            sum2 += f * f;
        }
        const double mean = sum / seeds, var = std::max(0.0, (sum2 - seeds * mean * mean) / (seeds - 1));
        const double se = std::sqrt(var / seeds);
        std::printf("--rays %d: mean %.6f over %d seeds, standard error %.2g, exact %.6f\n", rays, mean, seeds, se,
                    exact);
        EXPECT_LT(std::abs(mean - exact), 3 * se + 1e-6) << rays << " rays: mean " << mean << " se " << se;
    }
}

TEST(RaycastFormFactor, NoPairOfAnEmptyBoxIsOccludedByEitherBackend) {
    // 12 x 12 per face (864 patches): on Embree one pair came out 25% low (1 of its 4 rays
    // blocked). Its ray started within float rounding of a perpendicular wall and Embree's
    // single-precision traversal found that wall at t ~ 0. Segments are now trimmed by the
    // endpoint offset at both ends (Visibility::trimmed), in both backends.
    MeshingOptions o;
    o.max_edge = 1.0 / 12 * (1 + 1e-9);
    const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(0)}), o);
    ASSERT_EQ(mesh.size(), 864u);
    for (const char* backend : {"embree", "cgal"}) {
        const auto vis = make_visibility(backend, mesh.patches());
        const RaycastFormFactor ff(mesh.patches(), vis.get(), {});
        std::size_t blocked = 0;
        for (std::size_t i = 0; i < mesh.size(); ++i)
            for (std::size_t j = i + 1; j < mesh.size(); ++j) blocked += ff.visible_fraction(i, j) < 1.0;
        EXPECT_EQ(blocked, 0u) << backend;
    }
}

TEST(Visibility, ARayStartingAtAPerpendicularWallIsNotBlockedByIt) {
    // The false occlusion in an empty box: a ray whose origin lies within float rounding of a
    // perpendicular wall (here a floor point at x = delta from the wall x = 0, lifted by the
    // offset) going into the box. Embree rounds the origin to float (about 6e-8 of the box
    // here) and found the wall at t ~ 0; CGAL, exact, found it when delta = 0. Both backends
    // now ignore hits within the endpoint offset of either end.
    const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(0)}),
                         MeshingOptions{.subdivide = false});
    for (const char* backend : {"embree", "cgal"}) {
        const auto vis = make_visibility(backend, mesh.patches());
        const double eps = vis->offset();
        for (const double delta : {0.0, 1e-12, 1e-9, 1e-8, 3e-8, 1e-7}) {
            for (const glm::dvec3& to :
                 {glm::dvec3(0.5, 0.5, 1 - eps), glm::dvec3(1 - eps, 0.3, 0.7), glm::dvec3(0.2, 1 - eps, 0.1)}) {
                const glm::dvec3 from(delta, 0.5, eps);
                EXPECT_FALSE(vis->occluded(from, to)) << backend << " delta " << delta;
                const std::vector<Visibility::Segment> one = {
                    {from, to}, {from, to}, {from, to}, {from, to}, {from, to}};
                EXPECT_EQ(vis->open_fraction(one), 1.0) << backend << " delta " << delta;
            }
        }
        // A real blocker near the far end is still found.
        EXPECT_TRUE(vis->occluded({0.5, 0.5, 0.5}, {0.5, 0.5, 1.5}));
    }
}

TEST(RaycastFormFactor, AnEmptyConvexRoomCastsNoRaysAndABlockedSceneDoes) {
    // Every plane of an empty box lies beside every pair's shaft (ShaftCuller::clear), so no
    // ray is needed; with a blocker between two plates the pairs behind it still trace rays.
    MeshingOptions o;
    o.max_edge = 1.0 / 6 * (1 + 1e-9);
    const PatchMesh box(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(0)}), o);
    const CountingVisibility in_box(make_visibility("embree", box.patches()));
    const auto ff = make_form_factor_estimator("raycast", box.patches(), &in_box, {});
    const auto F = FormFactorMatrix::build(*ff, box.size(), std::size_t(1) << 30);
    EXPECT_EQ(in_box.segments.load(), 0u);
    for (const double s : F.row_sums()) EXPECT_NEAR(s, 1.0, 1e-6);

    Scene s = parallel_pair(1, 1, 1);
    s.surfaces.push_back(
        {{{0.1, 0.2, 0.4}, {0.6, 0.2, 0.4}, {0.6, 0.55, 0.4}, {0.1, 0.55, 0.4}}, 0, "blocker", {"t", 0}});
    const PatchMesh plates(s, MeshingOptions{.subdivide = false});
    const CountingVisibility between(make_visibility("embree", plates.patches()));
    const RaycastFormFactor rf(plates.patches(), &between, {});
    EXPECT_LT(rf.visible_fraction(0, 1), 1.0);
    EXPECT_GT(between.segments.load(), 0u);
}

TEST(RaycastFormFactor, ARotatedEmptyRoomCastsNoRaysEither) {
    // Tilted off the axes the room's box no longer proves its walls support the scene, so the
    // culler checks every vertex against each wall's plane: still no ray, rows still 1. A cube
    // floating inside makes its own faces candidate blockers again.
    const glm::dvec3 u = glm::normalize(glm::dvec3(1, 2, 3));
    const auto rotate = [&](const glm::dvec3& p) {  // 0.7 rad about u (Rodrigues)
        const double c = std::cos(0.7), s = std::sin(0.7);
        return p * c + glm::cross(u, p) * s + u * glm::dot(u, p) * (1 - c);
    };
    Scene room = closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(0)});
    for (auto& surface : room.surfaces)
        for (auto& v : surface.vertices) v = rotate(v);
    MeshingOptions o;
    o.max_edge = 1.0 / 4 * (1 + 1e-9);
    const PatchMesh box(room, o);
    const CountingVisibility in_box(make_visibility("embree", box.patches()));
    const auto ff = make_form_factor_estimator("raycast", box.patches(), &in_box, {});
    const auto F = FormFactorMatrix::build(*ff, box.size(), std::size_t(1) << 30);
    EXPECT_EQ(in_box.segments.load(), 0u);
    for (const double s : F.row_sums()) EXPECT_NEAR(s, 1.0, 1e-6);

    Scene cluttered = room;
    for (const auto& face : closed_box({0.2, 0.2, 0.2}, {"w", Rgb::gray(0.5), Rgb::gray(0)}).surfaces) {
        Surface outward = face;
        std::reverse(outward.vertices.begin(), outward.vertices.end());  // faces out of the small cube
        for (auto& v : outward.vertices) v = rotate(v + glm::dvec3(0.4));
        cluttered.surfaces.push_back(outward);
    }
    const PatchMesh inner(cluttered, o);
    const CountingVisibility around(make_visibility("embree", inner.patches()));
    const auto ff2 = make_form_factor_estimator("raycast", inner.patches(), &around, {});
    const auto F2 = FormFactorMatrix::build(*ff2, inner.size(), std::size_t(1) << 30);
    EXPECT_GT(around.segments.load(), 0u);
}

// ShaftCuller::unblocked for polygons the culler does not hold (a hierarchy's elements against
// the input patches): the quarters of two facing plates, with a blocker over part of the gap.
// Every pair it proves unblocked must pass all of 256 rays; the pair straight across the
// blocker must not be proved; and the plates the quarters lie on never count as blockers.
TEST(ShaftCuller, ProvesPolygonsOutsideItsPatchesUnblockedOnlyWhenNothingLiesBetween) {
    Scene s = parallel_pair(1, 1, 1);
    s.surfaces.push_back(
        {{{0.1, 0.1, 0.5}, {0.4, 0.1, 0.5}, {0.4, 0.4, 0.5}, {0.1, 0.4, 0.5}}, 0, "blocker", {"t", 0}});
    const PatchMesh input(s, MeshingOptions{.subdivide = false});
    const ShaftCuller culler(input.patches());
    const auto vis = make_visibility("embree", input.patches());
    MeshingOptions quarters;
    quarters.max_edge = 0.5 * (1 + 1e-9);
    const PatchMesh plates(parallel_pair(1, 1, 1), quarters);
    ASSERT_EQ(plates.size(), 8u);
    SplitMix64 rng{7};
    std::size_t proved = 0, refused = 0;
    for (std::size_t i = 0; i < plates.size(); ++i)
        for (std::size_t j = 0; j < plates.size(); ++j) {
            const Patch &p = plates.patches()[i], &q = plates.patches()[j];
            if (p.surface != 0 || q.surface != 1) continue;
            const bool unblocked = culler.unblocked(p, q);
            (unblocked ? proved : refused) += 1;
            std::vector<Visibility::Segment> rays;
            for (int r = 0; r < 256; ++r)
                rays.push_back({patch_point(p, rng.uniform(), rng.uniform()) + vis->offset() * p.normal,
                                patch_point(q, rng.uniform(), rng.uniform()) + vis->offset() * q.normal});
            const double open = vis->open_fraction(rays);
            if (unblocked) {
                EXPECT_EQ(open, 1.0) << "quarters " << i << " and " << j;
            }
            // Both over the blocker's corner (x, y < 0.5): the blocker lies in their shaft.
            if (p.centre.x < 0.5 && p.centre.y < 0.5 && q.centre.x < 0.5 && q.centre.y < 0.5) {
                EXPECT_FALSE(unblocked);
                EXPECT_LT(open, 1.0);
            }
        }
    EXPECT_EQ(proved + refused, 16u);
    // Quarters far from the blocker's corner (x and y both over 0.5 on each plate) see each other past it.
    EXPECT_GE(proved, 1u);
    EXPECT_GE(refused, 1u);
    // Without the blocker nothing is ever in the way (and the plates' planes, which every
    // vertex lies beside, are not even tested).
    const PatchMesh open_pair(parallel_pair(1, 1, 1), MeshingOptions{.subdivide = false});
    const ShaftCuller empty(open_pair.patches());
    for (const Patch& p : plates.patches())
        for (const Patch& q : plates.patches())
            if (p.surface != q.surface) {
                EXPECT_TRUE(empty.unblocked(p, q));
            }
}

// The planes a shaft may cross hold patches of their own: two blocks standing on a floor. An
// element on block A's front face sees the floor in front of it past nothing (A's own face and
// the floor it is cut from lie in the planes of the pair and never block), and the floor behind
// block B only through B.
TEST(ShaftCuller, ElementsOnABlocksFaceSeeTheFloorUnlessAnotherBlockStandsBetween) {
    Scene s;
    s.name = "blocks on a floor";
    s.materials = {{"m", Rgb::gray(0.5), Rgb()}};
    s.surfaces.push_back({{{-4, -4, 0}, {8, -4, 0}, {8, 4, 0}, {-4, 4, 0}}, 0, "floor", {"t", 0}});
    const auto block = [&s](double x0, double x1, const char* name) {
        const double y0 = -1, y1 = 1, h = 1;
        s.surfaces.push_back({{{x1, y0, 0}, {x1, y1, 0}, {x1, y1, h}, {x1, y0, h}}, 0, name, {"t", 0}});  // +x
        s.surfaces.push_back({{{x0, y0, 0}, {x0, y0, h}, {x0, y1, h}, {x0, y1, 0}}, 0, name, {"t", 0}});  // -x
        s.surfaces.push_back({{{x0, y0, h}, {x1, y0, h}, {x1, y1, h}, {x0, y1, h}}, 0, name, {"t", 0}});  // top
        s.surfaces.push_back({{{x0, y0, 0}, {x1, y0, 0}, {x1, y0, h}, {x0, y0, h}}, 0, name, {"t", 0}});  // -y
        s.surfaces.push_back({{{x0, y1, 0}, {x0, y1, h}, {x1, y1, h}, {x1, y1, 0}}, 0, name, {"t", 0}});  // +y
    };
    block(0, 1, "A");
    block(2, 3, "B");
    const PatchMesh input(s, MeshingOptions{.subdivide = false, .cut_contacts = false});
    const ShaftCuller culler(input.patches());
    ASSERT_GT(culler.plane_groups(), 0u);  // the blocks' side planes cut the floor
    const auto patch = [](std::vector<glm::dvec3> v) {
        Scene one;
        one.materials = {{"m", Rgb::gray(0.5), Rgb()}};
        one.surfaces.push_back({std::move(v), 0, "piece", {"t", 0}});
        return PatchMesh(one, MeshingOptions{.subdivide = false}).patches().front();
    };
    // A quarter of block A's +x face (x = 1), facing the floor between the blocks and beyond.
    const Patch face = patch({{1, 0, 0.5}, {1, 0.5, 0.5}, {1, 0.5, 1}, {1, 0, 1}});
    const Patch between = patch({{1.2, -0.5, 0}, {1.8, -0.5, 0}, {1.8, 0.5, 0}, {1.2, 0.5, 0}});
    const Patch beyond = patch({{3.5, -0.5, 0}, {4.5, -0.5, 0}, {4.5, 0.5, 0}, {3.5, 0.5, 0}});
    const Patch aside = patch({{1.2, 2.5, 0}, {1.8, 2.5, 0}, {1.8, 3.5, 0}, {1.2, 3.5, 0}});
    EXPECT_TRUE(culler.unblocked(face, between));
    EXPECT_TRUE(culler.unblocked(face, aside));
    EXPECT_FALSE(culler.unblocked(face, beyond));  // block B stands in the way
    const auto vis = make_visibility("embree", input.patches());
    SplitMix64 rng{3};
    for (const Patch* q : {&between, &aside, &beyond}) {
        std::vector<Visibility::Segment> rays;
        for (int r = 0; r < 256; ++r)
            rays.push_back({patch_point(face, rng.uniform(), rng.uniform()) + vis->offset() * face.normal,
                            patch_point(*q, rng.uniform(), rng.uniform()) + vis->offset() * q->normal});
        const double open = vis->open_fraction(rays);
        if (culler.unblocked(face, *q)) {
            EXPECT_EQ(open, 1.0);
        } else {
            EXPECT_LT(open, 1.0);
        }
    }
}

namespace {

/// The asymmetric blocker of shared/VALIDATION.md: unit squares 1 apart (parallel_pair) and
/// the blocker [0.1,0.6] x [0.2,0.55] at z = 0.4. F12 = 0.140126989 exactly.
Scene asymmetric_blocker() {
    Scene s = parallel_pair(1, 1, 1);
    s.surfaces.push_back(
        {{{0.1, 0.2, 0.4}, {0.6, 0.2, 0.4}, {0.6, 0.55, 0.4}, {0.1, 0.55, 0.4}}, 0, "blocker", {"test", 0}});
    return s;
}
constexpr double kAsymmetricBlockerF12 = 0.140126989;

}  // namespace

TEST(RaycastFormFactor, KernelWeightedRaysConvergeToTheOccludedFactor) {
    // The plain share of open rays tends to 0.135298 here (3.4% low): a ray's weight must be its
    // kernel. 4096 stratified rays on each of 12 seeds (each about 1% apart): their mean within 1%.
    const PatchMesh mesh(asymmetric_blocker(), MeshingOptions{.subdivide = false});
    const auto vis = make_visibility("embree", mesh.patches());
    double sum = 0;
    const int seeds = 12;
    for (int seed = 1; seed <= seeds; ++seed) {
        FormFactorOptions o;
        o.visibility_rays = 4096;
        o.seed = std::uint64_t(seed);
        o.clip_above = 0;
        const RaycastFormFactor ff(mesh.patches(), vis.get(), o);
        sum += ff.pair(0, 1);
    }
    std::printf("asymmetric blocker, 4096 rays, mean of %d seeds: %.6f\n", seeds, sum / seeds);
    EXPECT_NEAR(sum / seeds / kAsymmetricBlockerF12, 1.0, 0.01);
}

TEST(RaycastFormFactor, PartlyBlockedPairsGetMoreRaysWithoutBias) {
    // Both plates and the blocker cut 16 x 16, default options (2 rays a pair, 16 where they
    // disagree): F12 as the area-weighted sum of the plate's rows.
    MeshingOptions cut;
    cut.max_edge = 1.0 / 16 * (1 + 1e-9);
    const PatchMesh mesh(asymmetric_blocker(), cut);
    const auto vis = make_visibility("embree", mesh.patches());
    for (const int partial : {0, 16}) {
        FormFactorOptions o;
        o.partial_rays = partial;
        const RaycastFormFactor ff(mesh.patches(), vis.get(), o);
        std::vector<float> row(mesh.size());
        double num = 0, area = 0;
        for (std::size_t i = 0; i < mesh.size(); ++i) {
            if (mesh.patches()[i].surface != 0) continue;
            ff.compute_row(i, row);
            area += mesh.patches()[i].area;
            for (std::size_t j = 0; j < mesh.size(); ++j)
                if (mesh.patches()[j].surface == 1) num += mesh.patches()[i].area * double(row[j]);
        }
        std::printf("asymmetric blocker cut 16 x 16, partial rays %d: %.7f (error %.2g)\n", partial, num / area,
                    num / area - kAsymmetricBlockerF12);
        EXPECT_LT(std::abs(num / area - kAsymmetricBlockerF12), 1e-4);  // issue 34's goal for the default
    }
    // Whole surfaces, 2 rays: 0, 1/2 or 1 of the unoccluded 0.1998. With a pilot the partly
    // blocked pair is traced with 16 fresh rays: over 200 seeds the mean stays within 3 standard
    // errors of the exact factor (reusing the pilot's rays would not: the rays that agree decide
    // to stop), and the seeds scatter less (a pilot whose two rays agree still gives 0 or 1).
    const PatchMesh whole(asymmetric_blocker(), MeshingOptions{.subdivide = false});
    const auto wvis = make_visibility("embree", whole.patches());
    double deviation[2] = {0, 0};
    for (const int partial : {0, 16}) {
        const int seeds = 200;
        double sum = 0, sum2 = 0;
        for (int seed = 1; seed <= seeds; ++seed) {
            FormFactorOptions o;
            o.seed = std::uint64_t(seed);
            o.partial_rays = partial;
            o.clip_above = 0;
            const double f = RaycastFormFactor(whole.patches(), wvis.get(), o).pair(0, 1);
            sum += f;
            sum2 += f * f;
        }
        const double mean = sum / seeds, sd = std::sqrt(std::max(0.0, (sum2 - seeds * mean * mean) / (seeds - 1)));
        std::printf("asymmetric blocker whole, partial rays %d: mean %.5f, standard deviation %.4f\n", partial, mean,
                    sd);
        EXPECT_LT(std::abs(mean - kAsymmetricBlockerF12), 3 * sd / std::sqrt(double(seeds))) << partial;
        deviation[partial ? 1 : 0] = sd;
    }
    EXPECT_LT(deviation[1], 0.8 * deviation[0]);
}

TEST(RaycastFormFactor, LargePartlyBlockedPairsTakeTheBlockersExactShadows) {
    // Whole surfaces (one patch each) and the default options: the pair's unoccluded factor,
    // 0.1998, is above clip_above, so its visibility is the blocker's shadow clipped out of the
    // source at quadrature points on the receiver (the exact method's first two levels), not
    // two rays (which give 0, 0.0999 or 0.1998). Issue 34 asks for 1e-4; the shadow clipping is
    // within 1e-6, the same for every seed, and both ways round by reciprocity.
    const PatchMesh whole(asymmetric_blocker(), MeshingOptions{.subdivide = false});
    ASSERT_EQ(whole.size(), 3u);
    const auto vis = make_visibility("embree", whole.patches());
    for (int seed = 1; seed <= 5; ++seed) {
        FormFactorOptions o;
        o.seed = std::uint64_t(seed);
        const RaycastFormFactor ff(whole.patches(), vis.get(), o);
        EXPECT_NEAR(ff.pair(0, 1), kAsymmetricBlockerF12, 1e-6) << seed;
        EXPECT_NEAR(ff.pair(1, 0), kAsymmetricBlockerF12, 1e-6) << seed;  // equal areas
    }
    // Above the pair's factor the two rays decide, and miss the factor by far more.
    FormFactorOptions rays_only;
    rays_only.clip_above = 0.5;
    const double f = RaycastFormFactor(whole.patches(), vis.get(), rays_only).pair(0, 1);
    std::printf("asymmetric blocker whole, 2 rays: %.6f against %.6f\n", f, kAsymmetricBlockerF12);
    EXPECT_GT(std::abs(f - kAsymmetricBlockerF12), 1e-3);
}

TEST(RaycastFormFactor, OccludersThatAreNoPatchesBlockEvenInAConvexRoom) {
    // An empty convex box: the shaft test proves every pair open. A square occluder (a mirror,
    // say) across the middle of the box, which is no patch, must still block the floor's view
    // of the ceiling, for either backend.
    MeshingOptions o;
    o.max_edge = 0.5;
    const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(1)}), o);
    const auto& P = mesh.patches();
    const std::vector<OccluderTriangle> mirror = {
        {glm::dvec3(-1, -1, 0.5), glm::dvec3(2, -1, 0.5), glm::dvec3(2, 2, 0.5)},
        {glm::dvec3(-1, -1, 0.5), glm::dvec3(2, 2, 0.5), glm::dvec3(-1, 2, 0.5)}};
    for (const std::string backend : {"embree", "cgal"}) {
        const auto open = make_visibility(backend, P);
        const auto blocked = make_visibility(backend, P, mirror);
        EXPECT_FALSE(open->has_occluders());
        EXPECT_TRUE(blocked->has_occluders());
        const auto ff_open = make_form_factor_estimator("raycast", P, open.get(), {});
        const auto ff_blocked = make_form_factor_estimator("raycast", P, blocked.get(), {});
        std::vector<float> row_open(P.size()), row_blocked(P.size());
        double to_ceiling_open = 0, to_ceiling_blocked = 0;
        for (std::size_t i = 0; i < P.size(); ++i) {
            if (P[i].normal.z < 0.5) continue;  // floor patches (z = 0, facing +z)
            ff_open->compute_row(i, row_open);
            ff_blocked->compute_row(i, row_blocked);
            for (std::size_t j = 0; j < P.size(); ++j)
                if (P[j].normal.z < -0.5) to_ceiling_open += row_open[j], to_ceiling_blocked += row_blocked[j];
        }
        EXPECT_GT(to_ceiling_open, 0.5) << backend;
        EXPECT_EQ(to_ceiling_blocked, 0.0) << backend;
    }
    EXPECT_THROW(make_form_factor_estimator("exact", P, make_visibility("embree", P, mirror).get(), {}),
                 std::invalid_argument);
}
