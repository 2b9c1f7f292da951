// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>

#include "mesh/meshing/patch.h"
#include "mesh/meshing/patch_mesh.h"

namespace bounce {

/// Quadtree elements over root patches, for adaptive subdivision and hierarchical radiosity.
/// A node covers a region of its root given by corners in the root's parameter space (a quad
/// root: bilinear (u, v); a triangle root: c0 + u (c1 - c0) + v (c2 - c0)). Splitting a node
/// makes four children at the edge midpoints (and the centre for a quad): sub-quads of a
/// planar quad and midpoint triangles tile their parent exactly, so area and emitted power
/// are kept to rounding. Geometry is evaluated from the root's corners, so a point shared by
/// two nodes of one root is bit-identical in both.
class ElementTree {
public:
    struct Node {
        std::uint32_t root = 0;
        std::int32_t parent = -1;
        std::int32_t first_child = -1;  // four consecutive nodes, or -1 for a leaf
        int level = 0;
        int corner_count = 0;  // 3 or 4, as the root
        std::array<glm::dvec2, 4> corners{};
        bool leaf() const { return first_child < 0; }
    };

    explicit ElementTree(std::vector<Patch> roots);

    std::size_t size() const { return m_nodes.size(); }
    std::size_t root_count() const { return m_roots.size(); }
    const Node& node(std::size_t i) const { return m_nodes[i]; }
    /// The node's geometry as a Patch (material, normal and surface of its root). The vector
    /// grows as nodes split; hold it by reference, not its elements.
    const std::vector<Patch>& geometry() const { return m_geometry; }
    const std::vector<Patch>& roots() const { return m_roots; }

    /// Splits leaf `i` into four; returns the first child's index.
    std::size_t split(std::size_t i);
    /// Leaves in depth-first order (children in place of their parent).
    std::vector<std::uint32_t> leaves() const;
    /// A point of root r at parameters (u, v).
    glm::dvec3 point(std::uint32_t r, const glm::dvec2& uv) const;
    /// The leaf of root r containing parameter point uv (in the closed region; ties go to the
    /// first child that contains it).
    std::uint32_t locate(std::uint32_t r, const glm::dvec2& uv) const;

    /// The leaves as a mesh for display and export. Each leaf polygon gets every vertex of a
    /// neighbouring leaf that lies on its edges (the T-vertices of a finer neighbour), so the
    /// mesh is conforming and point data interpolates without cracks. Faces are in the
    /// order of `leaves`; PatchMesh::patches() are the leaves' geometry.
    PatchMesh conforming_mesh(const std::vector<std::uint32_t>& leaves) const;
    /// The distance within which conforming_mesh welds points of one surface into one vertex:
    /// 1e-9 of the diagonal of the roots' box (corners of neighbouring roots are computed from
    /// different roots' corners and may differ in the last bits).
    double weld() const;
    /// Per node: max - min of the luminance of `values` (one per node) over the leaves under
    /// it, 0 at a leaf: how much a node's mean hides.
    std::vector<double> leaf_luminance_spread(std::span<const Rgb> values) const;

private:
    Patch make_geometry(std::uint32_t root, int count, const std::array<glm::dvec2, 4>& corners) const;
    static bool contains(const Node& n, const glm::dvec2& uv);

    std::vector<Patch> m_roots;
    std::vector<Node> m_nodes;
    std::vector<Patch> m_geometry;
};

}  // namespace bounce
