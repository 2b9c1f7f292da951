// SPDX-License-Identifier: MIT
// The exact method: pair classification by shaft culling, exact unoccluded factors, and
// shadow-clipped visibility against closed forms.
#include <gtest/gtest.h>
#define GLM_ENABLE_EXPERIMENTAL
#include <glm/gtx/string_cast.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "mesh/geometry/contact_cuts.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/exact_form_factor.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/patch_sampling.h"
#include "solver/form_factors/reference_form_factors.h"
#include "solver/visibility/convex_blockers.h"
#include "solver/visibility/shaft_culler.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

/// Differential area at (px, py, 0) facing +z to the parallel rectangle [x1,x2]x[y1,y2] at
/// height c: the signed corner sum of Howell B-3 (the factor to a rectangle with one corner
/// straight above the point is odd in each of its sides).
double point_to_rectangle(double px, double py, double x1, double x2, double y1, double y2, double c) {
    if (x2 <= x1 || y2 <= y1) return 0.0;
    const auto f = [c](double a, double b) {
        if (a == 0 || b == 0) return 0.0;
        return (a > 0 ? 1 : -1) * (b > 0 ? 1 : -1) * point_to_rectangle_corner(std::abs(a), std::abs(b), c);
    };
    return f(x2 - px, y2 - py) - f(x1 - px, y2 - py) - f(x2 - px, y1 - py) + f(x1 - px, y1 - py);
}

/// The asymmetric blocker of shared/VALIDATION.md by the shadow-rectangle construction: from a
/// point x of the upper unit square (z = 1, facing down), the blocker [0.1,0.6]x[0.2,0.55] at
/// z = 0.4 casts the rectangle x + (b - x) / 0.6 on the plane z = 0; the point sees the lower
/// square minus that rectangle, F(x) = F(square) - F(square ∩ shadow), both parallel
/// rectangles in closed form. F21 (= F12, equal areas) is the mean of F(x) over the upper
/// square. A shadow edge leaves the square at x = 1/4 and y = 1/2 (the others stay inside or
/// outside throughout), so F(x) is smooth on the four cells between those lines, where
/// 16 x 16 Gauss-Legendre points per cell are exact to rounding.
double asymmetric_blocker_exact() {
    std::vector<double> gx, gw;
    gauss_legendre(16, gx, gw);
    const double xs[] = {0, 0.25, 1}, ys[] = {0, 0.5, 1};
    const auto shadow = [](double p, double b) { return p + (b - p) / 0.6; };
    double total = 0;
    for (int cx = 0; cx < 2; ++cx)
        for (int cy = 0; cy < 2; ++cy)
            for (int a = 0; a < 16; ++a)
                for (int b = 0; b < 16; ++b) {
                    const double x = xs[cx] + gx[a] * (xs[cx + 1] - xs[cx]);
                    const double y = ys[cy] + gx[b] * (ys[cy + 1] - ys[cy]);
                    const double w = gw[a] * gw[b] * (xs[cx + 1] - xs[cx]) * (ys[cy + 1] - ys[cy]);
                    const double full = point_to_rectangle(x, y, 0, 1, 0, 1, 1);
                    const double hidden =
                        point_to_rectangle(x, y, std::max(0.0, shadow(x, 0.1)), std::min(1.0, shadow(x, 0.6)),
                                           std::max(0.0, shadow(y, 0.2)), std::min(1.0, shadow(y, 0.55)), 1);
                    total += w * (full - hidden);
                }
    return total;
}

Scene blocker_scene(double x1, double x2, double y1, double y2, double z) {
    Scene s = parallel_pair(1, 1, 1);
    s.surfaces.push_back({{{x1, y1, z}, {x2, y1, z}, {x2, y2, z}, {x1, y2, z}}, 0, "blocker", {"test", 0}});
    return s;
}

}  // namespace

TEST(ShaftCuller, AnEmptyConvexBoxHasNoCandidateBlockers) {
    MeshingOptions o;
    o.max_edge = 1.0 / 6 * (1 + 1e-9);
    const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(0)}), o);
    const ShaftCuller culler(mesh.patches());
    std::vector<std::uint32_t> c;
    std::size_t found = 0;
    for (std::size_t i = 0; i < mesh.size(); ++i)
        for (std::size_t j = i + 1; j < mesh.size(); ++j) {
            culler.candidates(i, j, c);
            found += c.size();
        }
    EXPECT_EQ(found, 0u);
}

