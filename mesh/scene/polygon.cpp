// SPDX-License-Identifier: MIT
#include "mesh/scene/polygon.h"

#include <cmath>
#include <numeric>

#include <glm/geometric.hpp>

namespace bounce {

glm::dvec3 newell_normal(std::span<const glm::dvec3> poly) {
    glm::dvec3 n(0.0);
    const std::size_t k = poly.size();
    for (std::size_t i = 0; i < k; ++i) {
        const glm::dvec3& a = poly[i];
        const glm::dvec3& b = poly[(i + 1) % k];
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    return n;
}

double polygon_area(std::span<const glm::dvec3> poly) { return 0.5 * glm::length(newell_normal(poly)); }

glm::dvec3 polygon_centroid(std::span<const glm::dvec3> poly) {
    const glm::dvec3 n = newell_normal(poly);
    const double nn = glm::dot(n, n);
    glm::dvec3 c(0.0);
    double w = 0.0;
    for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
        // Signed triangle area along the polygon normal, so concave fans still add up.
        const double a = nn > 0 ? glm::dot(glm::cross(poly[i] - poly[0], poly[i + 1] - poly[0]), n) : 0.0;
        c += a * (poly[0] + poly[i] + poly[i + 1]) / 3.0;
        w += a;
    }
    if (w == 0.0) {
        for (const auto& p : poly) c += p;
        return c / double(poly.size());
    }
    return c / w;
}

std::vector<std::array<int, 3>> triangulate_polygon(std::span<const glm::dvec3> poly) {
    std::vector<std::array<int, 3>> tris;
    const int k = int(poly.size());
    if (k < 3) return tris;
    if (k == 3) return {{0, 1, 2}};
    const glm::dvec3 n = newell_normal(poly);
    std::vector<int> idx(k);
    std::iota(idx.begin(), idx.end(), 0);
    auto convex = [&](int a, int b, int c) {
        return glm::dot(glm::cross(poly[b] - poly[a], poly[c] - poly[b]), n) > 0;
    };
    auto inside = [&](int p, int a, int b, int c) {
        const glm::dvec3 x = poly[p];
        return glm::dot(glm::cross(poly[b] - poly[a], x - poly[a]), n) >= 0 &&
               glm::dot(glm::cross(poly[c] - poly[b], x - poly[b]), n) >= 0 &&
               glm::dot(glm::cross(poly[a] - poly[c], x - poly[c]), n) >= 0;
    };
    int guard = 0;
    while (idx.size() > 3 && guard < 4 * k * k) {
        ++guard;
        bool clipped = false;
        const int m = int(idx.size());
        for (int t = 0; t < m; ++t) {
            const int a = idx[(t + m - 1) % m], b = idx[t], c = idx[(t + 1) % m];
            if (!convex(a, b, c)) continue;
            bool ear = true;
            for (int q : idx) {
                if (q == a || q == b || q == c) continue;
                if (inside(q, a, b, c)) {
                    ear = false;
                    break;
                }
            }
            if (!ear) continue;
            tris.push_back({a, b, c});
            idx.erase(idx.begin() + t);
            clipped = true;
            break;
        }
        // A polygon with no ear is self-intersecting or degenerate: fall back to a fan.
        if (!clipped) break;
    }
    if (idx.size() == 3) {
        tris.push_back({idx[0], idx[1], idx[2]});
    } else {
        for (std::size_t t = 1; t + 1 < idx.size(); ++t) tris.push_back({idx[0], idx[t], idx[t + 1]});
    }
    return tris;
}

}  // namespace bounce
