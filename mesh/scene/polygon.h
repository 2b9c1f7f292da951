// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce {

/// Area-weighted normal of a planar or nearly planar polygon by Newell's method; its length
/// is twice the polygon's area. Counter-clockwise vertices give a normal towards the viewer.
glm::dvec3 newell_normal(std::span<const glm::dvec3> poly);

/// Area of a planar polygon (half the length of the Newell normal).
double polygon_area(std::span<const glm::dvec3> poly);

/// Centroid of a planar polygon (area-weighted, by a triangle fan).
glm::dvec3 polygon_centroid(std::span<const glm::dvec3> poly);

/// Triangulates a simple planar polygon (convex or not) by ear clipping; returns index
/// triples into poly, each counter-clockwise like the polygon.
std::vector<std::array<int, 3>> triangulate_polygon(std::span<const glm::dvec3> poly);

}  // namespace bounce
