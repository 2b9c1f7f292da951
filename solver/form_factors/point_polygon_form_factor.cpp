// SPDX-License-Identifier: MIT
#include "solver/form_factors/point_polygon_form_factor.h"

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>

namespace bounce {

double point_polygon_form_factor(const glm::dvec3& p, const glm::dvec3& n, std::span<const glm::dvec3> polygon) {
    // Sutherland-Hodgman clip against the tangent plane; small fixed buffer, no allocation
    // for triangles and quads (a clipped convex k-gon has at most k+1 vertices).
    const std::size_t k = polygon.size();
    std::array<glm::dvec3, 16> local;
    std::vector<glm::dvec3> heap;
    glm::dvec3* out = local.data();
    if (k + 1 > local.size()) {
        heap.resize(2 * k);
        out = heap.data();
    }
    std::size_t m = 0;
    bool all_above = true;
    for (std::size_t i = 0; i < k; ++i)
        if (glm::dot(n, polygon[i] - p) < 0) {
            all_above = false;
            break;
        }
    if (all_above) {
        for (std::size_t i = 0; i < k; ++i) out[m++] = polygon[i] - p;
    } else {
        for (std::size_t i = 0; i < k; ++i) {
            const glm::dvec3 a = polygon[i] - p, b = polygon[(i + 1) % k] - p;
            const double da = glm::dot(n, a), db = glm::dot(n, b);
            if (da >= 0) out[m++] = a;
            if ((da >= 0) != (db >= 0)) out[m++] = a + (da / (da - db)) * (b - a);
        }
    }
    if (m < 3) return 0.0;
    double sum = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
        const glm::dvec3& a = out[i];
        const glm::dvec3& b = out[(i + 1) % m];
        const glm::dvec3 c = glm::cross(a, b);
        const double cl = glm::length(c);
        if (cl == 0.0) continue;
        const double angle = std::atan2(cl, glm::dot(a, b));
        sum += angle * glm::dot(n, c) / cl;
    }
    return std::abs(sum) / (2.0 * std::numbers::pi);
}

}  // namespace bounce
