// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "mesh/cornell_box.h"
#include "mesh/input_error.h"
#include "mesh/patch_mesh.h"
#include "mesh/polygon.h"
#include "mesh/scene_loader.h"

using namespace bounce;

namespace {
double scene_area(const Scene& s) {
    double a = 0.0;
    for (const auto& f : s.surfaces) a += polygon_area(f.vertices);
    return a;
}
Rgb scene_power(const Scene& s) {
    Rgb p;
    for (const auto& f : s.surfaces) p += s.materials[f.material].emission * polygon_area(f.vertices);
    return p;
}
}  // namespace

TEST(PatchMesh, SubdivisionKeepsAreaAndEmittedPowerAndRespectsTheLimits) {
    const Scene s = load_scene("cornell");
    for (double max_area : {0.0, 5000.0, 900.0}) {
        MeshingOptions o;
        o.max_area = max_area;
        const PatchMesh m(s, o);
        EXPECT_NEAR(m.total_area() / scene_area(s), 1.0, 1e-12);
        const Rgb e = m.emitted_power(), e0 = scene_power(s);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c] / e0[c], 1.0, 1e-12);
        const double limit = max_area > 0 ? max_area : scene_area(s) / double(o.target_patches);
        for (const auto& p : m.patches()) {
            EXPECT_LE(p.area, limit * (1 + 1e-9));
            EXPECT_NEAR(glm::length(p.normal), 1.0, 1e-12);
            EXPECT_TRUE(p.vertex_count == 3 || p.vertex_count == 4);
        }
        if (max_area == 0.0) {
            EXPECT_GE(m.size(), 2000u);  // "a few thousand" by default
            EXPECT_LE(m.size(), 5000u);
        }
        EXPECT_EQ(m.mesh().n_faces(), m.size());
    }
}

TEST(PatchMesh, PatchesKeepTheirSurfaceOrientationAndMaterial) {
    const Scene s = make_cornell_box();
    const PatchMesh m(s, MeshingOptions{});
    for (const auto& p : m.patches()) {
        const auto& f = s.surfaces[p.surface];
        EXPECT_GT(glm::dot(p.normal, newell_normal(f.vertices)), 0.0);
        EXPECT_EQ(p.reflectance, s.materials[f.material].reflectance);
    }
}

TEST(PatchMesh, RefusesAbsurdMeshingBeforeBuilding) {
    const Scene s = make_cornell_box();
    MeshingOptions o;
    o.max_area = 1e-6;  // ~1e12 patches
    EXPECT_THROW(PatchMesh(s, o), InputError);
}

TEST(PatchMesh, NoSubdivideGivesOnePatchPerFace) {
    const Scene s = make_cornell_box();
    MeshingOptions o;
    o.subdivide = false;
    EXPECT_EQ(PatchMesh(s, o).size(), s.surfaces.size());
}
