// SPDX-License-Identifier: MIT
// Open parts (open_parts.h): which share of a patch is open to the scene, and whether what its
// open part misses is an opening or a black back side.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/open_parts.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

/// Five faces of the box [lo, hi] facing out, without the bottom (z = lo.z): a cabinet's open
/// underside.
void add_bottomless_box(Scene& s, glm::dvec3 lo, glm::dvec3 hi, int material) {
    const std::vector<std::vector<glm::dvec3>> faces = {
        {{lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}},  // +z
        {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}},  // -y
        {{lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}},  // +y
        {{lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}},  // -x
        {{hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}},  // +x
    };
    for (const auto& f : faces) s.surfaces.push_back({f, material, "box", {"test", 0}});
}

}  // namespace

TEST(OpenParts, AFloorHalfUnderABottomlessBoxIsHalfOpen) {
    // One floor patch [0,2] x [0,1], the half x > 1 under a box with no bottom: points there
    // see only the box's inside (back sides), points on the other half the box's outside and
    // the open sky.
    Scene s;
    s.name = "floor under a box";
    s.materials = {{"grey", Rgb::gray(0.5), Rgb()}};
    s.surfaces.push_back({{{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}}, 0, "floor", {"test", 0}});
    add_bottomless_box(s, {1, -0.5, 0}, {2.5, 1.5, 1}, 0);
    MeshingOptions whole;
    whole.subdivide = false;
    const PatchMesh mesh(s, whole);
    ASSERT_EQ(mesh.patches()[0].surface, 0);
    const auto vis = make_embree_visibility(mesh.patches());
    const auto open = open_parts(mesh.patches(), *vis);
    std::printf("floor half under a box: open share %.4f, closed %d, back share %.3f\n", open[0].area_share,
                int(open[0].closed), open[0].back_share);
    EXPECT_NEAR(open[0].area_share, 0.5, 0.07);  // 8 x 8 stratified points
    EXPECT_FALSE(open[0].closed);                // its open half sees the sky
    EXPECT_EQ(open[0].back_share, 0.0);          // and no back side: the box's outside faces it
    EXPECT_DOUBLE_EQ(open[0].receiving_share(), open[0].area_share);
}

TEST(OpenParts, EveryPartOfAClosedRoomIsClosedAndOpen) {
    MeshingOptions o;
    o.max_edge = 0.5;
    const PatchMesh mesh(closed_box({2, 3, 2}, {"w", Rgb::gray(0.5), Rgb::gray(1)}), o);
    const auto vis = make_cgal_visibility(mesh.patches());
    const auto open = open_parts(mesh.patches(), *vis);
    for (std::size_t i = 0; i < open.size(); ++i) {
        EXPECT_EQ(open[i].area_share, 1.0) << i;
        EXPECT_TRUE(open[i].closed) << i;
        // A closed part's row is scaled to send exactly its open share, whatever its sum.
        EXPECT_DOUBLE_EQ(open[i].shot_scale(0.97) * 0.97, 1.0);
    }
}

TEST(OpenParts, ALampHungBelowTheCeilingShowsItsBackAndBuriesTheCeilingBehindIt) {
    // A closed 4 x 4 x 3 room with a one-sided 1 x 1 lamp 5 cm below the ceiling, facing
    // down: the ceiling right behind it is buried (from there, rays escape past the lamp's
    // rim only beyond 84 degrees), the ceiling beside it sees the lamp's black back, and
    // nothing in a closed room sees an opening.
    Scene s = closed_box({4, 4, 3}, {"w", Rgb::gray(0.7), Rgb()});
    s.materials.push_back({"lamp", Rgb(), Rgb::gray(10)});
    s.surfaces.push_back(
        {{{1.5, 1.5, 2.95}, {1.5, 2.5, 2.95}, {2.5, 2.5, 2.95}, {2.5, 1.5, 2.95}}, 1, "lamp", {"test", 0}});
    MeshingOptions o;
    o.max_edge = 0.25 * (1 + 1e-9);
    const PatchMesh mesh(s, o);
    for (const auto& vis : {make_embree_visibility(mesh.patches()), make_cgal_visibility(mesh.patches())}) {
        const auto open = open_parts(mesh.patches(), *vis);
        int buried = 0, backs = 0, floor_closed = 0, floor = 0;
        for (std::size_t i = 0; i < open.size(); ++i) {
            const Patch& p = mesh.patches()[i];
            if (!open[i].closed) {
                EXPECT_EQ(open[i].back_share, 1.0) << i;  // no opening
            }
            if (open[i].area_share == 0.0) {
                ++buried;
                EXPECT_GT(p.centre.z, 2.99) << "only the ceiling behind the lamp is buried";
                EXPECT_LT(glm::length(glm::dvec2(p.centre.x - 2, p.centre.y - 2)), 0.5);
                EXPECT_EQ(open[i].shot_scale(0.01), 0.0) << "a buried patch sends nothing";
            }
            if (!open[i].closed && open[i].area_share > 0) ++backs;
            if (p.centre.z < 1e-9) {
                ++floor;
                floor_closed += open[i].closed;
            }
        }
        std::printf("%s: %d buried, %d seeing a back side, %d of %d floor patches closed\n", vis->name().c_str(),
                    buried, backs, floor_closed, floor);
        EXPECT_GE(buried, 4);  // the four 0.25 m patches behind the lamp's middle at least
        EXPECT_GT(backs, 0);
        EXPECT_EQ(floor_closed, floor) << "the floor sees only the lamp's front and the walls";
    }
}
