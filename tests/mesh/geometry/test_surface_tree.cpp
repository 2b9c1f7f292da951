// SPDX-License-Identifier: MIT
// SurfaceTree::in_box answers from bounding boxes where they decide and from CGAL's exact
// triangle-box test where they do not; its answer must be the exact one, triangle by triangle,
// also where a triangle only touches the box in a corner, along an edge or on a face.
#include <gtest/gtest.h>

#include <random>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "mesh/geometry/surface_tree.h"

using namespace bounce;
using V = glm::dvec3;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;

namespace {

K::Point_3 cgal(const V& p) { return {p.x, p.y, p.z}; }

/// Surfaces (one triangle each) meeting [lo, hi] by CGAL's exact test, one by one.
std::vector<int> in_box_one_by_one(const Scene& scene, const V& lo, const V& hi) {
    const K::Iso_cuboid_3 box(cgal(lo), cgal(hi));
    std::vector<int> out;
    for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
        const auto& v = scene.surfaces[s].vertices;
        if (CGAL::do_intersect(box, K::Triangle_3(cgal(v[0]), cgal(v[1]), cgal(v[2])))) out.push_back(int(s));
    }
    return out;
}

}  // namespace

TEST(SurfaceTree, InBoxIsTheExactTriangleBoxTest) {
    // Coordinates on a grid of quarter units, boxes on the same grid: many triangles touch a
    // box's face, edge or corner exactly, the cases where bounding boxes alone would decide
    // wrongly (a triangle's box meets the query while the triangle passes beside it).
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<int> q(0, 16);
    const auto grid = [&] { return V(q(rng), q(rng), q(rng)) * 0.25; };
    Scene scene;
    scene.materials.resize(1);
    while (scene.surfaces.size() < 600) {
        const V a = grid(), b = grid(), c = grid();
        if (glm::length(glm::cross(b - a, c - a)) == 0) continue;
        scene.surfaces.push_back({{a, b, c}, 0, "t", {}});
    }
    const SurfaceTree tree(scene);
    int nonempty = 0, partial = 0;
    for (int k = 0; k < 300; ++k) {
        V lo = grid(), hi = grid();
        for (int i = 0; i < 3; ++i)
            if (lo[i] > hi[i]) std::swap(lo[i], hi[i]);
        const std::vector<int> exact = in_box_one_by_one(scene, lo, hi);
        ASSERT_EQ(tree.in_box(lo, hi), exact) << "box " << k;
        nonempty += !exact.empty();
        partial += !exact.empty() && exact.size() < scene.surfaces.size();
    }
    // The boxes are not all trivial: most meet some triangles and miss others.
    EXPECT_GT(partial, 150);
    EXPECT_GT(nonempty, 150);
}
