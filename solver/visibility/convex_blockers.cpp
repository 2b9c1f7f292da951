// SPDX-License-Identifier: MIT
#include "solver/visibility/convex_blockers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <glm/geometric.hpp>

namespace bounce {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Hull = CGAL::Surface_mesh<Point>;

struct UnionFind {
    std::vector<std::uint32_t> parent;
    explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t a) {
        while (parent[a] != a) a = parent[a] = parent[parent[a]];
        return a;
    }
    void join(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

struct Plane {
    glm::dvec3 n;
    double d;  // n . x = d
};

bool same_plane(const Plane& a, const Plane& b, double tol) {
    return glm::dot(a.n, b.n) > 1.0 - 1e-9 && std::abs(a.d - b.d) <= tol;
}

glm::dvec3 to_glm(const Point& p) { return {p.x(), p.y(), p.z()}; }

/// Two unit vectors that span the plane with unit normal m (with m, a right-handed frame).
std::pair<glm::dvec3, glm::dvec3> plane_basis(const glm::dvec3& m) {
    const glm::dvec3 u =
        glm::normalize(std::abs(m.x) < 0.9 ? glm::cross(m, glm::dvec3(1, 0, 0)) : glm::cross(m, glm::dvec3(0, 1, 0)));
    return {u, glm::cross(m, u)};
}

/// Twice the signed area of the triangle a, b, c in the plane (positive: counter-clockwise).
double turn(const std::array<double, 2>& a, const std::array<double, 2>& b, const std::array<double, 2>& c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/// The convex hull of the points p in the plane (Andrew's monotone chain): their indices
/// counter-clockwise in `hull`, collinear points dropped; empty when fewer than 3 distinct
/// corners. `order` is scratch space.
void convex_hull_2d(const std::vector<std::array<double, 2>>& p, std::vector<std::uint32_t>& order,
                    std::vector<std::uint32_t>& hull) {
    hull.clear();
    if (p.size() < 3) return;
    order.resize(p.size());
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return p[a] < p[b]; });
    hull.assign(2 * p.size(), 0);
    std::size_t k = 0;
    for (std::size_t i = 0; i < order.size(); ++i) {
        while (k >= 2 && turn(p[hull[k - 2]], p[hull[k - 1]], p[order[i]]) <= 0.0) --k;
        hull[k++] = order[i];
    }
    for (std::size_t i = order.size() - 1, lower = k + 1; i-- > 0;) {
        while (k >= lower && turn(p[hull[k - 2]], p[hull[k - 1]], p[order[i]]) <= 0.0) --k;
        hull[k++] = order[i];
    }
    hull.resize(k < 4 ? 0 : k - 1);  // the last repeats the first
}

/// A surface cut into several patches on one plane, which tile a convex polygon without holes:
/// its outline as a flat solid (corners counter-clockwise about the plane's normal, edges round
/// them), or false.
bool make_flat(const Plane& plane, const std::vector<glm::dvec3>& points, double member_area,
               ConvexBlockers::Solid& out) {
    const auto [u, v] = plane_basis(plane.n);
    std::vector<std::array<double, 2>> p2(points.size());
    for (std::size_t k = 0; k < points.size(); ++k) p2[k] = {glm::dot(points[k], u), glm::dot(points[k], v)};
    std::vector<std::uint32_t> order, hull;
    convex_hull_2d(p2, order, hull);  // a tiled edge's inner vertices are dropped as collinear
    if (hull.empty()) return false;
    double area = 0.0;
    for (std::size_t i = 0; i < hull.size(); ++i)
        area += 0.5 * turn(p2[hull[0]], p2[hull[i]], p2[hull[(i + 1) % hull.size()]]);
    // The members cover the outline: no hole, no notch (a contact cut's missing piece).
    if (!(area > 0.0) || std::abs(member_area - area) > 1e-6 * area) return false;
    for (std::size_t i = 0; i < hull.size(); ++i) {
        out.corners.push_back(points[hull[i]]);
        out.edges.emplace_back(std::uint32_t(i), std::uint32_t((i + 1) % hull.size()));
    }
    out.flat = true;
    return true;
}

/// The solid the members form, or false (see ConvexBlockers).
bool make_solid(const std::vector<Patch>& patches, const std::vector<std::uint32_t>& members,
                const std::vector<std::uint8_t>& is_member, double tol, bool flat, ConvexBlockers::Solid& out) {
    std::vector<Plane> planes;  // distinct member planes, with the members' area on each
    std::vector<double> member_area;
    std::vector<glm::dvec3> points;
    for (const std::uint32_t i : members) {
        const Patch& p = patches[i];
        const Plane pl{p.normal, glm::dot(p.normal, p.vertices[0])};
        std::size_t k = 0;
        while (k < planes.size() && !same_plane(planes[k], pl, tol)) ++k;
        if (k == planes.size()) {
            planes.push_back(pl);
            member_area.push_back(0.0);
        }
        member_area[k] += p.area;
        for (int v = 0; v < p.vertex_count; ++v) points.push_back(p.vertices[v]);
    }
    if (planes.size() < 2) return flat && members.size() > 1 && make_flat(planes[0], points, member_area[0], out);
    // Convex: every vertex behind (or on) every member plane, so the normals face out.
    for (const auto& pl : planes)
        for (const auto& x : points)
            if (glm::dot(pl.n, x) - pl.d > tol) return false;
    std::vector<Point> cloud;
    cloud.reserve(points.size());
    for (const auto& x : points) cloud.emplace_back(x.x, x.y, x.z);
    Hull hull;
    CGAL::convex_hull_3(cloud.begin(), cloud.end(), hull);
    if (hull.number_of_faces() < 4) return false;  // degenerate (flat) hull
    // Closed: the hull's facets on each member plane are covered by members; a facet on no
    // member plane must rest on a non-member surface facing it (outward normal against it).
    std::vector<double> hull_area(planes.size(), 0.0);
    double sliver_scale = 0.0;
    for (const double a : member_area) sliver_scale += a;
    for (const auto f : hull.faces()) {
        std::array<glm::dvec3, 3> t;
        int k = 0;
        for (const auto v : CGAL::vertices_around_face(hull.halfedge(f), hull))
            t[std::size_t(k++)] = to_glm(hull.point(v));
        const glm::dvec3 c = glm::cross(t[1] - t[0], t[2] - t[0]);
        const double len = glm::length(c);
        // Slivers of rounding (measured: 1e-12 of a Cornell block's 1e5 faces) decide nothing.
        if (0.5 * len <= 1e-9 * sliver_scale) continue;
        const Plane fp{c / len, glm::dot(c / len, t[0])};
        std::size_t m = 0;
        while (m < planes.size() && !same_plane(planes[m], fp, tol)) ++m;
        if (m < planes.size()) {
            hull_area[m] += 0.5 * len;
            continue;
        }
        bool rests = false;
        for (std::size_t q = 0; q < patches.size() && !rests; ++q) {
            if (is_member[q]) continue;
            const Patch& p = patches[q];
            rests =
                glm::dot(p.normal, fp.n) < -(1.0 - 1e-9) && std::abs(glm::dot(p.normal, p.vertices[0]) + fp.d) <= tol;
        }
        if (!rests) return false;
    }
    for (std::size_t m = 0; m < planes.size(); ++m)
        if (member_area[m] < (1.0 - 1e-6) * hull_area[m]) return false;  // a hole in a face
    std::map<Hull::Vertex_index, std::uint32_t> index;
    for (const auto v : hull.vertices()) {
        index[v] = std::uint32_t(out.corners.size());
        out.corners.push_back(to_glm(hull.point(v)));
    }
    for (const auto e : hull.edges()) out.edges.emplace_back(index[hull.vertex(e, 0)], index[hull.vertex(e, 1)]);
    return true;
}

}  // namespace

