// SPDX-License-Identifier: MIT
#include "solver/refinement/cluster_tree.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace bounce {

ClusterTree::ClusterTree(const std::vector<Patch>& patches) : m_patch_parent(patches.size(), -1) {
    if (patches.size() < 2) return;
    m_clusters.reserve(patches.size() - 1);
    std::vector<std::uint32_t> ids(patches.size());
    for (std::uint32_t k = 0; k < ids.size(); ++k) ids[k] = k;
    build(patches, ids, 0, ids.size(), -1);
}

std::uint32_t ClusterTree::build(const std::vector<Patch>& patches, std::vector<std::uint32_t>& ids, std::size_t begin,
                                 std::size_t end, std::int32_t parent) {
    if (end - begin == 1) {
        m_patch_parent[ids[begin]] = parent;
        return ids[begin];
    }
    const auto c = std::uint32_t(m_clusters.size());
    m_clusters.emplace_back();  // parents before children
    m_clusters[c].parent = parent;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (std::size_t k = begin; k < end; ++k) {
        lo = glm::min(lo, patches[ids[k]].centre);
        hi = glm::max(hi, patches[ids[k]].centre);
    }
    const glm::dvec3 ext = hi - lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const std::size_t mid = begin + (end - begin) / 2;
    std::nth_element(ids.begin() + std::ptrdiff_t(begin), ids.begin() + std::ptrdiff_t(mid),
                     ids.begin() + std::ptrdiff_t(end), [&](std::uint32_t a, std::uint32_t b) {
                         const double ca = patches[a].centre[axis], cb = patches[b].centre[axis];
                         return ca < cb || (ca == cb && a < b);
                     });
    const std::array<std::uint32_t, 2> child{build(patches, ids, begin, mid, std::int32_t(c)),
                                             build(patches, ids, mid, end, std::int32_t(c))};
    // Aggregate the children (m_clusters may have grown: index, do not hold references).
    Cluster agg;
    agg.child = child;
    agg.parent = parent;
    struct Part {
        double area, radius;
        glm::dvec3 centre;
    };
    std::array<Part, 2> part{};
    std::array<std::array<glm::dvec3, 4>, 2> samples{}, normals{};
    std::array<int, 2> counts{};
    for (int s = 0; s < 2; ++s) {
        const std::uint32_t ref = child[s];
        if (is_cluster(ref)) {
            const Cluster& k = m_clusters[index(ref)];
            part[s] = {k.area, k.radius, k.centre};
            agg.lo = glm::min(agg.lo, k.lo);
            agg.hi = glm::max(agg.hi, k.hi);
            for (int a = 0; a < 6; ++a) agg.axis_area[a] += k.axis_area[a];
            agg.area_normal += k.area_normal;
            samples[s] = k.sample;
            normals[s] = k.sample_normal;
            counts[s] = k.sample_count;
        } else {
            const Patch& p = patches[ref];
            part[s] = {p.area, circumradius(p), p.centre};
            for (int v = 0; v < p.vertex_count; ++v) {
                agg.lo = glm::min(agg.lo, p.vertices[v]);
                agg.hi = glm::max(agg.hi, p.vertices[v]);
            }
            for (int a = 0; a < 3; ++a) {
                agg.axis_area[a] += p.area * std::max(0.0, p.normal[a]);
                agg.axis_area[a + 3] += p.area * std::max(0.0, -p.normal[a]);
            }
            agg.area_normal += p.area * p.normal;
            samples[s][0] = p.centre;
            normals[s][0] = p.normal;
            counts[s] = 1;
        }
    }
    agg.area = part[0].area + part[1].area;
    agg.centre = (part[0].area * part[0].centre + part[1].area * part[1].centre) / agg.area;
    for (int s = 0; s < 2; ++s)
        agg.radius = std::max(agg.radius, glm::length(part[s].centre - agg.centre) + part[s].radius);
    // Samples alternate between the children, so four of them reach four grandchildren.
    for (int k = 0; k < 4 && agg.sample_count < 4; ++k)
        for (int s = 0; s < 2 && agg.sample_count < 4; ++s)
            if (k < counts[s]) {
                agg.sample[std::size_t(agg.sample_count)] = samples[s][std::size_t(k)];
                agg.sample_normal[std::size_t(agg.sample_count)] = normals[s][std::size_t(k)];
                ++agg.sample_count;
            }
    // The normal cone about the mean normal, over the members (ids[begin, end)).
    const double len = glm::length(agg.area_normal);
    if (len > 1e-9 * agg.area) {
        agg.cone_axis = agg.area_normal / len;
        agg.cone_cos = 1.0;
        for (std::size_t k = begin; k < end; ++k)
            agg.cone_cos = std::min(agg.cone_cos, glm::dot(agg.cone_axis, patches[ids[k]].normal));
    }
    m_clusters[c] = agg;
    return c | cluster_bit;
}

ClusterTree::Range ClusterTree::projected_area(const Cluster& c, const glm::dvec3& d) {
    // Every member faces d (angle to the axis plus the cone's half-angle within 90 degrees):
    // the sum of A_j n_j . d is exact; every member faces away: nothing shows.
    if (c.cone_cos > -1.0) {
        const double a = std::acos(std::clamp(glm::dot(c.cone_axis, d), -1.0, 1.0));
        const double half = std::acos(std::clamp(c.cone_cos, -1.0, 1.0));
        if (a + half <= 0.5 * std::numbers::pi) {
            const double exact = std::max(0.0, glm::dot(c.area_normal, d));
            return {exact, exact};
        }
        if (a - half >= 0.5 * std::numbers::pi) return {0.0, 0.0};
    }
    // max(0, n.d) <= sum_k |d_k| max(0, sign(d_k) n_k), and sum_j A_j max(0, n_j.d) >= max(0, (sum_j A_j n_j).d).
    double hi = 0.0;
    for (int k = 0; k < 3; ++k) hi += std::abs(d[k]) * c.axis_area[std::size_t(d[k] >= 0 ? k : k + 3)];
    return {std::max(0.0, glm::dot(c.area_normal, d)), std::min(hi, c.area)};
}

}  // namespace bounce

namespace bounce {

double ClusterTree::shown_area(std::uint32_t ref, const glm::dvec3& d, const std::vector<Patch>& patches,
                               int depth) const {
    if (!is_cluster(ref)) return patches[ref].area * std::max(0.0, glm::dot(patches[ref].normal, d));
    const Cluster& c = cluster(ref);
    const Range r = projected_area(c, d);
    if (r.lo == r.hi) return r.lo;
    if (depth <= 0) return 0.5 * (r.lo + r.hi);
    return shown_area(c.child[0], d, patches, depth - 1) + shown_area(c.child[1], d, patches, depth - 1);
}

}  // namespace bounce
