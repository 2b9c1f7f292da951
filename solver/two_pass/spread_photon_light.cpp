// SPDX-License-Identifier: MIT
#include "solver/two_pass/spread_photon_light.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

namespace bounce {
namespace {

constexpr int kRings = 4, kSpokes = 8;  // points over the disc that sample its share on the surface
constexpr double kLeastShare = 0.25;    // below this the disc is mostly off the surface: no further boost

/// The cone-weighted share of the disc of radius r about x (normal n) that lies on a patch
/// facing like n: each sample point is lifted off the plane a little and a ray sent back.
double share_on_surface(const PatchSceneTracer& tracer, const glm::dvec3& x, const glm::dvec3& n, double r) {
    const glm::dvec3 t = glm::normalize(glm::cross(std::abs(n.x) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0), n));
    const glm::dvec3 b = glm::cross(n, t);
    const double lift = 10 * tracer.epsilon();
    double on = 0, all = 0;
    for (int i = 0; i < kRings; ++i) {
        const double rho = (i + 0.5) / kRings * r;
        const double w = (1 - rho / r) * rho;  // the cone filter times the ring's length
        for (int j = 0; j < kSpokes; ++j) {
            // Turned off the axes and diagonals, so that no point lies on the straight edge
            // through x of a patch grid, which a ray may hit or miss by rounding.
            const double phi = 2 * std::numbers::pi * (j + 0.25 + 0.5 * (i % 2)) / kSpokes;
            const glm::dvec3 p = x + rho * (std::cos(phi) * t + std::sin(phi) * b);
            const auto hit = tracer.trace(p + lift * n, -n);
            const bool on_surface =
                hit.kind == PatchSceneTracer::Hit::Kind::patch && hit.t < 2 * lift && glm::dot(hit.normal, n) >= 0.9;
            all += w;
            on += on_surface ? w : 0.0;
        }
    }
    return all > 0 ? on / all : 1.0;
}

}  // namespace

std::vector<Rgb> spread_photon_light(const CausticMap& map, const PatchMesh& mesh, const PatchSceneTracer& tracer) {
    const auto& P = mesh.patches();
    std::vector<int> cell(mesh.mesh().n_vertices(), -1);  // a cell around each vertex
    for (std::size_t c = 0; c < P.size(); ++c)
        for (const int v : mesh.patch_vertex_indices(c))
            if (v >= 0 && std::size_t(v) < cell.size() && cell[std::size_t(v)] < 0) cell[std::size_t(v)] = int(c);
    std::vector<Rgb> out(cell.size());
    tbb::parallel_for(std::size_t(0), cell.size(), [&](std::size_t v) {
        if (cell[v] < 0) return;
        const Patch& p = P[std::size_t(cell[v])];
        const glm::dvec3 x = mesh.vertex_position(v);
        double r = 0;
        const Rgb E = map.irradiance(x, p.normal, &r);
        if (!(E.max() > 0)) return;
        out[v] = p.reflectance * E * (1.0 / std::max(kLeastShare, share_on_surface(tracer, x, p.normal, r)));
    });
    return out;
}

}  // namespace bounce
