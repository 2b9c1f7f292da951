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
        for (const auto& p : patches)
            for (int k = 1; k + 1 < p.vertex_count; ++k)
                m_triangles.emplace_back(to_cgal(p.vertices[0]), to_cgal(p.vertices[k]), to_cgal(p.vertices[k + 1]));
        for (const auto& t : occluders) {
            const K::Triangle_3 tri(to_cgal(t[0]), to_cgal(t[1]), to_cgal(t[2]));
            if (!tri.is_degenerate()) m_triangles.push_back(tri);
        }
        m_tree.insert(m_triangles.cbegin(), m_triangles.cend());
        m_tree.build();  // build now: lazy construction inside concurrent queries would race
    }
    bool occluded(const glm::dvec3& a, const glm::dvec3& b) const override {
        const double t0 = trim(a, b);
        if (t0 >= 0.5) return false;
        return m_tree.do_intersect(K::Segment_3(to_cgal(a + t0 * (b - a)), to_cgal(b - t0 * (b - a))));
    }
    std::string name() const override { return "cgal"; }

private:
    Triangles m_triangles;
    Tree m_tree;
};

}  // namespace

std::unique_ptr<Visibility> make_cgal_visibility(const std::vector<Patch>& patches,
                                                 std::span<const OccluderTriangle> occluders) {
    return std::make_unique<CgalVisibility>(patches, occluders);
}

}  // namespace bounce
