// SPDX-License-Identifier: MIT
// Probe classes against the geometry that decides them: a square lamp over a plane, a square
// blocker half-way at 1.2 times the lamp's side (its shadow from the plane's point of view
// covers the whole lamp only near the centre), and a wall standing on the plane.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mesh/validation_scenes.h"
#include "solver/reference/probe_classes.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

Scene shadowed_plane() {
    Scene s = lamp_over_plane();  // plane [-2,3]^2 at z = 0, lamp [0,1]^2 at z = 1
    s.surfaces.push_back(
        {{{0.2, 0.2, 0.5}, {0.2, 0.8, 0.5}, {0.8, 0.8, 0.5}, {0.8, 0.2, 0.5}}, 2, "blocker", {"test", 0}});
    // A wall at x = -1 facing +x, 1 high: the plane beyond it (x < -1) never sees the lamp.
    s.surfaces.push_back({{{-1, -2, 0}, {-1, 3, 0}, {-1, 3, 1}, {-1, -2, 1}}, 2, "wall", {"test", 0}});
    return s;
}

SurfacePoint on_plane(double x, double y) { return {{x, y, 0}, {0, 0, 1}, 0}; }

}  // namespace

TEST(ProbeClasses, DirectLightShareFollowsTheBlockersShadowOnTheLamp) {
    const Scene scene = shadowed_plane();
    const PathTracer tracer(scene);
    // From (0.5, 0.5) the blocker, scaled by 2 about the point onto the lamp's plane, covers
    // [-0.1, 1.1]^2: nothing of the lamp is seen. From (0.9, 0.5) it covers x in [-0.5, 0.7]:
    // the strip x > 0.7 shows. Far out at (2.5, 2.5) it falls off the lamp.
    EXPECT_EQ(tracer.direct_light_share(on_plane(0.5, 0.5), 1024, 1), 0.0);
    const double part = tracer.direct_light_share(on_plane(0.9, 0.5), 1024, 1);
    EXPECT_GT(part, 0.2);
    EXPECT_LT(part, 0.6);
    EXPECT_EQ(tracer.direct_light_share(on_plane(2.5, 2.5), 1024, 1), 1.0);
    // No emitter in front: -1.
    const SurfacePoint on_lamp_back{{0.5, 0.5, 1.0}, {0, 0, 1}, 1};
    EXPECT_EQ(tracer.direct_light_share(on_lamp_back, 64, 1), -1.0);
}

TEST(ProbeClasses, ClearanceIsTheDistanceToTheNearestSurfaceInFront) {
    const Scene scene = shadowed_plane();
    const PathTracer tracer(scene);
    // Under the blocker's centre straight rays meet it at 0.5; slanted ones, further.
    const double c = tracer.clearance(on_plane(0.5, 0.5), 256, 1);
    EXPECT_GE(c, 0.5 - 1e-6);
    EXPECT_LT(c, 0.52);
    // 5 cm beside the wall, grazing rays meet it just over 5 cm away.
    const double w = tracer.clearance(on_plane(-0.95, 0.5), 256, 1);
    EXPECT_GE(w, 0.05 - 1e-6);
    EXPECT_LT(w, 0.08);
}

TEST(ProbeClasses, EachClassWhereItsGeometrySaysSo) {
    const Scene scene = shadowed_plane();
    const PathTracer tracer(scene);
    // The scene's diagonal is about 7.1, so a contact is nearer than about 0.18.
    EXPECT_EQ(classify_probe(tracer, on_plane(0.5, 0.5), 1), ProbeClass::unlit);
    EXPECT_EQ(classify_probe(tracer, on_plane(0.9, 0.5), 1), ProbeClass::penumbra);
    EXPECT_EQ(classify_probe(tracer, on_plane(2.5, 2.5), 1), ProbeClass::lit);
    EXPECT_EQ(classify_probe(tracer, on_plane(-1.5, 0.5), 1), ProbeClass::unlit);  // behind the wall
    EXPECT_EQ(classify_probe(tracer, on_plane(-0.95, 0.5), 1), ProbeClass::contact);
}

TEST(ProbeClasses, ProbesByClassGiveEachClassItsShare) {
    const Scene scene = shadowed_plane();
    const PathTracer tracer(scene);
    std::vector<ProbeClass> classes;
    const auto probes = probes_by_class(tracer, 12, 7, classes);
    ASSERT_EQ(probes.size(), 12u);
    ASSERT_EQ(classes.size(), 12u);
    for (const ProbeClass c : kProbeClasses) EXPECT_EQ(std::count(classes.begin(), classes.end(), c), 3);
    for (std::size_t k = 0; k < probes.size(); ++k) {
        EXPECT_EQ(probes[k].surface, 0);  // the plane: the lamp emits, the blocker and wall are black
        if (classes[k] == ProbeClass::contact) {
            EXPECT_LT(std::abs(probes[k].position.x + 1), 0.2);
        }
    }
}

TEST(ProbeClasses, ScoresSplitByClass) {
    ProbeScore score;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    score.smooth_error = {0.03, -0.04, 0.10, nan, 0.01};
    score.patch_error = {0.06, 0.08, -0.20, nan, 0.0};
    const std::vector<ProbeClass> classes = {ProbeClass::penumbra, ProbeClass::penumbra, ProbeClass::contact,
                                             ProbeClass::lit, ProbeClass::lit};
    const auto by = score_by_class(score, classes);
    const ClassScore& pen = by[std::size_t(ProbeClass::penumbra)];
    EXPECT_EQ(pen.scored, 2u);
    EXPECT_NEAR(pen.rms_smooth, std::sqrt((0.03 * 0.03 + 0.04 * 0.04) / 2), 1e-15);
    EXPECT_NEAR(pen.max_smooth, 0.04, 1e-15);
    EXPECT_NEAR(pen.rms_patch, std::sqrt((0.06 * 0.06 + 0.08 * 0.08) / 2), 1e-15);
    EXPECT_NEAR(by[std::size_t(ProbeClass::contact)].max_patch, 0.20, 1e-15);
    EXPECT_EQ(by[std::size_t(ProbeClass::lit)].scored, 1u);  // the NaN probe is skipped
    EXPECT_EQ(by[std::size_t(ProbeClass::unlit)].scored, 0u);
}
