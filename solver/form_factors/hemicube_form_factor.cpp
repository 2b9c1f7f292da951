// SPDX-License-Identifier: MIT
#include "solver/form_factors/hemicube_form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "solver/form_factors/patch_sampling.h"

namespace bounce {
namespace {

using V = glm::dvec3;

/// One face of the hemicube: pixel directions w = d + x a1 + y a2 with x in [-1,1] and y in
/// [ylo, 1] (ylo = -1 for the top, 0 for the sides, which keep only the half above the plane).
struct CubeFace {
    V d, a1, a2;
    double ylo;
};

}  // namespace

HemicubeFormFactor::HemicubeFormFactor(const std::vector<Patch>& patches, const FormFactorOptions& options)
    : m_patches(patches), m_options(options) {
    if (options.hemicube_exact_kernel) m_unoccluded.emplace(patches, options.unoccluded_tolerance);
    const int r = options.hemicube_resolution;
    if (r < 2 || r > 4096 || r % 2) throw std::invalid_argument("hemicube resolution must be even, 2..4096");
    const double h = 2.0 / r, da = h * h, pi = std::numbers::pi;
    m_top_delta.resize(std::size_t(r) * r);
    m_side_delta.resize(std::size_t(r) * (r / 2));
    for (int b = 0; b < r; ++b)
        for (int a = 0; a < r; ++a) {
            const double x = -1 + (a + 0.5) * h, y = -1 + (b + 0.5) * h, q = 1 + x * x + y * y;
            m_top_delta[std::size_t(b) * r + a] = da / (pi * q * q);
        }
    for (int b = 0; b < r / 2; ++b)
        for (int a = 0; a < r; ++a) {
            const double x = -1 + (a + 0.5) * h, z = (b + 0.5) * h, q = 1 + x * x + z * z;
            m_side_delta[std::size_t(b) * r + a] = z * da / (pi * q * q);
        }
    V lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const auto& p : patches)
        for (int k = 0; k < p.vertex_count; ++k) {
            lo = glm::min(lo, p.vertices[k]);
            hi = glm::max(hi, p.vertices[k]);
        }
    m_eps = patches.empty() ? 0.0 : 1e-6 * glm::length(hi - lo);
}