TEST(ShaftCuller, FindsTheBlockerBetweenTwoPlatesAndNothingBeside) {
    const PatchMesh mesh(blocker_scene(0.1, 0.6, 0.2, 0.55, 0.4), MeshingOptions{.subdivide = false});
    const ShaftCuller culler(mesh.patches());
    std::vector<std::uint32_t> c;
    culler.candidates(0, 1, c);
    ASSERT_EQ(c.size(), 1u);
    EXPECT_EQ(c[0], 2u);
    // Moved out of the shaft (beside the plates), it is no candidate.
    const PatchMesh beside(blocker_scene(1.2, 1.7, 0.2, 0.55, 0.4), MeshingOptions{.subdivide = false});
    const ShaftCuller c2(beside.patches());
    c2.candidates(0, 1, c);
    EXPECT_TRUE(c.empty());
}

TEST(ExactFormFactor, AsymmetricBlockerWithin1e4OfTheShadowRectangleValue) {
    // Unit squares 1 apart, the blocker [0.1,0.6]x[0.2,0.55] at z = 0.4, whole surfaces. The
    // unweighted ray fraction converges to 0.135298 (3.4% low); kernel-weighted shadows must not.
    const double exact = asymmetric_blocker_exact();
    EXPECT_NEAR(exact, 0.140126989, 5e-10);
    const PatchMesh mesh(blocker_scene(0.1, 0.6, 0.2, 0.55, 0.4), MeshingOptions{.subdivide = false});
    const ExactFormFactor ff(mesh.patches(), true, {});
    double err = 0;
    const double f = ff.pair(0, 1, &err);
    std::printf("asymmetric blocker: exact %.9f, method %.9f (error %.2g, estimated %.2g)\n", exact, f,
                std::abs(f - exact), err);
    EXPECT_LT(std::abs(f - exact), 1e-4);
    EXPECT_LT(std::abs(ff.pair(1, 0) - exact), 1e-4);  // equal areas: F21 = F12
    // The symmetric blocker hides exactly a quarter.
    const PatchMesh sym(blocker_scene(0, 0.5, 0, 0.5, 0.5), MeshingOptions{.subdivide = false});
    const ExactFormFactor fs(sym.patches(), true, {});
    EXPECT_LT(std::abs(fs.pair(0, 1) - 0.149868672), 1e-5);
    const PairTally t = ff.tally();
    EXPECT_EQ(t.partial, 2u);
}

TEST(ExactFormFactor, AsymmetricBlockerCut16x16Within1e4) {
    // Both plates and the blocker cut 16 x 16 (1 / 16 edges).
    MeshingOptions o;
    o.max_edge = 1.0 / 16 * (1 + 1e-9);
    const PatchMesh mesh(blocker_scene(0.1, 0.6, 0.2, 0.55, 0.4), o);
    const ExactFormFactor ff(mesh.patches(), true, {});
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<float> row(mesh.size());
    double num = 0, area = 0;
    for (std::size_t i = 0; i < mesh.size(); ++i) {
        if (mesh.patches()[i].surface != 0) continue;
        ff.compute_row(i, row);
        area += mesh.patches()[i].area;
        for (std::size_t j = 0; j < mesh.size(); ++j)
            if (mesh.patches()[j].surface == 1) num += mesh.patches()[i].area * double(row[j]);
    }
    const double f = num / area;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("asymmetric blocker cut 16 x 16: %.9f (error %.2g) in %.3f s\n", f, std::abs(f - 0.140126989), s);
    EXPECT_LT(std::abs(f - 0.140126989), 1e-4);
}

