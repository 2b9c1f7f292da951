// SPDX-License-Identifier: MIT
#pragma once

#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/scene.h"

namespace bounce {

/// The scene's input surfaces as triangles in an Embree BVH (single precision, recentred on
/// the scene's box, so rounding stays near 6e-8 of its diagonal): the contact cuts' enclosure
/// rays, 64 at every point they prove covered, at Embree's speed. The exact queries stay with
/// SurfaceTree; a first hit here is only placed along the ray, and what lies within a slack
/// of it is gathered with that slack, far above the rounding.
class SurfaceRays {
public:
    explicit SurfaceRays(const Scene& scene);
    ~SurfaceRays();
    SurfaceRays(const SurfaceRays&) = delete;
    SurfaceRays& operator=(const SurfaceRays&) = delete;

    /// Every surface the ray from `from` along `dir` meets where it meets the first, within
    /// `slack` along the ray either side (coincident faces: a box's side flush with a wall),
    /// sorted, each once; empty when it meets none (SurfaceTree::first_hits).
    std::vector<int> first_hits(const glm::dvec3& from, const glm::dvec3& dir, double slack) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace bounce
