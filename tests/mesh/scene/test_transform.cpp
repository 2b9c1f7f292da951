// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "mesh/readers/json_scene.h"
#include "mesh/scene/polygon.h"
#include "mesh/scene/transform.h"
#include "test_util.h"

using namespace bounce;
using V = glm::dvec3;

TEST(Transform, NormalsOfAShearedNonUniformlyScaledBoxStayPerpendicular) {
    glm::dmat4 m(1.0);
    m[1][0] = 0.7;   // x += 0.7 y (shear)
    m[2][1] = -0.4;  // y -= 0.4 z
    const Transform t = Transform(m) * Transform::scale({3.0, 0.5, 2.0});
    const std::vector<std::vector<V>> faces = {{{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
                                               {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}},
                                               {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}}};
    for (const auto& f : faces) {
        const V n0 = glm::normalize(newell_normal(f));
        const V n = t.normal(n0);
        std::vector<V> g;
        for (const auto& p : f) g.push_back(t.point(p));
        for (std::size_t k = 0; k < g.size(); ++k)
            EXPECT_NEAR(glm::dot(n, glm::normalize(g[(k + 1) % g.size()] - g[k])), 0.0, 1e-12);
        // And it is the same side: it agrees with the transformed face's own normal.
        EXPECT_NEAR(glm::dot(n, glm::normalize(newell_normal(g))), 1.0, 1e-12);
        // The plain (wrong) transform of the normal by T would not be perpendicular.
        const V naive = glm::normalize(glm::dvec3(t.matrix() * glm::dvec4(n0, 0.0)));
        EXPECT_GT(std::abs(glm::dot(naive, glm::normalize(g[1] - g[0]))) +
                      std::abs(glm::dot(naive, glm::normalize(g[2] - g[1]))),
                  1e-3);
    }
}

TEST(Transform, JsonBoxKeepsOutwardFacesUnderShearScaleAndMirror) {
    test::TempDir dir;
    for (const std::string tr :
         {R"({"scale": [3, 0.5, 2], "rotate": {"axis": [1, 2, 3], "degrees": 40}, "translate": [5, 6, 7]})",
          R"({"matrix": [1, 0.7, 0, 5,  0, 1, -0.4, 6,  0, 0, 2, 7,  0, 0, 0, 1]})",
          R"({"scale": [-1, 2, 1], "translate": [5, 6, 7]})"}) {
        const auto file = dir.write("box.json", R"({"objects": [{"type": "box", "transform": )" + tr + "}]}");
        const Scene s = read_json_scene(file);
        ASSERT_EQ(s.surfaces.size(), 6u);
        V centre(0.0);
        for (const auto& f : s.surfaces) centre += polygon_centroid(f.vertices);
        centre /= 6.0;
        EXPECT_NEAR(centre.x, 5, 1e-9);
        EXPECT_NEAR(centre.z, 7, 1e-9);
        for (const auto& f : s.surfaces)
            EXPECT_GT(glm::dot(newell_normal(f.vertices), polygon_centroid(f.vertices) - centre), 0.0) << tr;
    }
}

TEST(Transform, JsonRotationAndTranslationPlaceAQuad) {
    test::TempDir dir;
    const auto file = dir.write("q.json", R"({"materials": {"lamp": {"reflectance": 0, "emission": [1, 2, 3]}},
        "objects": [{"type": "quad", "material": "lamp",
                     "transform": {"scale": 2, "rotate": {"axis": [1, 0, 0], "degrees": 180}, "translate": [0, 0, 1]}}]})");
    const Scene s = read_json_scene(file);
    ASSERT_EQ(s.surfaces.size(), 1u);
    const V n = glm::normalize(newell_normal(s.surfaces[0].vertices));
    EXPECT_NEAR(n.z, -1.0, 1e-12);  // flipped to face down
    EXPECT_NEAR(polygon_area(s.surfaces[0].vertices), 4.0, 1e-12);
    EXPECT_NEAR(polygon_centroid(s.surfaces[0].vertices).z, 1.0, 1e-12);
    EXPECT_EQ(s.materials[s.surfaces[0].material].emission, Rgb(1, 2, 3));
}
