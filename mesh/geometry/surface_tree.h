// SPDX-License-Identifier: MIT
#pragma once

#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/scene.h"

namespace bounce {

/// The scene's input surfaces as triangles in a CGAL AABB tree, each answer naming the surface
/// (index into Scene::surfaces) a triangle was cut from: the ray and box queries of the meshing
/// stage (contact cuts, discontinuity traces), exact in their predicates.
class SurfaceTree {
public:
    explicit SurfaceTree(const Scene& scene);
    ~SurfaceTree();
    SurfaceTree(const SurfaceTree&) = delete;
    SurfaceTree& operator=(const SurfaceTree&) = delete;

    bool empty() const;
    /// The surface the ray from `from` along `dir` meets first, or -1.
    int first_hit(const glm::dvec3& from, const glm::dvec3& dir) const;
    /// Every surface the ray meets where it meets the first, within `slack` along the ray
    /// (coincident faces: a box's side flush with a wall), sorted; empty when it meets none.
    std::vector<int> first_hits(const glm::dvec3& from, const glm::dvec3& dir, double slack) const;
    /// Surfaces with a triangle meeting the box [lo, hi], sorted, each once.
    std::vector<int> in_box(const glm::dvec3& lo, const glm::dvec3& hi) const;
    /// Surfaces with a triangle meeting the segment a-b, sorted, each once.
    std::vector<int> on_segment(const glm::dvec3& a, const glm::dvec3& b) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace bounce
