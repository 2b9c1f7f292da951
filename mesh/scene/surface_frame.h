// SPDX-License-Identifier: MIT
#pragma once

#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace bounce {

/// The plane geometry discontinuity meshing shares between tracing boundaries
/// (trace_discontinuities) and triangulating surfaces along them (triangulate_surface).
namespace discontinuity {

using V = glm::dvec3;
using P2 = glm::dvec2;

/// A surface's plane with an orthonormal frame: e1, e2, normal right-handed, so counter-clockwise
/// in (e1, e2) is counter-clockwise seen from the front.
struct Frame {
    V origin{0.0}, e1{0.0}, e2{0.0}, normal{0.0};
    double area = 0.0;
    bool valid = false;
    double height(const V& x) const { return glm::dot(normal, x - origin); }
    P2 to2(const V& x) const { return {glm::dot(x - origin, e1), glm::dot(x - origin, e2)}; }
    V to3(const P2& p) const { return origin + p.x * e1 + p.y * e2; }
};

/// The frame of a planar polygon: its centroid as origin, its longest edge as e1 (well defined
/// for slivers too); not valid for fewer than 3 points or no area.
Frame frame_of(const std::vector<V>& poly);

inline double cross2(const P2& a, const P2& b) { return a.x * b.y - a.y * b.x; }

/// Whether p is inside `poly` (even-odd rule).
bool inside_polygon(const P2& p, const std::vector<P2>& poly);

/// The parameter intervals of segment a + t (b - a), t in [0, 1], inside `poly` (any simple
/// polygon): the segment is cut where it crosses an edge and each piece is classified by its
/// midpoint.
std::vector<std::pair<double, double>> inside_intervals(const P2& a, const P2& b, const std::vector<P2>& poly);

/// Removes from `intervals` the part of the segment inside convex `hole` (counter-clockwise).
void subtract_convex_interval(std::vector<std::pair<double, double>>& intervals, const P2& a, const P2& b,
                              const std::vector<P2>& hole);

}  // namespace discontinuity
}  // namespace bounce
