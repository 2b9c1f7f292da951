// SPDX-License-Identifier: MIT
#include "mesh/geometry/surface_tree.h"

#include <algorithm>
#include <iterator>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <boost/sort/spreadsort/integer_sort.hpp>
#include <glm/geometric.hpp>

#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

K::Point_3 to_cgal(const glm::dvec3& p) { return {p.x, p.y, p.z}; }

/// Lists the triangles meeting a box, answering from bounding boxes where they decide: a
/// triangle whose box lies inside the query meets it, one whose box misses it does not; only
/// those straddling the query's faces take CGAL's exact test. The answer is the exact one, at
/// a fraction of the cost when the query holds many small triangles (a furnished room).
class BoxListing {
public:
    BoxListing(const K::Iso_cuboid_3& query, std::vector<Primitive::Id>& out) : m_box(query.bbox()), m_out(out) {}
    bool go_further() const { return true; }
    void intersection(const K::Iso_cuboid_3& query, const Primitive& primitive) {
        const K::Triangle_3& tri = *primitive.id();
        const CGAL::Bbox_3 b = tri.bbox();
        if (!CGAL::do_overlap(b, m_box)) return;
        const bool inside = b.xmin() >= m_box.xmin() && b.xmax() <= m_box.xmax() && b.ymin() >= m_box.ymin() &&
                            b.ymax() <= m_box.ymax() && b.zmin() >= m_box.zmin() && b.zmax() <= m_box.zmax();
        if (inside || CGAL::do_intersect(query, tri)) m_out.push_back(primitive.id());
    }
    bool do_intersect(const K::Iso_cuboid_3&, const CGAL::AABB_node<Tree::AABB_traits>& node) const {
        return CGAL::do_overlap(node.bbox(), m_box);
    }

private:
    CGAL::Bbox_3 m_box;
    std::vector<Primitive::Id>& m_out;
};

}  // namespace

struct SurfaceTree::Impl {
    Triangles triangles;
    std::vector<int> owner;  // per triangle: its surface
    Tree tree;

    std::vector<int> owners(const std::vector<Primitive::Id>& ids) const {
        std::vector<int> out;
        out.reserve(ids.size());
        for (const auto& id : ids) out.push_back(owner[std::size_t(id - triangles.cbegin())]);
        // Thousands of ids per box query in a furnished room: a radix sort (Boost's
        // spreadsort, which CGAL already brings) instead of a comparison sort.
        boost::sort::spreadsort::integer_sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
        return out;
    }
};

SurfaceTree::SurfaceTree(const Scene& scene) : m_impl(std::make_unique<Impl>()) {
    for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
        const auto& poly = scene.surfaces[s].vertices;
        if (!(glm::length(newell_normal(poly)) > 0)) continue;  // no area, nothing to meet
        for (const auto& t : triangulate_polygon(poly)) {
            m_impl->triangles.emplace_back(to_cgal(poly[t[0]]), to_cgal(poly[t[1]]), to_cgal(poly[t[2]]));
            m_impl->owner.push_back(int(s));
        }
    }
    if (empty()) return;
    m_impl->tree.insert(m_impl->triangles.cbegin(), m_impl->triangles.cend());
    m_impl->tree.build();
}

SurfaceTree::~SurfaceTree() = default;

bool SurfaceTree::empty() const { return m_impl->triangles.empty(); }

int SurfaceTree::first_hit(const glm::dvec3& from, const glm::dvec3& dir) const {
    if (empty()) return -1;
    const auto hit = m_impl->tree.first_intersection(K::Ray_3(to_cgal(from), K::Vector_3(dir.x, dir.y, dir.z)));
    return hit ? m_impl->owner[std::size_t(hit->second - m_impl->triangles.cbegin())] : -1;
}

std::vector<int> SurfaceTree::first_hits(const glm::dvec3& from, const glm::dvec3& dir, double slack) const {
    if (empty()) return {};
    const auto hit = m_impl->tree.first_intersection(K::Ray_3(to_cgal(from), K::Vector_3(dir.x, dir.y, dir.z)));
    if (!hit) return {};
    // Where along the ray: on the first triangle's plane.
    const K::Triangle_3& tri = *hit->second;
    const glm::dvec3 a(tri[0].x(), tri[0].y(), tri[0].z()), b(tri[1].x(), tri[1].y(), tri[1].z()),
        c(tri[2].x(), tri[2].y(), tri[2].z());
    const glm::dvec3 n = glm::cross(b - a, c - a), u = glm::normalize(dir);
    const double along = glm::dot(n, u);
    if (along == 0.0) return {m_impl->owner[std::size_t(hit->second - m_impl->triangles.cbegin())]};
    const double t = glm::dot(n, a - from) / along;
    return on_segment(from + std::max(0.0, t - slack) * u, from + (t + slack) * u);
}

std::vector<int> SurfaceTree::in_box(const glm::dvec3& lo, const glm::dvec3& hi) const {
    if (empty()) return {};
    std::vector<Primitive::Id> ids;
    const K::Iso_cuboid_3 query(to_cgal(lo), to_cgal(hi));
    BoxListing listing(query, ids);
    m_impl->tree.traversal(query, listing);
    return m_impl->owners(ids);
}

std::vector<int> SurfaceTree::on_segment(const glm::dvec3& a, const glm::dvec3& b) const {
    if (empty()) return {};
    std::vector<Primitive::Id> ids;
    m_impl->tree.all_intersected_primitives(K::Segment_3(to_cgal(a), to_cgal(b)), std::back_inserter(ids));
    return m_impl->owners(ids);
}

}  // namespace bounce
