// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "mesh/meshing/element_tree.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"

using namespace bounce;

namespace {

std::vector<Patch> cornell_patches(std::size_t target) {
    MeshingOptions o;
    o.target_patches = target;
    return PatchMesh(load_scene("cornell"), o).patches();
}

/// Splits leaves unevenly: every third leaf of each generation, three generations deep, so
/// fine elements sit next to coarse ones (the T-vertices a conforming export must fix).
void refine_unevenly(ElementTree& tree) {
    for (int g = 0; g < 3; ++g) {
        const auto leaves = tree.leaves();
        for (std::size_t k = 0; k < leaves.size(); k += 3) tree.split(leaves[k]);
    }
}

/// Points of the same surface lying strictly inside an edge of a face (T-vertices).
std::size_t t_vertices(const std::vector<std::vector<glm::dvec3>>& faces, const std::vector<int>& surface) {
    std::size_t count = 0;
    for (std::size_t f = 0; f < faces.size(); ++f)
        for (std::size_t k = 0; k < faces[f].size(); ++k) {
            const glm::dvec3 a = faces[f][k], b = faces[f][(k + 1) % faces[f].size()];
            const double len = glm::length(b - a);
            for (std::size_t g = 0; g < faces.size(); ++g) {
                if (surface[g] != surface[f]) continue;
                for (const auto& p : faces[g]) {
                    const double t = glm::dot(p - a, b - a) / (len * len);
                    if (t > 1e-9 && t < 1 - 1e-9 && glm::length(a + t * (b - a) - p) < 1e-9 * len) ++count;
                }
            }
        }
    return count;
}

}  // namespace

TEST(ElementTree, SplittingKeepsAreaAndEmittedPowerExactly) {
    const auto roots = cornell_patches(60);
    ElementTree tree(roots);
    refine_unevenly(tree);
    double area = 0.0, area0 = 0.0;
    Rgb power, power0;
    for (const auto& p : roots) area0 += p.area, power0 += p.emission * p.area;
    const auto leaves = tree.leaves();
    EXPECT_GT(leaves.size(), 2 * roots.size());
    for (const auto l : leaves) {
        const Patch& g = tree.geometry()[l];
        area += g.area;
        power += g.emission * g.area;
        EXPECT_EQ(g.surface, roots[tree.node(l).root].surface);
    }
    EXPECT_NEAR(area / area0, 1.0, 1e-13);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(power[c] / power0[c], 1.0, 1e-13);
    // Each parent's children tile it: their areas add up to the parent's.
    for (std::size_t i = 0; i < tree.size(); ++i) {
        const auto& n = tree.node(i);
        if (n.leaf()) continue;
        double sum = 0.0;
        for (int k = 0; k < 4; ++k) sum += tree.geometry()[std::size_t(n.first_child + k)].area;
        EXPECT_NEAR(sum / tree.geometry()[i].area, 1.0, 1e-13) << "node " << i;
    }
}

TEST(ElementTree, ConformingMeshHasNoCracksWhereTheLeavesHaveTVertices) {
    // Triangles too: a pentagon is cut into them.
    auto roots = cornell_patches(30);
    ElementTree tree(roots);
    refine_unevenly(tree);
    const auto leaves = tree.leaves();
    std::vector<std::vector<glm::dvec3>> raw;
    std::vector<int> surface;
    for (const auto l : leaves) {
        const Patch& g = tree.geometry()[l];
        raw.emplace_back(g.vertices.begin(), g.vertices.begin() + g.vertex_count);
        surface.push_back(g.surface);
    }
    const std::size_t before = t_vertices(raw, surface);
    EXPECT_GT(before, 100u);  // the uneven refinement does make T-vertices

    const PatchMesh mesh = tree.conforming_mesh(leaves);
    ASSERT_EQ(mesh.size(), leaves.size());
    std::vector<std::vector<glm::dvec3>> faces;
    for (std::size_t f = 0; f < mesh.size(); ++f) {
        std::vector<glm::dvec3> poly;
        for (const int v : mesh.patch_vertex_indices(f)) {
            const auto p = mesh.mesh().point(OpenPatchMesh::VertexHandle(v));
            poly.emplace_back(p[0], p[1], p[2]);
        }
        faces.push_back(poly);
    }
    EXPECT_EQ(t_vertices(faces, surface), 0u);
    // Interior edges are shared by two faces, so the boundary is the surfaces' outlines and
    // has their length whatever the refinement: a crack would add boundary length.
    ElementTree uniform(roots);
    for (int g = 0; g < 3; ++g)
        for (const auto l : uniform.leaves()) uniform.split(l);
    const PatchMesh full = uniform.conforming_mesh(uniform.leaves());
    double len_adaptive = 0.0, len_full = 0.0;
    for (auto e : mesh.mesh().edges())
        if (mesh.mesh().is_boundary(e)) len_adaptive += mesh.mesh().calc_edge_length(e);
    for (auto e : full.mesh().edges())
        if (full.mesh().is_boundary(e)) len_full += full.mesh().calc_edge_length(e);
    EXPECT_GT(len_full, 0.0);
    EXPECT_NEAR(len_adaptive / len_full, 1.0, 1e-9);
    // The element polygons keep their area (the extra points are on the edges).
    for (std::size_t f = 0; f < mesh.size(); ++f) EXPECT_EQ(mesh.patches()[f].area, tree.geometry()[leaves[f]].area);
}

TEST(ElementTree, LocateFindsTheLeafContainingAPoint) {
    const auto roots = cornell_patches(30);
    ElementTree tree(roots);
    refine_unevenly(tree);
    for (const auto l : tree.leaves()) {
        const auto& n = tree.node(l);
        glm::dvec2 c(0.0);
        for (int k = 0; k < n.corner_count; ++k) c += n.corners[k];
        EXPECT_EQ(tree.locate(n.root, c / double(n.corner_count)), l);
    }
}