ConvexBlockers::ConvexBlockers(const std::vector<Patch>& patches, bool flat) : m_solid_of(patches.size(), -1) {
    if (patches.empty()) return;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const auto& p : patches)
        for (int v = 0; v < p.vertex_count; ++v) {
            lo = glm::min(lo, p.vertices[v]);
            hi = glm::max(hi, p.vertices[v]);
        }
    const double diag = glm::length(hi - lo), tol = 1e-9 * diag, cell = 1e-7 * diag;
    UnionFind sets(patches.size());
    std::map<int, std::uint32_t> first_of_surface;
    std::map<std::array<long long, 3>, std::vector<std::uint32_t>> at_vertex;
    for (std::uint32_t i = 0; i < patches.size(); ++i) {
        const auto [it, fresh] = first_of_surface.emplace(patches[i].surface, i);
        if (!fresh) sets.join(i, it->second);
        for (int v = 0; v < patches[i].vertex_count; ++v) {
            const glm::dvec3 q = glm::round(patches[i].vertices[v] / cell);
            at_vertex[{(long long)q.x, (long long)q.y, (long long)q.z}].push_back(i);
        }
    }
    // A convex edge between two surfaces: each wholly behind the other.
    for (const auto& [key, ids] : at_vertex)
        for (std::size_t a = 0; a < ids.size(); ++a)
            for (std::size_t b = a + 1; b < ids.size(); ++b) {
                const Patch &p = patches[ids[a]], &q = patches[ids[b]];
                if (p.surface != q.surface && wholly_behind(p, q) && wholly_behind(q, p)) sets.join(ids[a], ids[b]);
            }
    std::map<std::uint32_t, std::vector<std::uint32_t>> groups;
    for (std::uint32_t i = 0; i < patches.size(); ++i) groups[sets.find(i)].push_back(i);
    std::vector<std::uint8_t> is_member(patches.size(), 0);
    for (const auto& [root, members] : groups) {
        for (const auto i : members) is_member[i] = 1;
        Solid s;
        if (make_solid(patches, members, is_member, tol, flat, s)) {
            for (const auto i : members) m_solid_of[i] = std::int32_t(m_solids.size());
            m_solids.push_back(std::move(s));
        }
        for (const auto i : members) is_member[i] = 0;
    }
}