TEST(ExactFormFactor, AsymmetricBlockerEverySurfaceCut16x16Within1e6) {
    // The plates and the blocker each cut 16 x 16: the blocker's 256 patches tile one convex
    // rectangle, so they cast one flat shadow (ConvexBlockers) and every pair is clipped, where
    // more than two loose candidate shadows would fall back to kernel-weighted rays (1.5e-4).
    MeshingOptions o;
    o.max_edge = 1.0 / 16 * (1 + 1e-9);
    std::vector<Patch> patches = PatchMesh(parallel_pair(1, 1, 1), o).patches();
    // The blocker [0.1,0.6]x[0.2,0.55] at z = 0.4: a unit square cut 16 x 16, then scaled.
    Scene unit;
    unit.materials = {{"w", Rgb::gray(0.5), Rgb()}};
    unit.surfaces.push_back({{{0, 0, 0.4}, {1, 0, 0.4}, {1, 1, 0.4}, {0, 1, 0.4}}, 0, "blocker", {"test", 0}});
    const PatchMesh unit_mesh(unit, o);  // named: a temporary would die before the loop runs
    for (Patch p : unit_mesh.patches()) {
        for (int k = 0; k < p.vertex_count; ++k)
            p.vertices[std::size_t(k)] = {0.1 + 0.5 * p.vertices[std::size_t(k)].x,
                                          0.2 + 0.35 * p.vertices[std::size_t(k)].y, 0.4};
        p.centre = {0.1 + 0.5 * p.centre.x, 0.2 + 0.35 * p.centre.y, 0.4};
        p.area *= 0.5 * 0.35;
        p.surface = 2;
        patches.push_back(p);
    }
    ASSERT_EQ(patches.size(), 3u * 256u);
    const ExactFormFactor ff(patches, true, {}, nullptr);
    const auto rays = make_visibility("embree", patches);
    const ExactFormFactor with_rays(patches, true, {}, rays.get());
    double num = 0, num_rays = 0, area = 0;
    for (std::size_t i = 0; i < 256; ++i) {
        area += patches[i].area;
        for (std::size_t j = 256; j < 512; ++j) {
            num += patches[i].area * ff.pair(i, j);
            num_rays += patches[i].area * with_rays.pair(i, j);
        }
    }
    std::printf("asymmetric blocker, every surface cut 16 x 16: %.9f (error %.2g), with a ray backend %.2g\n",
                num / area, std::abs(num / area - 0.140126989), std::abs(num_rays / area - 0.140126989));
    EXPECT_LT(std::abs(num / area - 0.140126989), 1e-6);
    EXPECT_LT(std::abs(num_rays / area - 0.140126989), 1e-6);  // no pair has more than one shadow
}

TEST(ExactFormFactor, CubeRowsSumToOneAndAreReciprocal) {
    // Each face cut n x n: every row within 1e-9 of 1 and reciprocity to rounding. Each
    // unordered pair is computed once (in double; float storage would round entries to 6e-8)
    // and added to both rows; at 20 x 20 every 5th row is checked.
    for (const int n : {6, 12, 20}) {
        MeshingOptions o;
        o.max_edge = 1.0 / n * (1 + 1e-9);
        const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(0)}), o);
        const auto& P = mesh.patches();
        ASSERT_EQ(P.size(), std::size_t(6 * n * n));
        const ExactFormFactor ff(P, true, {});
        const auto t0 = std::chrono::steady_clock::now();
        const std::size_t stride = n == 20 ? 5 : 1;
        std::vector<double> sums(P.size(), 0.0);
        double worst_recip = 0;
        for (std::size_t i = 0; i < P.size(); i += stride)
            for (std::size_t j = 0; j < P.size(); ++j) {
                if (stride == 1 && j <= i) continue;
                const double fij = ff.pair(i, j);
                sums[i] += fij;
                if (stride == 1) sums[j] += fij * P[i].area / P[j].area;
                if (i % 97 == 0 && fij > 0)
                    worst_recip = std::max(worst_recip,
                                           std::abs(P[i].area * fij - P[j].area * ff.pair(j, i)) / (P[i].area * fij));
            }
        double worst = 0;
        for (std::size_t i = 0; i < P.size(); i += stride) worst = std::max(worst, std::abs(sums[i] - 1));
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::printf("cube %dx%d: worst |row sum - 1| %.3g, reciprocity %.3g (%.2f s, one thread)\n", n, n, worst,
                    worst_recip, s);
        EXPECT_LT(worst, 1e-9) << n;
        EXPECT_LT(worst_recip, 1e-12) << n;
        EXPECT_EQ(ff.tally().partial + ff.tally().hidden, 0u);
    }
}

TEST(ExactFormFactor, DefaultSettingsMatchEveryRectangleTableTo1e9OnWholeSurfaces) {
    // The method's own default tolerance (1e-8, a stopping threshold on successive orders that
    // overestimates the error) still meets 1e-9 on every rectangle of VALIDATION.md.
    for (auto [a, b, c] : {std::tuple{1.0, 1.0, 1.0},
                           {2.0, 1.0, 1.0},
                           {1.0, 1.0, 0.5},
                           {1.0, 1.0, 2.0},
                           {1.0, 1.0, 0.01},
                           {1.0, 1.0, 0.001}}) {
        const PatchMesh mesh(parallel_pair(a, b, c), MeshingOptions{.subdivide = false});
        const ExactFormFactor ff(mesh.patches(), true, {});
        EXPECT_LT(std::abs(ff.pair(0, 1) / parallel_rectangles(a, b, c) - 1), 1e-9) << a << " " << b << " " << c;
    }
    for (auto [h, w, l] : {std::tuple{1.0, 1.0, 1.0}, {2.0, 1.0, 1.0}, {1.0, 2.0, 1.0}, {1.0, 1.0, 0.5}}) {
        const PatchMesh mesh(perpendicular_pair(h, w, l), MeshingOptions{.subdivide = false});
        const ExactFormFactor ff(mesh.patches(), true, {});
        EXPECT_LT(std::abs(ff.pair(0, 1) / perpendicular_rectangles(h, w, l) - 1), 1e-9) << h << " " << w << " " << l;
    }
}

