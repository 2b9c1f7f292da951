// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "mesh/scene/polygon.h"

using namespace bounce;
using V = glm::dvec3;

TEST(Polygon, NewellNormalAndAreaOfATiltedRectangle) {
    // A 2 x 3 rectangle tilted 45 degrees about x: area 6, normal (0, -1, 1)/sqrt 2.
    const double s = std::sqrt(0.5);
    std::vector<V> r = {{0, 0, 0}, {2, 0, 0}, {2, 3 * s, 3 * s}, {0, 3 * s, 3 * s}};
    EXPECT_NEAR(polygon_area(r), 6.0, 1e-12);
    const V n = glm::normalize(newell_normal(r));
    EXPECT_NEAR(n.y, -s, 1e-12);
    EXPECT_NEAR(n.z, s, 1e-12);
    const V c = polygon_centroid(r);
    EXPECT_NEAR(c.x, 1.0, 1e-12);
    EXPECT_NEAR(c.y, 1.5 * s, 1e-12);
}

TEST(Polygon, EarClippingKeepsTheAreaOfAConcavePolygon) {
    // L shape of area 3 (a 2x2 square missing one unit square).
    std::vector<V> l = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
    const auto tris = triangulate_polygon(l);
    ASSERT_EQ(tris.size(), 4u);
    double area = 0.0;
    for (const auto& t : tris) {
        const double a = glm::cross(l[t[1]] - l[t[0]], l[t[2]] - l[t[0]]).z * 0.5;
        EXPECT_GT(a, 0.0) << "every triangle keeps the polygon's orientation";
        area += a;
    }
    EXPECT_NEAR(area, 3.0, 1e-12);
    EXPECT_NEAR(polygon_area(l), 3.0, 1e-12);
}
