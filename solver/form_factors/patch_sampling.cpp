// SPDX-License-Identifier: MIT
#include "solver/form_factors/patch_sampling.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace bounce {

std::array<double, 4> patch_point_weights(const Patch& p, double u, double v) {
    if (p.vertex_count == 4) return {(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v};
    const double su = std::sqrt(u);
    return {1 - su, su * (1 - v), su * v, 0.0};
}

glm::dvec3 patch_point(const Patch& p, double u, double v) {
    const auto& c = p.vertices;
    const std::array<double, 4> w = patch_point_weights(p, u, v);
    if (p.vertex_count == 4) return w[0] * c[0] + w[1] * c[1] + w[2] * c[2] + w[3] * c[3];
    return w[0] * c[0] + w[1] * c[1] + w[2] * c[2];
}

namespace {

/// Gauss-Legendre nodes and weights on [0,1] for n = 1..kMaxGaussPoints, computed once by
/// Newton's method on the Legendre recurrence.
constexpr int kMaxGaussPoints = 16;
struct GaussTable {
    double x[kMaxGaussPoints + 1][kMaxGaussPoints];
    double w[kMaxGaussPoints + 1][kMaxGaussPoints];
    GaussTable() {
        for (int n = 1; n <= kMaxGaussPoints; ++n)
            for (int i = 0; i < n; ++i) {
                double z = std::cos(3.14159265358979323846 * (i + 0.75) / (n + 0.5)), dp = 1;
                for (int it = 0; it < 100; ++it) {
                    double p0 = 1, p1 = z;
                    for (int k = 2; k <= n; ++k) {
                        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                        p0 = p1;
                        p1 = p2;
                    }
                    dp = n * (z * p1 - p0) / (z * z - 1);
                    const double dz = p1 / dp;
                    z -= dz;
                    if (std::abs(dz) < 1e-16) break;
                }
                x[n][i] = 0.5 * (1 - z);
                w[n][i] = 1.0 / ((1 - z * z) * dp * dp);
            }
    }
};
const GaussTable& gauss() {
    static const GaussTable table;
    return table;
}

}  // namespace

void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
    n = std::clamp(n, 1, kMaxGaussPoints);
    const auto& g = gauss();
    x.assign(g.x[n], g.x[n] + n);
    w.resize(n);
    for (int i = 0; i < n; ++i) w[i] = g.w[n][i];  // already for [0,1]: 1/((1-z^2) P_n'(z)^2)
}

void patch_quadrature(const Patch& p, int n, std::vector<AreaSample>& out) {
    out.clear();
    if (n <= 1) {
        out.push_back({p.centre, 1.0});
        return;
    }
    n = std::min(n, kMaxGaussPoints);
    const auto& g = gauss();
    const auto& c = p.vertices;
    double total = 0.0;
    for (int b = 0; b < n; ++b)
        for (int a = 0; a < n; ++a) {
            const double u = g.x[n][a], v = g.x[n][b];
            double jac;
            glm::dvec3 x;
            if (p.vertex_count == 4) {
                // Bilinear map of the unit square; its Jacobian weights the points.
                const glm::dvec3 du = (1 - v) * (c[1] - c[0]) + v * (c[2] - c[3]);
                const glm::dvec3 dv = (1 - u) * (c[3] - c[0]) + u * (c[2] - c[1]);
                jac = glm::length(glm::cross(du, dv));
                x = (1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + u * v * c[2] + (1 - u) * v * c[3];
            } else {
                // Collapsed square (Duffy): x = (1-u) c0 + u (1-v) c1 + u v c2, Jacobian ~ u.
                jac = u;
                x = (1 - u) * c[0] + u * (1 - v) * c[1] + u * v * c[2];
            }
            const double w = g.w[n][a] * g.w[n][b] * jac;
            out.push_back({x, w});
            total += w;
        }
    for (auto& s : out) s.weight /= total;
}

}  // namespace bounce
