// SPDX-License-Identifier: MIT
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/patch.h"

namespace bounce {

/// Answers "is the open segment a-b blocked by any patch?". Callers lift the endpoints off
/// their own patches along the normals (by `offset()`), so a ray never hits its own patch or
/// a coplanar neighbour. Implementations are thread-safe for concurrent queries.
class Visibility {
public:
    virtual ~Visibility() = default;
    virtual bool occluded(const glm::dvec3& a, const glm::dvec3& b) const = 0;
    virtual std::string name() const = 0;
    /// Distance to lift ray endpoints off their surfaces: tiny against the scene (1e-6 of its
    /// diagonal), yet far above the rounding error of the coordinates.
    double offset() const { return m_offset; }

protected:
    double m_offset = 0.0;
};

/// CGAL AABB tree of the patches' triangles, queried with exact predicates.
std::unique_ptr<Visibility> make_cgal_visibility(const std::vector<Patch>& patches);

}  // namespace bounce
