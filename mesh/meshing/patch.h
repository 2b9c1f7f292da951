// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"

namespace bounce {

/// One planar element of the radiosity system: a triangle or a quad, constant radiosity over
/// its area. Plain values copied out of the patch mesh so the solver's inner loops touch
/// contiguous memory.
struct Patch {
    std::array<glm::dvec3, 4> vertices{};  // counter-clockwise seen from the front
    int vertex_count = 0;                  // 3 or 4
    glm::dvec3 centre{0.0};                // area centroid
    glm::dvec3 normal{0.0};                // unit, towards the front (the lit side)
    double area = 0.0;                     // scene units squared
    Rgb reflectance;                       // rho in [0,1]
    Rgb emission;                          // E, emitted radiosity
    int surface = 0;                       // index of the input surface it was cut from

    std::span<const glm::dvec3> polygon() const { return {vertices.data(), std::size_t(vertex_count)}; }
    /// Signed height of x above the patch's plane (positive in front).
    double height(const glm::dvec3& x) const { return glm::dot(normal, x - vertices[0]); }
    std::string to_string() const;
};

/// Largest distance of a vertex from the patch's centre: a sphere about the centre with this
/// radius holds the patch (separation tests of form-factor rules).
inline double circumradius(const Patch& p) {
    double r = 0.0;
    for (int k = 0; k < p.vertex_count; ++k) r = std::max(r, glm::length(p.vertices[k] - p.centre));
    return r;
}

/// True when x, projected along p's normal onto its plane, lies within p (p convex): on the
/// inner side of every edge, or outside by at most `slack` in the edge's cross product with
/// x (a length squared; 0: exactly).
inline bool covers(const Patch& p, const glm::dvec3& x, double slack = 0.0) {
    for (int k = 0; k < p.vertex_count; ++k) {
        const glm::dvec3 u = p.vertices[k], w = p.vertices[(k + 1) % p.vertex_count];
        if (glm::dot(glm::cross(w - u, x - u), p.normal) < -slack) return false;
    }
    return true;
}

/// True when no vertex of `q` lies below `p`'s plane (a vertex within 1e-9 sqrt(A_q) of it
/// counts as on it): q is wholly in front of p, so no part of q needs clipping against p.
inline bool wholly_in_front(const Patch& p, const Patch& q) {
    const double below = -1e-9 * std::sqrt(q.area);
    for (int k = 0; k < q.vertex_count; ++k)
        if (p.height(q.vertices[k]) < below) return false;
    return true;
}

/// True when no vertex of `q` is strictly in front of `p`: p cannot send power to q (and, by
/// reciprocity, q none to p). The tolerance absorbs rounding of coplanar neighbours.
inline bool wholly_behind(const Patch& p, const Patch& q) {
    // q's centre is a convex combination of its vertices, so a centre in front means a vertex
    // in front: the common answer without the loop (or the root).
    const double hc = p.height(q.centre);
    if (hc > 0 && hc * hc > 1e-24 * (p.area + q.area)) return false;
    const double tol = 1e-12 * std::sqrt(p.area + q.area);
    for (int k = 0; k < q.vertex_count; ++k)
        if (p.height(q.vertices[k]) > tol) return false;
    return true;
}

}  // namespace bounce
