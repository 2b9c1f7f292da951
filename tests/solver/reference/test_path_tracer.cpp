// SPDX-License-Identifier: MIT
// The path-traced reference against cases with known answers (shared/VALIDATION.md): the
// furnace, direct light from a square emitter with and without an exactly known blocker, and
// the honesty of its error bars.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <tbb/global_control.h>

#include "mesh/readers/cornell_box.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/reference/path_tracer.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

SurfacePoint on(const PathTracer& pt, V p, V n) {
    const auto x = pt.locate(p, n);
    EXPECT_TRUE(x.has_value()) << "no surface at " << p.x << "," << p.y << "," << p.z;
    return x.value_or(SurfacePoint{});
}

}  // namespace

TEST(PathTracer, FurnaceReturnsEOverOneMinusRho) {
    for (const double rho : {0.5, 0.9}) {
        const Scene box = closed_box({1.0, 1.5, 2.0}, {"furnace", Rgb::gray(rho), Rgb(1.0, 2.0, 0.5)});
        const PathTracer pt(box);
        ReferenceOptions o;
        o.target_error = 0.005;
        o.seed = 7;
        const std::vector<SurfacePoint> points = {
            on(pt, {0.5, 0.75, 0}, {0, 0, 1}), on(pt, {0.005, 0.1, 1.9}, {1, 0, 0}),
            on(pt, {0.9, 1.5, 0.01}, {0, -1, 0}), on(pt, {0.3, 0.3, 2.0}, {0, 0, -1})};
        const auto est = pt.estimate_all(points, o);
        for (std::size_t k = 0; k < points.size(); ++k) {
            const auto& e = est[k];
            EXPECT_EQ(e.status, EstimateStatus::converged);
            for (int c = 0; c < 3; ++c) {
                const double exact = Rgb(1.0, 2.0, 0.5)[c] / (1 - rho);
                EXPECT_NEAR(e.radiosity[c], exact, 3 * e.standard_error[c])
                    << "rho " << rho << " point " << k << " channel " << c;
                EXPECT_LE(e.standard_error[c], 0.01 * exact);
                EXPECT_GT(e.standard_error[c], 0.0);
            }
        }
    }
}

TEST(PathTracer, DirectLightIsRhoETimesPointToPolygonFactor) {
    const Scene s = lamp_over_plane();
    const PathTracer pt(s);
    ReferenceOptions o;
    o.target_error = 0.002;
    const std::vector<V> where = {{0.5, 0.5, 0}, {0.1, 0.8, 0}, {1.7, -0.6, 0}, {-1.5, 2.5, 0}};
    std::vector<SurfacePoint> points;
    for (const auto& p : where) points.push_back(on(pt, p, {0, 0, 1}));
    const auto est = pt.estimate_all(points, o);
    const std::vector<V> lamp = s.surfaces[1].vertices;
    for (std::size_t k = 0; k < where.size(); ++k) {
        const double F = point_polygon_form_factor(where[k], {0, 0, 1}, lamp);
        for (int c = 0; c < 3; ++c) {
            const double exact = 0.5 * Rgb(3, 2, 1)[c] * F;
            EXPECT_NEAR(est[k].radiosity[c], exact, 3 * est[k].standard_error[c]) << "point " << k << " channel " << c;
            EXPECT_LT(est[k].standard_error[c], 0.01 * exact);
        }
    }
    // Under the lamp's centre, the closed form of a point below the centre of a square of side
    // a at height h (the square as four right triangles): 0.238…, checked against the kernel too.
    const double a = 0.5, h = 1.0,
                 closed =
                     4 / std::numbers::pi * (a / std::sqrt(a * a + h * h)) * std::atan(a / std::sqrt(a * a + h * h));
    EXPECT_NEAR(point_polygon_form_factor(where[0], {0, 0, 1}, lamp), closed, 1e-12);
}

TEST(PathTracer, BlockerHidesAnExactlyKnownPartOfTheEmitter) {
    Scene s = lamp_over_plane();
    // A black blocker at z = 0.5 over x in [0.5, 1]: seen from (0.5, 0.5, 0) its shadow on the
    // lamp's plane is x in [0.5, 1.5], so exactly the half x in [0.5, 1] of the lamp is hidden.
    s.surfaces.push_back({{{0.5, -1, 0.5}, {1.0, -1, 0.5}, {1.0, 2, 0.5}, {0.5, 2, 0.5}}, 2, "blocker", {"test", 0}});
    const PathTracer pt(s);
    ReferenceOptions o;
    o.target_error = 0.002;
    const SurfacePoint x = on(pt, {0.5, 0.5, 0}, {0, 0, 1});
    const auto e = pt.estimate(x, o, 0);
    const std::vector<V> visible = {{0, 0, 1}, {0, 1, 1}, {0.5, 1, 1}, {0.5, 0, 1}};
    const double F = point_polygon_form_factor(x.position, {0, 0, 1}, visible);
    const double unblocked = point_polygon_form_factor(x.position, {0, 0, 1}, s.surfaces[1].vertices);
    EXPECT_NEAR(F, 0.5 * unblocked, 1e-12);  // by symmetry: the test's premise
    for (int c = 0; c < 3; ++c) {
        const double exact = 0.5 * Rgb(3, 2, 1)[c] * F;
        EXPECT_NEAR(e.radiosity[c], exact, 3 * e.standard_error[c]) << "channel " << c;
        EXPECT_LT(e.standard_error[c], 0.01 * exact);
    }
}

