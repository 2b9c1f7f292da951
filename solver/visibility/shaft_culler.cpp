// SPDX-License-Identifier: MIT
#include "solver/visibility/shaft_culler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace bounce {
namespace {

struct Plane {
    glm::dvec3 n;  // the shaft is on the side n . x >= d
    double d;
};

/// The largest value of n . x over a box (the corner furthest along n).
double box_max(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& n) {
    return (n.x > 0 ? n.x * hi.x : n.x * lo.x) + (n.y > 0 ? n.y * hi.y : n.y * lo.y) +
           (n.z > 0 ? n.z * hi.z : n.z * lo.z);
}

}  // namespace

ShaftCuller::ShaftCuller(const std::vector<Patch>& patches) : m_patches(patches) {
    const std::size_t n = patches.size();
    m_lo.resize(n);
    m_hi.resize(n);
    glm::dvec3 lo(1e300), hi(-1e300);
    for (std::size_t k = 0; k < n; ++k) {
        m_lo[k] = m_hi[k] = patches[k].vertices[0];
        for (int v = 1; v < patches[k].vertex_count; ++v) {
            m_lo[k] = glm::min(m_lo[k], patches[k].vertices[v]);
            m_hi[k] = glm::max(m_hi[k], patches[k].vertices[v]);
        }
        lo = glm::min(lo, m_lo[k]);
        hi = glm::max(hi, m_hi[k]);
    }
    m_tol = n ? 1e-9 * glm::length(hi - lo) : 0.0;
    // Group by plane (normal and offset rounded; a plane split over two groups is only slower).
    std::map<std::array<long long, 4>, std::size_t> index;
    std::vector<std::vector<std::uint32_t>> members;
    const double unit = std::max(10.0 * m_tol, 1e-300);
    for (std::uint32_t k = 0; k < n; ++k) {
        const glm::dvec3 nk = patches[k].normal;
        const double dk = glm::dot(nk, patches[k].vertices[0]);
        const std::array<long long, 4> key = {std::llround(nk.x * 1e9), std::llround(nk.y * 1e9),
                                              std::llround(nk.z * 1e9), std::llround(dk / unit)};
        const auto [it, added] = index.try_emplace(key, m_groups.size());
        if (added) {
            m_groups.push_back({nk, dk, 0, 0.0});
            members.emplace_back();
        }
        members[it->second].push_back(k);
        Group& g = m_groups[it->second];
        for (int v = 0; v < patches[k].vertex_count; ++v)
            g.spread = std::max(g.spread, std::abs(glm::dot(g.normal, patches[k].vertices[v]) - g.offset));
    }
    // A group beside every vertex of the scene is beside every shaft: test it once here, not
    // per pair (equivalent to the per-pair test, so no answer changes).
    std::size_t kept = 0;
    for (std::size_t g = 0; g < m_groups.size(); ++g) {
        if (supporting(m_groups[g], patches, lo, hi)) continue;
        m_groups[kept] = m_groups[g];
        members[kept++] = std::move(members[g]);
    }
    m_groups.resize(kept);
    members.resize(kept);
    // Per-patch side bits, within a budget of patch x group tests: a scene of many planes (an
    // office's furniture) keeps the per-pair corner test instead of O(N x groups) memory.
    constexpr std::size_t kMaxSideTests = std::size_t(1) << 25;
    m_words = n * m_groups.size() <= kMaxSideTests ? (m_groups.size() + 63) / 64 : 0;
    m_above.assign(n * m_words, 0);
    m_below.assign(n * m_words, 0);
    for (std::size_t k = 0; k < n && m_words > 0; ++k)
        for (std::size_t g = 0; g < m_groups.size(); ++g) {
            const Sides s = sides(m_groups[g], patches[k].vertices.data(), patches[k].vertex_count);
            if (s.above) m_above[k * m_words + g / 64] |= std::uint64_t(1) << (g % 64);
            if (s.below) m_below[k * m_words + g / 64] |= std::uint64_t(1) << (g % 64);
        }
    m_nodes.reserve(2 * n + m_groups.size());
    for (std::size_t g = 0; g < m_groups.size(); ++g) {
        const std::uint32_t begin = std::uint32_t(m_order.size());
        m_order.insert(m_order.end(), members[g].begin(), members[g].end());
        m_groups[g].root = std::uint32_t(m_nodes.size());
        m_nodes.push_back({});
        build(m_groups[g].root, begin, std::uint32_t(m_order.size()));
    }
}

