// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "mesh/readers/validation_scenes.h"
#include "solver/reference/probe_score.h"

using namespace bounce;

namespace {

ReferencePoint probe(glm::dvec3 x, glm::dvec3 n, Rgb b) {
    ReferencePoint r;
    r.position = x;
    r.normal = n;
    r.radiosity = b;
    r.standard_error = b * 0.01;
    r.has_value = true;
    r.status = "converged";
    return r;
}

}  // namespace

// A plate of 2 x 2 patches with radiosity rising in x: the patch value is the cell's constant,
// the smooth value the linear interpolation of the area-weighted vertex means.
TEST(ProbeScore, PatchAndSmoothValuesAtKnownPoints) {
    Scene s = parallel_pair(2, 2, 1);
    s.surfaces.pop_back();  // the lower plate only, facing +z
    MeshingOptions m;
    m.max_edge = 1.0;
    const PatchMesh mesh(s, m);
    ASSERT_EQ(mesh.size(), 4u);
    std::vector<Rgb> B(4);
    for (std::size_t i = 0; i < 4; ++i) B[i] = Rgb::gray(mesh.patches()[i].centre.x < 1 ? 1.0 : 3.0);
    // Vertex means: 1 at x = 0, 2 at x = 1, 3 at x = 2, so the smooth field is 1 + x.
    const std::vector<ReferencePoint> ref = {probe({0.25, 0.5, 0}, {0, 0, 1}, Rgb::gray(1.25)),
                                             probe({1.5, 1.2, 0.001}, {0, 0, 1}, Rgb::gray(2.0)),
                                             probe({0.5, 0.5, 0}, {0, 0, -1}, Rgb::gray(1.0))};  // faces away
    const ProbeScore sc = score_at_probes(mesh, B, ref);
    EXPECT_EQ(sc.scored, 2u);
    EXPECT_EQ(sc.skipped, 1u);
    // Patch errors: |1 - 1.25|/1.25 = 0.2 and |3 - 2|/2 = 0.5; smooth: 0 and |2.5 - 2|/2 = 0.25.
    EXPECT_NEAR(sc.max_patch, 0.5, 1e-12);
    EXPECT_NEAR(sc.rms_patch, std::sqrt((0.04 + 0.25) / 2), 1e-12);
    EXPECT_NEAR(sc.max_smooth, 0.25, 1e-12);
    EXPECT_NEAR(sc.rms_smooth, std::sqrt(0.0625 / 2), 1e-12);
    EXPECT_NEAR(sc.rms_smooth_channel.g, sc.rms_smooth, 1e-12);
    EXPECT_NEAR(sc.reference_noise, 0.01, 1e-12);
    // Per probe, signed: the first reads low on its patch, the second high; the third is skipped.
    ASSERT_EQ(sc.patch_error.size(), 3u);
    EXPECT_NEAR(sc.patch_error[0], -0.2, 1e-12);
    EXPECT_NEAR(sc.patch_error[1], 0.5, 1e-12);
    EXPECT_NEAR(sc.smooth_error[1], 0.25, 1e-12);
    EXPECT_TRUE(std::isnan(sc.patch_error[2]));
}
