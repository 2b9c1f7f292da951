// SPDX-License-Identifier: MIT
// Contact cuts: what no light can reach is found (the blocks' footprints, the ceiling behind the
// lamp), what light can enter is kept, and the patch mesh leaves the covered parts out without
// cracks or T-vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include <glm/geometric.hpp>

#include "mesh/geometry/contact_cuts.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/readers/validation_scenes.h"
#include "mesh/scene/polygon.h"
#include "test_util.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

int surface_named(const Scene& s, const std::string& name) {
    for (std::size_t k = 0; k < s.surfaces.size(); ++k)
        if (s.surfaces[k].object == name) return int(k);
    return -1;
}

double perimeter(const std::vector<V>& poly) {
    double p = 0;
    for (std::size_t k = 0; k < poly.size(); ++k) p += glm::length(poly[(k + 1) % poly.size()] - poly[k]);
    return p;
}

/// A 4 x 4 floor (z = 0, facing up) with a unit "chimney" of four outward walls standing on it,
/// open at the top unless `lid`.
Scene chimney(bool lid) {
    Scene s;
    s.name = "chimney";
    s.materials = {{"white", Rgb::gray(0.5), Rgb()}};
    s.surfaces.push_back({{{0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}}, 0, "floor", {"test", 0}});
    const std::vector<V> base = {{1, 1, 0}, {2, 1, 0}, {2, 2, 0}, {1, 2, 0}};
    for (int k = 0; k < 4; ++k) {
        const V a = base[std::size_t(k)], b = base[std::size_t((k + 1) % 4)];
        // Counter-clockwise seen from outside the chimney.
        s.surfaces.push_back({{a, b, b + V(0, 0, 1), a + V(0, 0, 1)}, 0, "side", {"test", 0}});
    }
    if (lid) s.surfaces.push_back({{{1, 1, 1}, {2, 1, 1}, {2, 2, 1}, {1, 2, 1}}, 0, "lid", {"test", 0}});
    return s;
}

}  // namespace

TEST(ContactCuts, CornellBlocksFootprintsAndTheCeilingBehindTheLight) {
    const Scene s = load_scene("cornell");
    const int floor = surface_named(s, "floor"), ceiling = surface_named(s, "ceiling");
    ASSERT_EQ(s.covered.size(), 3u);
    double floor_area = 0, ceiling_area = 0;
    for (const auto& c : s.covered) {
        EXPECT_TRUE(c.surface == floor || c.surface == ceiling) << c.surface;
        (c.surface == floor ? floor_area : ceiling_area) += polygon_area(c.polygon);
    }
    // The blocks' sides are vertical, so their footprints are their tops; the lamp is 130 x 105.
    const double tops = polygon_area(s.surfaces[std::size_t(surface_named(s, "short block top"))].vertices) +
                        polygon_area(s.surfaces[std::size_t(surface_named(s, "tall block top"))].vertices);
    EXPECT_NEAR(floor_area / tops, 1.0, 1e-9);
    EXPECT_NEAR(ceiling_area, 130.0 * 105.0, 1e-6);
}

TEST(ContactCuts, AnOpenChimneyCutsNothingAClosedOneItsFootprint) {
    EXPECT_TRUE(find_covered_regions(chimney(false)).empty());
    const auto covered = find_covered_regions(chimney(true));
    ASSERT_EQ(covered.size(), 1u);
    EXPECT_EQ(covered[0].surface, 0);
    EXPECT_NEAR(polygon_area(covered[0].polygon), 1.0, 1e-12);
}

TEST(ContactCuts, SubtractingAConvexHole) {
    const std::vector<V> square = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const V up(0, 0, 1);
    const std::vector<V> hole = {{0.25, 0.25, 0}, {0.5, 0.25, 0}, {0.5, 0.75, 0}, {0.25, 0.75, 0}};
    const auto pieces = subtract_convex(square, hole, up, 1e-12);
    EXPECT_EQ(pieces.size(), 8u);  // a ring between two quads: 4 + 4 triangles
    double area = 0;
    for (const auto& p : pieces) {
        EXPECT_EQ(p.size(), 3u);
        EXPECT_GT(glm::dot(newell_normal(p), up), 0.0);  // counter-clockwise, none folded over
        area += polygon_area(p);
    }
    EXPECT_NEAR(area, 1 - 0.125, 1e-15);
    // A hole over a corner: the rest is an L, triangulated from the square's corners and the
    // hole's points only.
    const std::vector<V> corner = {{0.5, 0.5, 0}, {1.5, 0.5, 0}, {1.5, 1.5, 0}, {0.5, 1.5, 0}};
    double l_area = 0;
    for (const auto& p : subtract_convex(square, corner, up, 1e-12)) {
        l_area += polygon_area(p);
        for (const V& v : p) EXPECT_TRUE(v.x == 0 || v.x == 1 || v.x == 0.5 || v.y == 0 || v.y == 1 || v.y == 0.5);
    }
    EXPECT_NEAR(l_area, 0.75, 1e-15);
    // Apart: the square whole; covering: nothing.
    const std::vector<V> apart = {{2, 0, 0}, {3, 0, 0}, {3, 1, 0}, {2, 1, 0}};
    const auto same = subtract_convex(square, apart, up, 1e-12);
    ASSERT_EQ(same.size(), 1u);
    EXPECT_EQ(same[0], square);
    const std::vector<V> big = {{-1, -1, 0}, {2, -1, 0}, {2, 2, 0}, {-1, 2, 0}};
    EXPECT_TRUE(subtract_convex(square, big, up, 1e-12).empty());
}

