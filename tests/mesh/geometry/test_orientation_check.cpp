// SPDX-License-Identifier: MIT
#include "mesh/geometry/orientation_check.h"

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "mesh/readers/cornell_box.h"
#include "mesh/readers/obj_reader.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/polygon.h"
#include "test_util.h"

namespace bounce {
namespace {

using V = glm::dvec3;

// The six faces of the box [lo, hi], facing out (or in), one surface each, named by `object`
// and the face ("room: x-").
void add_box(Scene& s, const V& lo, const V& hi, bool inward, int material, const std::string& object) {
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            std::vector<V> poly(4);
            for (int k = 0; k < 4; ++k) {
                V p;
                p[axis] = side ? hi[axis] : lo[axis];
                p[u] = (k == 1 || k == 2) ? hi[u] : lo[u];
                p[v] = (k >= 2) ? hi[v] : lo[v];
                poly[k] = p;
            }
            V out(0.0);
            out[axis] = side ? 1.0 : -1.0;
            if ((glm::dot(newell_normal(poly), out) > 0) == inward) std::reverse(poly.begin(), poly.end());
            const std::string name = object + ": " + std::string(1, "xyz"[axis]) + (side ? "+" : "-");
            s.surfaces.push_back({poly, material, name, {name, 0}});
        }
}

// A closed 4 x 3 x 4 room (y up), a lamp panel 10 cm under the ceiling and two blocks resting
// on the floor.
Scene closed_room() {
    Scene s;
    s.materials = {{"white", Rgb::gray(0.7), Rgb()}, {"lamp", Rgb(), Rgb::gray(10)}};
    add_box(s, V(0), V(4, 3, 4), true, 0, "room");
    s.surfaces.push_back(
        {{V(1.5, 2.9, 1.5), V(2.5, 2.9, 1.5), V(2.5, 2.9, 2.5), V(1.5, 2.9, 2.5)}, 1, "lamp", {"lamp", 0}});
    add_box(s, V(0.5, 0, 0.5), V(1.5, 1.2, 1.5), false, 0, "tall block");
    add_box(s, V(2.5, 0, 2.2), V(3.4, 0.6, 3.1), false, 0, "short block");
    return s;
}

int find_surface(const Scene& s, const std::string& object) {
    for (std::size_t k = 0; k < s.surfaces.size(); ++k)
        if (s.surfaces[k].object == object) return int(k);
    return -1;
}

void reverse_surface(Scene& s, int k) {
    auto& v = s.surfaces[std::size_t(k)].vertices;
    std::reverse(v.begin(), v.end());
}

TEST(OrientationCheck, TheBuiltInCornellBoxAndAClosedRoomWithBlocksHaveNone) {
    EXPECT_TRUE(find_reversed_surfaces(make_cornell_box()).empty());
    EXPECT_TRUE(find_reversed_surfaces(closed_room()).empty());
    const Scene loaded = load_scene("cornell");
    for (const auto& w : loaded.warnings) EXPECT_EQ(w.find("orientation"), std::string::npos) << w;
}

TEST(OrientationCheck, OneWallReversedInAClosedRoomIsNamedAlone) {
    for (const std::string wall : {"room: x-", "room: y+", "room: z+", "room: y-"}) {
        Scene s = closed_room();
        const int k = find_surface(s, wall);
        ASSERT_GE(k, 0);
        reverse_surface(s, k);
        const auto r = find_reversed_surfaces(s);
        ASSERT_EQ(r.size(), 1u) << wall;
        EXPECT_EQ(r[0].surfaces, std::vector<int>{k}) << wall;
        EXPECT_LE(r[0].front_sees, 0.2) << wall;
        EXPECT_GE(r[0].back_sees, 0.5) << wall;
        const std::string w = reversed_surface_warning(s, r[0]);
        EXPECT_EQ(w.rfind("orientation: " + wall + " faces away from the scene", 0), 0u) << w;
        EXPECT_NE(w.find("Reverse the order of its vertices"), std::string::npos) << w;
    }
}

TEST(OrientationCheck, EveryFaceReversedIsLeftToTheSceneWideCheck) {
    // Nothing faces the inside of the room: no surface sees fronts from its back either.
    Scene s = closed_room();
    for (std::size_t k = 0; k < s.surfaces.size(); ++k) reverse_surface(s, int(k));
    EXPECT_TRUE(find_reversed_surfaces(s).empty());
}

TEST(OrientationCheck, AThinTableTopEitherWayIsNotReported) {
    // A table top modelled as one quad (no thickness): both of its sides see the room.
    for (const bool down : {false, true}) {
        Scene s = closed_room();
        std::vector<V> top = {V(1, 0.75, 2), V(1, 0.75, 3.5), V(3, 0.75, 3.5), V(3, 0.75, 2)};
        if ((glm::dot(newell_normal(top), V(0, 1, 0)) < 0) != down) std::reverse(top.begin(), top.end());
        s.surfaces.push_back({top, 0, "table", {"table", 0}});
        EXPECT_TRUE(find_reversed_surfaces(s).empty()) << down;
    }
}

TEST(OrientationCheck, TheCornellObjWithOnlyTheGreenWallReversed) {
    Scene s = read_obj(test::fixture("cornell_box.obj"));
    EXPECT_TRUE(find_reversed_surfaces(s).empty());
    std::vector<int> green;
    for (std::size_t k = 0; k < s.surfaces.size(); ++k)
        if (s.surfaces[k].object == "green_wall") {
            green.push_back(int(k));
            reverse_surface(s, int(k));
        }
    ASSERT_FALSE(green.empty());
    const auto r = find_reversed_surfaces(s);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].surfaces, green);
    const std::string w = reversed_surface_warning(s, r[0]);
    EXPECT_NE(w.find("cornell_box.obj:" + std::to_string(s.surfaces[std::size_t(green[0])].where.line) +
                     " (green_wall) faces away"),
              std::string::npos)
        << w;
}

TEST(OrientationCheck, AJsonObjectIsToldToFlip) {
    Scene s = closed_room();
    const int k = find_surface(s, "room: x+");
    reverse_surface(s, k);
    s.surfaces[std::size_t(k)].where = {"scene.json: objects[3] (quad)", 0};
    s.surfaces[std::size_t(k)].object = "east wall";
    const auto r = find_reversed_surfaces(s);
    ASSERT_EQ(r.size(), 1u);
    const std::string w = reversed_surface_warning(s, r[0]);
    EXPECT_NE(w.find("scene.json: objects[3] (quad) (east wall) faces away"), std::string::npos) << w;
    EXPECT_NE(w.find("\"flip\": true"), std::string::npos) << w;
}

TEST(OrientationCheck, TheExampleScenesHaveNone) {
    const auto dir = std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples" / "scenes";
    int seen = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
        if (e.path().extension() != ".json") continue;
        ++seen;
        const Scene s = load_scene(e.path().string());
        for (const auto& w : s.warnings) EXPECT_EQ(w.find("orientation"), std::string::npos) << e.path() << ": " << w;
    }
    EXPECT_GE(seen, 3);
}

}  // namespace
}  // namespace bounce