void convex_shadow(const ConvexBlockers::Solid& solid, const glm::dvec3& x, const glm::dvec3& o, const glm::dvec3& m,
                   std::vector<glm::dvec3>& out) {
    out.clear();
    const double hx = glm::dot(m, x - o);
    if (!(hx > 0.0)) return;
    // Only the part of the solid between the plane (h = 0) and just below x (a margin keeps
    // the projection finite) can cut a segment from x to the plane. Its corners are the
    // solid's corners in that slab and the crossings of the slab's faces by the solid's edges.
    const double top = (1.0 - 1e-7) * hx;
    thread_local std::vector<glm::dvec3> pts;
    pts.clear();
    const auto project = [&](const glm::dvec3& z, double h) { pts.push_back(x + (z - x) * (hx / (hx - h))); };
    for (const auto& c : solid.corners) {
        const double h = glm::dot(m, c - o);
        if (h >= 0.0 && h <= top) project(c, h);
    }
    for (const auto& [a, b] : solid.edges) {
        const glm::dvec3 &pa = solid.corners[a], &pb = solid.corners[b];
        const double ha = glm::dot(m, pa - o), hb = glm::dot(m, pb - o);
        for (const double level : {0.0, top})
            if ((ha - level) * (hb - level) < 0.0) project(pa + (pb - pa) * ((level - ha) / (hb - ha)), level);
    }
    if (pts.size() < 3) return;
    // Convex hull in the plane, counter-clockwise about m.
    const auto [u, v] = plane_basis(m);
    thread_local std::vector<std::array<double, 2>> p2;
    thread_local std::vector<std::uint32_t> order, chain;
    p2.resize(pts.size());
    for (std::size_t k = 0; k < pts.size(); ++k) p2[k] = {glm::dot(pts[k] - o, u), glm::dot(pts[k] - o, v)};
    convex_hull_2d(p2, order, chain);
    for (const std::uint32_t k : chain) out.push_back(pts[k]);
}

}  // namespace bounce