namespace {

/// The cube [lo, lo + size]^3 with outward faces (closed_box's inward faces, reversed), all
/// but the faces listed in `skip` (0: z = lo, the bottom).
void add_solid_cube(Scene& s, glm::dvec3 lo, double size, std::vector<int> skip = {}) {
    const Scene box = closed_box({size, size, size}, {"w", Rgb::gray(0.5), Rgb::gray(0)});
    for (std::size_t k = 0; k < box.surfaces.size(); ++k) {
        if (std::find(skip.begin(), skip.end(), int(k)) != skip.end()) continue;
        Surface f = box.surfaces[k];
        std::reverse(f.vertices.begin(), f.vertices.end());
        for (auto& v : f.vertices) v += lo;
        f.material = 0;
        s.surfaces.push_back(f);
    }
}

}  // namespace

TEST(ConvexBlockers, TheCornellBlocksAreSolidsAndNothingElseIs) {
    Scene s = make_cornell_box();
    s.covered = find_covered_regions(s);
    const PatchMesh mesh(s, MeshingOptions{});
    const auto& P = mesh.patches();
    const ConvexBlockers solids(P);
    std::size_t closed = 0;
    for (std::size_t k = 0; k < solids.solid_count(); ++k) closed += !solids.solid(k).flat;
    EXPECT_EQ(closed, 2u);
    for (std::size_t i = 0; i < P.size(); ++i) {
        const auto& surface = s.surfaces[std::size_t(P[i].surface)];
        const bool block = surface.object.find("block") != std::string::npos;
        const std::int32_t k = solids.solid_of(i);
        EXPECT_EQ(k >= 0 && !solids.solid(std::size_t(k)).flat, block) << i << " " << surface.object;
        // The walls are cut into patches on one plane, each tiling its rectangle: flat solids.
        // The floor and the ceiling are not: the blocks' footprints and the lamp's are cut out.
        if (!block) {
            EXPECT_EQ(k >= 0, surface.object != "floor" && surface.object != "ceiling") << i << " " << surface.object;
        }
    }
}

TEST(ConvexBlockers, ATiledConvexSurfaceIsOneFlatShadow) {
    // The asymmetric blocker cut 16 x 12: one flat solid, whose shadow from a point above is
    // the blocker's rectangle projected. (A notched surface is none: the Cornell floor above.)
    Scene s = blocker_scene(0.1, 0.6, 0.2, 0.55, 0.4);
    MeshingOptions o;
    o.max_edge = 0.5 / 16 * (1 + 1e-9);
    const PatchMesh mesh(s, o);
    const ConvexBlockers solids(mesh.patches());
    std::int32_t blocker = -1;
    std::size_t members = 0;
    for (std::size_t i = 0; i < mesh.size(); ++i)
        if (mesh.patches()[i].surface == 2) {
            blocker = solids.solid_of(i);
            ++members;
        }
    ASSERT_GT(members, 100u);
    ASSERT_GE(blocker, 0);
    const auto& flat = solids.solid(std::size_t(blocker));
    EXPECT_TRUE(flat.flat);
    EXPECT_EQ(flat.corners.size(), 4u);  // the tiles' inner vertices are no corners
    std::vector<glm::dvec3> shadow;
    convex_shadow(flat, {0.35, 0.375, 0.8}, {0, 0, 0}, {0, 0, 1}, shadow);
    glm::dvec3 twice(0.0);
    for (std::size_t k = 0; k < shadow.size(); ++k) twice += glm::cross(shadow[k], shadow[(k + 1) % shadow.size()]);
    EXPECT_NEAR(0.5 * twice.z, 0.5 * 0.35 * 4.0, 1e-12);  // scaled by 0.8 / (0.8 - 0.4) each way
}

