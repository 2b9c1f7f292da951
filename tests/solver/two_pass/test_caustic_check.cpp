// SPDX-License-Identifier: MIT
// The caustic under the glass sphere of cornell-spheres, the emitters' photon map against the
// path tracer's light from the lamp through the mirror and the glass (paths L S+ D): the power
// landing in the bright region within 5% of the path tracer's, and the peak within one pixel
// of a 512 x 512 picture through render's Cornell camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "solver/reference/path_tracer.h"
#include "solver/two_pass/caustic_check.h"
#include "solver/two_pass/caustic_map.h"
#include "solver/two_pass/patch_scene_tracer.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

/// render's classic Cornell front view (viewer/camera.cpp), 512 x 512.
CausticView cornell_view() {
    CausticView view;
    view.camera.position = V(278, 273, -800);
    view.camera.target = V(278, 273, 0);
    view.camera.vertical_fov = 39;
    return view;
}

}  // namespace

TEST(CausticCheck, TheEmittersPhotonMapMatchesThePathTracerUnderTheGlassSphere) {
    const Scene scene = make_cornell_spheres_box();
    const PatchMesh mesh(scene, MeshingOptions{});
    const PatchSceneTracer tracer(scene, mesh);
    CausticOptions co;
    co.photons = 2000000;  // the light pass's photons of the emitters
    const CausticMap map(mesh, tracer, co);
    const CausticRegion region = cornell_spheres_caustic_region();
    const CausticView view = cornell_view();
    const CausticMeasure photons = measure_caustic(map, region, view);

    const PathTracer pt(scene);
    TracedCausticOptions to;
    to.emitted_only = true;
    to.region_points = 16384;
    to.pixel_points = 64;
    const CausticMeasure traced = measure_caustic(pt, region, view, to);
    const double p = photons.power.luminance(), q = traced.power.luminance(), se = traced.power_se.luminance();

    std::cout << "caustic under the glass sphere: photon map " << p << " W, path tracer " << q << " +- " << se
              << " W; peak (" << photons.peak_col << ", " << photons.peak_row << ") " << photons.peak << " and ("
              << traced.peak_col << ", " << traced.peak_row << ") " << traced.peak << " +- " << traced.peak_se << "\n";
    // The power: both estimate the same integral without bias, so they agree within the path
    // tracer's noise (4 standard errors), and the goal, 5%, holds with 2 standard errors to
    // spare.
    EXPECT_GT(q, 0);
    EXPECT_LT(se, 0.01 * q);
    EXPECT_LT(std::abs(p - q), 4 * se) << "photon map " << p << " W, path tracer " << q << " +- " << se << " W";
    EXPECT_LT(std::abs(p - q) + 2 * se, 0.05 * q);
    // The peak: the same pixel or a neighbour.
    ASSERT_GT(photons.pixels, 1000u);
    EXPECT_LE(std::max(std::abs(photons.peak_col - traced.peak_col), std::abs(photons.peak_row - traced.peak_row)), 1)
        << "photon map peak at (" << photons.peak_col << ", " << photons.peak_row << "), path tracer at ("
        << traced.peak_col << ", " << traced.peak_row << ")";
    // The peak's height: the map's density estimate of 32 photons is noisy (its largest
    // smoothed pixel rides on that noise), the path tracer's within a few per cent.
    EXPECT_LT(traced.peak_se, 0.02 * traced.peak);
    EXPECT_NEAR(photons.peak, traced.peak, 0.1 * traced.peak);
}
