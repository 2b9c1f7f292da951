// SPDX-License-Identifier: MIT
// Solid cuts: the parts of surfaces inside a closed convex object, or outside a closed convex
// room, are found exactly, and nothing else is.
#include "mesh/geometry/solid_cuts.h"

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "mesh/geometry/contact_cuts.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "mesh/readers/validation_scenes.h"
#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using V = glm::dvec3;

// The six faces of the box [lo, hi], facing out (or in), one object named `object`.
void add_box(Scene& s, const V& lo, const V& hi, bool inward, const std::string& object) {
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            std::vector<V> poly(4);
            for (int k = 0; k < 4; ++k) {
                V p;
                p[axis] = side ? hi[axis] : lo[axis];
                p[u] = (k == 1 || k == 2) ? hi[u] : lo[u];
                p[v] = (k >= 2) ? hi[v] : lo[v];
                poly[std::size_t(k)] = p;
            }
            V out(0.0);
            out[axis] = side ? 1.0 : -1.0;
            if ((glm::dot(newell_normal(poly), out) > 0) == inward) std::reverse(poly.begin(), poly.end());
            s.surfaces.push_back({poly, 0, object, {object, 0}});
        }
}

Scene with_white() {
    Scene s;
    s.materials = {{"white", Rgb::gray(0.5), Rgb()}};
    return s;
}

// Covered area per surface.
std::vector<double> cut_area(const Scene& s, const std::vector<CoveredRegion>& cuts) {
    std::vector<double> a(s.surfaces.size(), 0.0);
    for (const auto& c : cuts) {
        EXPECT_GT(glm::dot(newell_normal(c.polygon), newell_normal(s.surfaces[std::size_t(c.surface)].vertices)), 0.0)
            << "counter-clockwise like its surface";
        a[std::size_t(c.surface)] += polygon_area(c.polygon);
    }
    return a;
}

TEST(SolidCuts, TwoCrossingBoxesHideExactlyTheirOverlap) {
    // A = [0,2]^3, B = [1,3] x [0.5,1.5]^2. A's face x = 2 has B's unit cross-section inside B;
    // B's face x = 1 lies inside A, and its four faces along x are inside A from x = 1 to 2.
    Scene s = with_white();
    add_box(s, V(0), V(2), false, "A");
    add_box(s, V(1, 0.5, 0.5), V(3, 1.5, 1.5), false, "B");
    const auto solids = find_convex_solids(s);
    ASSERT_EQ(solids.size(), 2u);
    EXPECT_FALSE(solids[0].inward);
    const auto a = cut_area(s, find_solid_cuts(s));
    // Surfaces: 0 x-, 1 x+, 2 y-, 3 y+, 4 z-, 5 z+ for A; 6-11 for B.
    const std::vector<double> expected = {0, 1, 0, 0, 0, 0, 1, 0, 1, 1, 1, 1};
    for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(a[k], expected[k], 1e-12) << k;
}

TEST(SolidCuts, ABoxPushedThroughARoomsFloorLosesWhatIsOutside) {
    // Room [0,4] x [0,3] x [0,4] (inward); box [1,2] x [-0.5,0.5] x [1,2]. The floor inside the
    // box (1 x 1), the box's sides below the floor (1 x 0.5 each) and its bottom are hidden.
    Scene s = with_white();
    add_box(s, V(0), V(4, 3, 4), true, "room");
    add_box(s, V(1, -0.5, 1), V(2, 0.5, 2), false, "box");
    const auto solids = find_convex_solids(s);
    ASSERT_EQ(solids.size(), 2u);
    EXPECT_EQ(int(solids[0].inward) + int(solids[1].inward), 1);
    const auto a = cut_area(s, find_solid_cuts(s));
    // Room: 2 is the floor (y = 0). Box: 6 x-, 7 x+, 8 y- (bottom), 9 y+ (top), 10 z-, 11 z+.
    const std::vector<double> expected = {0, 0, 1, 0, 0, 0, 0.5, 0.5, 1, 0, 0.5, 0.5};
    for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(a[k], expected[k], 1e-12) << k;
}

TEST(SolidCuts, TouchingOpenOrNeighbouringObjectsCutNothing) {
    // A box resting on the floor (the contact cuts' case), a box against a wall, a second room
    // beside the first, a box with its lid off crossing a box: no solid cut.
    Scene s = with_white();
    add_box(s, V(0), V(4, 3, 4), true, "room");
    add_box(s, V(4, 0, 0), V(8, 3, 4), true, "next room");
    add_box(s, V(1, 0, 1), V(2, 1, 2), false, "resting");
    add_box(s, V(3, 1, 1), V(4, 2, 2), false, "against the wall");
    Scene open = s;
    add_box(open, V(0.5, 0.5, 2.5), V(1.5, 1.5, 3.5), false, "lidless");
    open.surfaces.pop_back();  // its z+ face
    add_box(open, V(1, 1, 3), V(2, 2, 3.2), false, "crossing the lidless box");
    EXPECT_EQ(find_convex_solids(s).size(), 4u);
    EXPECT_TRUE(find_solid_cuts(s).empty());
    for (const auto& c : find_solid_cuts(open))
        EXPECT_NE(open.surfaces[std::size_t(c.surface)].object, "crossing the lidless box");
    EXPECT_TRUE(find_solid_cuts(make_cornell_box()).empty());
}

TEST(SolidCuts, ThePatchMeshLeavesTheHiddenPartsOut) {
    // Through the mesher: the floor and the box lose exactly the hidden area, with no cracks.
    Scene s = with_white();
    add_box(s, V(0), V(4, 3, 4), true, "room");
    add_box(s, V(1.25, -0.5, 1.25), V(2.25, 0.5, 2.25), false, "box");
    s.covered = find_covered_regions(s);
    MeshingOptions o;
    o.max_edge = 0.5;
    const PatchMesh mesh(s, o);
    double total = 0;
    for (const auto& p : mesh.patches()) total += p.area;
    // Room 2 x (12 + 12 + 16) = 80, less the floor's 1; the box keeps its top and four 1 x 0.5 sides.
    EXPECT_NEAR(total, 80 - 1 + 1 + 4 * 0.5, 1e-9);
}

}  // namespace
}  // namespace bounce

namespace bounce {
namespace {

TEST(SolidCuts, BoxesThroughACeilingDoNotHideTheWholeCeiling) {
    // Boxes crossing the ceiling at the centres of both triangles of its outline, either way it
    // is cut: the room's own outline is a closed loop of segments in the ceiling's plane, and
    // judged only at those centres (inside the boxes) it hid the whole ceiling.
    Scene s = with_white();
    add_box(s, V(0), V(4, 3, 4), true, "room");
    int k = 0;
    for (const double x : {4.0 / 3, 8.0 / 3})
        for (const double z : {4.0 / 3, 8.0 / 3})
            add_box(s, V(x - 0.3, 2.7, z - 0.3), V(x + 0.3, 3.3, z + 0.3), false, "box " + std::to_string(k++));
    const int ceiling = 3;  // y+ of the room
    ASSERT_NEAR(s.surfaces[ceiling].vertices[0].y, 3.0, 1e-12);
    double largest = 0;
    for (const auto& c : find_covered_regions(s))
        if (c.surface == ceiling) largest = std::max(largest, polygon_area(c.polygon));
    EXPECT_NEAR(largest, 0.36, 1e-9);  // one box's cross-section, not the ceiling's 16
}

}  // namespace
}  // namespace bounce
