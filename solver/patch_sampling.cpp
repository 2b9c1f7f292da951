// SPDX-License-Identifier: MIT
#include "solver/patch_sampling.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace bounce {

glm::dvec3 patch_point(const Patch& p, double u, double v) {
    const auto& c = p.vertices;
    if (p.vertex_count == 4)
        return (1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + u * v * c[2] + (1 - u) * v * c[3];
    const double su = std::sqrt(u);
    return (1 - su) * c[0] + su * (1 - v) * c[1] + su * v * c[2];
}

void patch_quadrature(const Patch& p, int n, std::vector<AreaSample>& out) {
    out.clear();
    const auto& c = p.vertices;
    if (n <= 1) {
        out.push_back({p.centre, 1.0});
        return;
    }
    if (p.vertex_count == 4) {
        double total = 0.0;
        for (int b = 0; b < n; ++b)
            for (int a = 0; a < n; ++a) {
                const double u = (a + 0.5) / n, v = (b + 0.5) / n;
                const glm::dvec3 du = (1 - v) * (c[1] - c[0]) + v * (c[2] - c[3]);
                const glm::dvec3 dv = (1 - u) * (c[3] - c[0]) + u * (c[2] - c[1]);
                const double w = glm::length(glm::cross(du, dv));
                out.push_back({patch_point(p, u, v), w});
                total += w;
            }
        for (auto& s : out) s.weight /= total;
        return;
    }
    const double w = 1.0 / (double(n) * n);
    const glm::dvec3 e1 = (c[1] - c[0]) / double(n), e2 = (c[2] - c[0]) / double(n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; i + j < n; ++j) {
            out.push_back({c[0] + (i + 1.0 / 3) * e1 + (j + 1.0 / 3) * e2, w});
            if (i + j + 1 < n) out.push_back({c[0] + (i + 2.0 / 3) * e1 + (j + 2.0 / 3) * e2, w});
        }
}

}  // namespace bounce
