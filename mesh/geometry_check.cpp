// SPDX-License-Identifier: MIT
#include "mesh/geometry_check.h"

#include <algorithm>
#include <cmath>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <glm/geometric.hpp>

#include "mesh/input_error.h"
#include "mesh/polygon.h"

namespace bounce {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

K::Point_3 to_cgal(const glm::dvec3& p) { return {p.x, p.y, p.z}; }

/// True when every vertex lies on one line (exact predicate, so no tolerance to tune).
bool all_collinear(const std::vector<glm::dvec3>& poly) {
    for (std::size_t i = 2; i < poly.size(); ++i)
        for (std::size_t j = 1; j < i; ++j)
            if (!CGAL::collinear(to_cgal(poly[0]), to_cgal(poly[j]), to_cgal(poly[i]))) return false;
    return true;
}

}  // namespace

void check_geometry(Scene& scene, const std::string& source) {
    std::vector<Surface> kept;
    kept.reserve(scene.surfaces.size());
    for (auto& s : scene.surfaces) {
        const std::string where = s.where.to_string() + (s.object.empty() ? "" : " (" + s.object + ")");
        // Consecutive duplicate vertices carry no edge; remove them first.
        std::vector<glm::dvec3> poly;
        for (const auto& v : s.vertices)
            if (poly.empty() || v != poly.back()) poly.push_back(v);
        while (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
        double size = 0.0;
        for (std::size_t i = 0; i < poly.size(); ++i)
            size = std::max(size, glm::length(poly[i] - poly[(i + 1) % poly.size()]));
        const double area = poly.size() >= 3 ? polygon_area(poly) : 0.0;
        if (poly.size() < 3 || all_collinear(poly) || !(area > 1e-12 * size * size)) {
            scene.warnings.push_back(where + ": degenerate face (zero area) dropped");
            continue;
        }
        s.vertices = poly;
        if (poly.size() > 3) {
            const glm::dvec3 n = glm::normalize(newell_normal(poly));
            const glm::dvec3 c = polygon_centroid(poly);
            double dev = 0.0;
            for (const auto& v : poly) dev = std::max(dev, std::abs(glm::dot(v - c, n)));
            if (dev > 1e-2 * size) {
                scene.warnings.push_back(where + ": non-planar face (off its plane by " +
                                         std::to_string(dev) + ") split into triangles");
                for (const auto& t : triangulate_polygon(poly)) {
                    Surface part = s;
                    part.vertices = {poly[t[0]], poly[t[1]], poly[t[2]]};
                    if (polygon_area(part.vertices) > 1e-12 * size * size) kept.push_back(std::move(part));
                }
                continue;
            }
            // Close to planar: project onto the mean plane, so patches tile the face exactly
            // and its area is one number. Beyond rounding-level deviations, say so.
            if (dev > 1e-3 * size)
                scene.warnings.push_back(where + ": face off its plane by " + std::to_string(dev) +
                                         "; flattened onto its mean plane");
            for (auto& v : s.vertices) v -= glm::dot(v - c, n) * n;
        }
        kept.push_back(std::move(s));
    }
    scene.surfaces = std::move(kept);
    if (scene.surfaces.empty())
        throw InputError(source + ": the scene has no usable faces (empty scene)");
}

}  // namespace bounce
