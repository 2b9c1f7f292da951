// SPDX-License-Identifier: MIT
#pragma once

#include <span>

#include <glm/vec3.hpp>

namespace bounce {

/// Exact, unoccluded form factor from a differential area at p with unit normal n to a planar
/// polygon (Lambert's formula, as used by Baum, Rushmeier and Winget 1989):
///
///     F(dA -> P) = 1/(2 pi) * | sum_k  angle_k * n . (R_k x R_k+1) / |R_k x R_k+1| |
///
/// R_k: vectors from p to the vertices, angle_k: the angle between R_k and R_k+1. The polygon
/// is first clipped to the hemisphere above p (n . (x - p) >= 0), so a polygon that straddles
/// the tangent plane counts only the part p can see. Whether the polygon faces p is the
/// caller's test (a one-sided emitter sends nothing backwards).
double point_polygon_form_factor(const glm::dvec3& p, const glm::dvec3& n, std::span<const glm::dvec3> polygon);

}  // namespace bounce