// 20 seeds at a point give a spread known to about 16%; the test pools three points (and the
// three channels) so that the factor-1.5 bound tests the error bars, not the luck of 20 draws.
TEST(PathTracer, ErrorBarsMatchTheSpreadOverSeeds) {
    const Scene box = make_cornell_box();
    const PathTracer pt(box);
    const std::vector<SurfacePoint> points = {on(pt, {400, 0, 100}, {0, 1, 0}),  // floor, in front of the tall block
                                              on(pt, {280, 300, 559.2}, {0, 0, -1}),  // back wall
                                              on(pt, {0, 200, 300}, {1, 0, 0})};      // green wall
    ReferenceOptions o;
    o.target_error = 0;  // run every seed to the same budget
    o.max_paths = 4096;
    constexpr int kSeeds = 20;
    double ratio2 = 0;
    int terms = 0;
    for (const auto& x : points) {
        std::vector<Rgb> values;
        Rgb reported;
        for (int seed = 1; seed <= kSeeds; ++seed) {
            o.seed = std::uint64_t(seed);
            const auto e = pt.estimate(x, o, 0);
            EXPECT_EQ(e.status, EstimateStatus::budget);
            EXPECT_EQ(e.paths, 4096u);
            values.push_back(e.radiosity);
            reported += e.standard_error * (1.0 / kSeeds);
        }
        for (int c = 0; c < 3; ++c) {
            double mean = 0, var = 0;
            for (const auto& v : values) mean += v[c] / kSeeds;
            for (const auto& v : values) var += (v[c] - mean) * (v[c] - mean) / (kSeeds - 1);
            ratio2 += var / (reported[c] * reported[c]);
            ++terms;
        }
    }
    const double ratio = std::sqrt(ratio2 / terms);
    EXPECT_GT(ratio, 1 / 1.5);
    EXPECT_LT(ratio, 1.5);
}

TEST(PathTracer, SameSeedSameAnswerOnAnyThreadCount) {
    const Scene box = make_cornell_box();
    const PathTracer pt(box);
    const auto points = pt.probes(12, 3);
    ASSERT_EQ(points.size(), 12u);
    ReferenceOptions o;
    o.target_error = 0.05;
    std::vector<RadiosityEstimate> one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = pt.estimate_all(points, o);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = pt.estimate_all(points, o);
    }
    for (std::size_t k = 0; k < points.size(); ++k) {
        EXPECT_EQ(one[k].radiosity, two[k].radiosity);
        EXPECT_EQ(one[k].paths, two[k].paths);
    }
    o.seed = 2;
    const auto other = pt.estimate_all(points, o);
    EXPECT_NE(other[0].radiosity, one[0].radiosity);
}

TEST(PathTracer, ProbesSpreadByAreaAwayFromEdgesAndInTheLight) {
    const Scene box = make_cornell_box();
    const PathTracer pt(box);
    const auto probes = pt.probes(200, 1);
    ASSERT_EQ(probes.size(), 200u);
    std::vector<int> per_surface(box.surfaces.size(), 0);
    for (const auto& p : probes) {
        ASSERT_GE(p.surface, 0);
        EXPECT_EQ(box.materials[std::size_t(box.surfaces[std::size_t(p.surface)].material)].emission.max(), 0.0);
        ++per_surface[std::size_t(p.surface)];
        // No probe under a block: the floor inside the short block's footprint never sees light.
        const bool on_floor = std::abs(p.position.y) < 1e-9;
        if (on_floor) {
            EXPECT_FALSE(p.position.x > 140 && p.position.x < 230 && p.position.z > 120 && p.position.z < 210);
        }
    }
    // The back wall holds about 17% of the non-emitting area; stratification keeps the share close.
    int back = -1;
    for (std::size_t s = 0; s < box.surfaces.size(); ++s)
        if (box.surfaces[s].object == "back wall") back = int(s);
    ASSERT_GE(back, 0);
    EXPECT_NEAR(per_surface[std::size_t(back)], 200 * 0.17, 8);
}

TEST(PathTracer, LocateSnapsAlongTheNormalToAFacingSurface) {
    const Scene box = closed_box({1.0, 1.0, 1.0}, {"w", Rgb::gray(0.5), Rgb::gray(1)});
    const PathTracer pt(box);
    const double snap = pt.snap_distance();  // 0.5% of sqrt(3)
    // Slightly above and slightly below the floor, facing up: the floor.
    for (const double dz : {0.5 * snap, -0.5 * snap}) {
        const auto x = pt.locate({0.3, 0.6, dz}, {0, 0, 2});
        ASSERT_TRUE(x.has_value());
        EXPECT_EQ(x->surface, 0);
        EXPECT_DOUBLE_EQ(x->position.z, 0.0);
        EXPECT_DOUBLE_EQ(x->position.x, 0.3);
    }
    // Facing down at the floor: the floor's front does not face that way, the ceiling is far.
    EXPECT_FALSE(pt.locate({0.3, 0.6, 0.001}, {0, 0, -1}).has_value());
    // Beyond the snap distance from every surface.
    EXPECT_FALSE(pt.locate({0.5, 0.5, 2 * snap}, {0, 0, 1}).has_value());
    // Near a corner, the normal decides: the x = 0 wall, not the floor.
    const auto w = pt.locate({0.5 * snap, 0.5, 0.01}, {1, 0, 0});
    ASSERT_TRUE(w.has_value());
    EXPECT_EQ(w->surface, 2);
}