TEST(ContactCuts, TheFloorMeshLeavesTheFootprintsOutWithoutCracks) {
    const Scene s = load_scene("cornell");
    const int floor = surface_named(s, "floor");
    for (const double max_area : {0.0, 900.0}) {
        MeshingOptions o;
        o.max_area = max_area;
        const PatchMesh m(s, o);
        const auto& om = m.mesh();
        double area = 0, boundary = 0;
        for (std::size_t i = 0; i < m.size(); ++i) {
            const Patch& p = m.patches()[i];
            if (p.surface != floor) continue;
            area += p.area;
            // No patch lies inside a footprint.
            for (const auto& c : s.covered) {
                if (c.surface != floor) continue;
                bool inside = true;
                for (std::size_t k = 0; k < c.polygon.size() && inside; ++k)
                    inside = glm::dot(glm::cross(c.polygon[(k + 1) % c.polygon.size()] - c.polygon[k],
                                                 p.centre - c.polygon[k]),
                                      p.normal) > 0;
                EXPECT_FALSE(inside) << p.to_string();
            }
            const auto f = om.face_handle(int(i));
            for (auto h = om.cfh_iter(f); h.is_valid(); ++h)
                if (om.is_boundary(om.opposite_halfedge_handle(*h))) boundary += om.calc_edge_length(*h);
        }
        double covered = 0, outlines = perimeter(s.surfaces[std::size_t(floor)].vertices);
        for (const auto& c : s.covered)
            if (c.surface == floor) {
                covered += polygon_area(c.polygon);
                outlines += perimeter(c.polygon);
            }
        EXPECT_NEAR(area / (polygon_area(s.surfaces[std::size_t(floor)].vertices) - covered), 1.0, 1e-12);
        // The open edges are exactly the floor's outline and the footprints' outlines: a crack or
        // a T-vertex would add edges on both of its sides.
        EXPECT_NEAR(boundary / outlines, 1.0, 1e-9) << "max area " << max_area;
    }
}

TEST(ContactCuts, ALampHungACentimetreBelowTheCeilingCutsItsFootprint) {
    // 1 cm is 1.3x the contact tolerance of this room (5e-4 of its 7.6 m diagonal) and 1/60 of
    // the lamp's side: hung, not resting, yet nothing under it sees the room but through the gap.
    Scene s = hung_lamp_room(0.01);
    s.covered = find_covered_regions(s);
    double area = 0;
    for (const auto& c : s.covered)
        if (c.surface == 4) {
            area += polygon_area(c.polygon);
            EXPECT_NEAR(c.gap, 0.01, 1e-12);
        }
    EXPECT_NEAR(area, 0.36, 1e-9);
    const PatchMesh mesh(s, MeshingOptions{});
    double ceiling = 0;
    for (const auto& p : mesh.patches())
        if (p.surface == 4) ceiling += p.area;
    EXPECT_NEAR(ceiling, 24.0 - 0.36, 1e-9);
    // Vertices on the lamp's outline ask to be gathered 8 gaps away; no other vertex a patch
    // uses does (the grid's points inside the footprint are left unused).
    std::vector<bool> used(mesh.mesh().n_vertices(), false);
    for (std::size_t p = 0; p < mesh.size(); ++p)
        for (const int v : mesh.patch_vertex_indices(p)) used[std::size_t(v)] = true;
    std::size_t asking = 0;
    for (std::size_t v = 0; v < used.size(); ++v) {
        if (!used[v]) continue;
        const V x = mesh.vertex_position(v);
        const bool on = std::abs(x.y - 2.5) < 1e-12 && x.x > -1.0701 && x.x < -0.4699 && x.z > -0.1701 && x.z < 0.4301;
        EXPECT_NEAR(mesh.gather_clearance(v), on ? PatchMesh::kGapBand * 0.01 : 0.0, 1e-12)
            << x.x << " " << x.y << " " << x.z;
        asking += on;
    }
    EXPECT_GE(asking, 8u);
}

TEST(ContactCuts, LampsHungFarOrNarrowLetLightUnderThem) {
    // 4 cm is more than 1/20 of the 0.6 m lamp's side: the ceiling under it keeps its patches.
    Scene far = hung_lamp_room(0.04);
    for (const auto& c : find_covered_regions(far)) EXPECT_NE(c.surface, 4);
    // A 0.6 x 0.1 strip at 1 cm: from half-way to its corners, grazing rays pass under its side.
    Scene strip = hung_lamp_room(0.01);
    for (auto& v : strip.surfaces[12].vertices) v.z = v.z > 0 ? 0.18 : 0.08;
    for (const auto& c : find_covered_regions(strip)) EXPECT_NE(c.surface, 4);
}

