// SPDX-License-Identifier: MIT
#include "mesh/geometry/geometry_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <set>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <glm/geometric.hpp>

#include "mesh/scene/input_error.h"
#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

/// "0.19% of the face's longest edge": how far off relative to the face's size.
std::string percent_of(double dev, double size) {
    char text[64];
    std::snprintf(text, sizeof text, "%.2g%% of its longest edge", 100.0 * dev / size);
    return text;
}

K::Point_3 to_cgal(const glm::dvec3& p) { return {p.x, p.y, p.z}; }

/// True when every vertex lies on one line (exact predicate, so no tolerance to tune).
bool all_collinear(const std::vector<glm::dvec3>& poly) {
    for (std::size_t i = 2; i < poly.size(); ++i)
        for (std::size_t j = 1; j < i; ++j)
            if (!CGAL::collinear(to_cgal(poly[0]), to_cgal(poly[j]), to_cgal(poly[i]))) return false;
    return true;
}

/// Warns about faces whose interiors cross each other (a self-intersecting model): a light
/// leak for the solver, since each face sees through the other. Faces that only touch (a
/// block standing on a floor, walls meeting at a corner) are fine; coplanar faces are not
/// checked. A crossing is a pair of triangles, each with vertices strictly on both sides of
/// the other's plane (exact predicates), that intersect.
void report_crossings(Scene& scene) {
    using Triangles = std::vector<K::Triangle_3>;
    using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
    using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
    Triangles tris;
    std::vector<std::size_t> owner;
    for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
        const auto& poly = scene.surfaces[s].vertices;
        for (const auto& t : triangulate_polygon(poly)) {
            tris.emplace_back(to_cgal(poly[t[0]]), to_cgal(poly[t[1]]), to_cgal(poly[t[2]]));
            owner.push_back(s);
        }
    }
    if (tris.size() < 2) return;
    Tree tree(tris.cbegin(), tris.cend());
    tree.build();
    // Crossing by less than 0.1% of the faces' size is rounding of the input (the published
    // Cornell walls are off plane by a millimetre), not a modelling error.
    auto straddles = [](const K::Triangle_3& plane_of, const K::Triangle_3& t) {
        bool pos = false, neg = false;
        for (int k = 0; k < 3; ++k) {
            const auto o = CGAL::orientation(plane_of[0], plane_of[1], plane_of[2], t[k]);
            pos |= o == CGAL::POSITIVE;
            neg |= o == CGAL::NEGATIVE;
        }
        if (!(pos && neg)) return false;
        const glm::dvec3 a(plane_of[0].x(), plane_of[0].y(), plane_of[0].z());
        const glm::dvec3 n =
            glm::normalize(glm::cross(glm::dvec3(plane_of[1].x(), plane_of[1].y(), plane_of[1].z()) - a,
                                      glm::dvec3(plane_of[2].x(), plane_of[2].y(), plane_of[2].z()) - a));
        double above = 0, below = 0, size = 0;
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 p(t[k].x(), t[k].y(), t[k].z());
            const double h = glm::dot(p - a, n);
            above = std::max(above, h);
            below = std::max(below, -h);
            size = std::max({size, std::sqrt(CGAL::to_double(CGAL::squared_distance(t[k], t[(k + 1) % 3]))),
                             std::sqrt(CGAL::to_double(CGAL::squared_distance(plane_of[k], plane_of[(k + 1) % 3])))});
        }
        return std::min(above, below) > 1e-3 * size;
    };
    std::set<std::pair<std::size_t, std::size_t>> reported;
    std::vector<Triangles::const_iterator> hits;
    for (std::size_t i = 0; i < tris.size(); ++i) {
        hits.clear();
        tree.all_intersected_primitives(tris[i], std::back_inserter(hits));
        for (auto it : hits) {
            const std::size_t j = std::size_t(it - tris.cbegin());
            if (owner[j] <= owner[i]) continue;
            if (!straddles(tris[i], tris[j]) || !straddles(tris[j], tris[i])) continue;
            if (!reported.insert({owner[i], owner[j]}).second) continue;
            const auto& a = scene.surfaces[owner[i]];
            const auto& b = scene.surfaces[owner[j]];
            if (reported.size() <= 20)
                scene.warnings.push_back(describe(a.where, a.object) + ": face crosses the face at " +
                                         describe(b.where, b.object) + ", a self-intersection");
        }
    }
    if (reported.size() > 20)
        scene.warnings.push_back(std::to_string(reported.size()) + " pairs of crossing faces in all (first 20 shown)");
}

}  // namespace

void check_geometry(Scene& scene, const std::string& source) {
    std::vector<Surface> kept;
    kept.reserve(scene.surfaces.size());
    for (auto& s : scene.surfaces) {
        const std::string where = describe(s.where, s.object);
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
                                         length_text(dev, scene.units) + ", " + percent_of(dev, size) +
                                         ") split into triangles");
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
                scene.warnings.push_back(where + ": face off its plane by " + length_text(dev, scene.units) + " (" +
                                         percent_of(dev, size) + "); flattened onto its mean plane");
            for (auto& v : s.vertices) v -= glm::dot(v - c, n) * n;
        }
        kept.push_back(std::move(s));
    }
    scene.surfaces = std::move(kept);
    report_crossings(scene);
    if (scene.surfaces.empty()) throw InputError(source + ": the scene has no usable faces (empty scene)");
}

}  // namespace bounce
