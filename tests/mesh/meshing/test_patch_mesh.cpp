// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/input_error.h"
#include "mesh/scene/polygon.h"

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
        // Every surface is kept but for the covered regions (the blocks' footprints, the ceiling
        // behind the light), which do not overlap one another.
        double covered = 0;
        for (const auto& c : s.covered) covered += polygon_area(c.polygon);
        EXPECT_GT(covered, 0.0);
        EXPECT_NEAR(m.total_area() / (scene_area(s) - covered), 1.0, 1e-12);
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

TEST(PatchMesh, ElementsTileTheirParentPatchesExactly) {
    // A scene with quads (the box) and triangles (a pentagon is cut into them).
    Scene s = load_scene("cornell");
    Surface penta = s.surfaces.front();
    penta.vertices = {{100, 300, 200}, {200, 300, 200}, {230, 300, 300}, {150, 300, 360}, {70, 300, 300}};
    s.surfaces.push_back(penta);
    MeshingOptions o;
    o.target_patches = 300;
    o.cut_contacts = false;  // elements tile uncut patches
    const PatchMesh coarse(s, o);
    for (const int split : {1, 3}) {
        o.element_split = split;
        const PatchMesh fine(s, o);
        ASSERT_EQ(fine.size(), coarse.size() * std::size_t(split * split));
        ASSERT_EQ(fine.parents().size(), fine.size());
        std::vector<double> area(coarse.size(), 0.0);
        std::vector<int> children(coarse.size(), 0);
        for (std::size_t e = 0; e < fine.size(); ++e) {
            const Patch& el = fine.patches()[e];
            const Patch& p = coarse.patches().at(fine.parents()[e]);
            area[fine.parents()[e]] += el.area;
            ++children[fine.parents()[e]];
            ASSERT_EQ(el.surface, p.surface);
            // The element's centre lies inside its parent (convex: left of every edge).
            for (int k = 0; k < p.vertex_count; ++k) {
                const glm::dvec3 a = p.vertices[k], b = p.vertices[(k + 1) % p.vertex_count];
                ASSERT_GT(glm::dot(glm::cross(b - a, el.centre - a), p.normal), 0.0) << "element " << e;
            }
        }
        for (std::size_t i = 0; i < coarse.size(); ++i) {
            EXPECT_EQ(children[i], split * split) << i;
            EXPECT_NEAR(area[i] / coarse.patches()[i].area, 1.0, 1e-12) << i;
        }
        EXPECT_NEAR(fine.total_area() / coarse.total_area(), 1.0, 1e-13);
        const Rgb ef = fine.emitted_power(), ec = coarse.emitted_power();
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(ef[c] / ec[c], 1.0, 1e-13);
    }
}

TEST(PatchMesh, TriangleMeshesGetThePatchBudgetTheyAskFor) {
    // Two triangles of area 1 each, in three shapes: a square cut on its diagonal, two
    // equilateral triangles, and a 1:16 rectangle cut on its diagonal. --patches 2000 must give
    // 1500-2500 patches (the edge rule quads use gave the square 8100).
    using V = glm::dvec3;
    const double r2 = std::sqrt(2.0), side = std::sqrt(4.0 / std::sqrt(3.0));
    const double w = std::sqrt(2.0 / 16.0), l = 16 * w;
    const std::vector<std::vector<std::vector<V>>> shapes = {
        {{{0, 0, 0}, {r2, 0, 0}, {r2, r2, 0}}, {{0, 0, 0}, {r2, r2, 0}, {0, r2, 0}}},
        {{{0, 0, 0}, {side, 0, 0}, {side / 2, side * std::sqrt(3.0) / 2, 0}},
         {{0, 0, 1}, {side, 0, 1}, {side / 2, side * std::sqrt(3.0) / 2, 1}}},
        {{{0, 0, 0}, {l, 0, 0}, {l, w, 0}}, {{0, 0, 0}, {l, w, 0}, {0, w, 0}}},
    };
    for (const auto& shape : shapes) {
        Scene s;
        s.materials = {{"w", Rgb::gray(0.5), Rgb()}};
        for (const auto& t : shape) s.surfaces.push_back({t, 0, "t", {"t.obj", 1}});
        EXPECT_NEAR(scene_area(s), 2.0, 1e-12);
        for (const std::size_t target : {std::size_t(2000), std::size_t(200)}) {
            MeshingOptions o;
            o.target_patches = target;
            const PatchMesh m(s, o);
            EXPECT_GE(double(m.size()), 0.75 * double(target)) << shape[0][1].x;
            EXPECT_LE(double(m.size()), 1.25 * double(target)) << shape[0][1].x;
            EXPECT_EQ(planned_patches(s, o), double(m.size()));
            EXPECT_NEAR(m.total_area(), 2.0, 1e-9);
            for (const auto& p : m.patches()) EXPECT_LE(p.area, 2.0 / double(target) * (1 + 1e-9));
        }
    }
}

TEST(PatchMesh, ElementsThatDoNotFormOneFanGetPointsOfTheirOwnWithOneWarning) {
    // Three triangles on one edge (0-1) make it non-manifold; a fourth meets the first only at
    // point 2 (a bow tie). OpenMesh refuses the first case ("complex edge") and, in the 10k
    // office's contact-cut elements, aborted on an assertion in its patch re-linking; the mesh
    // gives each fan around such a point a copy of it instead. Point 0 and point 1 each lie in
    // three fans (2 copies each), point 2 in two (1 copy): 7 + 5 points.
    const std::vector<glm::dvec3> points = {{0, 0, 0},   {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0},
                                            {0.5, 0, 1}, {1, 2, 0}, {0, 2, 0}};
    const std::vector<std::vector<std::uint32_t>> faces = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {2, 5, 6}};
    std::vector<Patch> patches;
    for (const auto& f : faces) {
        Patch p;
        p.vertex_count = 3;
        for (int k = 0; k < 3; ++k) p.vertices[k] = points[f[std::size_t(k)]];
        const glm::dvec3 n = newell_normal(p.polygon());
        p.area = 0.5 * glm::length(n);
        p.normal = n / (2.0 * p.area);
        p.centre = polygon_centroid(p.polygon());
        p.surface = int(patches.size());
        patches.push_back(p);
    }
    const PatchMesh mesh(patches, points, faces);
    ASSERT_EQ(mesh.size(), 4u);
    ASSERT_EQ(mesh.warnings().size(), 1u);
    EXPECT_NE(mesh.warnings()[0].find("3 element corners"), std::string::npos) << mesh.warnings()[0];
    EXPECT_EQ(mesh.mesh().n_vertices(), 12u);
    EXPECT_EQ(mesh.mesh().n_faces(), 4u);
    for (std::size_t f = 0; f < faces.size(); ++f) {
        const auto corners = mesh.patch_vertex_indices(f);
        ASSERT_EQ(corners.size(), 3u);
        for (const int v : corners) {
            const auto q = mesh.mesh().point(OpenMesh::VertexHandle(v));
            const glm::dvec3 x(q[0], q[1], q[2]);
            EXPECT_TRUE(x == points[faces[f][0]] || x == points[faces[f][1]] || x == points[faces[f][2]]) << f;
        }
    }
    // A manifold mesh is left whole: two triangles on one edge share its two points (and the
    // three points no face uses are left out: every vertex is a face's corner).
    const PatchMesh pair({patches[0], patches[1]}, points, {faces[0], faces[1]});
    EXPECT_TRUE(pair.warnings().empty());
    EXPECT_EQ(pair.mesh().n_vertices(), 4u);
}
