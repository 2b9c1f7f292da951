// SPDX-License-Identifier: MIT
// The coordinate grid: one geometry, however it was written, reaches the mesher as one set of
// bits.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mesh/readers/json_scene.h"
#include "mesh/readers/obj_reader.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/coordinate_grid.h"
#include "scene_as_obj.h"
#include "test_util.h"

using namespace bounce;

namespace {

Scene one_quad(const std::vector<glm::dvec3>& vertices) {
    Scene s;
    s.materials.push_back({});
    s.surfaces.push_back({vertices, 0, "quad", {"test", 1}});
    return s;
}

/// How many vertices of the two scenes' surfaces differ in any bit (the scenes must have the
/// same surfaces in the same order).
int vertices_that_differ(const Scene& a, const Scene& b) {
    int differ = 0;
    for (std::size_t s = 0; s < a.surfaces.size(); ++s)
        for (std::size_t k = 0; k < a.surfaces[s].vertices.size(); ++k)
            differ += a.surfaces[s].vertices[k] != b.surfaces[s].vertices[k];
    return differ;
}

}  // namespace

TEST(CoordinateGrid, WrittenDecimalsStayAndNeighboursMeet) {
    // Extent 555 (the Cornell box in millimetres): sqrt(2) 555 = 785, so 10 - 2 = 8 decimals.
    const double x = 548.8, up = std::nextafter(x, 1e9), down = std::nextafter(x, 0.0);
    const double third = 100.0 / 3;
    Scene s = one_quad({{0, 0, 0}, {555, 0, third}, {555, x, 0.1 + 0.2}, {0, up, down}});
    ASSERT_EQ(coordinate_decimals(s), 8);
    snap_coordinates(s);
    const auto& v = s.surfaces[0].vertices;
    EXPECT_EQ(v[2].y, 548.8);  // a written decimal keeps its bits
    EXPECT_EQ(v[3].y, 548.8);  // one ulp off: back on it
    EXPECT_EQ(v[3].z, 548.8);
    EXPECT_EQ(v[2].z, 0.3);  // 0.1 + 0.2 is 0.30000000000000004
    EXPECT_EQ(v[1].z, 33.33333333);
}

TEST(CoordinateGrid, ExtentsOneUlpApartKeepOneNumberOfDecimals) {
    // At a power of ten the decimal exponent of the extent itself would change between 10 and
    // 10 - ulp.
    for (const double e : {0.1, 1.0, 10.0, 100.0, 5.0, 2.0}) {
        const Scene a = one_quad({{0, 0, 0}, {e, 0, 0}, {e, 1e-3, 0}});
        const Scene b = one_quad({{0, 0, 0}, {std::nextafter(e, 0.0), 0, 0}, {e, 1e-3, 0}});
        const Scene c = one_quad({{0, 0, 0}, {std::nextafter(e, 1e9), 0, 0}, {e, 1e-3, 0}});
        ASSERT_TRUE(coordinate_decimals(a)) << e;
        EXPECT_EQ(coordinate_decimals(a), coordinate_decimals(b)) << e;
        EXPECT_EQ(coordinate_decimals(a), coordinate_decimals(c)) << e;
        const double step = std::pow(10.0, -*coordinate_decimals(a));
        EXPECT_GT(step, 1e-11 * e) << e;
        EXPECT_LT(step, 1.5e-10 * e) << e;
    }
    EXPECT_FALSE(coordinate_decimals(Scene{}));
}

TEST(CoordinateGrid, TheStudyAsJsonAndAsAnObjLoadsAsTheSameBits) {
    // The study places its boxes and lamps by scale, rotation and translation; printed to 15
    // digits as an OBJ, some vertices come back a few ulps away. Loaded, they are the same
    // bits, and so are the regions the contact cuts leave out.
    const std::string json = std::string(BOUNCE_SOURCE_DIR) + "/examples/scenes/study.json";
    test::TempDir dir;
    const Scene read = read_json_scene(json);
    const auto obj = test::write_scene_as_obj(read, dir, "study", 15);
    const Scene a = load_scene(json), b = load_scene(obj.string());
    ASSERT_EQ(a.surfaces.size(), b.surfaces.size());
    EXPECT_GT(vertices_that_differ(read, read_obj(obj.string())), 0);  // the inputs differ ...
    EXPECT_EQ(vertices_that_differ(a, b), 0);                          // ... the loaded scenes do not
    ASSERT_EQ(a.covered.size(), b.covered.size());
    ASSERT_GT(a.covered.size(), 0u);  // the legs on the floor and under the table top
    for (std::size_t k = 0; k < a.covered.size(); ++k) {
        EXPECT_EQ(a.covered[k].surface, b.covered[k].surface);
        EXPECT_EQ(a.covered[k].polygon, b.covered[k].polygon) << k;
    }
}
