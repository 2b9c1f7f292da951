// SPDX-License-Identifier: MIT
#include "solver/reference/probe_score.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace bounce {

namespace {

/// The patch whose polygon holds x (projected on its plane), with normal close to n; -1 if none.
int patch_at(const PatchMesh& mesh, const glm::dvec3& x, const glm::dvec3& n, double height_tolerance) {
    const auto& patches = mesh.patches();
    int best = -1;
    double best_height = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < patches.size(); ++i) {
        const Patch& p = patches[i];
        if (glm::dot(p.normal, n) < 0.9) continue;
        const double h = std::abs(p.height(x));
        if (h > height_tolerance || h >= best_height) continue;
        const glm::dvec3 q = x - p.height(x) * p.normal;
        const double scale = std::sqrt(p.area);
        bool inside = true;
        for (int k = 0; k < p.vertex_count && inside; ++k) {
            const glm::dvec3 a = p.vertices[std::size_t(k)], b = p.vertices[std::size_t((k + 1) % p.vertex_count)];
            inside = glm::dot(glm::cross(b - a, q - a), p.normal) >= -1e-9 * scale * glm::length(b - a);
        }
        if (inside) {
            best = int(i);
            best_height = h;
        }
    }
    return best;
}

/// Linear interpolation of vertex values over the fan triangles of patch i (as a renderer
/// draws a polygon cell), at the projection of x.
Rgb interpolate(const PatchMesh& mesh, std::size_t i, const glm::dvec3& x, const std::vector<Rgb>& at_vertex) {
    const Patch& p = mesh.patches()[i];
    const glm::dvec3 q = x - p.height(x) * p.normal;
    const auto ids = mesh.patch_vertex_indices(i);
    const glm::dvec3 a = mesh.vertex_position(std::size_t(ids[0]));
    Rgb nearest = at_vertex[std::size_t(ids[0])];
    double best_outside = std::numeric_limits<double>::infinity();
    for (std::size_t k = 1; k + 1 < ids.size(); ++k) {
        const glm::dvec3 b = mesh.vertex_position(std::size_t(ids[k])),
                         c = mesh.vertex_position(std::size_t(ids[k + 1]));
        const double area = glm::dot(glm::cross(b - a, c - a), p.normal);
        if (!(area > 0)) continue;
        const double wa = glm::dot(glm::cross(b - q, c - q), p.normal) / area;
        const double wb = glm::dot(glm::cross(c - q, a - q), p.normal) / area;
        const double wc = 1 - wa - wb;
        const Rgb value = at_vertex[std::size_t(ids[0])] * wa + at_vertex[std::size_t(ids[k])] * wb +
                          at_vertex[std::size_t(ids[k + 1])] * wc;
        const double outside = std::max({0.0, -wa, -wb, -wc});
        if (outside == 0) return value;
        if (outside < best_outside) {  // rounding at a fan edge: the triangle it is nearest to
            best_outside = outside;
            nearest = value;
        }
    }
    return nearest;
}

}  // namespace

ProbeScore score_at_probes(const PatchMesh& mesh, std::span<const Rgb> patch_radiosity,
                           std::span<const ReferencePoint> reference, std::span<const Rgb> point_values) {
    ProbeScore s;
    const auto at_vertex =
        point_values.size() == mesh.mesh().n_vertices()
            ? std::vector<Rgb>(point_values.begin(), point_values.end())
            : area_weighted_vertex_values(mesh, std::vector<Rgb>(patch_radiosity.begin(), patch_radiosity.end()));
    // Scene size from the patches' extent, for the on-plane tolerance.
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const auto& p : mesh.patches())
        for (int k = 0; k < p.vertex_count; ++k) {
            lo = glm::min(lo, p.vertices[std::size_t(k)]);
            hi = glm::max(hi, p.vertices[std::size_t(k)]);
        }
    const double tolerance = 0.005 * glm::length(hi - lo);  // the reference's snap distance

    std::vector<double> lum;
    for (const auto& r : reference)
        if (r.has_value) lum.push_back(r.radiosity.luminance());
    std::sort(lum.begin(), lum.end());
    const double dark = lum.empty() ? 0.0 : 1e-3 * lum[lum.size() / 2];

    double sum_patch = 0, sum_smooth = 0, sum_noise = 0;
    Rgb sum_patch_c, sum_smooth_c;
    Rgb count_c;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const auto& r : reference) {
        s.patch_error.push_back(nan);
        s.smooth_error.push_back(nan);
        const double ref = r.radiosity.luminance();
        if (!r.has_value || !(ref > dark)) {
            ++s.skipped;
            continue;
        }
        const int i = patch_at(mesh, r.position, r.normal, tolerance);
        if (i < 0) {
            ++s.skipped;
            continue;
        }
        const Rgb patch = patch_radiosity[std::size_t(i)];
        const Rgb smooth = interpolate(mesh, std::size_t(i), r.position, at_vertex);
        s.patch_error.back() = (patch.luminance() - ref) / ref;
        s.smooth_error.back() = (smooth.luminance() - ref) / ref;
        const double ep = std::abs(s.patch_error.back()), es = std::abs(s.smooth_error.back());
        sum_patch += ep * ep;
        sum_smooth += es * es;
        s.max_patch = std::max(s.max_patch, ep);
        s.max_smooth = std::max(s.max_smooth, es);
        const double noise = r.standard_error.luminance() / ref;
        sum_noise += noise * noise;
        for (int c = 0; c < 3; ++c) {
            if (!(r.radiosity[c] > dark)) continue;
            const double pc = (patch[c] - r.radiosity[c]) / r.radiosity[c];
            const double sc = (smooth[c] - r.radiosity[c]) / r.radiosity[c];
            sum_patch_c[c] += pc * pc;
            sum_smooth_c[c] += sc * sc;
            count_c[c] += 1;
        }
        ++s.scored;
    }
    if (s.scored) {
        const double n = double(s.scored);
        s.rms_patch = std::sqrt(sum_patch / n);
        s.rms_smooth = std::sqrt(sum_smooth / n);
        s.reference_noise = std::sqrt(sum_noise / n);
        for (int c = 0; c < 3; ++c)
            if (count_c[c] > 0) {
                s.rms_patch_channel[c] = std::sqrt(sum_patch_c[c] / count_c[c]);
                s.rms_smooth_channel[c] = std::sqrt(sum_smooth_c[c] / count_c[c]);
            }
    }
    return s;
}

}  // namespace bounce