bool ShaftCuller::supporting(const Group& g, const std::vector<Patch>& patches, const glm::dvec3& lo,
                             const glm::dvec3& hi) const {
    // The scene's box first (enough for axis-aligned rooms), then its vertices, stopping at the
    // first one on the wrong side (quick in cluttered scenes, where most planes are crossed).
    const double top = box_max(lo, hi, g.normal) - g.offset, bottom = -box_max(lo, hi, -g.normal) - g.offset;
    if (bottom >= g.spread - m_tol || top <= m_tol - g.spread) return true;
    bool above = true, below = true;
    for (std::size_t k = 0; k < patches.size() && (above || below); ++k) {
        const Sides s = sides(g, patches[k].vertices.data(), patches[k].vertex_count);
        above &= s.above;
        below &= s.below;
    }
    return above || below;
}

void ShaftCuller::build(std::uint32_t node, std::uint32_t begin, std::uint32_t end) {
    glm::dvec3 lo(1e300), hi(-1e300), clo(1e300), chi(-1e300);
    for (std::uint32_t k = begin; k < end; ++k) {
        lo = glm::min(lo, m_lo[m_order[k]]);
        hi = glm::max(hi, m_hi[m_order[k]]);
        const glm::dvec3 c = 0.5 * (m_lo[m_order[k]] + m_hi[m_order[k]]);
        clo = glm::min(clo, c);
        chi = glm::max(chi, c);
    }
    m_nodes[node].lo = lo;
    m_nodes[node].hi = hi;
    if (end - begin <= 4) {
        m_nodes[node].first = begin;
        m_nodes[node].count = end - begin;
        return;
    }
    // Median split along the widest axis of the box centres.
    const glm::dvec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(m_order.begin() + begin, m_order.begin() + mid, m_order.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                         return m_lo[a][axis] + m_hi[a][axis] < m_lo[b][axis] + m_hi[b][axis];
                     });
    const std::uint32_t left = std::uint32_t(m_nodes.size());
    m_nodes[node].first = left;
    m_nodes[node].count = 0;
    m_nodes.push_back({});
    m_nodes.push_back({});
    build(left, begin, mid);
    build(left + 1, mid, end);
}

namespace {

/// The vertices of both patches: the shaft is their convex hull.
struct ShaftCorners {
    std::array<glm::dvec3, 8> pts;
    int count = 0;
};

ShaftCorners shaft_corners(const Patch& p, const Patch& q) {
    ShaftCorners c;
    for (int k = 0; k < p.vertex_count; ++k) c.pts[std::size_t(c.count++)] = p.vertices[k];
    for (int k = 0; k < q.vertex_count; ++k) c.pts[std::size_t(c.count++)] = q.vertices[k];
    return c;
}

}  // namespace

ShaftCuller::Sides ShaftCuller::sides(const Group& g, const glm::dvec3* pts, int np) const {
    // Beyond the members' spread about the plane, less the tolerance: on it counts as both.
    Sides s;
    for (int m = 0; m < np; ++m) {
        const double h = glm::dot(g.normal, pts[m]) - g.offset;
        s.above &= h >= g.spread - m_tol;
        s.below &= h <= m_tol - g.spread;
    }
    return s;
}

bool ShaftCuller::beside(const Group& g, const glm::dvec3* pts, int np) const {
    // The whole shaft on one side of the group's plane: nothing in the group blocks.
    const Sides s = sides(g, pts, np);
    return s.above || s.below;
}

bool ShaftCuller::clear(std::size_t i, std::size_t j) const {
    if (m_groups.empty()) return true;  // every plane supports the scene: a convex room
    if (std::max(i, j) >= m_above.size() / std::max<std::size_t>(m_words, 1)) {
        // A patch added after construction (refinement appends elements), or no bits (over
        // their budget): test the corners.
        const ShaftCorners c = shaft_corners(m_patches[i], m_patches[j]);
        for (const Group& g : m_groups)
            if (!beside(g, c.pts.data(), c.count)) return false;
        return true;
    }
    // The shaft's corners are the two patches' vertices, so beside(g) for the pair is "both
    // patches above g" or "both below g", each precomputed per patch.
    const std::size_t groups = m_groups.size();
    for (std::size_t w = 0; w < m_words; ++w) {
        const std::uint64_t beside_all = (m_above[i * m_words + w] & m_above[j * m_words + w]) |
                                         (m_below[i * m_words + w] & m_below[j * m_words + w]);
        const std::size_t bits = std::min<std::size_t>(64, groups - 64 * w);
        const std::uint64_t all = bits == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << bits) - 1;
        if (beside_all != all) return false;
    }
    return true;
}

