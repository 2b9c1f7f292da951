// SPDX-License-Identifier: MIT
#include <algorithm>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <glm/geometric.hpp>

#include "solver/visibility/visibility.h"

namespace bounce {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

K::Point_3 to_cgal(const glm::dvec3& p) { return {p.x, p.y, p.z}; }

class CgalVisibility final : public Visibility {
public:
    CgalVisibility(const std::vector<Patch>& patches, std::span<const OccluderTriangle> occluders) {
        fit_offset(patches);
        m_has_occluders = !occluders.empty();
        for (std::size_t i = 0; i < patches.size(); ++i) {
            const Patch& p = patches[i];
            for (int k = 1; k + 1 < p.vertex_count; ++k) {
                m_triangles.emplace_back(to_cgal(p.vertices[0]), to_cgal(p.vertices[k]), to_cgal(p.vertices[k + 1]));
                m_patch_of.push_back(int(i));
            }
        }
        for (const auto& t : occluders) {
            const K::Triangle_3 tri(to_cgal(t[0]), to_cgal(t[1]), to_cgal(t[2]));
            if (tri.is_degenerate()) continue;
            m_triangles.push_back(tri);
            m_patch_of.push_back(kOccluder);
        }
        m_tree.insert(m_triangles.cbegin(), m_triangles.cend());
        m_tree.build();  // build now: lazy construction inside concurrent queries would race
    }
    bool occluded(const glm::dvec3& a, const glm::dvec3& b) const override {
        const double t0 = trim(a, b);
        if (t0 >= 0.5) return false;
        return m_tree.do_intersect(K::Segment_3(to_cgal(a + t0 * (b - a)), to_cgal(b - t0 * (b - a))));
    }
    int first_patch(const glm::dvec3& a, const glm::dvec3& b) const override {
        const double t0 = trim(a, b);
        if (t0 >= 0.5) return kNothing;
        const glm::dvec3 from = a + t0 * (b - a), to = b - t0 * (b - a);
        const auto hit = m_tree.first_intersection(K::Ray_3(to_cgal(from), to_cgal(to)));
        if (!hit) return kNothing;
        // A ray meets a triangle in a point, or (in its plane) a segment; its near end counts.
        K::Point_3 at;
        if (const auto* p = boost::get<K::Point_3>(&hit->first))
            at = *p;
        else if (const auto* s = boost::get<K::Segment_3>(&hit->first))
            at = CGAL::squared_distance(s->source(), to_cgal(from)) < CGAL::squared_distance(s->target(), to_cgal(from))
                     ? s->source()
                     : s->target();
        else
            return kNothing;
        const glm::dvec3 x(at.x(), at.y(), at.z());
        if (glm::dot(x - from, to - from) > glm::dot(to - from, to - from)) return kNothing;  // beyond b
        return m_patch_of[std::size_t(hit->second - m_triangles.cbegin())];
    }
    std::string name() const override { return "cgal"; }

private:
    Triangles m_triangles;
    std::vector<int> m_patch_of;  // per triangle: its patch, or kOccluder
    Tree m_tree;
};

}  // namespace

std::unique_ptr<Visibility> make_cgal_visibility(const std::vector<Patch>& patches,
                                                 std::span<const OccluderTriangle> occluders) {
    return std::make_unique<CgalVisibility>(patches, occluders);
}

}  // namespace bounce