TEST(ContactCuts, EveryVertexLeftIsACornerOfAPatch) {
    // Issue 35: the grid corners inside the regions the cuts remove (under the blocks, behind
    // the lamp) stayed in the mesh, 74 points of radiosity 0 in every default .vtu. They are
    // left out, the others keep their order, and the faces still join.
    const Scene s = load_scene("cornell");
    for (const double max_area : {0.0, 900.0}) {
        MeshingOptions o;
        o.max_area = max_area;
        const PatchMesh m(s, o);
        const auto& om = m.mesh();
        std::vector<bool> used(om.n_vertices(), false);
        for (std::size_t i = 0; i < m.size(); ++i)
            for (const int v : m.patch_vertex_indices(i)) used[std::size_t(v)] = true;
        EXPECT_EQ(std::count(used.begin(), used.end(), false), 0) << max_area;
        for (auto v : om.vertices()) EXPECT_FALSE(om.is_isolated(v));
        // Cut patches share the points on their edges: fewer vertices than corners.
        std::size_t corners = 0;
        for (std::size_t i = 0; i < m.size(); ++i) corners += m.patch_vertex_indices(i).size();
        EXPECT_LT(om.n_vertices(), corners / 2);
        EXPECT_EQ(om.n_faces(), m.size());
    }
}

TEST(ContactCuts, ABoxInACornerHidesItsFootprintOnTheFloorAndOnTheWall) {
    // A box standing on the floor with one side flush against a wall: that side and the wall
    // face each other at no distance, so a ray from under the box meets both at once and must
    // count the box's side (a back face) as what it meets. A box on the floor alone and a box
    // on the wall alone beside it.
    const test::TempDir dir;
    const auto path = dir.write("corner.json", R"({
      "materials": { "w": { "reflectance": 0.7 }, "lamp": { "reflectance": 0, "emission": 10 } },
      "objects": [
        { "type": "box", "material": "w", "inward": true, "name": "room",
          "transform": { "scale": [4, 3, 4], "translate": [0, 1.5, 0] } },
        { "type": "quad", "material": "lamp", "name": "lamp",
          "transform": { "scale": 0.5, "rotate": { "axis": [1, 0, 0], "degrees": 90 }, "translate": [0, 2.9, 0] } },
        { "type": "box", "material": "w", "name": "in the corner",
          "transform": { "scale": [0.4, 1.0, 1.0], "translate": [1.8, 0.5, 0] } },
        { "type": "box", "material": "w", "name": "on the floor",
          "transform": { "scale": [0.4, 1.0, 1.0], "translate": [-1, 0.5, 0] } },
        { "type": "box", "material": "w", "name": "on the wall",
          "transform": { "scale": [1, 0.5, 0.4], "translate": [0, 1.5, 1.8] } }
      ] })");
    const Scene s = load_scene(path.string());
    // The room's faces by where they lie.
    auto room_face = [&](int axis, double at) {
        for (std::size_t k = 0; k < s.surfaces.size(); ++k) {
            if (s.surfaces[k].object != "room") continue;
            bool on = true;
            for (const V& v : s.surfaces[k].vertices) on = on && std::abs(v[axis] - at) < 1e-12;
            if (on) return int(k);
        }
        return -1;
    };
    const int floor = room_face(1, 0.0), east = room_face(0, 2.0), north = room_face(2, 2.0);
    ASSERT_GE(floor, 0);
    ASSERT_GE(east, 0);
    ASSERT_GE(north, 0);
    std::map<int, double> hidden;
    for (const auto& c : s.covered) hidden[c.surface] += polygon_area(c.polygon);
    EXPECT_NEAR(hidden[floor], 0.4 + 0.4, 1e-9);  // both standing boxes' footprints
    EXPECT_NEAR(hidden[east], 1.0, 1e-9);         // the corner box's 1 x 1 side
    EXPECT_NEAR(hidden[north], 0.5, 1e-9);        // the wall box's back, 1 x 0.5
}

TEST(ContactCuts, ProgressCountsEverySurfaceOnceAndChangesNothing) {
    // The search reports blocks of surfaces from worker threads; the last report is the whole.
    const Scene s = load_scene("cornell");
    const SurfaceTree tree(s);
    std::mutex m;
    std::size_t calls = 0, most = 0, total_seen = 0;
    const auto with = find_covered_regions(s, tree, [&](std::size_t done, std::size_t total) {
        const std::lock_guard<std::mutex> lock(m);
        ++calls;
        most = std::max(most, done);
        total_seen = total;
    });
    const auto without = find_covered_regions(s, tree);
    EXPECT_GT(calls, 0u);
    EXPECT_EQ(most, s.surfaces.size());
    EXPECT_EQ(total_seen, s.surfaces.size());
    ASSERT_EQ(with.size(), without.size());
    for (std::size_t k = 0; k < with.size(); ++k) {
        EXPECT_EQ(with[k].surface, without[k].surface);
        EXPECT_EQ(with[k].polygon, without[k].polygon);
    }
}