template <class Found>
void ShaftCuller::walk(const Patch& p, const Patch& q, std::size_t i, std::size_t j, Found&& found) const {
    if (m_patches.empty()) return;
    const double tol = m_tol;
    // The shaft: the box of both patches and the supporting planes of their convex hull.
    glm::dvec3 lo = p.vertices[0], hi = p.vertices[0];
    for (int v = 0; v < p.vertex_count; ++v) lo = glm::min(lo, p.vertices[v]), hi = glm::max(hi, p.vertices[v]);
    for (int v = 0; v < q.vertex_count; ++v) lo = glm::min(lo, q.vertices[v]), hi = glm::max(hi, q.vertices[v]);
    lo -= tol;
    hi += tol;
    const ShaftCorners c = shaft_corners(p, q);
    const auto& pts = c.pts;
    const int np = c.count;
    std::array<Plane, 2 + 2 * 16> planes;
    int nplanes = 0;
    planes[nplanes++] = {p.normal, glm::dot(p.normal, p.vertices[0])};
    planes[nplanes++] = {q.normal, glm::dot(q.normal, q.vertices[0])};
    const auto add_edge_planes = [&](const Patch& a, const Patch& b) {
        for (int e = 0; e < a.vertex_count; ++e) {
            const glm::dvec3 &u = a.vertices[e], &v = a.vertices[(e + 1) % a.vertex_count];
            for (int k = 0; k < b.vertex_count; ++k) {
                glm::dvec3 n = glm::cross(v - u, b.vertices[k] - u);
                const double len = glm::length(n);
                if (len <= 1e-12 * glm::dot(v - u, v - u)) continue;
                n /= len;
                bool pos = true, neg = true;
                for (int m = 0; m < np; ++m) {
                    const double h = glm::dot(n, pts[m] - u);
                    pos &= h >= -tol;
                    neg &= h <= tol;
                }
                if (pos == neg) continue;  // not a supporting plane (or the hull is flat)
                if (neg) n = -n;
                planes[nplanes++] = {n, glm::dot(n, u)};
            }
        }
    };
    const auto outside = [&](const glm::dvec3& blo, const glm::dvec3& bhi) {
        if (blo.x > hi.x || blo.y > hi.y || blo.z > hi.z || bhi.x < lo.x || bhi.y < lo.y || bhi.z < lo.z) return true;
        for (int k = 0; k < nplanes; ++k)
            if (box_max(blo, bhi, planes[k].n) <= planes[k].d + tol) return true;
        return false;
    };
    thread_local std::vector<std::uint32_t> stack;
    stack.resize(m_groups.size() + 64);
    int top = 0;
    for (const Group& g : m_groups)
        if (!beside(g, pts.data(), np)) stack[top++] = g.root;
    if (top == 0) return;  // every plane group is beside the shaft (an empty convex room)
    add_edge_planes(p, q);
    add_edge_planes(q, p);
    while (top > 0) {
        const Node& node = m_nodes[stack[--top]];
        if (outside(node.lo, node.hi)) continue;
        if (node.count == 0) {
            stack[top++] = node.first;
            stack[top++] = node.first + 1;
            continue;
        }
        for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
            const std::uint32_t k = m_order[s];
            if (k == i || k == j || outside(m_lo[k], m_hi[k])) continue;
            const Patch& b = m_patches[k];
            // Separated by a shaft plane: every vertex of b outside or on it.
            bool separated = false;
            for (int c = 0; c < nplanes && !separated; ++c) {
                bool all_out = true;
                for (int v = 0; v < b.vertex_count && all_out; ++v)
                    all_out = glm::dot(planes[c].n, b.vertices[v]) <= planes[c].d + tol;
                separated = all_out;
            }
            if (separated) continue;
            // Separated by b's own plane: the whole shaft on one side of it.
            bool pos = true, neg = true;
            for (int m = 0; m < np; ++m) {
                const double h = b.height(pts[m]);
                pos &= h >= -tol;
                neg &= h <= tol;
            }
            if (pos || neg) continue;
            if (found(k)) return;
        }
    }
}

void ShaftCuller::candidates(std::size_t i, std::size_t j, std::vector<std::uint32_t>& out) const {
    out.clear();
    if (m_patches.empty()) return;
    walk(m_patches[i], m_patches[j], i, j, [&out](std::uint32_t k) {
        out.push_back(k);
        return false;
    });
}

bool ShaftCuller::unblocked(const Patch& p, const Patch& q) const {
    constexpr auto none = std::numeric_limits<std::size_t>::max();
    bool blocked = false;
    walk(p, q, none, none, [&blocked](std::uint32_t) { return blocked = true; });
    return !blocked;
}

}  // namespace bounce