void HemicubeFormFactor::compute_row(std::size_t i, std::span<float> row) const {
    const int r = m_options.hemicube_resolution;
    const Patch& s = m_patches[i];
    const V n = s.normal;
    V t = std::abs(n.x) < 0.9 ? glm::normalize(glm::cross(n, V(1, 0, 0))) : glm::normalize(glm::cross(n, V(0, 1, 0)));
    if (m_options.hemicube_jitter) {
        SplitMix64 rng{m_options.seed * 0xD1B54A32D192ED03ull ^ std::uint64_t(i)};
        const double angle = 2 * std::numbers::pi * rng.uniform();
        t = std::cos(angle) * t + std::sin(angle) * glm::cross(n, t);
    }
    const V b = glm::cross(n, t);
    const std::array<CubeFace, 5> faces = {
        {{n, t, b, -1.0}, {t, b, n, 0.0}, {-t, b, n, 0.0}, {b, t, n, 0.0}, {-b, t, n, 0.0}}};
    const V eye = s.centre + m_eps * n;

    thread_local std::vector<double> depth;
    thread_local std::vector<int> item;
    std::vector<double> f(m_patches.size(), 0.0);
    std::vector<double> covered(m_unoccluded ? m_patches.size() : 0, 0.0);  // pixels of j, hidden or not
    const bool strict = m_unoccluded.has_value();
    for (int fi = 0; fi < 5; ++fi) {
        const CubeFace& face = faces[fi];
        const int rows = fi == 0 ? r : r / 2;
        const std::vector<double>& delta = fi == 0 ? m_top_delta : m_side_delta;
        const double h = 2.0 / r;
        depth.assign(std::size_t(r) * rows, std::numeric_limits<double>::infinity());
        item.assign(std::size_t(r) * rows, -1);
        for (std::size_t j = 0; j < m_patches.size(); ++j) {
            if (j == i) continue;
            const Patch& p = m_patches[j];
            // Camera coordinates, then clip to the near plane z >= zn (Sutherland-Hodgman).
            std::array<V, 4> cam;
            bool any_front = false;
            for (int k = 0; k < p.vertex_count; ++k) {
                const V q = p.vertices[k] - eye;
                cam[k] = V(glm::dot(face.a1, q), glm::dot(face.a2, q), glm::dot(face.d, q));
                any_front |= cam[k].z > 0;
            }
            if (!any_front) continue;
            const double zn = 1e-9 * m_eps + 1e-300;
            std::array<V, 8> clip;
            int m = 0;
            for (int k = 0; k < p.vertex_count; ++k) {
                const V a = cam[k], c = cam[(k + 1) % p.vertex_count];
                if (a.z >= zn) clip[m++] = a;
                if ((a.z >= zn) != (c.z >= zn)) clip[m++] = a + ((zn - a.z) / (c.z - a.z)) * (c - a);
            }
            if (m < 3) continue;
            std::array<double, 8> X, Y;
            double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
            for (int k = 0; k < m; ++k) {
                X[k] = clip[k].x / clip[k].z;
                Y[k] = clip[k].y / clip[k].z;
                x0 = std::min(x0, X[k]);
                x1 = std::max(x1, X[k]);
                y0 = std::min(y0, Y[k]);
                y1 = std::max(y1, Y[k]);
            }
            if (x1 < -1 || x0 > 1 || y1 < face.ylo || y0 > 1) continue;
            // Vertices near the eye's plane project far out; clamp before converting to int.
            x0 = std::max(x0, -2.0);
            x1 = std::min(x1, 2.0);
            y0 = std::max(y0, -2.0);
            y1 = std::min(y1, 2.0);
            // Pixel range whose centres fall in the bounding box.
            const int ax0 = std::max(0, int(std::ceil((x0 + 1) / h - 0.5)));
            const int ax1 = std::min(r - 1, int(std::floor((x1 + 1) / h - 0.5)));
            const int by0 = std::max(0, int(std::ceil((y0 - face.ylo) / h - 0.5)));
            const int by1 = std::min(rows - 1, int(std::floor((y1 - face.ylo) / h - 0.5)));
            if (ax0 > ax1 || by0 > by1) continue;
            double area2 = 0;
            for (int k = 0; k < m; ++k) area2 += X[k] * Y[(k + 1) % m] - X[(k + 1) % m] * Y[k];
            const double orient = area2 >= 0 ? 1.0 : -1.0;
            // Depth along the pixel direction w: t = n_j . (v0 - eye) / n_j . w.
            const V nj(glm::dot(face.a1, p.normal), glm::dot(face.a2, p.normal), glm::dot(face.d, p.normal));
            const double num = glm::dot(nj, cam[0]);
            // A patch seen from behind still occludes, but receives nothing (one-sided).
            const int id = num < 0 ? int(j) : -2;
            for (int by = by0; by <= by1; ++by) {
                const double y = face.ylo + (by + 0.5) * h;
                for (int ax = ax0; ax <= ax1; ++ax) {
                    const double x = -1 + (ax + 0.5) * h;
                    bool inside = true;
                    for (int k = 0; k < m && inside; ++k) {
                        const int l = (k + 1) % m;
                        const double side = orient * ((X[l] - X[k]) * (y - Y[k]) - (Y[l] - Y[k]) * (x - X[k]));
                        // With the seen share, a pixel centre on an edge two patches share must
                        // belong to neither, or one of them would seem partly hidden.
                        inside = strict ? side > 0 : side >= 0;
                    }
                    if (!inside) continue;
                    const double den = nj.x * x + nj.y * y + nj.z;
                    const double dist = den != 0 ? num / den : 0.0;
                    const std::size_t px = std::size_t(by) * r + ax;
                    if (dist > 0 && id >= 0 && !covered.empty()) covered[j] += delta[px];
                    if (dist > 0 && dist < depth[px]) {
                        depth[px] = dist;
                        item[px] = id;
                    }
                }
            }
        }
        for (std::size_t px = 0; px < item.size(); ++px)
            if (item[px] >= 0) f[item[px]] += delta[px];
    }
    if (m_unoccluded) {
        // Baum, Rushmeier and Winget (1989): the pixels only decide how much of j the centre
        // sees, the visible share of j's own pixels (both sums alias alike, so an unhidden patch
        // has exactly 1); the unoccluded factor over both patches decides the amount. A patch
        // no pixel centre falls on is taken as seen: the pixels cannot tell.
        for (std::size_t j = 0; j < row.size(); ++j) {
            if (j == i) continue;
            const double seen = covered[j] > 0.0 ? f[j] / covered[j] : 1.0;
            f[j] = seen > 0.0 ? (*m_unoccluded)(i, j) * seen : 0.0;
        }
    }
    for (std::size_t j = 0; j < row.size(); ++j) row[j] = float(f[j]);
}

}  // namespace bounce