TEST(ConvexBlockers, AnOpenBoxIsNoSolidUnlessItsOpenFaceRestsOnASurface) {
    MeshingOptions o;
    o.max_edge = 0.25;
    Scene closed;
    closed.materials = {{"w", Rgb::gray(0.5), Rgb()}};
    add_solid_cube(closed, {0, 0, 0.5}, 1.0);
    EXPECT_EQ(ConvexBlockers(PatchMesh(closed, o).patches()).solid_count(), 1u);
    Scene open = closed;
    open.surfaces.clear();
    add_solid_cube(open, {0, 0, 0.5}, 1.0, {0});  // no bottom, floating: light gets in
    EXPECT_EQ(ConvexBlockers(PatchMesh(open, o).patches()).solid_count(), 0u);
    // The same open box standing on a floor that faces it: the floor closes it.
    Scene standing = open;
    for (auto& f : standing.surfaces)
        for (auto& v : f.vertices) v.z -= 0.5;
    standing.surfaces.push_back({{{-1, -1, 0}, {2, -1, 0}, {2, 2, 0}, {-1, 2, 0}}, 0, "floor", {"test", 0}});
    const PatchMesh on_floor(standing, o);
    const ConvexBlockers found(on_floor.patches());
    ASSERT_EQ(found.solid_count(), 2u);  // the box, and the floor as a flat solid
    for (std::size_t i = 0; i < on_floor.size(); ++i) {
        const std::int32_t k = found.solid_of(i);
        ASSERT_GE(k, 0) << i;
        EXPECT_EQ(found.solid(std::size_t(k)).flat, on_floor.patches()[i].centre.z < 1e-9) << i;  // the floor apart
    }
}

TEST(ConvexBlockers, ASolidsShadowEqualsItsFacesShadowsAndTheProjection) {
    // A cube [0,1]^2 x [1,2] over the plane z = 0, seen from (0.5, 0.5, 3): its top face
    // projects to a square of side 3 (factor 3 / (3 - 2)), which holds the rest: area 9.
    Scene s;
    s.materials = {{"w", Rgb::gray(0.5), Rgb()}};
    add_solid_cube(s, {0, 0, 1}, 1.0);
    const PatchMesh mesh(s, MeshingOptions{.subdivide = false});
    const auto& P = mesh.patches();
    const ConvexBlockers solids(P);
    ASSERT_EQ(solids.solid_count(), 1u);
    std::vector<glm::dvec3> shadow;
    convex_shadow(solids.solid(0), {0.5, 0.5, 3}, {0, 0, 0}, {0, 0, 1}, shadow);
    ASSERT_GE(shadow.size(), 4u);
    glm::dvec3 twice(0.0);
    for (std::size_t k = 0; k < shadow.size(); ++k) twice += glm::cross(shadow[k], shadow[(k + 1) % shadow.size()]);
    EXPECT_NEAR(0.5 * twice.z, 9.0, 1e-9);  // counter-clockwise about +z
    // From points around the cube, also level with it (only part of it lies between the point
    // and the plane), the point factor to a plate on z = 0 is the same with the solid's one
    // shadow as with its six faces' shadows.
    const std::vector<glm::dvec3> plate = {{-4, -4, 0}, {5, -4, 0}, {5, 5, 0}, {-4, 5, 0}};
    std::vector<std::span<const glm::dvec3>> faces;
    for (const auto& p : P) faces.push_back(p.polygon());
    const std::vector<std::uint32_t> which = {0};
    SplitMix64 rng{7};
    int checked = 0;
    for (int k = 0; k < 200; ++k) {
        const glm::dvec3 x(-2 + 5 * rng.uniform(), -2 + 5 * rng.uniform(), 0.2 + 3.5 * rng.uniform());
        if (x.x > -0.01 && x.x < 1.01 && x.y > -0.01 && x.y < 1.01 && x.z > 0.99 && x.z < 2.01) continue;  // inside
        const glm::dvec3 n = glm::normalize(glm::dvec3(rng.uniform() - 0.5, rng.uniform() - 0.5, -1.0));
        const double by_faces = shadowed_point_factor(x, n, plate, {0, 0, 1}, faces);
        const double by_solid = shadowed_point_factor(x, n, plate, {0, 0, 1}, {}, &solids, which);
        EXPECT_NEAR(by_solid, by_faces, 1e-12 + 1e-9 * by_faces) << glm::to_string(x);
        checked += by_faces < shadowed_point_factor(x, n, plate, {0, 0, 1}, {}) - 1e-6;  // the cube hides some
    }
    EXPECT_GT(checked, 50);
}
